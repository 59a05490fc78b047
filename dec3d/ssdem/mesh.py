"""Block meshes generated from a slope description (the thesis's users typed every block).

Two layouts:

* grid: the whole section between the ground profile and a flat base, cut into
  columns (every profile vertex is a column edge) and rows at fixed elevations
  `size` apart; the top block of a column follows the ground.  Rows of
  neighbouring columns need not line up: interfaces are found from overlapping
  edges.  Blocks on the base are fixed; the outermost columns are rollers (u_x and
  rotation fixed, free to settle), so the sides do not hold the soil up by shear.

* surface: a prescribed slip surface (circle or polyline), as the thesis's Example 1
  used Chang's critical circle.  The mass above it is cut into slices whose bases
  are chords of the surface, each slice into `rows` blocks between base and
  ground; the ground under every chord is one fixed block.  The base interfaces
  are the failure surface.
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from .soil import Slope


def _polygons(polys: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Stack polygons into CSR, dropping repeated consecutive vertices (wedges become triangles)."""
    out, offs = [], [0]
    for p in polys:
        keep = np.ones(len(p), bool)
        d = np.roll(p, -1, axis=0) - p
        keep &= np.hypot(d[:, 0], d[:, 1]) > 1e-12 * max(1.0, float(np.abs(p).max()))
        p = p[keep]
        out.append(p)
        offs.append(offs[-1] + len(p))
    return np.concatenate(out), np.asarray(offs, np.int64)


def column_breaks(x0: float, x1: float, size: float, must: np.ndarray) -> np.ndarray:
    """Column edges from x0 to x1 about `size` apart, through every x in `must`."""
    must = np.unique(np.concatenate([[x0, x1], must[(must > x0) & (must < x1)]]))
    xs = [must[:1]]
    for a, b in zip(must[:-1], must[1:]):
        k = max(1, int(np.ceil((b - a) / size - 1e-9)))
        xs.append(np.linspace(a, b, k + 1)[1:])
    return np.concatenate(xs)


class MeshTooLarge(ValueError):
    """A mesh estimated above the block budget (raised before anything is allocated)."""

    def __init__(self, estimate: float, budget: int, what: str, key: str):
        self.estimate, self.budget, self.key = estimate, budget, key
        super().__init__(f"the mesh would have about {estimate:.3g} blocks ({what}); the budget is "
                         f"{budget} blocks (about {budget * 31 / 1000 / 1024:.3g} GiB)")


def grid_estimate(slope: Slope, size: float, bottom: float) -> float:
    """Blocks of grid_mesh, from the section's area and width (within a few %)."""
    prof = slope.profile
    area = float(np.sum(np.diff(prof[:, 0]) * (0.5 * (prof[1:, 1] + prof[:-1, 1]) - bottom)))
    width = float(prof[-1, 0] - prof[0, 0])
    return max(area, 0.0) / size ** 2 + width / size + len(prof)


def grid_mesh(slope: Slope, size: float, bottom: float, max_blocks: float = np.inf):
    """Blocks of the whole section; returns (verts, offsets, fix) with fix (n, 3) DOF fixity."""
    prof = slope.profile
    est = grid_estimate(slope, size, bottom)
    if est > max_blocks:
        raise MeshTooLarge(est, int(max_blocks), f"block size {size:g} over the section", "size")
    xb = column_breaks(prof[0, 0], prof[-1, 0], size, prof[:, 0])
    top = slope.ground(xb)
    if np.any(top <= bottom):
        raise ValueError("the ground profile must lie above the mesh bottom everywhere")
    polys, fixed = [], []
    ncol = len(xb) - 1
    for i in range(ncol):
        xl, xr, tl, tr = xb[i], xb[i + 1], top[i], top[i + 1]
        # rows at fixed elevations; the last row is at least half a block below the ground
        nlev = max(0, int(np.floor((min(tl, tr) - bottom - 0.5 * size) / size + 1e-9)))
        levels = bottom + size * np.arange(nlev + 1)
        for k in range(nlev):
            polys.append(np.array([[xl, levels[k]], [xr, levels[k]], [xr, levels[k + 1]], [xl, levels[k + 1]]]))
            fixed.append(_fixity(k == 0, i == 0 or i == ncol - 1))
        yk = levels[-1]
        polys.append(np.array([[xl, yk], [xr, yk], [xr, tr], [xl, tl]]))
        fixed.append(_fixity(nlev == 0, i == 0 or i == ncol - 1))
    verts, offsets = _polygons(polys)
    return verts, offsets, np.array(fixed, bool)


def _fixity(base: bool, side: bool) -> tuple[bool, bool, bool]:
    return (True, True, True) if base else (side, False, side)


def surface_function(surface: dict):
    """y(x) of the slip surface (nan where it is not defined) and its own vertices' x."""
    if surface["type"] == "circle":
        xc, yc = surface["centre"]
        r = surface["radius"]

        def ys(x):
            x = np.asarray(x, float)
            d = r * r - (x - xc) ** 2
            return np.where(d >= 0, yc - np.sqrt(np.clip(d, 0, None)), np.nan)
        return ys, np.zeros(0), (xc - r, xc + r)
    pts = np.asarray(surface["points"], float)

    def yp(x):
        x = np.asarray(x, float)
        y = np.interp(x, pts[:, 0], pts[:, 1])
        return np.where((x >= pts[0, 0]) & (x <= pts[-1, 0]), y, np.nan)
    return yp, pts[:, 0], (pts[0, 0], pts[-1, 0])


def slip_extent(slope: Slope, ys, xlim) -> tuple[float, float]:
    """Entry and exit x of the slip surface (the one stretch where it is below the ground)."""
    lo = max(xlim[0], slope.profile[0, 0])
    hi = min(xlim[1], slope.profile[-1, 0])
    xs = np.linspace(lo, hi, 4001)
    f = slope.ground(xs) - ys(xs)
    inside = np.nan_to_num(f, nan=-1.0) > 0
    if not inside.any():
        raise ValueError("the slip surface does not pass below the ground surface")
    idx = np.flatnonzero(inside)
    if np.any(np.diff(idx) > 1):
        raise ValueError("the slip surface comes out of the ground more than once")

    def g(x):
        v = float(slope.ground(x) - ys(x))
        return -1.0 if np.isnan(v) else v
    def root(a, b):
        # the sign change between a sample outside (g <= 0) and one inside (g > 0)
        ga = g(a)
        return a if ga == 0 else brentq(g, a, b, xtol=1e-12 * max(1.0, abs(a)))
    i0, i1 = idx[0], idx[-1]
    x_in = root(xs[i0 - 1], xs[i0]) if i0 > 0 else xs[i0]
    x_out = root(xs[i1 + 1], xs[i1]) if i1 + 1 < len(xs) else xs[i1]
    return float(x_in), float(x_out)


def surface_mesh(slope: Slope, surface: dict, slices: int, rows: int | None, max_blocks: float = np.inf):
    """Slices above a slip surface plus one fixed ground block under each base chord.

    Returns (verts, offsets, fixed, base_pairs) where base_pairs (k, 2) lists
    (slice block, ground block) whose shared edge is on the surface.  A circle's slip
    mass is the widest stretch of its arc below the ground (Slope.circle_spans, the
    same rule as the Bishop search); a circle prescribed by the user must leave the
    ground only once, as a polyline must.
    """
    ys, own_x, xlim = surface_function(surface)
    if surface["type"] == "circle":
        x_in, x_out, n = (float(v[0]) for v in slope.circle_spans(*surface["centre"], surface["radius"]))
        if n == 0:
            raise ValueError("the slip surface does not pass below the ground surface")
        if n > 1 and "search" not in surface:         # the search's circles: the widest mass
            raise ValueError("the slip surface comes out of the ground more than once")
    else:
        x_in, x_out = slip_extent(slope, ys, xlim)
    width = (x_out - x_in) / slices
    xs = np.linspace(x_in, x_out, 201)
    h_est = float(np.nanmax(slope.ground(xs) - ys(xs), initial=0.0))
    est = (slices + len(slope.profile) + len(own_x)) * ((rows if rows else max(1.0, h_est / width)) + 1)
    if est > max_blocks:
        raise MeshTooLarge(est, int(max_blocks), f"{slices} slices" + (f" of {rows} rows" if rows else ""),
                           "rows" if rows and rows > slices else "slices")
    must = np.concatenate([slope.profile[:, 0], own_x])
    must = must[(must > x_in + 0.3 * width) & (must < x_out - 0.3 * width)]
    xb = column_breaks(x_in, x_out, width * (1 + 1e-9), must)
    # merge uniform breaks that fall too close to a required one
    keep = np.ones(len(xb), bool)
    for m in must:
        near = np.flatnonzero((np.abs(xb - m) < 0.3 * width) & (np.abs(xb - m) > 1e-9 * width))
        keep[near] = False
    xb = xb[keep]
    top = slope.ground(xb)
    base = ys(xb)
    base[0], base[-1] = top[0], top[-1]          # the surface meets the ground at both ends
    base = np.minimum(base, top)
    height = top - base
    if rows is None:
        rows = max(1, int(round(float(height.max()) / max(float(np.diff(xb).mean()), 1e-12))))
    y_bot = float(base.min()) - max(float(height.max()) * 0.25, width)
    polys, fixed, pairs = [], [], []
    for i in range(len(xb) - 1):
        lv_l = base[i] + height[i] * np.arange(rows + 1) / rows
        lv_r = base[i + 1] + height[i + 1] * np.arange(rows + 1) / rows
        first = len(polys)
        for k in range(rows):
            polys.append(np.array([[xb[i], lv_l[k]], [xb[i + 1], lv_r[k]], [xb[i + 1], lv_r[k + 1]], [xb[i], lv_l[k + 1]]]))
            fixed.append(False)
        pairs.append((first, None))
    for i in range(len(xb) - 1):
        polys.append(np.array([[xb[i], y_bot], [xb[i + 1], y_bot], [xb[i + 1], base[i + 1]], [xb[i], base[i]]]))
        fixed.append(True)
        pairs[i] = (pairs[i][0], len(polys) - 1)
    verts, offsets = _polygons(polys)
    return verts, offsets, np.array(fixed), np.array(pairs, np.int64)
