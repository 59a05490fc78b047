"""History export: one CSV with the chosen histories, one PNG plot per history (matplotlib, Agg)."""
from __future__ import annotations

import csv
from pathlib import Path

from dec3d.io.finite import require_finite


def write_csv(path: Path, hists, vs=None) -> None:
    """Columns: step, time, [the `vs` history,] then each history; one row per sample."""
    path.parent.mkdir(parents=True, exist_ok=True)
    cols = ([vs] if vs is not None else []) + list(hists)
    n = min(len(h.values) for h in cols) if cols else 0
    for h in cols:
        require_finite(f"history {h.name} ({h.label})", h.values[:n], missing_ok=True)   # NaN: no value yet
    with open(path, "w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(["step", "time"] + [f"{h.name} ({h.label})" for h in cols])
        for i in range(n):
            w.writerow([cols[0].steps[i], repr(cols[0].times[i])] +
                       [repr(h.values[i]) if h.values[i] == h.values[i] else "" for h in cols])


def write_png(path: Path, hist, vs=None) -> None:
    """Plot one history against time (or against the `vs` history)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path.parent.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(6.4, 4.0), dpi=100)
    n = len(hist.values) if vs is None else min(len(hist.values), len(vs.values))
    x = hist.times[:n] if vs is None else vs.values[:n]
    ax.plot(x, hist.values[:n], lw=1.2)
    ax.set_xlabel("time (s)" if vs is None else f"{vs.name} ({vs.label})")
    ax.set_ylabel(f"{hist.name} ({hist.label})")
    ax.grid(True, lw=0.4, alpha=0.5)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
