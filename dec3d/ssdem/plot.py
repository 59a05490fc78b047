"""Figure (matplotlib, Agg) and VTK files (meshio polygons) of an analysis."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import printable
from .analysis import Analysis
from .units import factors


def figure(an: Analysis, path: Path) -> None:
    """Write figure.png (see build_figure), cropped to what is drawn."""
    import matplotlib.pyplot as plt
    fig = build_figure(an)
    fig.savefig(path, bbox_inches="tight", pad_inches=0.1)
    plt.close(fig)


def build_figure(an: Analysis):
    """Mesh coloured by displacement, failure surface in red, unstable blocks crossed.

    Returns the matplotlib figure; its first axes hold the model, the second the colour bar."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection, PolyCollection

    p, st, s = an.problem, an.state, an.safety
    L = factors(p.units)["length"] if p.units in ("N-m", "kN-m", "lb-ft") else 1.0
    blk, itf = p.blocks, p.interfaces
    polys = [blk.polygon(i) / L for i in range(blk.n)]
    mag = np.hypot(st.u[:, 0], st.u[:, 1]) / L
    # the axes take the model's proportions (equal scales), so no empty band is left
    # above or beside it; the colour bar is cut to the height of the axes
    pts = blk.verts / L if p.profile is None else np.vstack([blk.verts, p.profile]) / L
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    span = np.maximum(hi - lo, 1e-9 * max(float(np.abs(pts).max()), 1.0))
    pad = 0.03 * span.max()
    lo, hi = lo - pad, hi + pad
    dx, dy = hi - lo
    w_ax = 9.0
    h_ax = min(max(w_ax * dy / dx, 1.0), 8.0)
    if w_ax * dy / dx > 8.0:
        w_ax = max(8.0 * dx / dy, 2.0)
    fig = plt.figure(figsize=(w_ax + 2.0, h_ax + 1.6), dpi=110)
    ax = fig.add_axes((0.06, 0.12, w_ax / (w_ax + 2.0), h_ax / (h_ax + 1.6)))
    cmap = matplotlib.colormaps["viridis"].with_extremes(bad="0.85")   # fixed and removed blocks grey
    pc = PolyCollection(polys, array=np.where(st.removed | blk.fixed, np.nan, mag), cmap=cmap,
                        edgecolors="0.35", linewidths=0.3)
    ax.add_collection(pc)
    from mpl_toolkits.axes_grid1 import make_axes_locatable
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal", adjustable="box")
    cax = make_axes_locatable(ax).append_axes("right", size=0.2, pad=0.15)
    fig.colorbar(pc, cax=cax, label=f"displacement magnitude ({p.units.split('-')[1] if '-' in p.units else 'm'})")
    if st.removed.any():
        ax.add_collection(PolyCollection([polys[i] for i in np.flatnonzero(st.removed)], facecolors="none",
                                         edgecolors="crimson", hatch="xx", linewidths=0.6))
        ax.plot([], [], "s", mfc="none", mec="crimson", label=f"unstable blocks ({int(st.removed.sum())})")
    if s.failure.any():
        segs = np.stack([itf.p0[s.failure], itf.p1[s.failure]], axis=1) / L
        ax.add_collection(LineCollection(segs, colors="red", linewidths=2.5))
        ax.plot([], [], "r-", lw=2.5, label="failure surface")
    if p.profile is not None:
        ax.plot(p.profile[:, 0] / L, p.profile[:, 1] / L, "k-", lw=1.0, label="ground surface")
    slope = p.slope
    if slope is not None:
        x = p.profile[:, 0]
        for lay in slope.layers[1:]:
            xs = np.unique(np.concatenate([x, lay.top[:, 0]]))
            ax.plot(xs / L, slope.layer_tops(xs)[slope.layers.index(lay)] / L, color="saddlebrown", lw=0.8)
        if slope.piezometric is not None:
            pz = slope.piezometric
            ax.plot(pz[:, 0] / L, np.minimum(pz[:, 1], slope.ground(pz[:, 0])) / L, "b-", lw=1.0,
                    label="piezometric line")
        for a, b_, q in slope.surcharges:
            xs = np.linspace(a, b_, 9)
            ax.plot(xs / L, slope.ground(xs) / L, color="darkorange", lw=4, alpha=0.7)
    b = an.bishop or {}
    for key, style, name in (("on_surface", "b--", "Bishop on failure surface"), ("search", "m:", "Bishop minimum")):
        c = b.get(key) if b.get("available") else None
        if c and c.get("centre") is not None and np.isfinite(c.get("fs", np.nan)):
            t = np.linspace(0, 2 * np.pi, 400)
            xs = c["centre"][0] + c["radius"] * np.cos(t)
            ys = c["centre"][1] + c["radius"] * np.sin(t)
            inside = (xs >= c["x_entry"]) & (xs <= c["x_exit"]) & (ys <= c["centre"][1])
            ax.plot(np.where(inside, xs, np.nan) / L, np.where(inside, ys, np.nan) / L, style, lw=1.5,
                    label=f"{name}: FS {c['fs']:.3f}")
    fs = s.fs_global
    title = printable(p.title)
    ax.set_title(f"{title}\nstatic DEM FS = {fs:.3f}" if np.isfinite(fs) else title)
    handles = ax.get_legend_handles_labels()[0]
    if handles:          # below the axes, so that it hides nothing of the model
        from matplotlib.transforms import offset_copy
        below = offset_copy(ax.transAxes, fig=fig, y=-22, units="points")     # under the tick labels
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, 0.0), bbox_transform=below,
                  ncol=min(3, len(handles)), fontsize=8, frameon=False)
    return fig


def vtk(an: Analysis, out: Path) -> list[Path]:
    """blocks.vtu (polygons with displacement, rotation, state) and interfaces.vtu (lines)."""
    import meshio

    p, st, s = an.problem, an.state, an.safety
    blk, itf = p.blocks, p.interfaces
    pts = np.column_stack([blk.verts, np.zeros(len(blk.verts))])
    counts = np.diff(blk.offsets)
    cells, order = [], []
    for k in np.unique(counts):
        ids = np.flatnonzero(counts == k)
        conn = blk.offsets[ids][:, None] + np.arange(k)[None, :]
        cells.append(({3: "triangle", 4: "quad"}.get(int(k), "polygon"), conn))
        order.append(ids)
    disp = np.column_stack([st.u[:, 0], st.u[:, 1], np.zeros(blk.n)])
    data = {"displacement": [disp[i] for i in order], "rotation": [st.u[i, 2] for i in order],
            "fixed": [blk.fixed[i].astype(float) for i in order],
            "unstable_step": [st.removed_step[i].astype(float) for i in order]}
    f1 = out / "blocks.vtu"
    meshio.Mesh(pts, cells, cell_data=data).write(f1)
    lp = np.column_stack([np.concatenate([itf.p0, itf.p1]), np.zeros(2 * itf.m)])
    lines = np.column_stack([np.arange(itf.m), itf.m + np.arange(itf.m)])
    fs = np.where(np.isfinite(s.fs), s.fs, -1.0)
    idata = {"sigma_n": [s.sigma_n], "tau": [s.tau], "fs": [fs], "yield_pct": [s.yield_pct],
             "state": [s.state.astype(float)], "failure_surface": [s.failure.astype(float)]}
    f2 = out / "interfaces.vtu"
    meshio.Mesh(lp, [("line", lines)], cell_data=idata).write(f2)
    return [f1, f2]
