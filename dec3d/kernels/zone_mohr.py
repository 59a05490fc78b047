"""Mohr-Coulomb zones: the constitutive update of a 4-node tetrahedron (the zone step that runs
it, with mixed discretization and NMD, is ``kernels/zone_plastic.py``).

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

Kernels may not import dec3d.model: the property columns and model codes below mirror
``dec3d.model.zones`` (a test checks they agree).
"""
import math

import numpy as np
from numba import njit

from .zones import hooke_increment, tet_add_forces, tet_kinematics

# mirrors of dec3d.model.zones
ZP_BULK = 0
ZP_SHEAR = 1
ZP_COHESION = 3
ZP_TANFRIC = 4
ZP_TENSION = 5
ZP_TANDIL = 6
ZMODEL_ELASTIC = 1
ZMODEL_MOHR = 2
SHEAR_NOW = 1
TENSION_NOW = 2
SHEAR_PAST = 4
TENSION_PAST = 8

#: shear planes: (i, j) = (more compressive, less compressive) principal index; planes 6-8: tension
_SH_I = np.array([0, 0, 1, 1, 2, 2], np.int64)
_SH_J = np.array([2, 1, 2, 0, 0, 1], np.int64)


@njit(cache=True)
def sym_eig3(s, lam, vec):
    """Eigen-decomposition of the symmetric tensor s (6,) (xx yy zz xy xz yz) by cyclic Jacobi
    rotations: lam (3,) ascending, vec (3, 3) with eigenvector k in column k. Deterministic
    (fixed sweep order, no library call)."""
    a00 = s[0]; a11 = s[1]; a22 = s[2]; a01 = s[3]; a02 = s[4]; a12 = s[5]
    for i in range(3):
        for j in range(3):
            vec[i, j] = 1.0 if i == j else 0.0
    scale = abs(a00) + abs(a11) + abs(a22) + abs(a01) + abs(a02) + abs(a12)
    if scale > 0.0:
        for _sweep in range(30):
            off = abs(a01) + abs(a02) + abs(a12)
            if off <= 1e-17 * scale:
                break
            for pq in range(3):
                if pq == 0:
                    p = 0; q = 1; apq = a01; app = a00; aqq = a11
                elif pq == 1:
                    p = 0; q = 2; apq = a02; app = a00; aqq = a22
                else:
                    p = 1; q = 2; apq = a12; app = a11; aqq = a22
                if apq == 0.0:
                    continue
                theta = (aqq - app) / (2.0 * apq)
                if abs(theta) > 1e150:
                    t = 0.5 / theta
                else:
                    t = 1.0 / (abs(theta) + math.sqrt(theta * theta + 1.0))
                    if theta < 0.0:
                        t = -t
                c = 1.0 / math.sqrt(t * t + 1.0)
                sn = t * c
                # A' = J^T A J with J_pp = J_qq = c, J_pq = sn, J_qp = -sn: a'_pq = 0
                app2 = app - t * apq
                aqq2 = aqq + t * apq
                r = 3 - p - q            # the third index
                if r == 0:
                    arp = a01 if p == 1 else a02
                    arq = a02 if q == 2 else a01
                elif r == 1:
                    arp = a01
                    arq = a12
                else:
                    arp = a02
                    arq = a12
                arp2 = c * arp - sn * arq
                arq2 = sn * arp + c * arq
                # write back
                if pq == 0:
                    a00 = app2; a11 = aqq2; a01 = 0.0; a02 = arp2; a12 = arq2
                elif pq == 1:
                    a00 = app2; a22 = aqq2; a02 = 0.0; a01 = arp2; a12 = arq2
                else:
                    a11 = app2; a22 = aqq2; a12 = 0.0; a01 = arp2; a02 = arq2
                for k in range(3):
                    vkp = vec[k, p]; vkq = vec[k, q]
                    vec[k, p] = c * vkp - sn * vkq
                    vec[k, q] = sn * vkp + c * vkq
    lam[0] = a00; lam[1] = a11; lam[2] = a22
    # sort ascending (3 elements), columns follow
    for i in range(2):
        for j in range(2 - i):
            if lam[j] > lam[j + 1]:
                tmp = lam[j]; lam[j] = lam[j + 1]; lam[j + 1] = tmp
                for k in range(3):
                    tmp = vec[k, j]; vec[k, j] = vec[k, j + 1]; vec[k, j + 1] = tmp


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


_THIRD = 1.0 / 3.0


@njit(cache=True, inline="always")
def _deviator(s0, s1, s2):
    """Diagonal of the deviator as ((s0 - s1) - (s2 - s0)) / 3, not s0 - m: exact differences
    when the mean stress is far above the deviator."""
    a = s0 - s1; b = s1 - s2; c = s2 - s0
    return (a - c) * _THIRD, (b - a) * _THIRD, (c - b) * _THIRD


#: x(u) = cos(2 arccos(u) / 3) on 0 <= u <= 1 as a polynomial in t = 2u - 1 (``_root``): the
#: Chebyshev interpolant of degree 18 at 600 Chebyshev nodes of 40-digit values (mpmath),
#: written as monomial coefficients c0 ... c18, with c0 and c1 then moved by 8e-16 and 1e-16 so
#: that the exact polynomial meets x(0) = 1/2 and x(1) = 1; largest error 1.1e-15 in double
#: precision, a unit in the last place at the ends (x itself lies in [1/2, 1]). x(u) is analytic on the whole interval: arccos(u) has its branch
#: point at u = 1, but cos(2 arccos(u) / 3) is even in arccos(u) there.
_XC = (0.7660444431189777, 0.24740906632285423, -0.015509188436501056,
       0.002466352815026528, -0.0005041246908393405, 0.00011642545390407192,
       -2.8919938766347355e-05, 7.541071632329256e-06, -2.035859516600697e-06,
       5.641781102042346e-07, -1.595665547802857e-07, 4.579921583679578e-08,
       -1.3318192881031793e-08, 4.0122241520328296e-09, -1.2070097655119283e-09,
       2.9158240048239817e-10, -8.479376924224957e-11, 5.545024435052661e-11,
       -1.680310434864443e-11)


@njit(cache=True, inline="always")
def _root(u):
    """cos(2 arccos(u) / 3) for 0 <= u <= 1 (``_XC``, Estrin's scheme: a few products deep
    instead of eighteen)."""
    t = 2.0 * u - 1.0
    t2 = t * t
    t4 = t2 * t2
    t8 = t4 * t4
    p0 = _XC[0] + _XC[1] * t; p1 = _XC[2] + _XC[3] * t; p2 = _XC[4] + _XC[5] * t
    p3 = _XC[6] + _XC[7] * t; p4 = _XC[8] + _XC[9] * t; p5 = _XC[10] + _XC[11] * t
    p6 = _XC[12] + _XC[13] * t; p7 = _XC[14] + _XC[15] * t; p8 = _XC[16] + _XC[17] * t
    q0 = p0 + t2 * p1; q1 = p2 + t2 * p3; q2 = p4 + t2 * p5; q3 = p6 + t2 * p7; q4 = p8 + t2 * _XC[18]
    r0 = q0 + t4 * q1; r1 = q2 + t4 * q3
    return (r0 + t8 * r1) + (t8 * t8) * q4


@njit(cache=True, inline="always")
def _dev_principal(s0, s1, s2, s3, s4, s5):
    """(m, lo, mid, hi): mean stress and the principal values of the deviator of the symmetric
    tensor (s0 s1 s2 s3 s4 s5) = (xx yy zz xy xz yz), ascending, in closed form: the
    trigonometric solution of the characteristic cubic λ³ - J2 λ - J3 = 0, λ = 2 r cos(θ + 2πk/3),
    r = (J2/3)^½, cos 3θ = J3 / (2 r³). With c = cos 3θ, cos θ = x(((1 + c)/2)^½) and
    cos(θ + 2π/3) = -x(((1 - c)/2)^½) for x(u) = cos(2 arccos(u) / 3) (half-angle formula:
    cos 3θ = 2u² - 1 with u = cos(3θ/2)), and x is a polynomial (``_root``): no arccos and cosines
    on the path of a yielding zone. The two values nearest each other are accurate to about
    eps r² / gap, the isolated one to eps r."""
    m, d0, d1, d2, j2, r = _invariants(s0, s1, s2, s3, s4, s5)
    lo, mid, hi = _values(d0, d1, d2, s3, s4, s5, j2, r)
    return m, lo, mid, hi


@njit(cache=True, inline="always")
def _invariants(s0, s1, s2, s3, s4, s5):
    """(m, d0, d1, d2, J2, r): mean stress, deviator diagonal, J2 and r = (J2/3)^½."""
    m = (s0 + s1 + s2) / 3.0
    d0, d1, d2 = _deviator(s0, s1, s2)
    j2 = 0.5 * (d0 * d0 + d1 * d1 + d2 * d2) + s3 * s3 + s4 * s4 + s5 * s5
    return m, d0, d1, d2, j2, math.sqrt(j2 * _THIRD)


@njit(cache=True, inline="always")
def _values(d0, d1, d2, s3, s4, s5, j2, r):
    """The principal values (lo, mid, hi) of the deviator (d0 d1 d2 s3 s4 s5) with J2 and r
    (``_dev_principal``)."""
    if j2 <= 0.0:
        return 0.0, 0.0, 0.0
    j3 = d0 * (d1 * d2 - s5 * s5) - s3 * (s3 * d2 - s5 * s4) + s4 * (s3 * s5 - d1 * s4)
    cs = 0.5 * j3 / (r * (j2 * _THIRD))        # J3 / (2 r³)
    if cs > 1.0:
        cs = 1.0
    elif cs < -1.0:
        cs = -1.0
    hi = 2.0 * r * _root(math.sqrt(0.5 + 0.5 * cs))
    lo = -2.0 * r * _root(math.sqrt(0.5 - 0.5 * cs))
    return lo, -lo - hi, hi


#: closed-form principal axes (``principal_axes``) when both gaps between the principal values are
#: at least this fraction of their spread; closer (nearly repeated) values go to Jacobi
GAP_REL = 0.02


@njit(cache=True)
def principal_axes(s, lam, pr, vec):
    """Principal values lam (3,) ascending and the projectors onto the axes of the least and the
    greatest, pr (12,) = P1 (xx yy zz xy xz yz), P3 (same order), of the symmetric tensor s (6,).
    Closed form when the values are well apart (``GAP_REL``): values by ``_dev_principal``,
    projectors by Sylvester's formula P1 = (D - l2 I)(D - l3 I) / ((l1 - l2)(l1 - l3)) on the
    deviator D (likewise P3), no eigenvectors; otherwise cyclic Jacobi (``sym_eig3``) and
    P_k = v_k v_k^T (vec (3, 3): scratch of the rotations). Returns True when the closed form was
    used."""
    m, l1, l2, l3 = _dev_principal(s[0], s[1], s[2], s[3], s[4], s[5])
    if l3 - l1 > 0.0 and min(l2 - l1, l3 - l2) >= GAP_REL * (l3 - l1):
        d0, d1, d2 = _deviator(s[0], s[1], s[2])
        a3 = s[3]; a4 = s[4]; a5 = s[5]
        # Q = D²
        q0 = d0 * d0 + a3 * a3 + a4 * a4
        q1 = a3 * a3 + d1 * d1 + a5 * a5
        q2 = a4 * a4 + a5 * a5 + d2 * d2
        q3 = d0 * a3 + a3 * d1 + a4 * a5
        q4 = d0 * a4 + a3 * a5 + a4 * d2
        q5 = a3 * a4 + d1 * a5 + a5 * d2
        # P1 = (Q - (l2 + l3) D + l2 l3 I) / ((l1 - l2)(l1 - l3)), P3 likewise
        b = l2 + l3; c = l2 * l3; f = 1.0 / ((l1 - l2) * (l1 - l3))
        pr[0] = (q0 - b * d0 + c) * f; pr[1] = (q1 - b * d1 + c) * f; pr[2] = (q2 - b * d2 + c) * f
        pr[3] = (q3 - b * a3) * f; pr[4] = (q4 - b * a4) * f; pr[5] = (q5 - b * a5) * f
        b = l1 + l2; c = l1 * l2; f = 1.0 / ((l3 - l1) * (l3 - l2))
        pr[6] = (q0 - b * d0 + c) * f; pr[7] = (q1 - b * d1 + c) * f; pr[8] = (q2 - b * d2 + c) * f
        pr[9] = (q3 - b * a3) * f; pr[10] = (q4 - b * a4) * f; pr[11] = (q5 - b * a5) * f
        lam[0] = m + l1; lam[1] = m + l2; lam[2] = m + l3
        return True
    sym_eig3(s, lam, vec)
    for h in range(2):
        c = 0 if h == 0 else 2
        o = 6 * h
        pr[o] = vec[0, c] * vec[0, c]; pr[o + 1] = vec[1, c] * vec[1, c]; pr[o + 2] = vec[2, c] * vec[2, c]
        pr[o + 3] = vec[0, c] * vec[1, c]; pr[o + 4] = vec[0, c] * vec[2, c]; pr[o + 5] = vec[1, c] * vec[2, c]
    return False


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
    scale = abs(p1) + abs(p3) + abs(p2) + coh + abs(ft)
    tol = 1e-10 * scale
    fs13 = p3 * npf - p1 - csn
    ft3 = p3 - ft
    if fs13 <= tol and ft3 <= tol:
        return 0, s0, s1, s2, s3, s4, s5, 0.0
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
    if not (hi * npf - lo - csn <= tol and hi - ft <= tol):
        return -1, s0, s1, s2, s3, s4, s5, 0.0
    # projectors P1, P3 (``principal_axes``' formulas) and the rotation back (``_rotate_back``)
    d0, d1, d2 = _deviator(s0, s1, s2)
    q0 = d0 * d0 + s3 * s3 + s4 * s4
    q1 = s3 * s3 + d1 * d1 + s5 * s5
    q2 = s4 * s4 + s5 * s5 + d2 * d2
    q3 = d0 * s3 + s3 * d1 + s4 * s5
    q4 = d0 * s4 + s3 * s5 + s4 * d2
    q5 = s3 * s4 + d1 * s5 + s5 * d2
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
    s1 = lam[0]; s3 = lam[2]
    scale = abs(s1) + abs(s3) + abs(lam[1]) + coh + abs(ft)
    tol = 1e-10 * scale
    fs13 = s3 * npf - s1 - csn          # = -f_s (Itasca), > 0 violated
    ft3 = s3 - ft
    if fs13 <= tol and ft3 <= tol:
        return 0, 0.0
    # Itasca's choice of the plane: h decides between shear and tension
    h = s3 - ft + ap * (s1 - sp)
    first = 0 if (fs13 > tol and (h <= 0.0 or ft3 <= tol)) else 8
    # fast path: Itasca's single-plane return in closed form, kept when it violates no plane
    if first == 0:
        ls = fs13 / den
        n1 = s1 + ls * (a1 - a2 * nps)
        n2 = lam[1] + ls * a2 * (1.0 - nps)
        n3 = s3 + ls * (a2 - a1 * nps)
        fast = SHEAR_NOW
    else:
        lt = ft3 / a1
        n1 = s1 - lt * a2
        n2 = lam[1] - lt * a2
        n3 = ft
        fast = TENSION_NOW
    lo = min(n1, min(n2, n3))
    hi = max(n1, max(n2, n3))
    if hi * npf - lo - csn <= tol and hi - ft <= tol:
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


@njit(cache=True)
def merge_state(old, now):
    """New ``zones.state``: the now bits of this step, the past bits of before and of now."""
    return (old & (SHEAR_PAST | TENSION_PAST)) | now | (now << 2)


@njit(cache=True)
def tet_mohr_step(pos, vel, gp, rows, prop, dt, stress, state, force):
    """One step of the Mohr-Coulomb 4-node zones ``rows`` without NMD: strain increment
    (``kernels.zones.tet_kinematics``), ``mohr_return`` with the zone's ``prop`` columns,
    ``state`` updated (``merge_state``), nodal forces added to ``force``."""
    av = np.empty((4, 3))
    de = np.empty(6)
    w = np.empty(3)
    work = mohr_work()
    for k in range(rows.shape[0]):
        z = rows[k]
        tet_kinematics(pos, vel, gp, z, dt, av, de, w)
        bits = 0
        if not mohr_trial(stress[z], de, prop[z, ZP_BULK], prop[z, ZP_SHEAR], prop[z, ZP_COHESION],
                          prop[z, ZP_TANFRIC], prop[z, ZP_TENSION]):
            bits, _dsp = mohr_plastic(stress[z], prop[z, ZP_BULK], prop[z, ZP_SHEAR], prop[z, ZP_COHESION],
                                      prop[z, ZP_TANFRIC], prop[z, ZP_TENSION], prop[z, ZP_TANDIL], work)
        state[z] = merge_state(state[z], bits)
        tet_add_forces(gp, z, av, stress[z], 1.0, force)
