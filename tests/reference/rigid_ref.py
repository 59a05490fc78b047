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


# ------------------------------------------------------------------------------------------------
# twin of dec3d.kernels.motion.rigid_motion_groups: plain Python, matrices, written from the
# module docstring (not from the kernel's code)
# ------------------------------------------------------------------------------------------------

def cayley_matrix(a):
    """Rotation matrix of the Cayley transform with Rodrigues vector a: (E − A)⁻¹ (E + A)."""
    a = np.asarray(a, float)
    A = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.linalg.solve(np.eye(3) - A, np.eye(3) + A)


def _sgn(x):
    return 1.0 if x > 0 else (-1.0 if x < 0 else 0.0)


def motion_groups_ref(dt, gravity, damp_mode, alpha, servo, full_inertia,
                      gstart, gmember, gmass, gimass, giscalar, gprin, gaxes, gcentroid,
                      mass, fixity, force, moment, fapp, mapp, vel, spin, centroid, disp,
                      vstart, vcount, vpos, vmax, out, rule=None):
    """Slow twin of rigid_motion_groups; same arguments, updated in place, same return.

    rule: the adaptive servo's bounds, needed with damp_mode 3 and given by the caller from the
    documented rule (dict start, floor, cap, each times 1/Δt); the target ratio, window and factor
    are read from the servo array, which the caller fills. Nothing is defaulted here, so no constant
    of the kernel is repeated in this twin."""
    NS = 10                                  # servo layout (motion.py docstring): 10 scalars, then 6 per group
    ng = len(gstart) - 1
    g_vec = np.asarray(gravity, float)
    hist = damp_mode == 2 and servo[8] != 0
    av = 0.0
    if damp_mode == 3:
        if rule is None or not (servo[4] > 0 and servo[5] >= 1 and servo[6] > 1):
            raise ValueError("adaptive damping: give the servo rule and fill ratio, window, factor")
        lo, hi = rule["floor"] / dt, rule["cap"] / dt
        av = servo[0] if servo[0] > 0 else rule["start"] / dt
        av = min(max(av, lo), hi)
        servo[0] = av
    elif damp_mode == 4:                     # Rayleigh's mass term: viscous damping with α_v = alpha, fixed
        av = alpha
    al = alpha if damp_mode in (1, 2) else 0.0
    D1, D2 = 1 - av * dt / 2, 1 / (1 + av * dt / 2)

    def damp(f, v, fprev):
        if damp_mode == 1:
            return al * abs(f) * _sgn(v)
        if damp_mode == 2:
            return al * abs(f) * (_sgn(v) - (_sgn(f - fprev) if hist else 0.0)) / 2
        return 0.0

    fmax = fsum = ke = work = dek = 0.0
    bad = -1
    for g in range(ng):
        mem = list(gmember[gstart[g]:gstart[g + 1]])
        if not mem:
            continue
        lead = mem[0]
        fx = int(fixity[lead])
        C = gcentroid[g].copy()
        F = np.zeros(3)
        M = np.zeros(3)
        for b in mem:
            f = force[b] + fapp[b] + mass[b] * g_vec
            F += f
            M += moment[b] + mapp[b] + np.cross(centroid[b] - C, f)
            fsum += float(np.sum(np.abs(mass[b] * g_vec) + np.abs(force[b])))
        w = spin[lead].copy()
        V = vel[lead] - np.cross(w, centroid[lead] - C)
        mi = gimass[g]
        Vn = V.copy()
        Fu = F.copy()
        for i in range(3):
            fp = servo[NS + 6 * g + i] if damp_mode == 2 else 0.0
            if fx >> i & 1:
                Fu[i] = 0.0
            else:
                Vn[i] = (D1 * V[i] + (F[i] - damp(F[i], V[i], fp)) / mi * dt) * D2
        if damp_mode == 2:
            servo[NS + 6 * g: NS + 6 * g + 3] = F
        fmax = max(fmax, float(np.linalg.norm(Fu)))
        ek0 = 0.5 * mi * V @ V
        ek1 = 0.5 * mi * Vn @ Vn
        wn = w.copy()
        mp = servo[NS + 6 * g + 3: NS + 6 * g + 6].copy() if damp_mode == 2 else np.zeros(3)
        if not full_inertia:
            I = giscalar[g]
            for i in range(3):
                if not fx >> (3 + i) & 1:
                    wn[i] = (D1 * w[i] + (M[i] - damp(M[i], w[i], mp[i])) / I * dt) * D2
            ek0 += 0.5 * I * w @ w
            ek1 += 0.5 * I * wn @ wn
        else:
            R = gaxes[g]
            J = R @ np.diag(gprin[g] * (gimass[g] / gmass[g])) @ R.T
            a = w * dt / 2
            P = cayley_matrix(a / (1 + math.sqrt(1 + a @ a)))
            L = P.T @ J @ w
            ek0 += 0.5 * w @ L
            for i in range(3):
                if not fx >> (3 + i) & 1:
                    L[i] = (D1 * L[i] + (M[i] - damp(M[i], w[i], mp[i])) * dt) * D2
            wn = np.linalg.solve(J, L)
            for _ in range(200):
                a = wn * dt / 2
                P = cayley_matrix(a / (1 + math.sqrt(1 + a @ a)))
                wn = np.linalg.solve(J, P.T @ L)
            for i in range(3):
                if fx >> (3 + i) & 1:
                    wn[i] = w[i]
            ek1 += 0.5 * wn @ L
        if damp_mode == 2:
            servo[NS + 6 * g + 3: NS + 6 * g + 6] = M
        if damp_mode == 3:
            work += av * dt * (ek0 + ek1)
            dek += abs(ek1 - ek0)
        Jr = gaxes[g] @ np.diag(gprin[g]) @ gaxes[g].T
        ke += 0.5 * gmass[g] * Vn @ Vn + 0.5 * wn @ Jr @ wn
        if not (np.abs(Vn).sum() < vmax and np.all(np.isfinite(wn))):
            bad = g if bad < 0 else bad
            for b in mem:
                vel[b] = Vn
                spin[b] = wn
            continue
        Q = cayley_matrix(wn * dt / 2)
        dx = Vn * dt
        for b in mem:
            for v in range(vstart[b], vstart[b] + vcount[b]):
                vpos[v] = C + dx + Q @ (vpos[v] - C)
            cn = C + dx + Q @ (centroid[b] - C)
            disp[b] += cn - centroid[b]
            centroid[b] = cn
            vel[b] = Vn + np.cross(wn, cn - (C + dx))
            spin[b] = wn
        gaxes[g] = Q @ gaxes[g]
        gcentroid[g] = C + dx
    for b in gmember[gstart[0]:gstart[ng]]:
        force[b] = 0.0
        moment[b] = 0.0
    if damp_mode == 2:
        servo[8] = 1.0
    if damp_mode == 3:
        servo[1] += work
        servo[2] += dek
        servo[3] += 1
        if servo[3] >= servo[5]:
            if servo[2] > 0:
                r = servo[1] / servo[2]
                servo[7] = r
                f, ratio = servo[6], servo[4]
                servo[0] = min(max(servo[0] * f if r < ratio else servo[0] / f, lo), hi)
            servo[1] = servo[2] = servo[3] = 0.0
    servo[9] += 1
    out[:] = (fmax, fsum, ke, av)
    return bad
