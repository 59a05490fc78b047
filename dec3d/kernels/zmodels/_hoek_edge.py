"""The edge returns of zone model ``hoek-brown`` on the nonlinear envelope, in scalars and in terms
of sums (``hoek_brown.py`` holds the model, its sources and conventions; ``_hoek_line.py`` the
returns on the envelope's straight part; only ``hoek_brown.py`` imports this module).

An edge return ends with two principal values equal: σ1 = σ2 (E12, planes σ1-σ3 and σ2-σ3) or
σ2 = σ3 (E23, planes σ1-σ3 and σ1-σ2), the flow of each Mohr-Coulomb's with the dilation fixed
from the trial (α1 = K + 4G/3, α2 = K - 2G/3, 2G = α1 - α2, b = α2 (N_ψ - 1)). With S the sum of
the two multipliers, the new values are, tension positive,

    E12: p1 = p2 = (p1 + p2)/2 - S (b - G),        p3 - S (b + 2G N_ψ)
    E23: p1 - S (b - 2G),                          p2 = p3 = (p2 + p3)/2 - S (b + G N_ψ)

and the multipliers' difference is fixed by the two values meeting: (p2 - p1)/2G (E12),
(p3 - p2)/(2G N_ψ) (E23); the edge holds where S exceeds it (both multipliers positive). The
return solves σ1(S) = q(σ3(S)) on the envelope (``_envelope``; g(S) = σ1 - q(σ3) is convex and
decreasing) by ``_hoek_envelope.edge_root`` from that point (``hoek_brown._edge_values``' root too), ending with a Newton
step: the general path's fixed point (its last Mohr-Coulomb return onto the tangent at the
result is this two-plane return; that return being unique, whichever plane Itasca's rule tries
first). ``hoek_brown._edge_values`` solves the same equation on each value (accurate with Jacobi's
values); here the results depend on the sum of the two values that meet and on the third, which the
closed-form values give to about eps r however close the two are, and the new stress needs only
the projector onto the third value's axis: σ = n_a I + (n_b - n_a) P_b (``_hoek_line``).
"""
from numba import njit

from ..principal import GAP_REL, _deviator, dev_square
from ._common import SHEAR_NOW
from ._hoek_envelope import edge_root
from ._hoek_line import KIND12, KIND23, _projector


@njit(cache=True)
def edge_sum_values(p1, p2, p3, nps, a1, a2, mb, s, a, sci, st, tol, mar, erel, maxit):
    """The edge return of the trial p1 <= p2 <= p3 (the module text): (bits, n1, n2, n3, kind),
    bits -1 where it is not clearly the return (the edge first met by the single-plane return not
    reached by more than ``erel`` of the multipliers, not converged, tension active at the
    result, the values not clearly apart)."""
    g2 = a1 - a2
    b = a2 * (nps - 1.0)
    d12 = (p2 - p1) / g2
    d23 = (p3 - p2) / (g2 * nps)
    if d12 < d23:
        kind = KIND12                    # the single-plane return meets σ1 = σ2 first
        d = d12
        c1 = -0.5 * (p1 + p2)
        k1 = b - 0.5 * g2
        c3 = -p3
        k3 = b + g2 * nps
    else:
        kind = KIND23
        d = d23
        c1 = -p1
        k1 = b - g2
        c3 = -0.5 * (p2 + p3)
        k3 = b + 0.5 * g2 * nps
    done, S = edge_root(c1, k1, c3, k3, d, mb, s, a, sci, tol, mar, maxit)
    if not done:
        return -1, p1, p2, p3, kind
    if not S - d > erel * (S + d):
        return -1, p1, p2, p3, kind
    na = -(c1 + k1 * S)                  # p1
    nb = -(c3 + k3 * S)                  # p3
    if not (nb <= st - mar and nb - na > mar):
        return -1, p1, p2, p3, kind
    if kind == KIND12:
        return SHEAR_NOW, na, na, nb, kind
    return SHEAR_NOW, na, nb, nb, kind


@njit(cache=True)
def edge_sum_return(s0, s1, s2, s3, s4, s5, m, l1, l2, l3, nps, a1, a2, mb, s, a, sci, st, tol, mar, erel,
                    maxit):
    """``edge_sum_values`` on the trial s0..s5 (deviatoric values l1 <= l2 <= l3 about the mean m,
    ``_dev_principal``'s) and the new stress from one projector: (code, t0..t5, dsp) as
    ``zone_mohr._fast_return``, code -1 where not settled here."""
    spread = l3 - l1
    if not spread > 0.0:
        return -1, s0, s1, s2, s3, s4, s5, 0.0
    bits, n1, n2, n3, kind = edge_sum_values(m + l1, m + l2, m + l3, nps, a1, a2, mb, s, a, sci, st, tol, mar,
                                             erel, maxit)
    if bits < 0:
        return -1, s0, s1, s2, s3, s4, s5, 0.0
    d0, d1, d2 = _deviator(s0, s1, s2)
    q0, q1, q2, q3, q4, q5 = dev_square(d0, d1, d2, s3, s4, s5)
    dsp = m - (n1 + n2 + n3) / 3.0
    if kind == KIND12 and l3 - l2 >= GAP_REL * spread:
        u0, u1, u2, u3, u4, u5 = _projector(d0, d1, d2, s3, s4, s5, q0, q1, q2, q3, q4, q5, l3, l1, l2)
        e = n3 - n1
        return bits, n1 + e * u0, n1 + e * u1, n1 + e * u2, e * u3, e * u4, e * u5, dsp
    if kind == KIND23 and l2 - l1 >= GAP_REL * spread:
        u0, u1, u2, u3, u4, u5 = _projector(d0, d1, d2, s3, s4, s5, q0, q1, q2, q3, q4, q5, l1, l2, l3)
        e = n1 - n3
        return bits, n3 + e * u0, n3 + e * u1, n3 + e * u2, e * u3, e * u4, e * u5, dsp
    return -1, s0, s1, s2, s3, s4, s5, 0.0
