"""A Session: one model, its FISH variables, and the machinery to read and run decks.

    s = dec3d.Session()
    s.command("model gravity 0 0 -9.81")
    s.call("deck.dat")

A deck (with every file it calls by a literal name) is parsed and bound completely
before its first command runs; a syntax or keyword error anywhere stops it before
any work is done. Commands then run in order; `[expr]` and `@name` values are
evaluated just before their command runs.
"""
from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterable, TextIO

from .commands import load_all
from .commands.binder import BindContext, Binder, CommandCall, ExprStatement
from .commands.values import Deferred, ValueRangeError
from .errors import BindError, CommandError, Dec3dError, ExpressionError, SourceLocation, printable
from .lang.expr import EvalContext, evaluate
from .lang.parser import ParsedDeck, parse_deck
from .lang.prepass import FishBlock
from .model.model import Model


@dataclass(frozen=True)
class FishDefine:
    block: FishBlock
    location: SourceLocation
    source: str


@dataclass(frozen=True)
class Enter:
    """Marks the start of a called file in the item list (for echo and `program return`)."""

    path: Path
    location: SourceLocation
    source: str


Item = CommandCall | ExprStatement | FishDefine | Enter


class StopDeck(Exception):
    """`program exit`: stop running, keep the model."""


class Session:
    def __init__(self, out_dir: str | Path | None = None, echo: bool = False, stdout: TextIO | None = None):
        load_all()
        self.model = Model()
        self.variables: dict[str, Any] = {}
        self.fish: dict[str, FishBlock] = {}
        self.out_dir = Path(out_dir) if out_dir is not None else Path.cwd()
        self.echo = echo
        self.stdout = stdout if stdout is not None else sys.stdout
        self.log_path: Path | None = None
        self.log_on = False
        self._log_handle: TextIO | None = None
        self.record: list[str] = []       # text of every command run, for save files
        self.results: dict[str, float] = {}  # named figures commands report (verification reads them)
        self.bind_context = BindContext(self.variables)

    # ------------------------------------------------------------------ output
    def write(self, text: str) -> None:
        """Print a line to the console (and the log file when logging is on).

        Control characters (from deck text: echoed commands, `io.out` strings) are written as
        visible escapes, so a deck cannot drive the terminal."""
        text = printable(text, newlines=True)
        print(text, file=self.stdout)
        if self.log_on and self._log_handle is not None:
            self._log_handle.write(text + "\n")
            self._log_handle.flush()

    def out_path(self, name: str | Path) -> Path:
        """Where a file the deck names is written: relative names go under the output folder."""
        p = Path(name)
        return p if p.is_absolute() else self.out_dir / p

    def open_log(self, path: Path | None, append: bool = False) -> None:
        self.close_log()
        self.log_path = path or self.log_path or self.out_path("dec3d.log")
        self.log_path.parent.mkdir(parents=True, exist_ok=True)
        self._log_handle = open(self.log_path, "a" if append else "w", encoding="utf-8")

    def close_log(self) -> None:
        if self._log_handle is not None:
            self._log_handle.close()
            self._log_handle = None

    # ------------------------------------------------------------------ reading
    def load_text(self, text: str, filename: str = "<input>", base_dir: Path | None = None,
                  stack: tuple[SourceLocation, ...] = ()) -> list[Item]:
        """Parse and bind text (and the files it calls); nothing runs."""
        deck = parse_deck(text, filename, stack)
        return self._bind_deck(deck, base_dir or Path.cwd(), stack)

    def load_file(self, path: str | Path, stack: tuple[SourceLocation, ...] = ()) -> list[Item]:
        path = Path(path)
        try:
            text = path.read_text(encoding="utf-8", errors="replace")
        except OSError as exc:
            # a called file: point at the `program call` line that names it
            raise CommandError(f"cannot read deck `{path}`: {exc.strerror or exc}",
                               stack[-1] if stack else None) from None
        return self.load_text(text, str(path), path.parent, stack)

    def _bind_deck(self, deck: ParsedDeck, base_dir: Path, stack) -> list[Item]:
        binder = Binder(deck, self.bind_context, stack)
        items: list[Item] = []
        fish = iter(deck.fish)
        next_fish = next(fish, None)
        for raw in deck.lines:
            while next_fish is not None and next_fish.line < raw.line:
                items.append(self._fish_item(deck, next_fish, stack))
                next_fish = next(fish, None)
            call = binder.bind_line(raw)
            if isinstance(call, ExprStatement):
                items.append(call)
                continue
            path = call.command.path
            if path == ("program", "call") and not isinstance(call.args["file"], Deferred):
                # a literal name: the called file is read and bound now, in place of the call
                target = self._resolve_call_path(call.args["file"], base_dir)
                if any(Path(s.file) == target for s in stack) or Path(deck.filename) == target:
                    raise BindError(f"`{target.name}` calls itself (directly or through other files)", call.location)
                items.append(Enter(target, call.location, call.text))
                items.extend(self.load_file(target, stack + (call.location,)))
                continue
            items.append(call)
            if path == ("program", "return"):
                break       # the rest of this file is not run (3DEC: return to the caller)
        while next_fish is not None:
            items.append(self._fish_item(deck, next_fish, stack))
            next_fish = next(fish, None)
        return items

    def _fish_item(self, deck: ParsedDeck, block: FishBlock, stack) -> FishDefine:
        self.bind_context.define_fish(block)
        text = deck.source_lines[block.line - 1]
        loc = SourceLocation(deck.filename, block.line, 1, text, len(text.rstrip()), tuple(stack))
        return FishDefine(block, loc, text.strip())

    def _resolve_call_path(self, name: str, base_dir: Path) -> Path:
        p = Path(name)
        if not p.is_absolute():
            p = base_dir / p
        if not p.exists() and not p.suffix:
            for ext in (".dat", ".3ddat", ".fis", ".dec"):   # 3DEC adds a default extension
                if p.with_suffix(ext).exists():
                    return p.with_suffix(ext)
        return p

    # ------------------------------------------------------------------ running
    def command(self, text: str) -> None:
        """Run one or more command lines typed by a user (REPL, Python)."""
        items = self.load_text(text, "<command>", Path.cwd())
        self.run_items(items)

    def call(self, path: str | Path) -> None:
        """Read, bind and run a deck file."""
        items = self.load_file(path)
        self.run_items(items)

    def run_items(self, items: Iterable[Item]) -> None:
        try:
            for item in items:
                self._run_one(item)
        except StopDeck:
            pass

    def _run_one(self, item: Item) -> None:
        if self.echo:
            src = item.source if not isinstance(item, CommandCall) else _source_of(item)
            if src:
                self.write(f"dec3d> {src}")
        try:
            if isinstance(item, CommandCall):
                call = self.resolve(item)
                item.command.handler(self, call)
                self.record.append(_source_of(item))
            elif isinstance(item, ExprStatement):
                evaluate(item.node, EvalContext(self.variables, self.write))
                self.bind_context.assigned.update(self.variables)
            elif isinstance(item, FishDefine):
                self.fish[item.block.name.lower()] = item.block
                self.bind_context.define_fish(item.block)
        except Dec3dError as exc:
            raise exc.with_location(item.location)

    def resolve(self, call: CommandCall) -> CommandCall:
        """Evaluate `[expr]`/`@name` values and convert them like literals; other values as bound."""
        if not _has_deferred(call):
            return call
        params = call.command.by_key
        args = dict(call.args)
        for key, value in args.items():
            p = params.get(key)
            if p is None or not _contains_deferred(value):
                continue
            where = call.locations.get(key, call.location)
            if p.repeat:
                args[key] = [self._value(p.value, v, where, p.name) for v in value]
            else:
                args[key] = self._value(p.value, value, where, p.name)
        extra = {k: (self.evaluate(v, v.where) if isinstance(v, Deferred) else v) for k, v in call.extra.items()}
        return CommandCall(call.command, args, call.given, call.range, call.location, extra, call.locations)

    def range_mask(self, call: CommandCall, store: str):
        """Boolean mask over the live rows of `store` selected by the call's range clause
        (all rows when it has none). Elements are ANDed, or ORed after `union`."""
        import numpy as np

        n = len(self.model.store(store))
        if call.range is None:
            return np.ones(n, dtype=bool)
        masks = []
        for rc in call.range.elements:
            params = {p.key: p for p in rc.element.positional + rc.element.keywords}
            args = {}
            for k, v in rc.args.items():
                p = params.get(k)
                if p is not None and _contains_deferred(v):
                    # a repeated keyword (`group 'a' or [x] or [y]`) holds a list of values
                    v = ([self._value(p.value, x, rc.location, p.name) for x in v] if p.repeat
                         else self._value(p.value, v, rc.location, p.name))
                args[k] = v
            try:
                m = np.asarray(rc.element.mask(self, store, args), dtype=bool)
            except Dec3dError as exc:
                raise exc.with_location(rc.location)
            if m.shape != (n,):  # pragma: no cover - a bug in a range element, not user input
                raise CommandError(f"range element `{rc.element.name}` gave {m.shape[0]} values for {n} {store}s",
                                   rc.location)
            masks.append(~m if rc.negate else m)
        if call.range.union:
            return np.logical_or.reduce(masks)
        return np.logical_and.reduce(masks)

    def _value(self, vtype, value, where, name: str = ""):
        """A deferred value evaluated and converted by its type; `name` (the keyword) is put in
        front of a range error."""
        try:
            if isinstance(value, tuple):
                item = getattr(vtype, "item", None)
                if item is None:
                    raw = tuple(self.evaluate(v, where) if isinstance(v, Deferred) else v for v in value)
                    return vtype.convert(raw, where)
                # each evaluated number is checked at its own position
                return tuple(item.convert(self.evaluate(v, v.where or where), v.where or where)
                             if isinstance(v, Deferred) else v for v in value)
            if isinstance(value, Deferred):
                at = value.where or where
                return vtype.convert(self.evaluate(value, at), at)
        except ValueRangeError as exc:
            raise exc.named(name) if name else exc
        except ExpressionError as exc:
            if name and not exc.message.startswith("value of `"):
                exc.message = f"value of `{name}`: {exc.message}"
                exc.args = (exc.message,)
            raise
        return value

    def evaluate(self, d: Deferred, where: SourceLocation | None = None):
        try:
            return evaluate(d.node, EvalContext(self.variables, self.write))
        except ExpressionError as exc:
            raise exc.with_location(where) if where else exc

    def new_model(self) -> None:
        """`model new`: a fresh model; FISH variables and functions are cleared too (as in 3DEC)."""
        self.model = Model()
        self.variables.clear()
        self.fish.clear()
        self.bind_context = BindContext(self.variables)


def _contains_deferred(v) -> bool:
    if isinstance(v, Deferred):
        return True
    if isinstance(v, (tuple, list)):
        return any(_contains_deferred(x) for x in v)
    return False


def _has_deferred(call: CommandCall) -> bool:
    return any(_contains_deferred(v) for v in call.args.values()) or any(
        isinstance(v, Deferred) for v in call.extra.values())


def _source_of(call: CommandCall) -> str:
    return call.text


def run_deck(path: str | Path, out_dir: str | Path | None = None, echo: bool = False) -> Session:
    """Run a deck in a new Session and return it."""
    s = Session(out_dir=out_dir if out_dir is not None else Path(path).parent, echo=echo)
    s.call(path)
    return s
