"""Principal values and axes of a symmetric 3 × 3 tensor (stress), for the Mohr-Coulomb zones
(``kernels/zone_mohr.py``): cyclic Jacobi (``sym_eig3``), the closed-form deviator values
(``_dev_principal``, the trigonometric solution of the characteristic cubic with the cosine of a
third of the angle as a polynomial, ``_root``) and the projectors onto the extreme axes
(``principal_axes``). Tensors as 6-vectors (xx yy zz xy xz yz).
"""
import math

from numba import njit

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


@njit(cache=True, inline="always")
def dev_square(d0, d1, d2, a3, a4, a5):
    """Q = D² of the symmetric tensor D = (d0 d1 d2 a3 a4 a5) (xx yy zz xy xz yz), same order."""
    return (d0 * d0 + a3 * a3 + a4 * a4, a3 * a3 + d1 * d1 + a5 * a5, a4 * a4 + a5 * a5 + d2 * d2,
            d0 * a3 + a3 * d1 + a4 * a5, d0 * a4 + a3 * a5 + a4 * d2, a3 * a4 + d1 * a5 + a5 * d2)


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
        q0, q1, q2, q3, q4, q5 = dev_square(d0, d1, d2, a3, a4, a5)
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
