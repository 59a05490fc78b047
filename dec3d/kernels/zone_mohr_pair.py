"""Mohr-Coulomb returns that the single-plane scalar path (``zone_mohr.mohr_scalar``) leaves, in
scalars: Itasca's plane with one other (the edge or corner return, the first stage of
``zone_mohr.mohr_plastic``'s search), and trial stresses with two nearly equal principal values
(one gap under ``principal.GAP_REL`` of the spread), which ``principal_axes`` hands to Jacobi.

Why: ``mohr_plastic`` works on arrays (its scratch ``mw`` and the chunk scratch), and every call
of it and of its helpers pays the reference counts of about ten arrays; with Jacobi and the
candidate search that was 450-900 ns a zone against about 120 for a single-plane zone, and in
``bench/zone_bench.py``'s scene 2-3 % of the zones take it after 30 steps (σ2 near σ1 or σ3).

Nearly repeated values (l_a ≈ l_b, l_c isolated, l deviatoric principal values of the closed form
``principal._dev_principal``): the projector of the isolated value by Sylvester's formula,
P_c = (D - l_a I)(D - l_b I) / ((l_c - l_a)(l_c - l_b)), is well conditioned (its numerator
and denominator take l_a + l_b and l_a l_b, which the closed form gives to about eps r², r² =
J2/3, however small the gap). On Q = I - P_c, D - c̄ I with c̄ = (l_a + l_b)/2 = -l_c/2 has the
eigenvalues ±g, g = (l_b - l_a)/2, so M = D - c̄ I - (l_c - c̄) P_c = g (P_b - P_a) and
g = ‖M‖_F / √2: the pair's values c̄ ∓ g to about eps r (as Jacobi's; the closed form has them
to eps r² / gap only), P_a = (Q - M/g)/2, P_b = (Q + M/g)/2. A zero g (exactly repeated
values) or a zero spread goes to ``mohr_plastic``.

Well-apart values take ``principal_axes``' formulas, and the pair search ``_try_planes`` /
``_solve_small``'s arithmetic, so that such a zone's stress has the bits of ``mohr_plastic``'s
(tests/test_zone_mohr_step_kernels.py); with nearly repeated values the stress agrees with the
Jacobi path to round-off.
"""
import math

from numba import njit

from .principal import GAP_REL, _deviator, _dev_principal, dev_square
from .zone_mohr import plane_return
from .zones import SHEAR_NOW, TENSION_NOW

#: shear planes k < 6: (i, j) = (more compressive, less compressive) index (``zone_mohr._SH_I/_SH_J``);
#: planes 6-8: the tension cut-off on value k - 6
_PI = (0, 0, 1, 1, 2, 2, 0, 1, 2)
_PJ = (2, 1, 2, 0, 0, 1, -1, -1, -1)


@njit(cache=True, inline="always")
def _pick(v0, v1, v2, i):
    if i == 0:
        return v0
    if i == 1:
        return v1
    return v2


@njit(cache=True, inline="always")
def _plane(k, npf, csn, ft, nps, a1, a2):
    """Plane k: (i, j, r, D m) (``mohr_plastic``'s nn, rr, dm rows: shear F = n_j s_j - s_i - r with
    n_j = N_phi; tension F = s_i - r)."""
    i = _PI[k]
    j = _PJ[k]
    if j >= 0:
        b = a2 * (nps - 1.0)
        di = b + (a1 - a2) * -1.0
        dj = b + (a1 - a2) * nps
        m0 = di if i == 0 else (dj if j == 0 else b)
        m1 = di if i == 1 else (dj if j == 1 else b)
        m2 = di if i == 2 else (dj if j == 2 else b)
        return i, j, csn, m0, m1, m2
    return i, j, ft, a1 if i == 0 else a2, a1 if i == 1 else a2, a1 if i == 2 else a2


@njit(cache=True, inline="always")
def _f(i, j, r, npf, v0, v1, v2):
    """n . v - r of a plane (``_plane``)."""
    if j >= 0:
        return (npf * _pick(v0, v1, v2, j) - _pick(v0, v1, v2, i)) - r
    return _pick(v0, v1, v2, i) - r


@njit(cache=True)
def _pair(kf, kk, lam0, lam1, lam2, npf, csn, ft, nps, a1, a2, tol):
    """``_try_planes`` on the planes (kf, kk): (ok, x_f, x_k, sn0, sn1, sn2), same arithmetic."""
    fi, fj, fr, f0, f1, f2 = _plane(kf, npf, csn, ft, nps, a1, a2)
    ki, kj, kr, k0, k1, k2 = _plane(kk, npf, csn, ft, nps, a1, a2)
    b0 = _f(fi, fj, fr, npf, lam0, lam1, lam2)
    b1 = _f(ki, kj, kr, npf, lam0, lam1, lam2)
    m00 = _f(fi, fj, 0.0, npf, f0, f1, f2)
    m01 = _f(fi, fj, 0.0, npf, k0, k1, k2)
    m10 = _f(ki, kj, 0.0, npf, f0, f1, f2)
    m11 = _f(ki, kj, 0.0, npf, k0, k1, k2)
    big = max(max(abs(m00), abs(m01)), max(abs(m10), abs(m11)))
    if big == 0.0:
        return False, 0.0, 0.0, 0.0, 0.0, 0.0
    if abs(m10) > abs(m00):
        t = m00; m00 = m10; m10 = t
        t = m01; m01 = m11; m11 = t
        t = b0; b0 = b1; b1 = t
    if abs(m00) < 1e-12 * big:
        return False, 0.0, 0.0, 0.0, 0.0, 0.0
    f = m10 / m00
    m11 -= f * m01
    b1 -= f * b0
    if abs(m11) < 1e-12 * big:
        return False, 0.0, 0.0, 0.0, 0.0, 0.0
    x1 = b1 / m11
    x0 = (b0 - m01 * x1) / m00
    xmax = max(max(0.0, abs(x0)), abs(x1))
    if x0 < -1e-12 * xmax or x1 < -1e-12 * xmax:
        return False, 0.0, 0.0, 0.0, 0.0, 0.0
    sn0 = (lam0 - x0 * f0) - x1 * k0
    sn1 = (lam1 - x0 * f1) - x1 * k1
    sn2 = (lam2 - x0 * f2) - x1 * k2
    for k in range(9):
        i, j, r, d0, d1, d2 = _plane(k, npf, csn, ft, nps, a1, a2)
        if _f(i, j, r, npf, sn0, sn1, sn2) > tol:
            return False, 0.0, 0.0, 0.0, 0.0, 0.0
    return True, x0, x1, sn0, sn1, sn2


@njit(cache=True)
def mohr_pair(s0, s1, s2, s3, s4, s5, coh, npf, csn, ft, nps, a1, a2, sp, ap, den):
    """The trial stress s0..s5 returned as described in the module text, with the zone's cohesion
    and ``zone_mohr.mohr_constants``: (code, t0..t5, dsp) as ``zone_mohr._fast_return``; code -1:
    not settled here (t = s), ``mohr_plastic`` must do it."""
    m, l1, l2, l3 = _dev_principal(s0, s1, s2, s3, s4, s5)
    spread = l3 - l1
    if not spread > 0.0:
        return -1, s0, s1, s2, s3, s4, s5, 0.0
    d0, d1, d2 = _deviator(s0, s1, s2)
    q0, q1, q2, q3, q4, q5 = dev_square(d0, d1, d2, s3, s4, s5)
    if min(l2 - l1, l3 - l2) >= GAP_REL * spread:
        # ``principal_axes``' closed form, its bits
        b = l2 + l3; c = l2 * l3; f = 1.0 / ((l1 - l2) * (l1 - l3))
        p0 = (q0 - b * d0 + c) * f; p1 = (q1 - b * d1 + c) * f; p2 = (q2 - b * d2 + c) * f
        p3 = (q3 - b * s3) * f; p4 = (q4 - b * s4) * f; p5 = (q5 - b * s5) * f
        b = l1 + l2; c = l1 * l2; f = 1.0 / ((l3 - l1) * (l3 - l2))
        r0 = (q0 - b * d0 + c) * f; r1 = (q1 - b * d1 + c) * f; r2 = (q2 - b * d2 + c) * f
        r3 = (q3 - b * s3) * f; r4 = (q4 - b * s4) * f; r5 = (q5 - b * s5) * f
    elif l2 - l1 < l3 - l2:
        # l1 ≈ l2: P3 by Sylvester, the pair from M = D - c̄ I - (l3 - c̄) P3
        b = l1 + l2; c = l1 * l2; f = 1.0 / ((l3 - l1) * (l3 - l2))
        r0 = (q0 - b * d0 + c) * f; r1 = (q1 - b * d1 + c) * f; r2 = (q2 - b * d2 + c) * f
        r3 = (q3 - b * s3) * f; r4 = (q4 - b * s4) * f; r5 = (q5 - b * s5) * f
        cb = -0.5 * l3; w = l3 - cb
        e0 = d0 - cb - w * r0; e1 = d1 - cb - w * r1; e2 = d2 - cb - w * r2
        e3 = s3 - w * r3; e4 = s4 - w * r4; e5 = s5 - w * r5
        g = math.sqrt(0.5 * (e0 * e0 + e1 * e1 + e2 * e2) + e3 * e3 + e4 * e4 + e5 * e5)
        if not g > 0.0:
            return -1, s0, s1, s2, s3, s4, s5, 0.0
        l1 = cb - g; l2 = cb + g
        h = 0.5 / g
        p0 = 0.5 * (1.0 - r0) - h * e0; p1 = 0.5 * (1.0 - r1) - h * e1; p2 = 0.5 * (1.0 - r2) - h * e2
        p3 = -0.5 * r3 - h * e3; p4 = -0.5 * r4 - h * e4; p5 = -0.5 * r5 - h * e5
    else:
        # l2 ≈ l3: P1 by Sylvester, the pair from M = D - c̄ I - (l1 - c̄) P1
        b = l2 + l3; c = l2 * l3; f = 1.0 / ((l1 - l2) * (l1 - l3))
        p0 = (q0 - b * d0 + c) * f; p1 = (q1 - b * d1 + c) * f; p2 = (q2 - b * d2 + c) * f
        p3 = (q3 - b * s3) * f; p4 = (q4 - b * s4) * f; p5 = (q5 - b * s5) * f
        cb = -0.5 * l1; w = l1 - cb
        e0 = d0 - cb - w * p0; e1 = d1 - cb - w * p1; e2 = d2 - cb - w * p2
        e3 = s3 - w * p3; e4 = s4 - w * p4; e5 = s5 - w * p5
        g = math.sqrt(0.5 * (e0 * e0 + e1 * e1 + e2 * e2) + e3 * e3 + e4 * e4 + e5 * e5)
        if not g > 0.0:
            return -1, s0, s1, s2, s3, s4, s5, 0.0
        l2 = cb - g; l3 = cb + g
        h = 0.5 / g
        r0 = 0.5 * (1.0 - p0) + h * e0; r1 = 0.5 * (1.0 - p1) + h * e1; r2 = 0.5 * (1.0 - p2) + h * e2
        r3 = -0.5 * p3 + h * e3; r4 = -0.5 * p4 + h * e4; r5 = -0.5 * p5 + h * e5
    lam0 = m + l1; lam1 = m + l2; lam2 = m + l3
    # ``mohr_plastic`` from here, on these values and projectors
    bits, n1, n2, n3, ok, tol = plane_return(lam0, lam1, lam2, coh, npf, csn, ft, nps, a1, a2, sp, ap, den)
    if bits == 0:
        return 0, s0, s1, s2, s3, s4, s5, 0.0
    first = 0 if bits == SHEAR_NOW else 8
    if not ok:
        for k in range(9):
            if k != first:
                ok, x0, x1, n1, n2, n3 = _pair(first, k, lam0, lam1, lam2, npf, csn, ft, nps, a1, a2, tol)
                if ok:
                    bits = 0
                    if x0 > 0.0:
                        bits |= SHEAR_NOW if first < 6 else TENSION_NOW
                    if x1 > 0.0:
                        bits |= SHEAR_NOW if k < 6 else TENSION_NOW
                    break
        if not ok:
            return -1, s0, s1, s2, s3, s4, s5, 0.0
    # ``_rotate_back``
    u0 = n1 - lam0; u1 = n2 - lam1; u2 = n3 - lam2
    v0 = u0 - u1; v2 = u2 - u1
    return (bits, s0 + (u1 + v0 * p0 + v2 * r0), s1 + (u1 + v0 * p1 + v2 * r1), s2 + (u1 + v0 * p2 + v2 * r2),
            s3 + (v0 * p3 + v2 * r3), s4 + (v0 * p4 + v2 * r4), s5 + (v0 * p5 + v2 * r5), -(u0 + u1 + u2) / 3.0)
