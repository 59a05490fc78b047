"""`dec3d check deck.dat`: read a deck line by line and say what dec3d can run.

Unlike `dec3d run`, which stops at the first error, this binds every line on its own
and reports each: runnable, not supported yet (a 3DEC command or FISH feature dec3d
knows but does not implement), legacy 3DEC 5 syntax, or an error. Called files are
not followed (each file is checked on its own), and FISH variables a file uses but
never assigns are taken to come from the deck that calls it.
"""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from pathlib import Path

from .commands import load_all
from .commands.binder import BindContext, Binder, CommandCall, LegacySyntaxError
from .errors import Dec3dError, NotSupportedError
from .lang.parser import parse_deck

RUNNABLE, NOT_SUPPORTED, LEGACY, ERROR = "runnable", "not supported yet", "legacy syntax", "error"


@dataclass(frozen=True)
class LineReport:
    line: int
    status: str
    what: str          # command name, or the error message


def check_text(text: str, filename: str = "<input>") -> list[LineReport]:
    """Raises DeckSyntaxError if the text does not parse at all."""
    load_all()
    deck = parse_deck(text, filename)
    ctx = BindContext({}, lenient_names=True)
    binder = Binder(deck, ctx)
    reports: list[LineReport] = []
    fish = sorted(deck.fish, key=lambda b: b.line)
    for b in fish:
        ctx.define_fish(b)            # functions may be called before they are defined (callbacks, later files)
    k = 0
    for raw in deck.lines:
        while k < len(fish) and fish[k].line < raw.line:
            reports.extend(_check_fish(fish[k], deck, ctx))
            k += 1
        try:
            item = binder.bind_line(raw)
            what = item.name if isinstance(item, CommandCall) else item.source
            reports.append(LineReport(raw.line, RUNNABLE, what))
        except LegacySyntaxError as exc:
            reports.append(LineReport(raw.line, LEGACY, exc.message))
        except NotSupportedError as exc:
            reports.append(LineReport(raw.line, NOT_SUPPORTED, exc.message))
        except Dec3dError as exc:
            reports.append(LineReport(raw.line, ERROR, exc.format()))
    for b in fish[k:]:
        reports.extend(_check_fish(b, deck, ctx))
    return reports


def _check_fish(block, deck, ctx) -> list[LineReport]:
    """A `fish define`: parsed, its command lines bound and its body compiled (nothing runs).
    Intrinsics dec3d does not implement make it "not supported yet", naming them."""
    from .fish import FishRuntime, compile_function, parse_block
    from .fish.compiler import _deferreds  # noqa: F401  (the compiler walks bound lines itself)

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
    legacy = sorted(n for n in _called_names(fdef.body) if n in LEGACY_FISH and n not in ctx.fish_functions)
    if legacy:
        hints = "; ".join(f"`{n}` -> {LEGACY_FISH[n]}" for n in legacy)
        return out + [LineReport(block.line, LEGACY, f"{what} uses 3DEC 5 (legacy) FISH intrinsics: {hints}")]
    if fn.unsupported:
        names = ", ".join(f"`{n}`" for n in sorted(fn.unsupported))
        return out + [LineReport(block.line, NOT_SUPPORTED, f"{what}: FISH intrinsic(s) not supported yet: {names}")]
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


def check_file(path: str | Path) -> list[LineReport]:
    p = Path(path)
    return check_text(p.read_text(encoding="utf-8", errors="replace"), str(p))


def summary(reports: list[LineReport]) -> Counter:
    return Counter(r.status for r in reports)


def main(paths: list[str], verbose: bool = False) -> int:
    bad = 0
    for path in paths:
        try:
            reports = check_file(path)
        except Dec3dError as exc:
            print(exc.format())
            bad += 1
            continue
        c = summary(reports)
        print(f"{path}: " + ", ".join(f"{c[s]} {s}" for s in (RUNNABLE, NOT_SUPPORTED, LEGACY, ERROR) if c[s]))
        for r in reports:
            if r.status == ERROR or (verbose and r.status != RUNNABLE):
                print(f"  line {r.line}: {r.status}: {r.what}")
        bad += c[ERROR] > 0
    return 1 if bad else 0
