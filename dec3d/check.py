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
    k = 0
    for raw in deck.lines:
        while k < len(fish) and fish[k].line < raw.line:
            ctx.define_fish(fish[k])
            reports.append(LineReport(fish[k].line, RUNNABLE, f"fish define {fish[k].name}"))
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
        reports.append(LineReport(b.line, RUNNABLE, f"fish define {b.name}"))
    return reports


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
