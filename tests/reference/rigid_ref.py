"""Slow, obviously-correct twins of the rigid-block kernels (commonplane, jointlaw, motion)."""
import math

import numpy as np
from scipy.optimize import minimize


def hull_distance(va, vb):
    """Euclidean distance between the convex hulls of two vertex sets: minimise
    |Σ λ_i a_i − Σ μ_j b_j| over the two simplices of weights (SLSQP)."""
    na, nb = len(va), len(vb)

    def f(x):
        d = x[:na] @ va - x[na:] @ vb
        return d @ d

    cons = [{"type": "eq", "fun": lambda x: x[:na].sum() - 1.0},
            {"type": "eq", "fun": lambda x: x[na:].sum() - 1.0}]
    x0 = np.concatenate([np.full(na, 1.0 / na), np.full(nb, 1.0 / nb)])
    r = minimize(f, x0, bounds=[(0, 1)] * (na + nb), constraints=cons, method="SLSQP",
                 options={"ftol": 1e-16, "maxiter": 500})
    return math.sqrt(max(r.fun, 0.0))


def sampled_best_gap(va, vb, n_dirs=40000, seed=0):
    """max over many unit directions of min_B n·V − max_A n·V (a lower bound of the best gap)."""
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(n_dirs, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    g = (vb @ d.T).min(axis=0) - (va @ d.T).max(axis=0)
    return float(g.max())


def coulomb_ref(p, model, area, dun, dus, un, udil, fs, us, failed):
    """Scalar Coulomb slip law written from the text (Eqs. 24-43 with the ERRATA), plain Python.
    p: dict kn ks phi coh ten dil zdil phir cohr tenr (angles in radians)."""
    fs = np.array(fs, float) - p["ks"] * area * np.asarray(dus)
    us = np.array(us, float) + np.asarray(dus)
    un = un + dun
    fn = -p["kn"] * area * (un - udil)
    slip = False
    if model == "elastic":
        if fn < 0:
            return 0.0, np.zeros(3), un, udil, us, failed, False
        return fn, fs, un, udil, us, failed, False
    coh, ten, phi = (p["cohr"], p["tenr"], p["phir"]) if failed else (p["coh"], p["ten"], p["phi"])
    if fn < -ten * area:
        return 0.0, np.zeros(3), un, udil, us, True, False
    fsmax = max(coh * area + fn * math.tan(phi), 0.0)
    mag = float(np.linalg.norm(fs))
    if mag > fsmax:
        if not failed:
            failed = True
            fsmax = max(p["cohr"] * area + fn * math.tan(p["phir"]), 0.0)
        fs = fs * (fsmax / mag)
        slip = True
        dm = float(np.linalg.norm(dus))
        if p["dil"] != 0 and dm > 0 and (p["zdil"] <= 0 or np.linalg.norm(us) <= p["zdil"]):
            sgn = 1.0 if np.dot(dus, us) >= 0 else -1.0
            udil += sgn * dm * math.tan(p["dil"])
            fn += p["kn"] * area * sgn * dm * math.tan(p["dil"])
    return fn, fs, un, udil, us, failed, slip


def rotate_rodrigues(r, theta):
    """Rotate vector r by the rotation whose Cayley (Rodrigues-parameter) vector is θ/2."""
    a = np.asarray(theta) / 2.0
    A = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    R = np.linalg.solve(np.eye(3) - A, np.eye(3) + A)
    return R @ r
