"""Returns of zone model ``hoek-brown`` on the envelope's straight part, in scalars (``hoek_brown.py``
holds the model, its sources and conventions; kept apart because that module is near the 600-line
rule; only ``hoek_brown.py`` imports it).

For σ3 <= 0 (compression positive; tension-positive principal values p1 <= p2 <= p3, p3 >= 0)
the envelope is the line σ1 = q0 + N0 σ3 tangent to the Hoek-Brown curve at σ3 = 0, cut off at
p <= σt = s σci/mb. A trial with p3 > 0 starts the general path (``hoek_brown._general``) on that
line; when the result has p3 >= 0 too, it stops after that one Mohr-Coulomb return
(``zone_mohr.mohr_plastic`` with the fixed cohesion and friction of the line, σt, the dilation of
the trial): its stress is the solution of a linear complementarity problem in the multipliers of
the nine planes (shear lines of each ordered pair of principal stresses, three cut-offs). Here
that return is written in closed form for each set of active planes a yielding trial reaches in
practice, with the same planes and flows (shear flow m = (-1, 0, N_ψ), tension flow e3; α1 = K +
4G/3, α2 = K - 2G/3, 2G = α1 - α2, b = α2 (N_ψ - 1)):

    S   shear σ1-σ3 alone               T   tension p3 alone
    E12 σ1-σ3 and σ2-σ3 (p1 = p2)       E23 σ1-σ3 and σ1-σ2 (p2 = p3)
    C   σ1-σ3 and p3 = σt               F   σ1-σ3, σ2-σ3, p3 = σt: p1 = p2 = N0 σt - q0
    G   σ1-σ3, σ1-σ2, p2 = p3 = σt: p1 = N0 σt - q0 (four planes meet: a one-parameter family of
        multipliers, consistent where it meets the positive orthant)
    W   p2 = p3 = σt (two cut-offs)

A set is taken only when it is clearly consistent: every multiplier (times 2G or α1) and every
inactive plane clear of zero by FAST_MARGIN of the stress scale, the result on the line (p3 >=
that margin). With the planes fixed, the consistent return is unique (checked by brute force over
all sets of up to three planes on random trials, and by the tests against the general path), so
the stress is the general path's to round-off whichever consistent set that path meets first; the
bits (shear 1, tension 2) are those of every consistent set here (both kinds of multiplier are
positive at F and G). Anything else is left to the caller (the general path).

Where two new principal values are equal (E12, E23, F, G, W) the new stress needs one projector
only, onto the axis of the third value: σ = n_a I + (n_b - n_a) P_b; and those results depend on
the sum of the two equal trial values, not on each: both are accurate however close the two trial
values are (the closed-form values are accurate to about eps r² / gap; their sum and the isolated
value to eps r), so these are done in scalars without Jacobi. S, T and C move the three values
apart and need both projectors and each value: closed form only with the values well apart
(``GAP_REL``), else Jacobi's axes (``hoek_brown._slow``, kind 0 below).
"""
from numba import njit

from ..principal import GAP_REL, _deviator, dev_square
from ._common import SHEAR_NOW, TENSION_NOW

#: result kinds: 0 three distinct new values (both projectors), 1 p1 = p2 (P3 only), 2 p2 = p3
#: (P1 only)
KIND3 = 0
KIND12 = 1
KIND23 = 2


@njit(cache=True, inline="always")
def _two_cutoffs(p1, p2, p3, a1, a2, q0, n0, st, mar):
    """The return onto the cut-offs of p2 and p3 together (tension positive p1 <= p2 <= p3, the
    envelope's line at σ3 = 0 through q0 with slope n0): [α1 α2; α2 α1] (λ2, λ3) = (p2 - σt,
    p3 - σt), p1 lowered by α2 (λ2 + λ3); α1 = K + 4G/3, α2 = K - 2G/3. (settled, new p1):
    settled where both multipliers are clearly positive and the result clearly inside the third
    cut-off and the shear line."""
    v2 = p2 - st
    v3 = p3 - st
    det = (a1 - a2) * (a1 + a2)
    n1 = p1 - a2 * (v2 + v3) / (a1 + a2)
    ok = (a1 * v2 - a2 * v3) * a1 > mar * det and (a1 * v3 - a2 * v2) * a1 > mar * det
    ok = ok and n1 < st - mar and -n1 - (q0 - n0 * st) < -mar
    return ok, n1


@njit(cache=True)
def line_values(p1, p2, p3, N, C, st, nps, a1, a2, mar):
    """The return of the trial p1 <= p2 <= p3 on the line σ1 = C + N σ3 (2c √N = C) with the
    cut-off σt = st, flow N_ψ = nps (the module text): (bits, n1, n2, n3, kind), bits -1 where no
    set is clearly consistent. The caller has checked p3 > mar, st > mar, C - (N - 1) st > mar
    (the cut-off clearly inside the line's apex) and α1 > α2."""
    g2 = a1 - a2
    b = a2 * (nps - 1.0)
    dm1 = b - g2                         # D m of σ1-σ3 (tension positive): (dm1, b, dm3)
    dm3 = b + g2 * nps
    f13 = N * p3 - p1 - C                # > 0: shear violated
    n1c = N * st - C                     # p1 where σ1-σ3 meets p3 = σt
    # T: tension alone
    if p3 - st > mar:
        tau = (p3 - st) / a1
        n1 = p1 - tau * a2
        n2 = p2 - tau * a2
        if n2 <= st - mar and n1 - n1c > mar:
            return TENSION_NOW, n1, n2, st, KIND3
    if f13 > mar:
        # S: shear σ1-σ3 alone
        lam = f13 / (a1 * (1.0 + N * nps) - a2 * (N + nps))
        n1 = p1 - lam * dm1
        n2 = p2 - lam * b
        n3 = p3 - lam * dm3
        if lam > 0.0 and n2 - n1 > mar and n3 - n2 > mar and st - n3 > mar and n3 > mar:
            return SHEAR_NOW, n1, n2, n3, KIND3
    d1 = (p2 - p1) / g2                  # μ - ν where σ1 = σ2 (E12, F)
    # E12: p1 = p2 = ((p1 + p2) - S (2b - 2G))/2, p3 - S dm3, S = μ + ν
    den = N * dm3 - (b - 0.5 * g2)
    if den > 0.0:
        S = (N * p3 - 0.5 * (p1 + p2) - C) / den
        n1 = 0.5 * (p1 + p2) - S * (b - 0.5 * g2)
        n3 = p3 - S * dm3
        if (S - d1) * g2 > mar and st - n3 > mar and n3 - n1 > mar and n3 > mar:
            return SHEAR_NOW, n1, n1, n3, KIND12
    # E23: p2 = p3 = ((p2 + p3) - S (2b + 2G N_ψ))/2, p1 - S dm1
    den = N * (b + 0.5 * g2 * nps) - dm1
    if den > 0.0:
        S = (0.5 * N * (p2 + p3) - p1 - C) / den
        n1 = p1 - S * dm1
        n3 = 0.5 * (p2 + p3) - S * (b + 0.5 * g2 * nps)
        if (S - (p3 - p2) / (g2 * nps)) * g2 > mar and st - n3 > mar and n3 - n1 > mar and n3 > mar:
            return SHEAR_NOW, n1, n3, n3, KIND23
    # C: σ1-σ3 and p3 = σt: [dm3 α1; dm1 α2] (μ, τ) = (p3 - σt, p1 + C - N σt)
    det = dm3 * a2 - dm1 * a1
    if det != 0.0:
        r1 = p3 - st
        r2 = p1 - n1c
        mu = (r1 * a2 - a1 * r2) / det
        tau = (dm3 * r2 - dm1 * r1) / det
        n2 = p2 - mu * b - tau * a2
        if mu * g2 > mar and tau * a1 > mar and n2 - n1c > mar and st - n2 > mar:
            return SHEAR_NOW | TENSION_NOW, n1c, n2, st, KIND3
    # F: p1 = p2 = n1c, p3 = σt: (S, τ) from [2b - 2G, 2 α2; dm3, α1] = (p1 + p2 - 2 n1c, p3 - σt)
    det = (2.0 * b - g2) * a1 - 2.0 * a2 * dm3
    if det != 0.0:
        r1 = p1 + p2 - 2.0 * n1c
        r2 = p3 - st
        S = (r1 * a1 - 2.0 * a2 * r2) / det
        tau = ((2.0 * b - g2) * r2 - dm3 * r1) / det
        if (S - d1) * g2 > mar and tau * a1 > mar:
            return SHEAR_NOW | TENSION_NOW, n1c, n1c, st, KIND12
    # G: p1 = n1c, p2 = p3 = σt: shear S = μ + ν, tension T = τ2 + τ3 from
    # [2 dm1, 2 α2; b + dm3, α1 + α2] (S, T) = (2 (p1 - n1c), p2 + p3 - 2 σt), then μ - ν = u,
    # τ3 - τ2 = D - u N_ψ (D = (p3 - p2)/2G): some |u| <= S with |D - u N_ψ| <= T
    det = 2.0 * dm1 * (a1 + a2) - 2.0 * a2 * (b + dm3)
    if det != 0.0:
        r1 = 2.0 * (p1 - n1c)
        r2 = p2 + p3 - 2.0 * st
        S = (r1 * (a1 + a2) - 2.0 * a2 * r2) / det
        T = (2.0 * dm1 * r2 - (b + dm3) * r1) / det
        D = (p3 - p2) / g2
        lo = max(-S, (D - T) / nps)
        hi = min(S, (D + T) / nps)
        if S * g2 > mar and T * a1 > mar and (hi - lo) * g2 > mar:
            return SHEAR_NOW | TENSION_NOW, n1c, st, st, KIND23
    # W: p2 = p3 = σt (``_two_cutoffs``)
    ok, n1 = _two_cutoffs(p1, p2, p3, a1, a2, C, N, st, mar)
    if ok:
        return TENSION_NOW, n1, st, st, KIND23
    return -1, p1, p2, p3, KIND3


@njit(cache=True, inline="always")
def _projector(d0, d1, d2, s3, s4, s5, q0, q1, q2, q3, q4, q5, la, lb, lc):
    """The projector onto the axis of the deviator's value la (the others lb, lc): (Q - (lb + lc) D
    + lb lc I) / ((la - lb)(la - lc)), Q = D² (Sylvester's formula, ``principal_axes``')."""
    b = lb + lc
    c = lb * lc
    f = 1.0 / ((la - lb) * (la - lc))
    return ((q0 - b * d0 + c) * f, (q1 - b * d1 + c) * f, (q2 - b * d2 + c) * f,
            (q3 - b * s3) * f, (q4 - b * s4) * f, (q5 - b * s5) * f)


@njit(cache=True)
def line_return(s0, s1, s2, s3, s4, s5, m, l1, l2, l3, N, C, st, nps, a1, a2, mar):
    """``line_values`` on the trial s0..s5 (deviatoric values l1 <= l2 <= l3 about the mean m,
    ``_dev_principal``'s) and the new stress in closed form: (code, t0..t5, dsp) as
    ``zone_mohr._fast_return``; code -1 where no set is clearly consistent, -5 where one is but
    needs the axes of close values (``hoek_brown._slow`` then takes Jacobi's axes)."""
    spread = l3 - l1
    if not spread > 0.0:
        return -1, s0, s1, s2, s3, s4, s5, 0.0
    p1 = m + l1
    p2 = m + l2
    p3 = m + l3
    bits, n1, n2, n3, kind = line_values(p1, p2, p3, N, C, st, nps, a1, a2, mar)
    if bits < 0:
        return -1, s0, s1, s2, s3, s4, s5, 0.0
    apart12 = l2 - l1 >= GAP_REL * spread
    apart23 = l3 - l2 >= GAP_REL * spread
    d0, d1, d2 = _deviator(s0, s1, s2)
    q0, q1, q2, q3, q4, q5 = dev_square(d0, d1, d2, s3, s4, s5)
    dsp = m - (n1 + n2 + n3) / 3.0
    if kind == KIND12 and apart23:
        # σ = n1 I + (n3 - n1) P3
        u0, u1, u2, u3, u4, u5 = _projector(d0, d1, d2, s3, s4, s5, q0, q1, q2, q3, q4, q5, l3, l1, l2)
        e = n3 - n1
        return bits, n1 + e * u0, n1 + e * u1, n1 + e * u2, e * u3, e * u4, e * u5, dsp
    if kind == KIND23 and apart12:
        # σ = n3 I + (n1 - n3) P1
        u0, u1, u2, u3, u4, u5 = _projector(d0, d1, d2, s3, s4, s5, q0, q1, q2, q3, q4, q5, l1, l2, l3)
        e = n1 - n3
        return bits, n3 + e * u0, n3 + e * u1, n3 + e * u2, e * u3, e * u4, e * u5, dsp
    if kind == KIND3 and apart12 and apart23:
        # σ = s + e2 I + (e1 - e2) P1 + (e3 - e2) P3, e = new - trial values
        u0, u1, u2, u3, u4, u5 = _projector(d0, d1, d2, s3, s4, s5, q0, q1, q2, q3, q4, q5, l1, l2, l3)
        v0, v1, v2, v3, v4, v5 = _projector(d0, d1, d2, s3, s4, s5, q0, q1, q2, q3, q4, q5, l3, l1, l2)
        e2 = n2 - p2
        f1 = (n1 - p1) - e2
        f3 = (n3 - p3) - e2
        return (bits, s0 + (e2 + f1 * u0 + f3 * v0), s1 + (e2 + f1 * u1 + f3 * v1), s2 + (e2 + f1 * u2 + f3 * v2),
                s3 + (f1 * u3 + f3 * v3), s4 + (f1 * u4 + f3 * v4), s5 + (f1 * u5 + f3 * v5), dsp)
    return -5, s0, s1, s2, s3, s4, s5, 0.0
