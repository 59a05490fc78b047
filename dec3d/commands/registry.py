"""The command registry: one declaration per command, one per range element.

    @command("model gravity", positional=[P("g", Nums(1, 3), "...")], doc="...",
             examples=["model gravity 0 0 -9.81"])
    def model_gravity(session, call): ...

Commands live in a tree keyed by their words. Each node knows its children, so
abbreviations resolve level by level (`b his` is `block history`). 3DEC commands that
dec3d does not implement yet are in the tree too (see catalogue.py): binding one
raises "`<command>` is not supported yet" instead of "unknown command".
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Iterable, Sequence

from ..lang.abbrev import matches
from .values import InPath, OutPath, Param


@dataclass
class Command:
    path: tuple[str, ...]
    handler: Callable
    positional: tuple[Param, ...] = ()
    keywords: tuple[Param, ...] = ()
    range: str | None = None            # store the range selects from ("block", "contact", ...)
    doc: str = ""
    details: str = ""
    examples: tuple[str, ...] = ()
    open_keywords: bool = False        # accept keywords not declared (user joint-model properties)
    accepts_anything: bool = False     # display-only commands: every token ignored
    module: str = ""
    check: Callable | None = None      # check(call) at bind time: value combinations, not-supported choices
    # batch(session, calls) -> n: run lines of commands sharing this function, met one after another
    # in a deck, in one pass; runs the first n calls as the handler would have, one by one, and stops
    # before a call it cannot do (the session runs that one and the rest through the handler)
    batch: Callable | None = None

    def __post_init__(self) -> None:
        # looked up for every bound line: computed once
        self.keyword_names: tuple[str, ...] = tuple(p.name for p in self.keywords)
        self.by_name: dict[str, Param] = {p.name: p for p in self.keywords}
        self.by_key: dict[str, Param] = {p.key: p for p in self.positional + self.keywords}
        # the parameters naming files (OutPath, InPath), in declaration order: checked at bind time
        self.file_params: tuple[Param, ...] = tuple(p for p in self.positional + self.keywords
                                                    if isinstance(p.value, (OutPath, InPath)))

    @property
    def name(self) -> str:
        return " ".join(self.path)

    def keyword(self, name: str) -> Param | None:
        return self.by_name.get(name)


@dataclass
class Node:
    """A word of the command tree."""

    name: str
    children: dict[str, "Node"] = field(default_factory=dict)
    command: Command | None = None
    known: bool = False                # a 3DEC command or command group dec3d knows by name
    keywords: tuple[Param, ...] = ()   # keywords allowed before the next command word (`block create group 'g' poly`)
    alias_of: tuple[str, ...] | None = None
    cache: dict = field(default_factory=dict, repr=False)   # word -> matching child names

    def match(self, word: str) -> list[str]:
        """Children `word` may abbreviate (memoised per node: decks repeat their words)."""
        hit = self.cache.get(word)
        if hit is None:
            hit = self.cache[word] = matches(word, self.children)
        return hit

    def child(self, name: str) -> "Node":
        node = self.children.get(name)
        if node is None:
            node = self.children[name] = Node(name)
            self.cache.clear()
        return node


@dataclass
class RangeElement:
    name: str
    mask: Callable | None               # mask(session, store, args) -> bool array
    positional: tuple[Param, ...] = ()
    keywords: tuple[Param, ...] = ()
    doc: str = ""
    stores: tuple[str, ...] = ()        # stores the element applies to; () = all
    supported: bool = True


class Registry:
    def __init__(self) -> None:
        self.root = Node("")
        self.commands: dict[tuple[str, ...], Command] = {}
        self.range_elements: dict[str, RangeElement] = {}
        self.aliases: dict[str, tuple[str, ...]] = {}
        self._resolve_cache: dict = {}

    # ---------------------------------------------------------------- building
    def add(self, cmd: Command) -> Command:
        if cmd.path in self.commands:
            raise ValueError(f"command `{cmd.name}` registered twice")
        node = self.root
        for w in cmd.path:
            node = node.child(w)
        node.command = cmd
        node.known = True
        self.commands[cmd.path] = cmd
        self._resolve_cache.clear()
        return cmd

    def know(self, path: str | Sequence[str]) -> Node:
        """Declare a 3DEC command (group) by name only."""
        words = path.split() if isinstance(path, str) else list(path)
        node = self.root
        for w in words:
            node = node.child(w)
            node.known = True
        return node

    def node_keywords(self, path: str, keywords: Iterable[Param]) -> None:
        node = self.know(path)
        node.keywords = tuple(keywords)

    def alias(self, word: str, target: str) -> None:
        """A top-level word standing for a longer command (`call` = `program call`)."""
        node = self.root.child(word)
        node.known = True
        self.root.cache.clear()
        node.alias_of = tuple(target.split())
        self.aliases[word] = node.alias_of

    def add_range_element(self, elem: RangeElement) -> RangeElement:
        if elem.name in self.range_elements and self.range_elements[elem.name].supported and elem.supported:
            raise ValueError(f"range element `{elem.name}` registered twice")
        self.range_elements[elem.name] = elem
        return elem

    def node(self, path: Sequence[str]) -> Node | None:
        node = self.root
        for w in path:
            node = node.children.get(w)
            if node is None:
                return None
        return node

    def walk(self, node: Node | None = None, prefix=()):
        """Yield (path, node) for every node under `node`, depth first, sorted."""
        node = node or self.root
        for name in sorted(node.children):
            child = node.children[name]
            path = prefix + (name,)
            yield path, child
            yield from self.walk(child, path)


REGISTRY = Registry()


def command(path: str, *, positional: Sequence[Param] = (), keywords: Sequence[Param] = (),
            range: str | None = None, doc: str = "", details: str = "", examples: Sequence[str] = (),
            open_keywords: bool = False, accepts_anything: bool = False, check: Callable | None = None,
            batch: Callable | None = None, registry: Registry = REGISTRY):
    """Register the decorated function as the handler of `path`.

    `check(call)`, if given, runs when a line is bound (before anything in the deck runs):
    for rules one keyword's type cannot say, such as a model name dec3d knows but does not
    implement (raise NotSupportedError) or keywords that exclude each other (BindError).
    `batch(session, calls) -> n`, if given, runs a run of such lines in one pass (``Command.batch``)."""

    def deco(fn: Callable) -> Callable:
        registry.add(Command(tuple(path.split()), fn, tuple(positional), tuple(keywords), range,
                             doc or (fn.__doc__ or "").strip().split("\n")[0], details, tuple(examples),
                             open_keywords, accepts_anything, fn.__module__, check, batch))
        return fn

    return deco


def range_element(name: str, *, positional: Sequence[Param] = (), keywords: Sequence[Param] = (),
                  doc: str = "", stores: Sequence[str] = (), registry: Registry = REGISTRY):
    """Register the decorated function `mask(session, store, args) -> bool array` as a range element."""

    def deco(fn: Callable) -> Callable:
        registry.add_range_element(RangeElement(name, fn, tuple(positional), tuple(keywords),
                                                doc or (fn.__doc__ or "").strip().split("\n")[0], tuple(stores)))
        return fn

    return deco
