"""Slow twins and single-zone load paths shared by the zone-model tests (strain-softening,
ubiquitous-joint). Written from the formulas with numpy; nothing here comes from the kernels.

- ``twin_hooke``: s + D:d for isotropic elasticity (tensor shear components).
- ``twin_mc``: the Mohr-Coulomb return of a trial stress in principal space (numpy ``eigh``), the
  nine planes (shear for each ordered pair of principal stresses, the cut-off on each), solved
  generically for the active set in the order the Mohr-Coulomb text of dec3d states (Itasca's
  plane by the h function alone; with one other; each other alone; two others; any three), the
  first consistent set (multipliers >= 0, all planes satisfied) taken; returns the multipliers.
- ``triaxial_path``: drive a zone's ``update`` with a prescribed axial strain increment per
  step while the other five stress components are held at their targets (Newton on the five
  other strain components, finite-difference Jacobian).
"""
from __future__ import annotations

import itertools
import math

import numpy as np


def tensor(s):
    return np.array([[s[0], s[3], s[4]], [s[3], s[1], s[5]], [s[4], s[5], s[2]]], dtype=float)


def vec6(t):
    return np.array([t[0, 0], t[1, 1], t[2, 2], t[0, 1], t[0, 2], t[1, 2]])


def nfac(tan_angle):
    sn = math.sin(math.atan(tan_angle))
    return (1 + sn) / (1 - sn)


def twin_hooke(s, d, K, G):
    eps = tensor(d)
    return tensor(s) + (K - 2 * G / 3) * np.trace(eps) * np.eye(3) + 2 * G * eps


def twin_mc(trial, K, G, c, tanphi, ten, tanpsi):
    """Mohr-Coulomb return of the 3x3 trial stress (tension positive). Returns (new 3x3,
    {plane key: multiplier > 0}, principal trial w, principal new, flow vectors {key: m}, the
    keys of the planes the new stress lies on).
    Keys: ("s", i, j) shear with i the more compressive, ("t", i) tension on principal i."""
    w, v = np.linalg.eigh(trial)
    nphi, npsi = nfac(tanphi), nfac(tanpsi)
    st = min(ten, c / tanphi) if tanphi > 0 else ten
    a1, a2 = K + 4 * G / 3, K - 2 * G / 3
    dmat = np.full((3, 3), a2) + (a1 - a2) * np.eye(3)
    planes = {}
    for (i, j) in [(0, 2), (0, 1), (1, 2), (1, 0), (2, 0), (2, 1)]:
        n = np.zeros(3); n[i] = -1; n[j] = nphi
        m = np.zeros(3); m[i] = -1; m[j] = npsi
        planes[("s", i, j)] = (n, 2 * c * math.sqrt(nphi), m)
    for i in range(3):
        e = np.zeros(3); e[i] = 1
        planes[("t", i)] = (e, st, e.copy())
    order = list(planes)
    F = lambda key, sv: planes[key][0] @ sv - planes[key][1]      # noqa: E731
    tol = 1e-10 * (abs(w).sum() + c + abs(st))
    flows = {k: planes[k][2] for k in order}
    if all(F(k, w) <= tol for k in order):
        return trial.copy(), {}, w, w.copy(), flows, []
    s1, s3 = w[0], w[2]
    sig_p = st * nphi - 2 * c * math.sqrt(nphi)
    alpha_p = math.sqrt(1 + nphi ** 2) + nphi
    h = s3 - st + alpha_p * (s1 - sig_p)
    first = ("s", 0, 2) if (F(("s", 0, 2), w) > tol and (h <= 0 or F(("t", 2), w) <= tol)) else ("t", 2)

    def solve(keys):
        M = np.array([[planes[a][0] @ dmat @ planes[b][2] for b in keys] for a in keys])
        if np.linalg.cond(M) > 1e11:
            return None
        lam = np.linalg.solve(M, np.array([F(a, w) for a in keys]))
        if lam.min() < -1e-12 * np.abs(lam).max():
            return None
        sv = w - sum(l_ * (dmat @ planes[a][2]) for l_, a in zip(lam, keys))
        if any(F(k, sv) > tol for k in order):
            return None
        return sv, dict(zip(keys, lam))

    others = [k for k in order if k != first]
    cands = ([[first]] + [[first, k] for k in others] + [[k] for k in others]
             + [list(p) for p in itertools.combinations(others, 2)]
             + [list(p) for p in itertools.combinations(order, 3)])
    for keys in cands:
        got = solve(keys)
        if got is not None:
            new, mult = got
            break
    else:
        raise AssertionError("twin: no consistent Mohr-Coulomb return")
    out = trial + v @ np.diag(new - w) @ v.T
    on = [k for k in order if F(k, new) >= -1e-8 * (abs(w).sum() + c + abs(st))]
    return out, {k: x for k, x in mult.items() if x > 0}, w, new, flows, on


def triaxial_path(step, s0, deps, nsteps, targets=None, tol=1e-4, on_step=None):
    """Drive ``step(s, d) -> (bits, new s)`` (6-vectors; ``step`` must not keep state between
    calls it is asked to redo: it receives a flag ``commit``) with d_zz = deps per step and the
    other five stress components held at ``targets`` (default: their values in s0), by Newton
    on the other five strain components (finite-difference Jacobian, least-squares steps: where
    the zone flows on an edge of its yield surface the split of the lateral strains is free). Returns the list of
    (total strain 6, stress 6, bits) after each step."""
    free = [0, 1, 3, 4, 5]
    s = np.array(s0, float)
    tgt = s[free].copy() if targets is None else np.asarray(targets, float)
    eps = np.zeros(6)
    out = []
    x = np.zeros(5)
    for _ in range(nsteps):
        def resid(xv):
            d = np.zeros(6); d[2] = deps; d[free] = xv
            _, sn = step(s, d, False)
            return sn[free] - tgt
        r = resid(x)
        for _it in range(30):
            if np.abs(r).max() <= tol:
                break
            J = np.empty((5, 5))
            h = 1e-9
            for k in range(5):
                xp = x.copy(); xp[k] += h
                J[:, k] = (resid(xp) - r) / h
            # (least squares: on an edge of the Mohr-Coulomb pyramid the lateral split is free)
            x = x - np.linalg.lstsq(J, r, rcond=1e-9)[0]
            r = resid(x)
        else:
            raise AssertionError(f"triaxial path: no convergence (residual {np.abs(r).max():.3g} Pa)")
        d = np.zeros(6); d[2] = deps; d[free] = x
        bits, s = step(s, d, True)
        eps = eps + d
        out.append((eps.copy(), s.copy(), bits))
        if on_step is not None:
            on_step(len(out) - 1)
    return out
