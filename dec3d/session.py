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
from contextlib import suppress
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterable, TextIO

from .commands import load_all
from .commands._file_check import bind_check, path_params
from .commands.binder import BindContext, Binder, CommandCall, ExprStatement
from .commands.values import Deferred, OutPath, ValueRangeError
from .errors import (BindError, CommandError, Dec3dError, ExpressionError, SourceLocation, StopDeck,
                     UnimplementedError, printable)
from .fish import FishRuntime, compile_function, compile_inline, inline_source, parse_block, parse_inline
from .io import paths
from .io.guard import FileRecord
from .lang.parser import ParsedDeck, gc_paused, parse_deck
from .lang.prepass import FishBlock
from .lang.progress import BindProgress
from .lang.unsupported import Unsupported, empty_range, unsupported
from .model.model import Model


@dataclass(frozen=True)
class FishDefine:
    block: FishBlock
    location: SourceLocation
    source: str
    fdef: Any = None          # dec3d.fish.FishDef: parsed when the deck is read
    bound: Any = None         # id(command node) -> bound command lines of its command sections


@dataclass(frozen=True)
class Enter:
    """Marks the start of a called file in the item list (for echo and `program return`)."""

    path: Path
    location: SourceLocation
    source: str


Item = CommandCall | ExprStatement | FishDefine | Enter | Unsupported


#: file names of text that does not come from a file (its folder is the working folder)
PSEUDO_FILES = ("<input>", "<command>", "<repl>")
#: largest deck file read (bytes): a deck is text, a bigger file is not one
DECK_MAX_BYTES = 64 * 2**20


class Session:
    """One model and the decks run on it. out_dir: the output folder (default: the working folder);
    every file a deck writes stays in it. allow_outside_paths: let decks read and write anywhere
    (regular files only), for decks the user trusts; allow_overwrite: let outputs replace existing
    files dec3d did not write (never the run's inputs). See docs/safety.md."""

    def __init__(self, out_dir: str | Path | None = None, echo: bool = False, stdout: TextIO | None = None,
                 allow_outside_paths: bool = False, parameters: dict[str, Any] | None = None,
                 allow_overwrite: bool = False):
        load_all()
        self.allow_outside_paths = bool(allow_outside_paths)
        #: `model restore` installs the FISH code of saves this user's key did not sign (`--trust-save`)
        self.trust_saves = False
        self.model = Model()
        # values set from outside the deck (`dec3d batch --param`): FISH variables from the start, kept
        # through `model new`, and a deck's own assignment of one (its default) does not replace it
        self.parameters: dict[str, Any] = dict(parameters or {})
        self.variables: dict[str, Any] = dict(self.parameters)
        self.fish: dict[str, FishBlock] = {}
        self.fish_rt = FishRuntime(self)
        self.out_dir = Path(out_dir) if out_dir is not None else Path.cwd()
        self.echo = echo
        self.stdout = stdout if stdout is not None else sys.stdout
        self.log_path: Path | None = None
        self.log_on = False
        self._log_handle: TextIO | None = None
        self.record: list[str] = []       # text of every command run, for save files
        self.results: dict[str, float] = {}  # named figures commands report (verification reads them)
        self.warnings: list[str] = []     # said again at the end of `dec3d run` (e.g. an unconverged solve)
        self.bind_context = BindContext(self.variables)
        self._text_dirs: dict[str, Path] = {}  # folder of text given by load_text(base_dir=…)
        self.written: set[Path] = set()        # resolved files `model save` wrote (read first by restores)
        self.files = FileRecord(self.out_dir, allow_overwrite)  # what the run read and wrote (io/guard.py)

    # ------------------------------------------------------------------ output
    def write(self, text: str) -> None:
        """Print a line to the console (and the log file when logging is on).

        Control characters (from deck text: echoed commands, `io.out` strings) are written as
        visible escapes, so a deck cannot drive the terminal."""
        text = printable(text, newlines=True)
        print(text, file=self.stdout)
        if self.log_on and self._log_handle is not None:
            try:
                self._log_handle.write(text + "\n")
                self._log_handle.flush()
            except OSError as exc:
                # a full disk, a removed medium: logging stops, the run is told once
                self.log_on = False
                handle, self._log_handle = self._log_handle, None
                with suppress(OSError):
                    handle.close()
                raise CommandError(f"cannot write the log file '{self.log_path}': {paths.os_error_text(exc)}; "
                                   "logging is off") from None

    def out_path(self, name: str | Path, where=None) -> Path:
        """The file a deck's name writes: under the output folder (``dec3d.io.paths.output_path``);
        a name that leaves it, or is not a regular file, raises ``PathError`` at ``where``."""
        try:
            return self.files.claim(paths.output_path(name, self.out_dir, self.allow_outside_paths), name)
        except paths.PathError as exc:
            raise exc.with_location(where) if where is not None else exc

    def in_path(self, name: str, where, exts: tuple[str, ...] = (), what: str = "file") -> Path:
        """The file a deck's name reads: beside the deck of ``where``, then in the output folder; a file
        this session wrote (``self.written``) first, so a run never reads an older copy beside the deck
        in place of the one it has just saved."""
        try:
            return self.files.read(paths.find_input(name, self._read_bases(where), self._read_roots(where),
                                   self.allow_outside_paths, exts, what, prefer=self.written), f"the {what} `{name}`")
        except paths.PathError as exc:
            raise exc.with_location(where)

    def _deck_folder(self, file: str) -> Path:
        return (self._text_dirs.get(file) or Path.cwd()) if file in PSEUDO_FILES else Path(file).parent

    def _read_bases(self, where) -> list[Path]:
        loc = getattr(where, "resolve", lambda: where)()
        base = self._deck_folder(loc.file) if loc is not None else Path.cwd()
        return [base, self.out_dir]

    def _read_roots(self, where) -> list[Path]:
        """Reads stay under the folder of the deck the run started from and the output folder."""
        loc = getattr(where, "resolve", lambda: where)()
        if loc is None:
            return [Path.cwd(), self.out_dir]
        top = loc.stack[0] if loc.stack else loc
        return [self._deck_folder(top.file), self.out_dir]

    def open_log(self, path: Path | None, append: bool = False, where=None) -> None:
        target = path or self.log_path or self.out_path("dec3d.log", where)
        target = self.out_path(target, where)          # checked again: a symlink may have appeared
        try:
            target.parent.mkdir(parents=True, exist_ok=True)
            handle = open(target, "a" if append else "w", encoding="utf-8")
        except OSError as exc:
            raise CommandError(f"cannot open the log file '{target}': {paths.os_error_text(exc)}", where) from None
        self.close_log()
        self.log_path = target
        self._log_handle = handle

    def close_log(self) -> None:
        if self._log_handle is not None:
            with suppress(OSError):
                self._log_handle.close()
            self._log_handle = None

    # ------------------------------------------------------------------ reading
    def load_text(self, text: str, filename: str = "<input>", base_dir: Path | None = None,
                  stack: tuple[SourceLocation, ...] = ()) -> list[Item]:
        """Parse and bind text (and the files it calls); nothing runs."""
        # the collector paused over reading and binding together (lang.parser.gc_paused); the token
        # lines are let go once bound (what a bound line still needs, its values' tokens, stays)
        with gc_paused():
            deck = parse_deck(text, filename, stack)
            if base_dir is not None and filename in PSEUDO_FILES:
                self._text_dirs[filename] = Path(base_dir)     # where its calls and restores look first
            try:
                items = self._bind_deck(deck, base_dir or Path.cwd(), stack)
            finally:
                deck.lines = []
        if not stack:                       # every deck is read: no literal output may replace an input
            bind_check(self, items)
        return items

    def load_file(self, path: str | Path, stack: tuple[SourceLocation, ...] = ()) -> list[Item]:
        """Read and bind a deck. With a ``stack`` the file is called by a deck (its last entry is
        the `program call` line): a file already on the stack is a cycle and is refused."""
        path = Path(path)
        where = stack[-1] if stack else None
        shown = paths.printable(str(path))
        kind = paths.file_kind(path)
        if kind is not None:
            raise CommandError(f"cannot read deck `{shown}`: it is {kind}, not a regular file", where)
        if stack:
            try:
                me = path.resolve()
                callers = [Path(s.file).resolve() for s in stack if s.file not in PSEUDO_FILES]
            except (OSError, RuntimeError):
                me, callers = path, []
            if me in callers:
                raise BindError(f"`{paths.printable(path.name)}` calls itself (directly or through other files)", where)
        if path.suffix.lower() == ".py":      # a Python file: refused unless allowed (commands.program_cmds)
            from .commands.program_cmds import python_call

            return python_call(self, path, where)
        try:
            size = path.stat().st_size
            if size > DECK_MAX_BYTES:
                raise CommandError(f"cannot read deck `{shown}`: {size} bytes is more than a deck "
                                   f"({DECK_MAX_BYTES // 2**20} MiB at most)", where)
            raw = path.read_bytes()
            self.files.read(path, "a deck it calls" if stack else "the running deck")
        except OSError as exc:
            # a called file: point at the `program call` line that names it
            raise CommandError(f"cannot read deck `{shown}`: {paths.os_error_text(exc)}", where) from None
        if raw.startswith(b"\xef\xbb\xbf"):
            raw = raw[3:]                   # a UTF-8 byte-order mark
        if path.suffix.lower() == ".dec":
            from .lang.unsupported import load_dec
            return load_dec(self, raw, path, shown, where, stack)
        text = raw.decode("utf-8", errors="replace")
        return self.load_text(text, str(path), path.parent, stack)

    def _bind_deck(self, deck: ParsedDeck, base_dir: Path, stack) -> list[Item]:
        binder = Binder(deck, self.bind_context, stack)
        items: list[Item] = []
        fish = iter(deck.fish)
        next_fish = next(fish, None)
        progress = BindProgress(self.write, paths.printable(deck.filename))
        count = 0
        bind_line = binder.bind_line
        for raw in deck.lines:
            line = raw.line
            count += 1
            if not count & 1023:            # progress.tick's own test, written out
                progress.tick_at(line)
            while next_fish is not None and next_fish.line < line:
                items.append(self._fish_item(deck, next_fish, stack))
                next_fish = next(fish, None)
            try:                            # lang.unsupported.bind_or_defer, written out
                call = bind_line(raw)
            except UnimplementedError as exc:
                call = unsupported(exc)
            if type(call) is not CommandCall and isinstance(call, (ExprStatement, Unsupported)):
                items.append(call)
                continue
            cmd = call.command
            path = cmd.path
            if cmd.file_params:
                self._check_paths(call)
            if path == ("program", "call") and not isinstance(call.args["file"], Deferred):
                # a literal name: the called file is read and bound now, in place of the call
                target = self.find_deck(call.args["file"], call.locations.get("file", call.location))
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
        fdef = parse_block(block, deck.filename, deck.source_lines, stack)
        bound = self.bind_fish_commands(fdef, deck, stack)
        return FishDefine(block, loc, text.strip(), fdef, bound)

    def bind_fish_commands(self, fdef, deck: ParsedDeck, stack) -> dict:
        """Bind the lines of a function's `command ... endcommand` sections, as deck lines
        (their `[ ]`/`@` names may be the function's own locals and globals)."""
        bound = {}
        if not fdef.commands:
            return bound
        ctx = BindContext(self.variables)
        ctx.fish_functions.update(self.bind_context.fish_functions)
        ctx.fish_variables.update(self.bind_context.fish_variables)
        ctx.assigned |= self.bind_context.assigned | fdef.locals | fdef.globals | fdef.assigned | set(fdef.params)
        for node in fdef.commands:
            items = []
            for first, last in node[1]:
                text = "\n" * (first - 1) + "\n".join(deck.source_lines[first - 1:last])
                sub = parse_deck(text, deck.filename, stack)
                binder = Binder(sub, ctx, stack)
                for raw in sub.lines:
                    items.append(binder.bind_line(raw))
            bound[id(node)] = items
        return bound

    def find_deck(self, name: str, where) -> Path:
        """The file `program call '<name>'` reads (3DEC adds a default extension when there is none)."""
        return self.in_path(name, where, (".dat", ".3ddat", ".fis", ".dec"), "deck")

    def _check_paths(self, call: CommandCall) -> None:
        """Bind time: the literal file names of a call must be allowed (``dec3d.io.paths``)."""
        for p in path_params(call.command):
            vt = p.value
            value = call.args.get(p.key)
            if not isinstance(value, str):
                continue                      # absent, or an [expr] checked when the command runs
            where = call.locations.get(p.key, call.location)
            try:
                if isinstance(vt, OutPath):
                    paths.output_path(vt.final(value), self.out_dir, self.allow_outside_paths)
                else:
                    paths.check_input_name(value, self._read_bases(call.location),
                                           self._read_roots(call.location), self.allow_outside_paths)
            except paths.PathError as exc:
                raise exc.with_location(where) from None

    # ------------------------------------------------------------------ running
    def command(self, text: str) -> None:
        """Run one or more command lines typed by a user (REPL, Python)."""
        items = self.load_text(text, "<command>", Path.cwd())
        self.run_items(items)

    def call(self, path: str | Path) -> None:
        """Read, bind and run a deck file."""
        self.run_items(self.load_file(path))

    def run_items(self, items: Iterable[Item]) -> None:
        """Run bound items; a top-level call ends by recording the files written (io/guard.py)."""
        self._depth = getattr(self, "_depth", 0) + 1
        try:
            self._run_items(list(items))
        finally:
            self._depth -= 1
            if self._depth == 0:
                self.files.finish(still_writing=[self.log_path if self._log_handle is not None else None])

    def _run_items(self, items: list) -> None:
        i = 0
        try:
            while i < len(items):
                j = self._batch_end(items, i)
                if j > i + 1:
                    i += self._run_batch(items[i:j])
                    continue
                self._run_one(items[i])
                i += 1
        except StopDeck:
            pass

    batch_min = 50      # shorter runs of batchable lines go line by line (a cold compile costs seconds)

    def _batch_end(self, items: list, i: int) -> int:
        """End of the run of lines from ``items[i]`` sharing a batch function (i + 1 if under batch_min)."""
        item = items[i]
        if self.echo or not isinstance(item, CommandCall) or item.command.batch is None:
            return i + 1
        fn, j = item.command.batch, i + 1
        while j < len(items) and isinstance(items[j], CommandCall) and items[j].command.batch is fn:
            j += 1
        return j if j - i >= self.batch_min else i + 1

    def _run_batch(self, items: list) -> int:
        """Run a run of batchable lines (``Command.batch``): as many as the batch function does in
        one pass, then the first it stopped before through its own handler (which reports the error
        at its line, with the lines before it done, as line-by-line running would). Returns how many
        lines ran."""
        calls = []
        for item in items:
            try:
                calls.append(self.resolve(item))
            except Dec3dError:
                break                   # that line runs on its own, below, and reports
        done = items[0].command.batch(self, calls) if len(calls) > 1 else 0
        self.record.extend(_source_of(item) for item in items[:done])
        if done < len(items):
            self._run_one(items[done])
            done += 1
        return done

    def _run_one(self, item: Item) -> None:
        try:
            if self.echo:
                src = item.source if not isinstance(item, CommandCall) else _source_of(item)
                if src:
                    self.write(f"dec3d> {src}")
            if isinstance(item, CommandCall):
                call = self.resolve(item)
                item.command.handler(self, call)
                if item.command.path != ("model", "restore"):
                    # a restore takes the saved model's record as it is: restore → save gives the same file
                    self.record.append(_source_of(item))
            elif isinstance(item, ExprStatement):
                if item.node[0] == "assign" and item.node[2] == "=" and item.node[1] in self.parameters:
                    return          # the deck's default of a batch parameter: the parameter's value stays
                self.run_statement(item)
                self.bind_context.assigned.update(self.variables)
            elif isinstance(item, FishDefine):
                self.define_fish(item)
            elif isinstance(item, Unsupported):
                item.run(self)
        except Dec3dError as exc:
            raise exc.with_location(item.location)
        except OSError as exc:
            # a write or read the file system refused at run time (full disk, read-only folder, ...)
            name = f" '{exc.filename}'" if getattr(exc, "filename", None) else ""
            raise CommandError(f"file error{name}: {paths.os_error_text(exc)}", item.location) from None

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
        mask = np.logical_or.reduce(masks) if call.range.union else np.logical_and.reduce(masks)
        if n and not mask.any():
            empty_range(self, call, store, n)
        return mask

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
        """A `[expr]` or `@name` value, evaluated by dec3d.fish (inside a FISH command section,
        in the scope of the running function)."""
        rt = self.fish_rt
        try:
            if rt.command_scope:
                closures, frame = rt.command_scope[-1]
                c = closures.get(id(d))
                if c is not None:
                    return c(frame)
            tok = d.token
            if where is not None and hasattr(where, "resolve"):
                where = where.resolve()
            file = where.file if where is not None else "<input>"
            key = (str(tok), file, tok.line, tok.column)
            c = rt.inline_cache.get(key)
            if c is None:
                text = where.text if where is not None else str(tok)
                stack = where.stack if where is not None else ()
                if d.kind == "at":
                    src = inline_source(file, tok.line, tok.column + 1, str(tok)[1:], text, stack)
                else:
                    src = inline_source(file, tok.line, tok.column + 1, str(tok)[1:-1], text, stack)
                node, _ = parse_inline(src.lines[0], src)
                c, _sc = compile_inline(rt, node, src)
                if len(rt.inline_cache) > 100_000:
                    rt.inline_cache.clear()
                rt.inline_cache[key] = c
            return c([0])
        except ExpressionError as exc:
            raise exc.with_location(where) if where else exc

    def run_statement(self, item: ExprStatement) -> None:
        """A line holding only `[ ... ]` or `@name`: run it as a FISH statement."""
        text = item.source.strip()
        loc = item.location
        rt = self.fish_rt
        key = (text, loc.file, loc.line, loc.column)
        c = rt.inline_cache.get(key)
        if c is None:
            inner = text[1:] if text.startswith("@") else text[1:-1]
            src = inline_source(loc.file, loc.line, loc.column + 1, inner, loc.text, loc.stack)
            node, _ = parse_inline(inner, src)
            c, _sc = compile_inline(rt, node, src)
            rt.inline_cache[key] = c
        c([0])

    def define_fish(self, item: FishDefine) -> None:
        """`fish define` runs: compile the function (names checked now if automatic-create is off)."""
        rt = self.fish_rt
        fn = compile_function(rt, item.fdef, item.bound, item.location)
        for name in (item.fdef.globals | item.fdef.assigned) - item.fdef.locals - {fn.name}:
            if "." not in name and name not in rt.functions and name not in self.variables:
                self.variables[name] = 0           # FISH creates the variables a function names when it is defined
        rt.define(fn)
        self.fish[item.block.name.lower()] = item.block
        self.bind_context.define_fish(item.block)

    def run_fish_command(self, item, stack=()) -> None:
        """A line of a FISH `command ... endcommand` section (bound when the deck was read)."""
        try:
            call = self.resolve(item)
            item.command.handler(self, call)
            self.record.append(_source_of(item))
        except Dec3dError as exc:
            if exc.location is None and stack:
                loc = item.location
                exc.location = SourceLocation(loc.file, loc.line, loc.column, loc.text, loc.length, tuple(stack))
            raise exc.with_location(item.location)

    def system_command(self, text: str, stack=(), refuse=None) -> None:
        """FISH `system.command(s)`: bind ``s`` as deck lines now and run them (as a line of a
        `command … endcommand` section would run). ``refuse(path)`` gives a reason a command may not
        run here (a FISH callback), or None."""
        deck = parse_deck(text, "<command>", tuple(stack))
        binder = Binder(deck, self.bind_context, tuple(stack))
        for raw in deck.lines:
            item = binder.bind_line(raw)
            if isinstance(item, ExprStatement):
                self.run_statement(item)
                continue
            why = refuse(item.command.path) if refuse is not None else None
            if why:
                raise CommandError(why, item.location)
            self._check_paths(item)
            self.run_fish_command(item, stack)

    def new_model(self) -> None:
        """`model new`: a fresh model; FISH variables and functions are cleared too (as in 3DEC)."""
        self.model = Model()
        self.variables.clear()
        self.variables.update(self.parameters)
        self.fish.clear()
        self.fish_rt.clear()
        self.bind_context = BindContext(self.variables)


def _contains_deferred(v) -> bool:
    return isinstance(v, Deferred) or (isinstance(v, (tuple, list)) and any(_contains_deferred(x) for x in v))


def _has_deferred(call: CommandCall) -> bool:
    return any(_contains_deferred(v) for v in call.args.values()) or any(
        isinstance(v, Deferred) for v in call.extra.values())


def _source_of(call: CommandCall) -> str:
    return call.text


def run_deck(path: str | Path, out_dir: str | Path | None = None, echo: bool = False,
             allow_outside_paths: bool = False, allow_overwrite: bool = False) -> Session:
    """Run a deck in a new Session and return it."""
    s = Session(out_dir=out_dir if out_dir is not None else Path(path).parent, echo=echo,
                allow_outside_paths=allow_outside_paths, allow_overwrite=allow_overwrite)
    s.call(path)
    return s
