"""History export: one CSV with the chosen histories, one PNG plot per history (matplotlib, Agg)."""
from __future__ import annotations

import csv
from pathlib import Path

from dec3d.io.finite import require_finite


def write_csv(path: Path, hists, vs=None) -> None:
    """Columns: step, time, [the `vs` history,] then each history; one row per step any of them
    sampled, aligned by step (a history made later, or deleted blocks' histories, leave cells empty)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    cols = ([vs] if vs is not None else []) + list(hists)
    for h in cols:
        require_finite(f"history {h.name} ({h.label})", h.values, missing_ok=True)   # NaN: no value yet
    at = [dict(zip(h.steps, h.values)) for h in cols]
    times = {}
    for h in cols:
        times.update(zip(h.steps, h.times))
    with open(path, "w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(["step", "time"] + [f"{h.name} ({h.label})" for h in cols])
        for step in sorted(times):
            vals = [a.get(step, float("nan")) for a in at]
            w.writerow([step, repr(times[step])] + [repr(v) if v == v else "" for v in vals])


def write_png(path: Path, hist, vs=None, time_unit: str = "") -> None:
    """Plot one history against time (or against the `vs` history); ``time_unit`` is the model time's
    unit when the deck declares one (``dec3d.units``)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path.parent.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(6.4, 4.0), dpi=100)
    n = len(hist.values) if vs is None else min(len(hist.values), len(vs.values))
    x = hist.times[:n] if vs is None else vs.values[:n]
    ax.plot(x, hist.values[:n], lw=1.2)
    ax.set_xlabel(f"time{time_unit}" if vs is None else f"{vs.name} ({vs.label})")
    ax.set_ylabel(f"{hist.name} ({hist.label})")
    ax.grid(True, lw=0.4, alpha=0.5)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
