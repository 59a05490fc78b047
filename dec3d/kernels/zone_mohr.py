"""Mohr-Coulomb zones: the constitutive update of a 4-node tetrahedron (the zone step that runs
it, with mixed discretization and NMD, is ``kernels/zone_step.py``; the model's plug-in is
``kernels/zmodels/mohr.py``).

Mohr-Coulomb (Itasca's formulation: FLAC3D/3DEC documentation, "Mohr-Coulomb Model",
https://docs.itascacg.com/itasca920/common/models/mohr/doc/modelmohr.html; the 3DEC theory
text 000_*, "Deformable Block Motion": "the basic failure model for blocks in 3DEC is the
Mohr-Coulomb failure criterion with a nonassociated flow rule"). Compression negative; the
principal stresses of the elastic trial are ordered s1 <= s2 <= s3 (s1 the most compressive):

    shear yield       f_s = s1 - s3 N_phi + 2 c sqrt(N_phi)     (yield when f_s < 0)
    tension cut-off   f_t = s3 - sigma_t                        (yield when f_t > 0)
    N_phi = (1 + sin phi) / (1 - sin phi), N_psi likewise from the dilation angle psi,
    sigma_t capped at c / tan phi (the apex of the shear cone), as Itasca does;
    potentials g_s = s1 - s3 N_psi (non-associated), g_t = -s3 (associated);
    alpha1 = K + 4G/3, alpha2 = K - 2G/3 (principal-axis Hooke's law);
    corner function h = s3 - sigma_t + alpha_P (s1 - sigma_P), alpha_P = sqrt(1 + N_phi^2) + N_phi,
    sigma_P = sigma_t N_phi - 2 c sqrt(N_phi): shear return when f_s < 0 and h <= 0,
    tension return when f_t > 0 and h > 0.
    Shear return: lambda_s = f_s / ((alpha1 - alpha2 N_psi) - (alpha2 - alpha1 N_psi) N_phi),
    s1 -= lambda_s (alpha1 - alpha2 N_psi), s2 -= lambda_s alpha2 (1 - N_psi),
    s3 -= lambda_s (alpha2 - alpha1 N_psi). Tension return: s3 = sigma_t, s1 and s2 lowered by
    (s3 - sigma_t) alpha2 / alpha1. The principal directions are kept.

Written here as planes in principal-stress space, F_k(s) = n_k . s - r_k (F > 0: violated),
with plastic flow m_k and return s = s_trial - sum_k lambda_k D m_k, F_k(s) = 0 on the
active planes: the one plane Itasca's h picks gives exactly the formulas above. dec3d's
completion (where Itasca's single-plane return leaves another plane violated: a tension return
past the shear line near the corner, s2 crossing s1 on a shear return near the compression
edge, two or three principal stresses over sigma_t), candidate active sets are tried in a fixed
order and the first consistent one is taken (the system above regular, every multiplier >= 0,
all planes satisfied): Itasca's plane with one other (the corner or edge return), each other
plane alone, any two planes without Itasca's, any three. The planes are the shear line for every
ordered pair of principal stresses and the cut-off on each of the three. (Should none be
consistent, which the tests never meet, the stress goes to the isotropic admissible point.)

Plastic state bits (``zones.state``): 1 shear now, 2 tension now, 4 shear in the past,
8 tension in the past; the "now" bits are those of the last step.

The plastic-state bits are ``kernels/zones.py``'s (one definition for the store, the models and
the step).
"""
import math

import numpy as np
from numba import njit

from .principal import _THIRD, GAP_REL, _deviator, _dev_principal, _invariants, _values, dev_square, principal_axes
from .zones import SHEAR_NOW, TENSION_NOW, hooke_increment

#: shear planes: (i, j) = (more compressive, less compressive) principal index; planes 6-8: tension
_SH_I = np.array([0, 0, 1, 1, 2, 2], np.int64)
_SH_J = np.array([2, 1, 2, 0, 0, 1], np.int64)


@njit(cache=True)
def _solve_small(m, b, na, x):
    """Solve m[:na, :na] x = b[:na] by Gaussian elimination with partial pivoting (m and b are
    overwritten). Returns False when the system is singular (pivot below 1e-12 of the largest)."""
    big = 0.0
    for i in range(na):
        for j in range(na):
            if abs(m[i, j]) > big:
                big = abs(m[i, j])
    if big == 0.0:
        return False
    for col in range(na):
        piv = col
        for i in range(col + 1, na):
            if abs(m[i, col]) > abs(m[piv, col]):
                piv = i
        if abs(m[piv, col]) < 1e-12 * big:
            return False
        if piv != col:
            for j in range(na):
                tmp = m[col, j]; m[col, j] = m[piv, j]; m[piv, j] = tmp
            tmp = b[col]; b[col] = b[piv]; b[piv] = tmp
        for i in range(col + 1, na):
            f = m[i, col] / m[col, col]
            for j in range(col, na):
                m[i, j] -= f * m[col, j]
            b[i] -= f * b[col]
    for i in range(na - 1, -1, -1):
        acc = b[i]
        for j in range(i + 1, na):
            acc -= m[i, j] * x[j]
        x[i] = acc / m[i, i]
    return True


@njit(cache=True)
def _try_planes(act, na, nn, dm, rr, lam, tol, mm, bb, x, sn):
    """Return onto the planes act[:na] from the trial principal stresses lam: solve
    sum_b (n_a . D m_b) x_b = F_a(trial), accept when the system is regular, every multiplier
    x >= 0 and the result sn satisfies all nine planes (F <= tol). Fills x and sn."""
    for a in range(na):
        ka = act[a]
        bb[a] = nn[ka, 0] * lam[0] + nn[ka, 1] * lam[1] + nn[ka, 2] * lam[2] - rr[ka]
        for b in range(na):
            kb = act[b]
            mm[a, b] = nn[ka, 0] * dm[kb, 0] + nn[ka, 1] * dm[kb, 1] + nn[ka, 2] * dm[kb, 2]
    if not _solve_small(mm, bb, na, x):
        return False
    xmax = 0.0
    for a in range(na):
        xmax = max(xmax, abs(x[a]))
    for a in range(na):
        if x[a] < -1e-12 * xmax:
            return False
    for t in range(3):
        acc = lam[t]
        for a in range(na):
            acc -= x[a] * dm[act[a], t]
        sn[t] = acc
    for k in range(9):
        if nn[k, 0] * sn[0] + nn[k, 1] * sn[1] + nn[k, 2] * sn[2] - rr[k] > tol:
            return False
    return True

@njit(cache=True)
def mohr_work():
    """Scratch arrays of ``mohr_core`` (allocate once per batch, not per zone)."""
    return (np.empty(3), np.empty(12), np.empty((9, 3)), np.empty((9, 3)), np.empty(9),
            np.empty(3, np.int64), np.empty((3, 3)), np.empty(3), np.empty(3), np.empty(3))


@njit(cache=True)
def mohr_return(s, de, bulk, shear, coh, tanfric, ten, tandil):
    """Mohr-Coulomb update of one zone in place: s (6,) holds the stress at the start of the step
    and receives the new stress (elastic trial s + D:de, then Itasca's return; see the module
    text). de (6,): strain increment (xx yy zz xy xz yz, engineering shear halved: tensor
    components). Returns (bits, dsp): bits = 1 shear now | 2 tension now (0: elastic), dsp = mean
    trial stress - mean returned stress (the plastic correction K de^p of Eq. 73 of the 3DEC text,
    tension positive; 0 when elastic)."""
    return mohr_core(s, de, bulk, shear, coh, tanfric, ten, tandil, mohr_work())


@njit(cache=True)
def mohr_core(s, de, bulk, shear, coh, tanfric, ten, tandil, work):
    """``mohr_return`` with the scratch arrays ``work`` of ``mohr_work``."""
    if mohr_trial(s, de, bulk, shear, coh, tanfric, ten):
        return 0, 0.0
    return mohr_plastic(s, bulk, shear, coh, tanfric, ten, tandil, work)


@njit(cache=True, inline="always")
def _strength(coh, tanfric, ten):
    """(N_phi, 2 c sqrt(N_phi), sigma_t capped at the apex c / tan phi)."""
    sphi = tanfric / math.sqrt(1.0 + tanfric * tanfric)
    npf = (1.0 + sphi) / (1.0 - sphi)
    ft = ten
    if tanfric > 0.0 and coh / tanfric < ft:
        ft = coh / tanfric
    return npf, 2.0 * coh * math.sqrt(npf), ft


@njit(cache=True, inline="always")
def _bounds_elastic(m, r, coh, npf, csn, ft):
    """Clearly elastic from the bounds m - 2r <= s1, s3 <= m + 2r (r = sqrt(J2 / 3))."""
    r2 = 2.0 * r
    bscale = 3.0 * (abs(m) + r2) + coh + abs(ft)
    return (m + r2) * npf - (m - r2) - csn < -1e-7 * bscale and m + r2 - ft < -1e-7 * bscale


@njit(cache=True, inline="always")
def _yield_test(s0, s1, s2, s3, s4, s5, coh, npf, csn, ft):
    """(clearly elastic, m, l1, l2, l3): the bounds test (``_bounds_elastic``), then, when it
    cannot tell, the principal values (``_dev_principal``'s, from the same invariants) and
    ``_values_elastic``; l1..l3 are 0 when the bounds sufficed."""
    m, d0, d1, d2, j2, r = _invariants(s0, s1, s2, s3, s4, s5)
    if _bounds_elastic(m, r, coh, npf, csn, ft):
        return True, m, 0.0, 0.0, 0.0
    l1, l2, l3 = _values(d0, d1, d2, s3, s4, s5, j2, r)
    return _values_elastic(m, l1, l3, coh, npf, csn, ft), m, l1, l2, l3


@njit(cache=True, inline="always")
def _values_elastic(m, l1, l3, coh, npf, csn, ft):
    """Clearly elastic from the principal values m + l1 <= m + l3 (``_dev_principal``), with a
    margin far above their round-off."""
    q1 = m + l1
    q3 = m + l3
    q2 = 3.0 * m - q1 - q3
    qscale = abs(q1) + abs(q2) + abs(q3) + coh + abs(ft)
    return q3 * npf - q1 - csn < -1e-7 * qscale and q3 - ft < -1e-7 * qscale


@njit(cache=True)
def mohr_trial(s, de, bulk, shear, coh, tanfric, ten):
    """First half of ``mohr_core``: s += D:de (the elastic trial); True when the trial is clearly
    elastic (then s is the new stress), False when ``mohr_plastic`` must finish the update.
    Kept apart so that hot loops pass the scratch arrays (whose reference counting costs more
    than this test) only for the zones near or at yield."""
    hooke_increment(s, de, bulk, shear)
    npf, csn, ft = _strength(coh, tanfric, ten)
    # clearly elastic: first from bounds, then from the closed-form principal values; no axes
    return _yield_test(s[0], s[1], s[2], s[3], s[4], s[5], coh, npf, csn, ft)[0]


@njit(cache=True, inline="always")
def mohr_constants(bulk, shear, coh, tanfric, ten, tandil):
    """What the single-plane returns take from a zone's properties: (N_phi, 2 c sqrt(N_phi),
    sigma_t capped, N_psi, alpha1, alpha2, sigma_P, alpha_P, the shear return's denominator);
    a tuple hot loops can keep while the properties stay the same."""
    npf, csn, ft = _strength(coh, tanfric, ten)
    spsi = tandil / math.sqrt(1.0 + tandil * tandil)
    nps = (1.0 + spsi) / (1.0 - spsi)
    a1 = bulk + 4.0 * shear / 3.0
    a2 = bulk - 2.0 * shear / 3.0
    sp = ft * npf - csn
    ap = math.sqrt(1.0 + npf * npf) + npf
    return npf, csn, ft, nps, a1, a2, sp, ap, a1 * (1.0 + npf * nps) - a2 * (npf + nps)


@njit(cache=True, inline="always")
def plane_return(p1, p2, p3, coh, npf, csn, ft, nps, a1, a2, sp, ap, den):
    """Itasca's single-plane return of the principal stresses p1 <= p2 <= p3 (the module text),
    with the zone's cohesion and ``mohr_constants``: (code, n1, n2, n3, admissible, tol). code 0:
    clearly elastic (n = p); SHEAR_NOW or TENSION_NOW: the plane Itasca's h picks, n the returned
    values and admissible whether they violate no plane (to tol, 1e-10 of the stresses'
    scale). The one copy of this return for ``_fast_return``, ``mohr_plastic`` and
    ``zone_mohr_pair.mohr_pair`` (so their bits agree)."""
    scale = abs(p1) + abs(p3) + abs(p2) + coh + abs(ft)
    tol = 1e-10 * scale
    fs13 = p3 * npf - p1 - csn          # = -f_s (Itasca), > 0 violated
    ft3 = p3 - ft
    if fs13 <= tol and ft3 <= tol:
        return 0, p1, p2, p3, True, tol
    # Itasca's choice of the plane: h decides between shear and tension
    h = p3 - ft + ap * (p1 - sp)
    if fs13 > tol and (h <= 0.0 or ft3 <= tol):
        ls = fs13 / den
        n1 = p1 + ls * (a1 - a2 * nps)
        n2 = p2 + ls * a2 * (1.0 - nps)
        n3 = p3 + ls * (a2 - a1 * nps)
        code = SHEAR_NOW
    else:
        lt = ft3 / a1
        n1 = p1 - lt * a2
        n2 = p2 - lt * a2
        n3 = ft
        code = TENSION_NOW
    lo = min(n1, min(n2, n3))
    hi = max(n1, max(n2, n3))
    return code, n1, n2, n3, hi * npf - lo - csn <= tol and hi - ft <= tol, tol


@njit(cache=True, inline="always")
def _fast_return(s0, s1, s2, s3, s4, s5, m, l1, l2, l3, coh, npf, csn, ft, nps, a1, a2, sp, ap, den):
    """``mohr_plastic`` in scalars for the common case: principal values well apart (closed
    form, ``GAP_REL``) and Itasca's single plane giving an admissible stress. The trial stress
    s0..s5 with its deviatoric principal values l1 <= l2 <= l3 about the mean m
    (``_dev_principal``), the zone's cohesion and ``mohr_constants``. Returns (code, t0..t5,
    dsp): code 0 elastic (t = s, dsp = 0), SHEAR_NOW or TENSION_NOW (t the returned stress, dsp
    as ``mohr_return``), -1 not settled here (t = s: ``mohr_plastic``'s general path must do it).
    The formulas of ``mohr_plastic``'s array path (``principal_axes``' projectors, ``_rotate_back``),
    arranged for one division instead of three; a stress takes one path or the other, never both."""
    if not (l3 - l1 > 0.0 and min(l2 - l1, l3 - l2) >= GAP_REL * (l3 - l1)):
        return -1, s0, s1, s2, s3, s4, s5, 0.0
    p1 = m + l1; p2 = m + l2; p3 = m + l3
    code, n1, n2, n3, ok, _tol = plane_return(p1, p2, p3, coh, npf, csn, ft, nps, a1, a2, sp, ap, den)
    if code == 0:
        return 0, s0, s1, s2, s3, s4, s5, 0.0
    if not ok:
        return -1, s0, s1, s2, s3, s4, s5, 0.0
    # projectors P1, P3 (``principal_axes``' formulas) and the rotation back (``_rotate_back``)
    d0, d1, d2 = _deviator(s0, s1, s2)
    q0, q1, q2, q3, q4, q5 = dev_square(d0, d1, d2, s3, s4, s5)
    # (both denominators from one division: it is on the path of every yielding zone)
    e1 = n1 - p1; e2 = n2 - p2; e3 = n3 - p3
    den1 = (l1 - l2) * (l1 - l3)
    den3 = (l3 - l1) * (l3 - l2)
    inv = 1.0 / (den1 * den3)
    b = l2 + l3; c = l2 * l3; f = (e1 - e2) * (den3 * inv)
    u0 = (q0 - b * d0 + c) * f; u1 = (q1 - b * d1 + c) * f; u2 = (q2 - b * d2 + c) * f
    u3 = (q3 - b * s3) * f; u4 = (q4 - b * s4) * f; u5 = (q5 - b * s5) * f
    b = l1 + l2; c = l1 * l2; f = (e3 - e2) * (den1 * inv)
    v0 = (q0 - b * d0 + c) * f; v1 = (q1 - b * d1 + c) * f; v2 = (q2 - b * d2 + c) * f
    v3 = (q3 - b * s3) * f; v4 = (q4 - b * s4) * f; v5 = (q5 - b * s5) * f
    return (code, s0 + (e2 + u0 + v0), s1 + (e2 + u1 + v1), s2 + (e2 + u2 + v2),
            s3 + (u3 + v3), s4 + (u4 + v4), s5 + (u5 + v5), -(e1 + e2 + e3) * _THIRD)


@njit(cache=True, inline="always")
def mohr_scalar(s0, s1, s2, s3, s4, s5, coh, npf, csn, ft, nps, a1, a2, sp, ap, den):
    """``mohr_trial``'s test and ``mohr_plastic``'s common case on the trial stress s0..s5 in
    scalars (no arrays, for hot loops), with the zone's cohesion and ``mohr_constants``: (code,
    t0..t5, dsp) as ``_fast_return``; code -1: the caller runs ``mohr_plastic`` on the trial
    stress. The bits of mohr_trial + mohr_plastic."""
    elastic, m, l1, l2, l3 = _yield_test(s0, s1, s2, s3, s4, s5, coh, npf, csn, ft)
    if elastic:
        return 0, s0, s1, s2, s3, s4, s5, 0.0
    return _fast_return(s0, s1, s2, s3, s4, s5, m, l1, l2, l3, coh, npf, csn, ft, nps, a1, a2, sp, ap, den)


@njit(cache=True)
def mohr_plastic(s, bulk, shear, coh, tanfric, ten, tandil, work):
    """Second half of ``mohr_core``: the return of the trial stress s (in place); (bits, dsp).
    The common case in scalars (``_fast_return``), the rest on the arrays of ``work``."""
    npf, csn, ft, nps, a1, a2, sp, ap, den = mohr_constants(bulk, shear, coh, tanfric, ten, tandil)
    m, l1, l2, l3 = _dev_principal(s[0], s[1], s[2], s[3], s[4], s[5])
    code, t0, t1, t2, t3, t4, t5, dsp = _fast_return(s[0], s[1], s[2], s[3], s[4], s[5], m, l1, l2, l3, coh, npf, csn,
                                                     ft, nps, a1, a2, sp, ap, den)
    if code >= 0:
        s[0] = t0; s[1] = t1; s[2] = t2; s[3] = t3; s[4] = t4; s[5] = t5
        return code, dsp
    lam, pr, nn, dm, rr, act, mm, bb, x, sn = work
    principal_axes(s, lam, pr, mm)
    # Itasca's single-plane return in closed form, kept when it violates no plane
    fast, n1, n2, n3, ok, tol = plane_return(lam[0], lam[1], lam[2], coh, npf, csn, ft, nps, a1, a2, sp, ap, den)
    if fast == 0:
        return 0, 0.0
    first = 0 if fast == SHEAR_NOW else 8
    if ok:
        sn[0] = n1; sn[1] = n2; sn[2] = n3
        return _rotate_back(s, lam, pr, sn, fast)
    # the nine planes: n (normal of F), dm (D times the flow direction), r
    nn[:, :] = 0.0
    for k in range(6):
        i = _SH_I[k]; j = _SH_J[k]
        nn[k, i] = -1.0; nn[k, j] = npf
        rr[k] = csn
        # flow m: m_i = -1, m_j = N_psi;  D m = a2 * sum(m) + (a1 - a2) * m
        sm = nps - 1.0
        for t in range(3):
            dm[k, t] = a2 * sm
        dm[k, i] += (a1 - a2) * -1.0
        dm[k, j] += (a1 - a2) * nps
    for i in range(3):
        nn[6 + i, i] = 1.0
        rr[6 + i] = ft
        for t in range(3):
            dm[6 + i, t] = a2
        dm[6 + i, i] = a1
    sn[0] = lam[0]; sn[1] = lam[1]; sn[2] = lam[2]
    # Itasca's plane alone failed (the fast path above): with one other (corner / edge), then
    # without it
    ok = False
    na = 1
    if not ok:
        na = 2
        for k in range(9):
            if k != first:
                act[0] = first; act[1] = k
                ok = _try_planes(act, 2, nn, dm, rr, lam, tol, mm, bb, x, sn)
                if ok:
                    break
    if not ok:
        na = 1
        for k in range(9):
            if k != first:
                act[0] = k
                ok = _try_planes(act, 1, nn, dm, rr, lam, tol, mm, bb, x, sn)
                if ok:
                    break
    if not ok:
        na = 2
        for k in range(9):
            for k2 in range(k + 1, 9):
                if k != first and k2 != first and not ok:
                    act[0] = k; act[1] = k2
                    ok = _try_planes(act, 2, nn, dm, rr, lam, tol, mm, bb, x, sn)
            if ok:
                break
    if not ok:
        na = 3
        for k in range(9):
            for k2 in range(k + 1, 9):
                for k3 in range(k2 + 1, 9):
                    if not ok:
                        act[0] = k; act[1] = k2; act[2] = k3
                        ok = _try_planes(act, 3, nn, dm, rr, lam, tol, mm, bb, x, sn)
    bits = 0
    if ok:
        for a in range(na):
            if x[a] > 0.0:
                bits |= SHEAR_NOW if act[a] < 6 else TENSION_NOW
    else:
        # no consistent return found (not met in the tests): the isotropic admissible point
        piso = min((lam[0] + lam[1] + lam[2]) / 3.0, ft)
        sn[0] = piso; sn[1] = piso; sn[2] = piso
        bits = SHEAR_NOW
        if piso == ft:
            bits |= TENSION_NOW
    return _rotate_back(s, lam, pr, sn, bits)


@njit(cache=True)
def _rotate_back(s, lam, pr, sn, bits):
    """s (6,) += sum_k (sn_k - lam_k) P_k (principal directions kept), with P2 = I - P1 - P3 and
    the projectors P1, P3 of ``principal_axes`` in pr; returns (bits, dsp)."""
    d0 = sn[0] - lam[0]; d1 = sn[1] - lam[1]; d2 = sn[2] - lam[2]
    e0 = d0 - d1; e2 = d2 - d1
    s[0] += d1 + e0 * pr[0] + e2 * pr[6]
    s[1] += d1 + e0 * pr[1] + e2 * pr[7]
    s[2] += d1 + e0 * pr[2] + e2 * pr[8]
    s[3] += e0 * pr[3] + e2 * pr[9]
    s[4] += e0 * pr[4] + e2 * pr[10]
    s[5] += e0 * pr[5] + e2 * pr[11]
    return bits, -(d0 + d1 + d2) / 3.0


@njit(cache=True)
def mohr_update(stress6, de6, bulk, shear, coh, tanfric, ten, tandil):
    """One zone, not in place: returns (new stress (6,), bits, dsp) as ``mohr_return``."""
    s = stress6.copy()
    bits, dsp = mohr_return(s, de6, bulk, shear, coh, tanfric, ten, tandil)
    return s, bits, dsp
