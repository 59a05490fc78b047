"""Text summary, CSV tables and the JSON record of an analysis (in the input's units)."""
from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np

from ..errors import printable
from .analysis import Analysis, summary_numbers
from .safety import STATE_NAMES
from .solve import contact_length
from .units import factors, labels


def _clean(v):
    """JSON-safe: numpy to Python, non-finite floats to None."""
    if isinstance(v, dict):
        return {str(k): _clean(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_clean(x) for x in v]
    if isinstance(v, np.ndarray):
        return _clean(v.tolist())
    if isinstance(v, (np.floating, float)):
        return float(v) if math.isfinite(v) else None
    if isinstance(v, np.integer):
        return int(v)
    if isinstance(v, np.bool_):
        return bool(v)
    return v


def tables(an: Analysis) -> tuple[dict, dict]:
    """Column arrays of the block and interface tables, converted to the input's units."""
    p, st, s = an.problem, an.state, an.safety
    fac = factors(p.units if p.units in ("N-m", "kN-m", "lb-ft") else "N-m")
    L, S, F = fac["length"], fac["stress"], fac["force"]
    blk, itf = p.blocks, p.interfaces
    u = st.u
    blocks = {
        "block": np.arange(blk.n), "x": blk.ref[:, 0] / L, "y": blk.ref[:, 1] / L,
        "fixed": blk.fixed.astype(int), "removed_at_step": st.removed_step,
        "ux": u[:, 0] / L, "uy": u[:, 1] / L, "rotation": u[:, 2], "u_magnitude": np.hypot(u[:, 0], u[:, 1]) / L,
        "fx": blk.force[:, 0] / F, "fy": blk.force[:, 1] / F,
    }
    interfaces = {
        "interface": np.arange(itf.m), "block_a": itf.a, "block_b": itf.b,
        "side_a": itf.side_a, "side_b": itf.side_b,
        "x": itf.mid[:, 0] / L, "y": itf.mid[:, 1] / L, "length": itf.length / L,
        "contact_length": contact_length(p, st) / L,
        "normal_angle_deg": np.degrees(np.arctan2(itf.normal[:, 1], itf.normal[:, 0])),
        "sigma_n": s.sigma_n / S, "tau": s.tau / S, "sigma_n_eff": s.sig_eff / S,
        "tau_available": s.tau_avail / S, "fs": s.fs, "yield_pct": s.yield_pct,
        "ks_ratio": np.where(itf.ks > 0, st.ks / np.where(itf.ks > 0, itf.ks, 1), 0.0),
        "state": np.array([STATE_NAMES[k] for k in s.state]), "failure_surface": s.failure.astype(int),
    }
    return blocks, interfaces


def write_csv(path: Path, cols: dict) -> None:
    keys = list(cols)
    n = len(cols[keys[0]])
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(keys)
        for i in range(n):
            w.writerow([_fmt(cols[k][i]) for k in keys])


def _fmt(v):
    if isinstance(v, (float, np.floating)):
        return "inf" if v == np.inf else ("nan" if not np.isfinite(v) else f"{v:.6g}")
    return printable(v) if isinstance(v, str) else v      # a layer name from the input: no raw control bytes


def summary_text(an: Analysis) -> str:
    p, st, s = an.problem, an.state, an.safety
    q = summary_numbers(an)
    lab = labels(p.units) if p.units in ("N-m", "kN-m", "lb-ft") else {"length": "m"}
    out = [f"dec3d ssdem - {p.title}", f"input: {p.source} ({p.fmt}), units {p.units}",
           f"blocks: {p.blocks.n} ({int(p.blocks.fixed.sum())} fixed), interfaces: {p.interfaces.m}",
           f"pore pressure: r_u = {p.settings.ru:g} ({p.settings.ru_mode})" if p.settings.ru else "pore pressure: "
           + ("piezometric line" if np.any(p.interfaces.u_pore) else "none"),
           f"load steps: {p.settings.n_steps}; secant iterations per step: {[r.iterations for r in st.steps]}",
           f"converged in every step: {'yes' if q['converged'] else 'NO'} (tolerance {p.settings.tol:g})",
           f"largest block displacement: {q['max_displacement'] / factors(p.units)['length']:.4g} {lab['length']}"]
    rm = np.flatnonzero(st.removed)
    out.append(f"unstable blocks removed: {len(rm)}" + (": " + ", ".join(f"{i} (step {st.removed_step[i]})" for i in rm[:50]) if len(rm) else ""))
    out.append(f"yielded interfaces: {int(q['n_yielded'])}, cracked: {int(q['n_cracked'])}")
    if st.s1 is not None:
        lc, live = contact_length(p, st), ~(st.removed[p.interfaces.a] | st.removed[p.interfaces.b])
        part = live & (lc > 0) & (lc < p.interfaces.length * (1 - 1e-9))
        out.append(f"no-tension interfaces: {int(np.sum(live & (lc <= 0)))} open, {int(part.sum())} partly open")
    ids = np.flatnonzero(s.failure)
    kinds = {"prescribed": "the prescribed slip surface", "yield": "yielded/cracked interfaces and edges of removed blocks",
             "none": "none formed (no interface yielded)"}
    out.append(f"failure surface: {kinds[s.surface_kind]}; {len(ids)} interfaces, {s.n_averaged} carry stress and are averaged")
    if len(ids):
        out.append("  interfaces: " + " ".join(map(str, ids[:200])) + (" ..." if len(ids) > 200 else ""))
    out.extend(_limit_lines(an))
    at = " at the limit state" if (an.limit or {}).get("state") else ""
    out.append(f"FS (static DEM, shear-force weighted average = Eq. 2.6){at}: {_num(q['fs_dem'])}")
    out.append(f"FS (static DEM, arithmetic mean of interface FS, thesis App. C){at}: {_num(q['fs_dem_mean'])}")
    if s.surface_kind == "yield":
        out.append("  (a yielded interface carries its full strength, so an average over yielded interfaces is 1 "
                   "by construction; for the safety of a stable slope give a [surface] - a trial or the critical circle)")
    fin = s.fs[np.isfinite(s.fs)]
    if len(fin):
        out.append(f"smallest interface FS: {fin.min():.3f} (interface {int(np.flatnonzero(s.fs == fin.min())[0])})")
    b = an.bishop
    if b is not None:
        if not b.get("available"):
            out.append(f"Bishop: not available - {b['reason']}")
        else:
            if b.get("on_surface"):
                o = b["on_surface"]
                out.append(f"Bishop simplified on the failure surface ({o['how']}): {_num(o['fs'])} "
                           f"(ordinary method {_num(o['fs_ordinary'])})")
            sr = b.get("search") or {}
            if sr.get("centre") is not None:
                L = factors(p.units)["length"]
                out.append(f"Bishop simplified, minimum over circles: {_num(sr['fs'])} at centre "
                           f"({sr['centre'][0] / L:.3f}, {sr['centre'][1] / L:.3f}), radius {sr['radius'] / L:.3f} {lab['length']}")
    r = an.reduction
    if r is not None:
        if r.get("fs") is not None:
            out.append(f"FS (strength reduction of c' and tan phi' until the static DEM fails): {r['fs']:.3f} "
                       f"(holds at {r['holds_at']:.3f}, fails at {r['fails_at']:.3f}; {len(r['trials'])} trials)")
        else:
            out.append(f"FS (strength reduction): n/a - {r['reason']}")
    for note in p.notes:
        out.append(f"note: {note}")
    out.append(f"time: read {an.timings.get('read', 0):.2f} s, solve {an.timings.get('solve', 0):.2f} s "
               f"({an.timings.get('per_step', 0):.3f} s per load step)")
    return "\n".join(out) + "\n"


def _limit_lines(an: Analysis) -> list[str]:
    """What the summary says when the run does not hold at full strength (analysis.run_problem)."""
    lim = an.limit
    if lim is None:
        return []
    out = [f"the slope does not hold at full strength: {lim['full_strength']}"]
    b, st = lim["bracket"], lim["state"]
    if st is None:
        out.append(f"  no strength factor found at which it holds: {b.get('reason', '')}; the FS below is on "
                   "the state the run stopped in")
        return out
    proof = "a mechanism: proven" if st["failure_proven"] else "not proven: a larger [analysis] max_iterations may settle it"
    out.append(f"  with c' and tan phi' divided by F it holds (converged in every step) at F = {st['factor']:.3f} "
               f"and not at F = {st['fails_at']:.3f} ({st['fails_because']}; {proof})")
    out.append(f"  FS below: Eq. 2.6 with the full strengths on the converged state at F = {st['factor']:.3f} "
               f"(iterations per step {st['iterations']}); on the state the full-strength run stopped in it is "
               f"{_num(an.safety.fs_global)}; the files hold that state")
    return out


def _num(v) -> str:
    return "n/a" if v is None or not np.isfinite(v) else f"{v:.3f}"


def record(an: Analysis) -> dict:
    """Everything but the timings (timings.json), for result.json: the same input gives
    the same bytes."""
    p, st = an.problem, an.state
    blocks, interfaces = tables(an)
    return _clean(dict(
        title=p.title, input=p.source, format=p.fmt, units=p.units,
        settings=vars(p.settings), summary=summary_numbers(an),
        failure_surface=dict(kind=an.safety.surface_kind, interfaces=np.flatnonzero(an.safety.failure),
                             averaged=int(an.safety.n_averaged),
                             definition="fs_dem = sum(tau_available*L)/sum(tau_mobilised*L) over the failure surface"),
        steps=[vars(r) for r in st.steps], unstable_blocks=np.flatnonzero(st.removed),
        bishop=an.bishop, strength_reduction=an.reduction, limit=an.limit, surface=p.surface, notes=p.notes,
        blocks=blocks, interfaces=interfaces,
    ))


def write_all(an: Analysis, out: Path) -> list[Path]:
    out.mkdir(parents=True, exist_ok=True)
    blocks, interfaces = tables(an)
    files = [out / "summary.txt", out / "blocks.csv", out / "interfaces.csv", out / "steps.csv", out / "result.json",
             out / "timings.json"]
    files[0].write_text(printable(summary_text(an), newlines=True))   # titles and names from the input
    write_csv(files[1], blocks)
    write_csv(files[2], interfaces)
    steps = an.state.steps
    write_csv(files[3], {k: [getattr(r, k) for r in steps] for k in vars(steps[0])} if steps else {"step": []})
    files[4].write_text(json.dumps(record(an), indent=1))
    files[5].write_text(json.dumps(_clean(an.timings), indent=1, sort_keys=True))
    return files
