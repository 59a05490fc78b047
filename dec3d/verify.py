"""`dec3d verify`: run the verification problems and print a pass/fail table.

Each folder of `verification/` holds a `problem.toml`:

    title = "..."; kind = "deck" | "ssdem"; source = "..."
    deck = "deck.dat"            # kind = "deck": quantities are FISH variables and session results
    input = "..."; args = [...]  # kind = "ssdem"
    [[expect]]  quantity = "..."  value = 1.0  rel_tol = 0.01 | abs_tol = ...  [note = "..."]
    [[expect]]  quantity = "..."  below = "<other quantity>"
    [[expect]]  quantity = "..."  value = ...  not_comparable = "because ..."
    [[derive]]  name = "..."  kind = "slope" | "curvature" | "mean" | "max" | "min"
                csv = "<history export file>"  history = "<name>"  [vs = "<name>"]
                [t0 = <s>]  [t1 = <s>]       # window, seconds after the file's first sample
    [[derive]]  name = "..."  kind = "damping-ratio"  csv = …  history = …  [t0, t1]   # log decrement
    [[derive]]  name = "..."  kind = "trend" | "plunge"  of = ["<qx>", "<qy>", "<qz>"]   # degrees
    [[derive]]  name = "..."  kind = "kirsch"  p1 = …  p2 = …  a = …  bulk = …  shear = …
                # a closed-form field against the model state (``dec3d.verify_fields``): adds
                # "<name>.<measure>" for each of its measures (kirsch: sigr, sigt, disp, in %)

`derive` adds quantities worked out from exported history files (kind = "deck"): the least-squares
slope d(history)/dt (or d(history)/d(vs) with `vs`), the curvature 2·c₂ of a least-squares quadratic
c₀ + c₁t + c₂t² (an acceleration from a displacement), the mean/max/min over the window, the damping
ratio ξ = δ/√(4π² + δ²) of a decaying oscillation about zero (δ the logarithmic decrement: ln of the
first over the last positive peak, each refined by a parabola through its three samples, over the number
of periods between them; `damping_ratio`); and the
trend (clockwise from +y) and plunge (down from horizontal) of a vector of three other quantities.

Every `[[expect]]` is either a bar the measurement must meet (a value with its tolerance, or `below`)
or `not_comparable`: a published figure the measurement is shown against but cannot be held to, with
the reason. The table prints the bars, then the count, then the not-comparable rows in a section of
their own, so nothing that was not checked stands beside a PASS.

Expectations are data; the runner knows no problem by name.
"""
from __future__ import annotations

import math
import sys
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from .verify_fields import FIELDS


@dataclass
class Check:
    problem: str
    quantity: str
    measured: float | None
    expected: str
    passed: bool | None        # None: not comparable (shown with its reason, never counted)
    note: str = ""


def _deck_quantities(folder: Path, spec: dict) -> dict[str, float]:
    import tempfile

    from .session import Session

    with tempfile.TemporaryDirectory() as out:
        s = Session(out_dir=out)
        s.call(folder / spec["deck"])
        q = {k: float(v) for k, v in s.variables.items() if isinstance(v, (int, float)) and not isinstance(v, bool)}
        q.update(s.results)
        for d in spec.get("derive", []):
            if d["kind"] in FIELDS:
                q.update(field_errors(d, s.model))
            else:
                q[d["name"]] = derive(d, q, Path(out))
        return q


def field_errors(d: dict, model) -> dict[str, float]:
    """The measures of a closed-form field (``dec3d.verify_fields``) on the model, as
    "<name>.<measure>" quantities."""
    func, params = FIELDS[d["kind"]]
    missing = [p for p in params if p not in d]
    if missing:
        raise ValueError(f"derive {d.get('name', d['kind'])}: kind {d['kind']!r} needs {', '.join(missing)}")
    got = func(model, **{p: float(d[p]) for p in params})
    return {f"{d['name']}.{k}": v for k, v in got.items()}


def _column(rows: list[list[str]], name: str, path: Path):
    import numpy as np

    head = rows[0]
    for j, h in enumerate(head[2:], start=2):
        if h == name or h.startswith(name + " ("):
            return np.array([float(r[j]) for r in rows[1:]])
    raise KeyError(f"{path.name}: no history '{name}' (columns: {', '.join(head[2:])})")


def damping_ratio(v) -> float:
    """ξ of a sampled oscillation about zero, from the logarithmic decrement of its positive peaks."""
    peaks = []
    for i in range(1, len(v) - 1):
        if v[i] > 0.0 and v[i] > v[i - 1] and v[i] >= v[i + 1]:
            y0, y1, y2 = v[i - 1], v[i], v[i + 1]
            den = y0 - 2.0 * y1 + y2
            peaks.append(y1 - 0.125 * (y0 - y2) ** 2 / den if den else y1)
    if len(peaks) < 3:
        raise ValueError("damping-ratio: fewer than three positive peaks in the window")
    delta = math.log(peaks[0] / peaks[-1]) / (len(peaks) - 1)
    return delta / math.sqrt(4.0 * math.pi ** 2 + delta ** 2)


def derive(d: dict, q: dict[str, float], out: Path) -> float:
    """One `[[derive]]` quantity (see the module docstring)."""
    import csv

    import numpy as np

    kind = d["kind"]
    if kind in ("trend", "plunge"):
        x, y, z = (q[k] for k in d["of"])
        if kind == "trend":
            return math.degrees(math.atan2(x, y)) % 360.0
        return math.degrees(math.atan2(-z, math.hypot(x, y)))
    path = out / d["csv"]
    rows = list(csv.reader(open(path, encoding="utf-8")))
    t = np.array([float(r[1]) for r in rows[1:]])
    v = _column(rows, d["history"], path)
    rel = t - t[0]
    sel = (rel >= float(d.get("t0", -math.inf))) & (rel <= float(d.get("t1", math.inf)))
    if sel.sum() < (3 if kind == "curvature" else 2 if kind == "slope" else 1):
        raise ValueError(f"derive {d.get('name', kind)}: too few samples in the window")
    x = _column(rows, d["vs"], path) if "vs" in d else t
    if kind == "slope":
        return float(np.polyfit(x[sel], v[sel], 1)[0])
    if kind == "curvature":
        return float(2.0 * np.polyfit(x[sel], v[sel], 2)[0])
    if kind in ("mean", "max", "min"):
        return float(getattr(np, kind)(v[sel]))
    if kind == "damping-ratio":
        return damping_ratio(v[sel])
    raise ValueError(f"derive {d.get('name', kind)}: unknown kind {kind!r}")


def _ssdem_quantities(folder: Path, spec: dict) -> dict[str, float]:
    from .ssdem.verify import quantities

    return quantities(folder, spec)


KINDS: dict[str, Callable[[Path, dict], dict[str, float]]] = {
    "deck": _deck_quantities,
    "ssdem": _ssdem_quantities,
}


def default_root() -> Path:
    here = Path.cwd() / "verification"
    return here if here.is_dir() else Path(__file__).resolve().parent.parent / "verification"


def problems(root: Path) -> list[Path]:
    return sorted(p.parent for p in root.glob("*/problem.toml"))


EXPECT_KEYS = {"quantity", "value", "rel_tol", "abs_tol", "below", "not_comparable", "note"}


def _expect_error(e: dict) -> str | None:
    """What is wrong with one [[expect]] entry, or None."""
    if "report_only" in e:
        return ("'report_only' is gone: give the quantity a bar (value with rel_tol or abs_tol, or below) "
                "or say why it cannot have one: not_comparable = \"because ...\"")
    unknown = sorted(set(e) - EXPECT_KEYS)
    if unknown:
        return f"unknown key(s) {', '.join(unknown)} (known: {', '.join(sorted(EXPECT_KEYS))})"
    if "quantity" not in e:
        return "no 'quantity'"
    if "not_comparable" in e:
        if not isinstance(e["not_comparable"], str) or not e["not_comparable"].strip():
            return "'not_comparable' must be the reason, as text"
        if "value" not in e or set(e) & {"rel_tol", "abs_tol", "below"}:
            return "a not_comparable entry gives the published 'value' and no tolerance or 'below'"
        return None
    if "below" in e:
        return None if not set(e) & {"value", "rel_tol", "abs_tol"} else "'below' takes no value or tolerance"
    if "value" not in e or len(set(e) & {"rel_tol", "abs_tol"}) != 1:
        return "a bar needs 'value' and exactly one of 'rel_tol', 'abs_tol'"
    return None


def check_problem(folder: Path) -> list[Check]:
    where = folder / "problem.toml"
    spec = tomllib.loads(where.read_text(encoding="utf-8"))
    kind = spec.get("kind")
    if kind not in KINDS:
        raise ValueError(f"{where}: kind must be one of {sorted(KINDS)}, got {kind!r}")
    for i, e in enumerate(spec.get("expect", []), start=1):
        err = _expect_error(e)
        if err:
            raise ValueError(f"{where}: [[expect]] number {i} ({e.get('quantity', '?')}): {err}")
    q = KINDS[kind](folder, spec)
    checks = []
    for e in spec.get("expect", []):
        name = e["quantity"]
        m = q.get(name)
        if "below" in e:
            other = q.get(e["below"])
            ok = m is not None and other is not None and m < other
            checks.append(Check(folder.name, name, m, f"< {e['below']} ({other:.4g})" if other is not None else
                                f"< {e['below']} (missing)", ok, e.get("note", "")))
            continue
        v = float(e["value"])
        if "not_comparable" in e:
            checks.append(Check(folder.name, name, m, f"{v:.6g}", None, e["not_comparable"].strip()))
            continue
        if "rel_tol" in e:
            tol = abs(v) * float(e["rel_tol"])
            exp = f"{v:.6g} ± {100 * float(e['rel_tol']):g} %"
        else:
            tol = float(e["abs_tol"])
            exp = f"{v:.6g} ± {tol:g}"
        ok = m is not None and math.isfinite(m) and abs(m - v) <= tol
        checks.append(Check(folder.name, name, m, exp, ok, e.get("note", "")))
    return checks


def render(rows: list[Check]) -> str:
    """The verify table: the checked rows with PASS/FAIL and their count, then, in a section of their
    own, the rows shown beside a published figure they are not comparable with, each with the reason."""
    def meas(c: Check) -> str:
        return "-" if c.measured is None else f"{c.measured:.6g}"

    checked = [c for c in rows if c.passed is not None]
    shown = [c for c in rows if c.passed is None]
    out = [f"{'problem':32s} {'quantity':22s} {'measured':>12s}  {'expected':28s} result"]
    for c in checked:
        out.append(f"{c.problem:32s} {c.quantity:22s} {meas(c):>12s}  {c.expected:28s} "
                   f"{'PASS' if c.passed else 'FAIL'}" + (f"  {c.note}" if c.note else ""))
    out.append(f"{sum(c.passed is True for c in checked)} passed, {sum(c.passed is False for c in checked)} failed")
    if shown:
        out += ["", "Not comparable (shown beside a published figure, not checked):",
                f"{'problem':32s} {'quantity':22s} {'measured':>12s}  {'published':>10s}  because"]
        for c in shown:
            out.append(f"{c.problem:32s} {c.quantity:22s} {meas(c):>12s}  {c.expected:>10s}  {c.note}")
    return "\n".join(out)


def main(names: list[str] | None = None, root: str | Path | None = None) -> int:
    root = Path(root) if root else default_root()
    folders = problems(root)
    if names:
        unknown = [n for n in names if not any(f.name == n or f.name.startswith(n) for f in folders)]
        if unknown:
            known = ", ".join(f.name for f in folders) or "none"
            print(f"dec3d verify: error: no verification problem named {', '.join(f'`{n}`' for n in unknown)} "
                  f"in {root} (a name or the start of one; there are: {known})", file=sys.stderr)
            return 2
        folders = [f for f in folders if f.name in names or any(f.name.startswith(n) for n in names)]
    rows: list[Check] = []
    for f in folders:
        try:
            rows += check_problem(f)
        except Exception as exc:  # a crashing problem is a failed problem, reported, and the others still run
            rows.append(Check(f.name, "(run)", None, "runs", False, f"{type(exc).__name__}: {exc}"))
    print(render(rows))
    return 1 if any(c.passed is False for c in rows) else 0
