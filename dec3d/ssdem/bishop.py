"""Bishop's simplified method of slices on circles, and a circular-surface search.

For a slice of width b, base inclination alpha, weight W, vertical surcharge Q,
base pore pressure u, base length l = b / cos(alpha) (Bishop 1955; Fredlund & Krahn
1977, the F_m equation with zero interslice shear):

    N  = [W + Q - (c l - u l tan phi) sin(alpha) / F] / m_alpha,
    m_alpha = cos(alpha) + psi tan(phi) sin(alpha) / F
    F  = sum(c l + (psi N - u l) tan phi) / sum((W + Q) sin(alpha) + kh W (y_c - y_g) / R)

psi = 1 normally; psi = 1 - r_u with u = 0 reproduces the thesis listing's
sigma'_n = (1 - r_u) sigma_n.  alpha is measured so that sin(alpha) > 0 where the
base rises towards the crest; the mass slides towards the face.  All circles of a
batch are evaluated at once (arrays of shape (circles, slices)).
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import minimize

from .soil import Slope


def _extent(slope: Slope, xc, yc, R):
    """Entry / exit x of each circle's slip mass: the widest stretch of its lower arc
    below the ground (nan when none); see Slope.circle_spans."""
    x_in, x_out, _ = slope.circle_spans(xc, yc, R)
    return x_in, x_out


def _slices(slope: Slope, xc, yc, R, n, span=None):
    with np.errstate(all="ignore"):
        return _slices_raw(slope, xc, yc, R, n, span)


def _slices_raw(slope: Slope, xc, yc, R, n, span):
    x_in, x_out = _extent(slope, xc, yc, R) if span is None else span
    e = x_in[:, None] + (x_out - x_in)[:, None] * np.linspace(0, 1, n + 1)[None, :]
    xm = 0.5 * (e[:, 1:] + e[:, :-1])
    b = np.diff(e, axis=1)
    yb = yc[:, None] - np.sqrt(np.clip(R[:, None] ** 2 - (xm - xc[:, None]) ** 2, 0, None))
    return x_in, x_out, xm, b, yb


def fs_circles(slope: Slope, xc, yc, R, n: int = 60, ordinary: bool = False, tol: float = 1e-7, span=None):
    """Bishop (or ordinary) FS of many circles; inf where a circle misses the slope or m_alpha <= 0.

    span: the circles' (x_in, x_out) when already known (_extent)."""
    with np.errstate(all="ignore"):
        return _fs_circles(slope, xc, yc, R, n, ordinary, tol, span)


def _fs_circles(slope, xc, yc, R, n, ordinary, tol, span):
    xc, yc, R = (np.atleast_1d(np.asarray(v, float)) for v in (xc, yc, R))
    x_in, x_out, xm, b, yb = _slices(slope, xc, yc, R, n, span)
    k, ns = xm.shape
    fx, fy = xm.ravel(), yb.ravel()
    top = slope.ground(fx)
    h = np.clip(top - fy, 0, None)
    W = (slope.overburden(fx, fy) * b.ravel()).reshape(k, ns)
    Q, _ = slope.surcharge_on(fx - 0.5 * b.ravel(), fx + 0.5 * b.ravel())
    Q = Q.reshape(k, ns)
    lay = slope.layer_at(fx, fy)
    c = slope.prop("c", lay).reshape(k, ns)
    tp = np.tan(np.radians(slope.prop("phi", lay))).reshape(k, ns)
    u = slope.pore_pressure(fx, fy).reshape(k, ns)
    psi = 1.0 - slope.ru if (slope.ru_mode == "listing" and slope.piezometric is None) else 1.0
    side = 1.0 if slope.faces_left() else -1.0
    sa = side * (xm - xc[:, None]) / R[:, None]
    ca = np.sqrt(np.clip(1 - sa ** 2, 0, None))
    l = b / np.maximum(ca, 1e-12)
    c = np.where(h.reshape(k, ns) > 0, c, 0.0)
    ymid = 0.5 * (yb + top.reshape(k, ns))
    drive = np.sum((W + Q) * sa + slope.kh * W * (yc[:, None] - ymid) / R[:, None], axis=1)
    if ordinary:
        N = (W + Q) * ca
        F = np.sum(c * l + (psi * N - u * l) * tp, axis=1) / drive
    else:
        F = np.full(k, 1.5)
        act = np.arange(k)                  # circles still iterating (finite, not yet converged)
        for _ in range(200):
            Fa = F[act][:, None]
            m = ca[act] + psi * tp[act] * sa[act] / Fa
            N = (W[act] + Q[act] - (c[act] * l[act] - u[act] * l[act] * tp[act]) * sa[act] / Fa) / m
            Fn = np.sum(c[act] * l[act] + (psi * N - u[act] * l[act]) * tp[act], axis=1) / drive[act]
            moving = np.isfinite(Fn) & ~(np.abs(Fn - F[act]) <= tol * np.abs(Fn))
            F[act] = Fn
            act = act[moving]
            if not len(act):
                break
        m = ca + psi * tp * sa / F[:, None]
        F = np.where(np.all(m > 0.05, axis=1), F, np.inf)
    # no driving moment (beyond round-off of the weights' moments): no slip to resist
    scale = np.sum(np.abs((W + Q) * sa), axis=1)
    bad = ~np.isfinite(x_in) | (x_out - x_in <= 0) | ~(drive > 1e-9 * scale)
    return np.where(bad, np.inf, F)


def bishop(slope: Slope, centre, radius, n: int = 200) -> dict:
    """Bishop and ordinary FS on one circle, with where it meets the ground."""
    xc, yc = centre
    fs = float(fs_circles(slope, xc, yc, radius, n)[0])
    fo = float(fs_circles(slope, xc, yc, radius, n, ordinary=True)[0])
    x_in, x_out = _extent(slope, np.array([xc], float), np.array([yc], float), np.array([radius], float))
    return dict(fs=fs, fs_ordinary=fo, centre=[float(xc), float(yc)], radius=float(radius),
                x_entry=float(x_in[0]), x_exit=float(x_out[0]))


def fit_circle(points: np.ndarray) -> tuple[tuple[float, float], float]:
    """Least-squares circle through points (algebraic fit, Kasa 1976)."""
    x, y = points[:, 0], points[:, 1]
    A = np.column_stack([x, y, np.ones(len(x))])
    sol, *_ = np.linalg.lstsq(A, x * x + y * y, rcond=None)
    xc, yc = sol[0] / 2, sol[1] / 2
    return (float(xc), float(yc)), float(np.sqrt(sol[2] + xc * xc + yc * yc))


def search(slope: Slope, bottom: float | None = None, grid: int = 14, n: int = 40, min_depth: float | None = None) -> dict:
    """Minimum Bishop FS over circles: a grid of centres and radii, then Nelder-Mead.

    Circles stay above `bottom` (a firm base or the mesh bottom).  Slip masses shallower
    than `min_depth` (default 2 % of the slope height) are ignored: they are surface
    ravelling, not the slope mechanism.
    """
    prof = slope.profile
    x0, x1 = float(prof[0, 0]), float(prof[-1, 0])
    g0, g1 = float(prof[:, 1].min()), float(prof[:, 1].max())
    # the height scale of the grid: the slope, but not less than 5 % of the section width
    H = max(g1 - g0, 0.05 * (x1 - x0), 1e-6)
    lo_y = bottom if bottom is not None else g0 - H
    depth_min = 0.02 * H if min_depth is None else min_depth
    xs = np.linspace(x0, x1, grid)
    ys = np.linspace(g0 + 0.2 * H, g1 + 2.0 * H, grid)
    XC, YC = np.meshgrid(xs, ys)
    XC, YC = XC.ravel(), YC.ravel()
    # radii from just below the ground at the centre to the lowest allowed elevation
    t = np.linspace(0.05, 1.0, grid)
    R = (YC - lo_y)[:, None] * t[None, :]
    XC = np.repeat(XC, grid)
    YC = np.repeat(YC, grid)
    R = R.ravel()

    def objective(xc, yc, r):
        span = _extent(slope, xc, yc, r)
        f = fs_circles(slope, xc, yc, r, n, span=span)
        sag = _depth(slope, xc, yc, r, span)
        f = np.where(sag < depth_min, np.inf, f)
        f = np.where(_lowest(slope, xc, yc, r, span) < lo_y - 1e-9, np.inf, f)
        return f
    F = objective(XC, YC, R)
    order = np.argsort(F)[:5]
    best = (np.inf, None)
    for i in order:
        if not np.isfinite(F[i]):
            continue
        res = minimize(lambda p: float(objective(*(np.array([v]) for v in p))[0]),
                       x0=[XC[i], YC[i], R[i]], method="Nelder-Mead",
                       options=dict(xatol=1e-4 * H, fatol=1e-6, maxiter=600))
        if res.fun < best[0]:
            best = (float(res.fun), res.x)
    if best[1] is None:
        return dict(fs=float("nan"), centre=None, radius=None)
    xc, yc, r = best[1]
    out = bishop(slope, (xc, yc), r)
    return out


def _lowest(slope: Slope, xc, yc, R, span=None):
    """Lowest elevation of each slip surface (the arc between entry and exit)."""
    x_in, x_out = _extent(slope, xc, yc, R) if span is None else span
    xl = np.clip(xc, x_in, x_out)
    with np.errstate(all="ignore"):
        return np.where(np.isfinite(x_in), yc - np.sqrt(np.clip(R * R - (xl - xc) ** 2, 0, None)), np.inf)


def _depth(slope: Slope, xc, yc, R, span=None):
    """Largest vertical depth of each slip mass (0 when the circle misses)."""
    x_in, x_out, xm, b, yb = _slices(slope, np.atleast_1d(xc), np.atleast_1d(yc), np.atleast_1d(R), 20, span)
    d = slope.ground(xm) - yb
    return np.where(np.isfinite(x_in), np.nanmax(np.where(np.isfinite(d), d, 0), axis=1), 0.0)
