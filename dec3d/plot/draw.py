"""One plot of a deck into one picture: a chart when it holds chart-history items, else the 3-D view."""
from __future__ import annotations

from pathlib import Path

from .items import Item


def draw_plot(model, plot, path: Path, size=None) -> list[str]:
    """Draw ``plot`` (``commands.plot_cmds._Plot``) of ``model`` into ``path``; returns notices."""
    charts = [i for i in plot.items if i.kind == "chart"]
    if charts:
        return draw_chart(model, charts, path, size, title=plot.name)
    from .render import SIZE, render
    from .scene import scene_from_model

    items = plot.items or [Item("contour", "displacement")]
    _, notices = render(scene_from_model(model), items, path, title=plot.name, background=plot.background,
                        size=size or SIZE)
    return notices


def draw_chart(model, charts, path: Path, size=None, title: str = "") -> list[str]:
    """Line chart of the histories of ``charts`` (each against its `vs` history, or time)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..physics.history import histories

    hs = histories(model)
    notices: list[str] = []

    def find(key):
        h = hs.find(key)
        if h is None and str(key).strip().isdigit():
            h = hs.find(int(key))
        if h is None:
            notices.append(f"there is no history {key}: not charted")
        return h

    w, h = size or (800, 500)
    fig, ax = plt.subplots(figsize=(w / 100, h / 100), dpi=100)
    xlabel = "time"
    for it in charts:
        vs = find(it.vs) if it.vs is not None else None
        if vs is not None:
            xlabel = vs.label or vs.name
        for key in it.histories:
            hist = find(key)
            if hist is None:
                continue
            n = len(hist.values) if vs is None else min(len(hist.values), len(vs.values))
            x = hist.times[:n] if vs is None else vs.values[:n]
            ax.plot(x, hist.values[:n], lw=1.4, label=hist.label or hist.name)
    if ax.lines:
        ax.legend(loc="best", fontsize=9)
    ax.set_xlabel(xlabel)
    ax.set_title(title)
    ax.grid(True, lw=0.4, alpha=0.5)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return notices
