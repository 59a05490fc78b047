"""`dec3d check deck.dat`: read a deck line by line and say what `dec3d run` would do with each.

`dec3d run` reads and binds the whole deck, with every file it calls by a literal name, before
anything runs, and stops at the first line it cannot bind. `check` walks the same way (the
same binder, the same FISH-name bookkeeping and the same resolution of called files as
``Session``) but goes on after a bad line and reports every line, in the file it is in:

- runnable: the line binds and its command runs;
- does nothing: read but without effect (`plot …`, which is display only; lines after a
  `program return`, which are never read);
- not supported yet: a 3DEC command or FISH feature dec3d knows but does not implement (this
  stops a run);
- legacy syntax: 3DEC 5 syntax (stops a run);
- a `fish define` is compiled as the run compiles it: runnable, or not supported yet when it
  uses FISH intrinsics dec3d lacks (they fail when the function is called), or legacy syntax; a line
  that calls such a function (directly or through others: `[…]`, `@f`, `fish callback add f`,
  `fish history f`) is reported as not runnable too, where the run would stop;
- error: anything else that stops a run (a called file that is missing, an undefined FISH name,
  a bad keyword or value).

``standalone=True`` checks one file as a piece of a larger deck instead: calls are not
followed and FISH names it never assigns are taken to come from the deck that calls it.
"""
from __future__ import annotations

import re
import sys
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

from .commands import load_all
from .commands.binder import BindContext, Binder, CommandCall, LegacySyntaxError
from .commands.values import Deferred
from .errors import Dec3dError, NotSupportedError, SourceLocation, UnimplementedError
from .lang.parser import parse_deck

RUNNABLE, DOES_NOTHING, NOT_SUPPORTED, LEGACY, ERROR = (
    "runnable", "does nothing", "not supported yet", "legacy syntax", "error")
#: the statuses that stop `dec3d run` before anything runs
BLOCKERS = (NOT_SUPPORTED, LEGACY, ERROR)
ORDER = (RUNNABLE, DOES_NOTHING, NOT_SUPPORTED, LEGACY, ERROR)


@dataclass(frozen=True)
class LineReport:
    line: int
    status: str
    what: str          # command name, what happens, or the error message
    file: str = "<input>"
    column: int = 1
    #: when the problem stops `dec3d run`: "bind" (before anything runs), "called" (a `fish define` whose
    #: body cannot run: only when the function is called), "run" (a line that calls such a function),
    #: "cycle" (a callback or FISH history of such a function: the first cycling step that calls it)
    when: str = "bind"


class _Walker:
    def __init__(self, standalone: bool):
        from .session import Session

        load_all()
        self.standalone = standalone
        self.ctx = BindContext({}, lenient_names=standalone)
        # the run's own resolution and checks of called files (beside the calling deck, then the
        # output folder; default extensions; only regular files under the deck's or output folder)
        self.session = Session()
        self.reports: list[LineReport] = []
        #: FISH functions whose bodies cannot run (name -> (status, why)) and the names each function calls
        self.bad_fns: dict[str, tuple[str, str]] = {}
        self.fn_calls: dict[str, set] = {}

    def add(self, deck, line, status, what, column=1, when="bind"):
        self.reports.append(LineReport(line, status, what, deck.filename, column, when))

    def problem(self, deck, raw, status, exc, when="bind"):
        loc = exc.location
        col = loc.column if loc is not None and loc.line == raw.line and loc.file == deck.filename else 1
        self.add(deck, raw.line, status, exc.message + (f" (hint: {exc.hint})" if getattr(exc, "hint", None) else ""),
                 col, when=when)

    def fish(self, deck, block):
        """A `fish define`: parsed, its command lines bound and its body compiled, as `dec3d run`
        does when it reads the deck (nothing runs)."""
        self.ctx.define_fish(block)
        name = block.name.lower()
        self.bad_fns.pop(name, None)                     # a later define replaces the function
        for r in _check_fish(block, deck, self.ctx, self.fn_calls):
            self.add(deck, r.line, r.status, r.what, when=r.when)
            if r.when == "called":
                self.bad_fns[name] = (r.status, r.what)

    def _blocked_call(self, raw, item) -> tuple[str, str, str] | None:
        """(status, why, when) when the line calls (directly, or through other functions) a FISH function whose
        body cannot run: its `[…]`/`@name` values, a bare `@f`/`[f]` line, `fish callback add f`,
        `fish history f` (when "cycle": the run stops at the first step that calls it)."""
        if not self.bad_fns:
            return None
        names, when = set(), "run"
        for tok in raw.tokens:
            if tok.type in ("EXPR", "ATNAME"):
                names.update(n.lower() for n in _IDENT.findall(_QUOTED.sub("", str(tok))))
        if isinstance(item, CommandCall):
            path = item.command.path
            if path[:3] == ("fish", "callback", "add") and isinstance(item.args.get("function"), str):
                names.add(item.args["function"].lower())
                when = "cycle"
            elif path == ("fish", "history") and isinstance(item.args.get("what"), tuple):
                names.add(str(item.args["what"][1]).lower())
                when = "cycle"
        seen, todo = set(), list(names)
        while todo:
            n = todo.pop()
            if n in seen:
                continue
            seen.add(n)
            if n in self.bad_fns:
                status, why = self.bad_fns[n]
                lead = "calls" if when == "run" else "registers for cycling a FISH function that calls"
                return status, f"{lead} FISH function `{n}`, which cannot run ({why})", when
            todo.extend(self.fn_calls.get(n, ()))
        return None

    def walk(self, text: str, filename: str, base_dir: Path, stack: tuple[SourceLocation, ...] = ()) -> None:
        deck = parse_deck(text, filename, stack)
        binder = Binder(deck, self.ctx, stack)
        fish = sorted(deck.fish, key=lambda b: b.line)
        k = 0
        returned = False
        for raw in deck.lines:
            while k < len(fish) and fish[k].line < raw.line:
                self.fish(deck, fish[k])
                k += 1
            if returned:
                self.add(deck, raw.line, DOES_NOTHING, "after `program return`: never read")
                continue
            try:
                item = binder.bind_line(raw)
            except LegacySyntaxError as exc:
                self.problem(deck, raw, LEGACY, exc)
                continue
            except NotSupportedError as exc:
                # a command, keyword, range element or intrinsic dec3d does not implement: the run goes up
                # to it (dec3d.lang.unsupported); other such problems stop the deck before it runs
                self.problem(deck, raw, NOT_SUPPORTED, exc, when="run" if isinstance(exc, UnimplementedError)
                             else "bind")
                continue
            except Dec3dError as exc:
                self.problem(deck, raw, ERROR, exc)
                continue
            blocked = self._blocked_call(raw, item)
            if blocked is not None:
                self.add(deck, raw.line, blocked[0], blocked[1], when=blocked[2])
                continue
            if not isinstance(item, CommandCall):
                self.add(deck, raw.line, RUNNABLE, item.source)
                continue
            path = item.command.path
            if path == ("plot",):
                from .commands.plot_cmds import does_nothing
                why = does_nothing(item)
                self.add(deck, raw.line, DOES_NOTHING if why else RUNNABLE, why or "plot")
            elif path == ("program", "call"):
                self.call(deck, raw, item, base_dir, stack)
            else:
                self.add(deck, raw.line, RUNNABLE, item.name)
                returned = path == ("program", "return")
        for b in fish[k:]:
            self.fish(deck, b)

    def call(self, deck, raw, item, base_dir, stack):
        name = item.args["file"]
        if isinstance(name, Deferred):
            self.add(deck, raw.line, RUNNABLE, "program call: the file is named by an expression, "
                                               "read when the line runs (not checked here)")
            return
        if self.standalone:
            self.add(deck, raw.line, RUNNABLE, f"program call '{name}' (not followed)")
            return
        try:
            target = self.session.find_deck(name, item.locations.get("file", item.location))
        except Dec3dError as exc:
            self.problem(deck, raw, ERROR, exc)
            return
        if any(Path(s.file).resolve() == target.resolve() for s in stack) or \
                Path(deck.filename).resolve() == target.resolve():
            self.add(deck, raw.line, ERROR, f"`{target.name}` calls itself (directly or through other files)")
            return
        if target.suffix.lower() == ".py":     # dec3d run refuses it unless --allow-python (docs/python.md)
            self.add(deck, raw.line, ERROR, f"`{target.name}` is a Python file: `dec3d run` refuses it unless you "
                                            "pass --allow-python (then it runs when the deck reaches it; not checked)")
            return
        try:
            text = target.read_text(encoding="utf-8", errors="replace")
        except OSError as exc:
            self.add(deck, raw.line, ERROR, f"cannot read deck `{target}`: {exc.strerror or exc}")
            return
        self.add(deck, raw.line, RUNNABLE, f"program call: reads {target}")
        self.walk(text, str(target), target.parent, stack + (item.location,))


def _check_fish(block, deck, ctx, fn_calls=None) -> list[LineReport]:
    """A `fish define`: parsed, its command lines bound and its body compiled (nothing runs).
    Intrinsics dec3d does not implement make it "not supported yet", naming them (``when`` "called": the
    run stops only when the function is called). ``fn_calls`` gets the names the body calls."""
    from .fish import FishRuntime, compile_function, parse_block

    what = f"fish define {block.name}"
    out: list[LineReport] = []
    try:
        fdef = parse_block(block, deck.filename, deck.source_lines)
    except LegacySyntaxError as exc:
        return [LineReport(exc.location.line if exc.location else block.line, LEGACY, exc.message)]
    except NotSupportedError as exc:
        return [LineReport(block.line, NOT_SUPPORTED, exc.message)]
    except Dec3dError as exc:
        return [LineReport(exc.location.line if exc.location else block.line, ERROR, exc.format())]
    bound = {}
    sub_ctx = BindContext({}, lenient_names=True)
    sub_ctx.fish_functions.update(ctx.fish_functions)
    for node in fdef.commands:
        items = []
        for first, last in node[1]:
            text = "\n" * (first - 1) + "\n".join(deck.source_lines[first - 1:last])
            sub = parse_deck(text, deck.filename)
            binder = Binder(sub, sub_ctx)
            for raw in sub.lines:
                try:
                    item = binder.bind_line(raw)
                    items.append(item)
                    name = item.name if isinstance(item, CommandCall) else item.source
                    out.append(LineReport(raw.line, RUNNABLE, name))
                except LegacySyntaxError as exc:
                    out.append(LineReport(raw.line, LEGACY, exc.message))
                except NotSupportedError as exc:
                    out.append(LineReport(raw.line, NOT_SUPPORTED, exc.message))
                except Dec3dError as exc:
                    out.append(LineReport(raw.line, ERROR, exc.format()))
        bound[id(node)] = items

    class _Quiet:
        variables: dict = {}

        def write(self, text):
            pass

    rt = FishRuntime(_Quiet())
    try:
        fn = compile_function(rt, fdef, bound)
    except Dec3dError as exc:
        return out + [LineReport(exc.location.line if exc.location else block.line, ERROR, exc.format())]
    called = _called_names(fdef.body)
    if fn_calls is not None:
        fn_calls[block.name.lower()] = {n.lower() for n in called}
    legacy = sorted(n for n in called if n in LEGACY_FISH and n not in ctx.fish_functions)
    if legacy:
        hints = "; ".join(f"`{n}` -> {LEGACY_FISH[n]}" for n in legacy)
        return out + [LineReport(block.line, LEGACY, f"{what} uses 3DEC 5 (legacy) FISH intrinsics: {hints}",
                                 deck.filename, 1, "called")]
    if fn.unsupported:
        names = ", ".join(f"`{n}`" for n in sorted(fn.unsupported))
        return out + [LineReport(block.line, NOT_SUPPORTED, f"{what}: FISH intrinsic(s) not supported yet: {names}",
                                 deck.filename, 1, "called")]
    return out + [LineReport(block.line, RUNNABLE, what)]


#: 3DEC 5 FISH intrinsics and their 3DEC 7+ spelling (reference section 9 and 13)
LEGACY_FISH = {
    "out": "io.out", "sqrt": "math.sqrt", "abs": "math.abs", "sin": "math.sin", "cos": "math.cos",
    "atan": "math.atan", "atan2": "math.atan2", "block_head": "block.list", "b_next": "loop foreach over block.list",
    "b_zone": "block.zone.list", "z_next": "loop foreach over block.zone.list", "b_gp": "block.gplist",
    "gp_next": "loop foreach over block.gp.list", "gp_x": "block.gp.pos.x", "gp_y": "block.gp.pos.y",
    "gp_z": "block.gp.pos.z", "z_sxx": "block.zone.stress.xx", "z_sig1": "block.zone.stress.prin.x",
    "z_sig3": "block.zone.stress.prin.z", "open": "file.open", "write": "file.write", "close": "file.close",
    "lose_array": "(lists are freed automatically)", "c_near": "block.contact.near",
}


_QUOTED = re.compile(r"'[^']*'|\"[^\"]*\"")
_IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*(?:\.[A-Za-z_][A-Za-z0-9_]*)*")


def _called_names(body) -> set:
    names: set = set()

    def walk(n):
        if isinstance(n, tuple):
            if n and n[0] in ("call", "name") and isinstance(n[1], str):
                names.add(n[1])
            for x in n:
                walk(x)
        elif isinstance(n, list):
            for x in n:
                walk(x)
    walk(body)
    return names


def check_text(text: str, filename: str = "<input>", base_dir: Path | None = None,
               standalone: bool = False) -> list[LineReport]:
    """Reports for every line of ``text`` and of the files it calls (in reading order).
    Raises DeckSyntaxError if the text does not parse at all."""
    w = _Walker(standalone)
    w.walk(text, filename, base_dir if base_dir is not None else Path.cwd())
    return w.reports


def check_file(path: str | Path, standalone: bool = False, legacy: bool = True) -> list[LineReport]:
    """Reports for a deck file; a 3DEC 4/5 deck is checked as `dec3d run` runs it, through its translation
    (dec3d.lang.legacy), its reports placed on the original lines (``legacy=False``: as written)."""
    from dataclasses import replace

    from .lang.legacy import looks_legacy, translate_text

    p = Path(path)
    text = p.read_text(encoding="utf-8", errors="replace")
    if not (legacy and looks_legacy(text)):
        return check_text(text, str(p), p.parent, standalone)
    from .commands.legacy import legacy_models
    from .lang.legacy.translate import State

    tr = translate_text(text, str(p), State(models=legacy_models()))
    out = []
    for r in check_text(tr.text, str(p), p.parent, standalone):
        if r.file == str(p):
            line, col = tr.map.where(r.line, r.column)
            r = replace(r, line=line, column=col)
        out.append(r)
    return out


def _before(a: LineReport, b: LineReport, reports: list[LineReport]) -> bool:
    """Whether report ``a`` comes before ``b`` in reading order."""
    return next(i for i, r in enumerate(reports) if r is a) < next(i for i, r in enumerate(reports) if r is b)


def summary(reports: list[LineReport]) -> Counter:
    return Counter(r.status for r in reports)


def main(paths: list[str], verbose: bool = False) -> int:
    """Exit 0 when every deck would run, 1 when one would stop or has FISH functions that cannot run, 2 when a
    deck cannot be read."""
    worst = 0
    for path in paths:
        p = Path(path)
        if not p.is_file() or p.suffix.lower() == ".py":
            why = ("is a folder, not a deck file" if p.is_dir() else "does not exist" if not p.is_file() else
                   "is a Python driver, not a deck (`dec3d run` runs it; docs/python.md)")
            print(f"dec3d check: error: `{path}` {why}", file=sys.stderr)
            worst = 2
            continue
        try:
            reports = check_file(p)
        except Dec3dError as exc:
            print(exc.format())
            worst = max(worst, 1)
            continue
        except OSError as exc:
            print(f"dec3d check: error: cannot read `{path}`: {exc.strerror or exc}", file=sys.stderr)
            worst = 2
            continue
        c = summary(reports)
        files = {r.file for r in reports}
        more = f" (in {len(files)} files)" if len(files) > 1 else ""
        print(f"{path}: " + ", ".join(f"{c[s]} {s}" for s in ORDER if c[s]) + more)
        blockers = [r for r in reports if r.status in BLOCKERS]
        for r in reports:
            if r.status in BLOCKERS or verbose:
                print(f"  {r.file}:{r.line}:{r.column}: {r.status}: {r.what}")
        at_bind = [r for r in blockers if r.when == "bind"]
        at_run = [r for r in blockers if r.when == "run"]
        at_cycle = [r for r in blockers if r.when == "cycle"]
        if at_bind:
            first = at_bind[0]
            print(f"  dec3d run would stop before running anything, at {first.file}:{first.line}")
        elif at_run or at_cycle:
            first = (at_run or at_cycle)[0]
            if at_cycle and (not at_run or _before(at_cycle[0], first, reports)):
                c = at_cycle[0]
                print(f"  dec3d run would stop at the first cycling step after {c.file}:{c.line} (a callback or "
                      "history calls a FISH function that cannot run)" +
                      (f", or at {first.file}:{first.line}, where one is called" if at_run else ""))
            else:
                why = ("it calls a FISH function that cannot run" if first.status != NOT_SUPPORTED else
                       "dec3d does not implement it yet (`dec3d run --skip-unsupported` skips such lines)")
                print(f"  dec3d run would run the lines before {first.file}:{first.line} and stop there: {why}")
        elif blockers:
            print("  dec3d run would run to the end: no line calls the FISH functions above (they stop a run "
                  "only when called)")
        if blockers:
            worst = max(worst, 1)
        else:
            print("  no line stops `dec3d run` before it starts (what happens while it runs is not checked)")
    return worst
