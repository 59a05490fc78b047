"""Zone model ``hoek-brown``: Itasca's Hoek-Brown model (generalized criterion, tension cut-off,
user-controlled dilation), with the return carried to the nonlinear surface.

Source: Itasca, FLAC3D/3DEC documentation, "Hoek-Brown Model"
(https://docs.itascacg.com/itasca910/common/models/hoek/doc/modelhoek.html; also pfc700/pfc600
copies). What the page states and is implemented here, in principal stresses with compression
positive (σ1 >= σ3; dec3d's tension-positive principal values p1 <= p2 <= p3 give σ1 = -p1,
σ3 = -p3):

- shear yield for σ3 >= 0: σ1 = σ3 + σci (mb σ3/σci + s)^a  (Eq. 1 of the page);
- for σ3 tensile, "a combination of the Mohr-Coulomb envelope (tangent to Hoek-Brown at σ3 = 0)
  and a tensile cut-off at σ3 = -s σci/mb": here σ1 = σci s^a + N0 σ3 for σ3 < 0, with
  N0 = 1 + a mb s^(a-1), and p3 <= σt = s σci/mb (the point where the Hoek-Brown curve meets
  σ1 = σ3; the tangent line is still above σ1 = σ3 there, by σci s^a (1 - a));
- "the nonlinear failure surface is continuously approximated by the Mohr-Coulomb tangent at the
  current stress level σ3": the tangent at σ3 >= 0 has N_φc = 1 + a mb (mb σ3/σci + s)^(a-1)
  (sin φc = (N_φc - 1)/(N_φc + 1)) and cohesion c_c from 2 c_c √N_φc = σ1(σ3) - N_φc σ3;
- the model is "derived directly from the Mohr-Coulomb model" and adds a "dilation angle as an
  input parameter": the flow rule is Mohr-Coulomb's non-associated one with dilation ψ.

Itasca's model evaluates the tangent once, at the trial σ3, and makes one Mohr-Coulomb return.
dec3d repeats it (Newton's method on the plastic multiplier): the Mohr-Coulomb return of the
trial stress (``zone_mohr.mohr_plastic``: single plane, edges, tension corner, apex; principal
directions kept) onto the tangent at the σ3 of the previous result, until the result is on the
Hoek-Brown surface itself (|f| <= 1e-12 of the stress scale) or admissible (tension returns).
The envelope is concave, so every tangent lies outside it: each iterate stays outside or on the
surface and the multiplier grows monotonically to the root (quadratically). The dilation,
and so the flow direction, is fixed from the trial state (σ3 of the trial, as Itasca takes it).

That iteration on arrays is the general path (``_general``). The common cases take a scalar
path with the same result (to ~1e-12 of the stress scale, the same bits): a single-plane shear
return leaving σ2 between σ1 and σ3, Itasca's tension return, a shear edge (σ2 = σ3 or
σ1 = σ2 at the result; also for principal values not well apart, ``GAP_REL``, on Jacobi's
axes as the general path), two cut-offs, and the apex of the three (σ = σt I). With the principal
directions and the flow direction fixed, the return is one scalar equation in the plastic
multiplier, solved by Halley's steps (``_fast``, ``_edge``); the last step and the rotation back
are ``zone_mohr._fast_return``'s (or ``principal_axes`` and ``zone_mohr._rotate_back`` for
edges, close values and two cut-offs). A trial with p3 > 0 whose return stays at p3 >= 0 is one
Mohr-Coulomb return on the envelope's line: its corners and edges in closed form (``_hoek_line``);
edges on the curve are solved on sums of the two values that meet (``_hoek_edge``, no Jacobi).
Whatever they do not settle clearly (decisions within FAST_MARGIN of a threshold) goes to the
general path.

The property keywords, the dilation rule and the trial-state tangent are taken from Itasca's
published source of the model (``modelhoek.cpp``: ``ModelHoek::getProperties`` lists
constant-mb, constant-s, constant-a, constant-sci, flag-dilation, constant-dilation …;
``ModelHoek::run`` computes φc, c_c and ψ at the trial σ3, its compressive part); the search tool
returned only the opening part of the documentation page, not its property table.

Properties (own columns):
column P_OWN     mb         (``constant-mb`` > 0)
       P_OWN+1   s          (``constant-s``, 0..1)
       P_OWN+2   a          (``constant-a``, 0 < a <= 1)
       P_OWN+3   σci [Pa]   (``constant-sci`` > 0)
       P_OWN+4   tan ψ      (``constant-dilation``, degrees; default 0: no plastic volume change)
       P_OWN+5   flag       (``flag-dilation``: 0 uses constant-dilation; < 0: ψ = φc, the local
                             friction angle; > 0: ψ = flag × φc), ψ capped at φc in every case,
                             φc taken at the trial σ3 (compressive part, >= 0).

Not implemented: Itasca's table-* properties and softening (flag-evolution, strain-plastic,
length-calibration), its optional Mohr-Coulomb ``tension`` cap below s σci/mb, and its
factor-of-safety option (``flag-fos``; see the host for strength reduction). Where s = 0 the
curve is vertical at σ3 = 0: slopes N_φc (and N0) are capped at 1e6 (φc ≈ 89.9°), so for
σ3 below (σci/mb) (1e-6 a mb)^(1/(1-a)) (2.5e-12 σci for mb = 10, a = 0.5) the stress is
returned to the capped line, not the curve.
"""
import math

from numba import njit

from ..principal import GAP_REL, _dev_principal, principal_axes
from ..zone_mohr import SHEAR_NOW, TENSION_NOW, _fast_return, _rotate_back, mohr_plastic
from ._common import P_OWN, hooke
from ._hoek_edge import edge_sum_return
from ._hoek_line import _two_cutoffs, line_return, line_values
from ._hoek_envelope import NPHI_MAX, _envelope, _tangent, edge_root, hb_strength  # noqa: F401 (NPHI_MAX: the tests')

NAME = "hoek-brown"
CODE = 4          # kept in save files: never renumber
NCOLS = P_OWN + 6
NHIST = 0
HIST_NAMES = ()
PLASTIC = True

#: own columns
C_MB = P_OWN
C_S = P_OWN + 1
C_A = P_OWN + 2
C_SCI = P_OWN + 3
C_TANDIL = P_OWN + 4
C_FLAGDIL = P_OWN + 5

#: Newton iterations at most; convergence: |f| <= RTOL × stress scale
MAXIT = 60
RTOL = 1e-12


@njit(cache=True, inline="always")
def _dot(p, o, u0, u1, u2, u3, u4, u5):
    """P : u for the projector p[o:o+6] (xx yy zz xy xz yz) and the tensor u."""
    return p[o] * u0 + p[o + 1] * u1 + p[o + 2] * u2 + 2.0 * (p[o + 3] * u3 + p[o + 4] * u4 + p[o + 5] * u5)


@njit(cache=True, inline="always")
def _nps(flag, tandil, n0):
    """N_ψ = (1 + sin ψ)/(1 - sin ψ) of the flow rule: ψ from the dilation rule (column C_FLAGDIL,
    C_TANDIL = tan ψ), capped at φc, the friction angle of the tangent at the trial σ3, whose
    N_φc is n0 (so N_ψ = n0 where ψ = φc); the same ψ as the general path's, without its
    arctangent and tangent in the common cases (flag 0, flag < 0)."""
    if flag < 0.0:
        return n0
    if flag == 0.0 and tandil == 0.0:
        return 1.0
    tphi0 = 0.5 * (n0 - 1.0) / math.sqrt(n0)
    if flag > 0.0:
        phic = math.atan(tphi0)
        psi = flag * phic
        if psi >= phic:
            return n0
        sp = math.sin(psi)
    else:
        if tandil >= tphi0:
            return n0
        sp = tandil / math.sqrt(1.0 + tandil * tandil)
    return (1.0 + sp) / (1.0 - sp)


#: the scalar return takes a state only when its decisions are this far (relative to the stress
#: scale) from the general path's thresholds; nearer states go to the general path
FAST_MARGIN = 1e-8


#: the single-plane return and the edge return are told apart when the multiplier of the first is
#: this far (relative) from where σ2 meets σ1 or σ3; nearer states go to the general path
EDGE_REL = 1e-6


@njit(cache=True, inline="always")
def _edge_values(p1, p2, p3, nps, a1, a2, mb, s, a, sci, st, tol, mar):
    """The edge return in scalars (``_slow``'s, where the single-plane return would carry σ2
    past σ3 or σ1): two shear surfaces, σ1-σ3 and σ1-σ2 (σ2 = σ3 at the result) or σ1-σ3 and
    σ2-σ3 (σ1 = σ2), the flow of each Mohr-Coulomb's with the dilation fixed from the trial.
    The trial's principal values p1 <= p2 <= p3. With the multipliers μ of σ1-σ3
    and μ - d of the other (d: where the single-plane return meets the edge), the condition
    that the two equal principal values stay equal is linear and leaves σ1(μ) = c1 + k1 μ,
    σ3(μ) = c3 + k3 μ; the return solves σ1(μ) = q(σ3(μ)) from μ = d by the steps of ``_fast``
    (g again convex and decreasing). This is the general path's two-plane return (the Itasca
    plane with the plane of the pair that became equal), iterated onto the same tangents.
    Returns (settled, n1, n2, n3): the new principal values."""
    dm1 = a2 * nps - a1                  # D m of σ1-σ3 (tension positive): (dm1, b, dm3)
    dm3 = a1 * nps - a2
    b = a2 * (nps - 1.0)
    g2 = a1 - a2                         # 2G
    d3 = (p3 - p2) / (g2 * nps)
    d1 = (p2 - p1) / g2
    e3 = d3 <= d1
    if e3:                               # σ2 = σ3: the second plane σ1-σ2, D m = (dm1, dm3, b)
        d = d3
        c1 = -p1 - d3 * dm1
        k1 = 2.0 * dm1
        c3 = -p3 - d3 * b
        k3 = dm3 + b
    else:                                # σ1 = σ2: the second plane σ2-σ3, D m = (b, dm1, dm3)
        d = d1
        c1 = -p1 - d1 * b
        k1 = dm1 + b
        c3 = -p3 - d1 * dm3
        k3 = 2.0 * dm3
    done, mu = edge_root(c1, k1, c3, k3, d, mb, s, a, sci, tol, mar, MAXIT)
    if not done:
        return False, p1, p2, p3
    if not mu - d > EDGE_REL * mu:
        return False, p1, p2, p3
    if e3:
        n1 = p1 - (2.0 * mu - d3) * dm1
        n3 = p3 - mu * dm3 - (mu - d3) * b
        n2 = n3
    else:
        n1 = p1 - mu * dm1 - (mu - d1) * b
        n2 = n1
        n3 = p3 - (2.0 * mu - d1) * dm3
    if not (n3 <= st - mar and n3 - n1 > mar):
        return False, p1, p2, p3
    return True, n1, n2, n3


@njit(cache=True, inline="always")
def _plane(p1, p3, nps, a1, a2, mb, s, a, sci, tol, mar):
    """The single-plane shear return of ``_fast`` (its steps, no tension violated at the trial)
    for principal values p1 <= p3 that need not be well apart: (settled, λ) with λ the
    multiplier of the last Newton step."""
    dm1 = a2 * nps - a1
    dm3 = a1 * nps - a2
    lam = 0.0
    yk = -p3
    qk, nk, ck = _envelope(yk, mb, s, a, sci)
    g = -p1 - qk
    if not g > mar:
        return False, 0.0
    for _it in range(MAXIT):
        if not ck > -1e300:
            break
        csn = qk - nk * yk
        if csn < 0.0:
            csn = 0.0
        den = a1 * (1.0 + nk * nps) - a2 * (nk + nps)
        if nk * p3 - p1 - csn <= mar:
            break
        dn = g / den
        y3 = yk + dn * dm3
        if 0.5 * (-ck) * (dm3 * dm3) * (dn * dn) <= 0.01 * tol and not (yk < 0.0 and y3 > 0.0):
            return True, lam + dn
        step = dn
        dd = 2.0 * den * den + g * ck * (dm3 * dm3)
        if dd > den * den:
            step = 2.0 * g * den / dd
        lam += step
        yk = -p3 + lam * dm3
        qk, nk, ck = _envelope(yk, mb, s, a, sci)
        g = (-p1 + lam * dm1) - qk
    return False, 0.0




@njit(cache=True, inline="always")
def _fast(flag, tandil, K, G, s0, s1, s2, s3, s4, s5, m, l1, l2, l3, x0, q0, n0, mb, s, a, sci, st):
    """The return of the trial s0..s5 in scalars for the common case (``update``'s fast path):
    principal values well apart (``GAP_REL``, as ``zone_mohr._fast_return``), a clear shear
    return onto the σ1-σ3 surface leaving σ2 between them, or Itasca's tension return. Given
    the trial's deviatoric principal values l1 <= l2 <= l3 about the mean m
    (``_dev_principal``) and the envelope's tangent at x0 = max(σ3, 0) of the trial
    (σ1 = q0 + n0 (σ3 - x0)).

    With the principal directions kept and the flow direction fixed from the trial (ψ, so
    N_ψ), the principal stresses of the return are p(λ) = p_trial - λ D m, m = (-1, 0, N_ψ):
    σ1(λ) = -p1 + λ (α2 N_ψ - α1), σ3(λ) = -p3 + λ (α1 N_ψ - α2), and the shear return solves
    g(λ) = σ1(λ) - q(σ3(λ)) = 0. g is convex (q is concave, σ1 and σ3 linear in λ) and
    decreasing (g' = -den < 0). The general path's iteration is Newton's method on g (its
    Mohr-Coulomb return of the trial onto the tangent at σ3(λ_k) is the Newton step from
    λ_k). Here: Halley's steps (g'' = -dN/dσ3 (dσ3/dλ)², from the same power), until the
    Newton step from the current point is known to land on the surface: its error
    g''/2 × step² (exact where the envelope is straight) at most RTOL/100 of the stress scale.
    That last Newton step, with the rotation back, is ``zone_mohr._fast_return`` on the
    tangent at the current point (its constants computed here from the tangent's N), so that
    the admissibility checks are the general path's own. A trial beyond the tension cut-off
    takes Newton's steps instead, each tangent's choice between shear and tension (Itasca's h)
    checked as the general path makes it. Returns (code, t0..t5, dsp) as ``_fast_return``:
    code -1 when not settled here (the general path then does it), -2 where the single-plane
    return would carry σ2 past σ1 or σ3, -3 for a clear shear return with principal values
    not well apart, -4 for the return onto two cut-offs (``_slow`` then does them)."""
    p1 = m + l1
    p2 = m + l2
    p3 = m + l3
    scale = abs(p1) + abs(p2) + abs(p3) + sci
    tol = RTOL * scale
    mar = FAST_MARGIN * scale
    yk = -p3                                     # σ3 of the current point (compression positive)
    g = -p1 - (q0 + n0 * (yk - x0))              # g at the trial: the shear yield function
    ten = p3 - st
    # the apex: the three cut-offs together, every multiplier clearly positive (λ = D⁻¹(p - σt),
    # λ1 ∝ (p1 - σt) - (α2/K)(m - σt)): σ = σt I, no rotation; not where the shear lines meet
    # there too (a = 1: the envelope's line at σ3 = 0 passes through σ1 = σ3 = -σt)
    if (ten > mar and x0 == 0.0 and K > 0.0 and (p1 - st) - (1.0 - 2.0 * G / (3.0 * K)) * (m - st) > mar
            and q0 - (n0 - 1.0) * st > mar):
        return TENSION_NOW, st, st, st, 0.0, 0.0, 0.0, m - st
    if (ten > mar and x0 == 0.0 and q0 - (n0 - 1.0) * st > mar
            and _two_cutoffs(p1, p2, p3, K + 4.0 * G / 3.0, K - 2.0 * G / 3.0, q0, n0, st, mar)[0]):
        return -4, s0, s1, s2, s3, s4, s5, 0.0    # (two cut-offs: ``_hoek_line``)
    if not (l3 - l1 > 0.0 and min(l2 - l1, l3 - l2) >= GAP_REL * (l3 - l1)):
        if ten < -mar and g > mar:
            return -3, s0, s1, s2, s3, s4, s5, 0.0    # (a clear shear return: ``_slow``)
        return -1, s0, s1, s2, s3, s4, s5, 0.0
    if ten <= tol and g <= tol:
        return 0, s0, s1, s2, s3, s4, s5, 0.0    # (the general path's test: elastic)
    tens = ten > tol
    if (tens and ten <= mar) or abs(g) <= mar:
        return -1, s0, s1, s2, s3, s4, s5, 0.0
    # the curvature dN/dσ3 at the trial (``_envelope``'s, from N)
    if yk < 0.0:
        ck = 0.0
    elif n0 < NPHI_MAX:
        ck = (a - 1.0) * mb * (n0 - 1.0) / (sci * (mb * x0 / sci + s))
    else:
        ck = math.nan
    nps = _nps(flag, tandil, n0)
    a1 = K + 4.0 * G / 3.0
    a2 = K - 2.0 * G / 3.0
    dm1 = a2 * nps - a1                          # dσ1/dλ
    dm3 = a1 * nps - a2                          # dσ3/dλ (> 0)
    xk = x0                                      # the tangent at the current point:
    qk = q0                                      # σ1 = qk + nk (σ3 - xk)
    nk = n0
    lam = 0.0
    ap = 0.0
    sp = 0.0
    code = SHEAR_NOW
    done = False
    for it in range(MAXIT):
        if not ck > -1e300:
            break                                # (N capped on the curve: no tangent)
        csn = qk - nk * xk                       # the tangent: σ1 = csn + nk σ3
        if csn < 0.0:
            csn = 0.0
        den = a1 * (1.0 + nk * nps) - a2 * (nk + nps)
        if tens:
            # Itasca's choice between shear and tension returns (``zone_mohr``'s h), tangent k
            ap = math.sqrt(1.0 + nk * nk) + nk
            sp = st * nk - csn
            hk = ten + ap * (p1 - sp)
            hm = FAST_MARGIN * (1.0 + ap) * scale
            if it == 0 and (g < -mar or hk > hm):
                code = TENSION_NOW               # Itasca's tension return
                done = True
                break
            if hk >= -hm:
                break
        if nk * p3 - p1 - csn <= mar:
            break                                # (the tangent's return would be elastic)
        dn = g / den                             # Newton's step
        y3 = yk + dn * dm3
        if tens and it == 0 and -y3 > st - mar:
            break                                # (the general path may take the tension corner)
        if 0.5 * (-ck) * (dm3 * dm3) * (dn * dn) <= 0.01 * tol and not (yk < 0.0 and y3 > 0.0):
            done = True                          # Newton's step from here is on the surface
            break
        step = dn
        if not tens:
            dd = 2.0 * den * den + g * ck * (dm3 * dm3)
            if dd > den * den:
                step = 2.0 * g * den / dd        # Halley's step
        lam += step
        yk = -p3 + lam * dm3
        qk, nk, ck = _envelope(yk, mb, s, a, sci)
        xk = yk
        g = (-p1 + lam * dm1) - qk
    if not done:
        return -1, s0, s1, s2, s3, s4, s5, 0.0
    if not tens:
        ap = 0.0                                 # (h is not looked at: no tension violated)
        sp = 0.0
        if code == SHEAR_NOW:
            # σ2 stays between σ1 and σ3 up to the multiplier dmin; beyond it, the edge return
            lamf = lam + g / den
            g2 = a1 - a2
            dmin = min((p3 - p2) / (g2 * nps), (p2 - p1) / g2)
            if lamf > (1.0 + EDGE_REL) * dmin:
                return -2, s0, s1, s2, s3, s4, s5, 0.0        # (the edge return: ``_slow``)
            if lamf > (1.0 - EDGE_REL) * dmin:
                return -1, s0, s1, s2, s3, s4, s5, 0.0
    coh = 0.5 * csn / math.sqrt(nk)
    r = _fast_return(s0, s1, s2, s3, s4, s5, m, l1, l2, l3, coh, nk, csn, st, nps, a1, a2, sp, ap, den)
    if r[0] != code:
        return -1, s0, s1, s2, s3, s4, s5, 0.0
    return r


@njit(cache=True)
def fast_update(p, h, z, K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5, tab, wf, mw):
    """``update``'s scalar paths alone (for the tests): (code, t0..t5, dsp) of ``_scalar``; code
    -1 where ``update`` takes the general path, below -1 where it takes ``_slow`` (and the general
    path if that does not settle)."""
    return _scalar(K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5, p[z, C_MB], p[z, C_S], p[z, C_A],
                   p[z, C_SCI], p[z, C_FLAGDIL], p[z, C_TANDIL])


@njit(cache=True, inline="always")
def update(p, h, z, K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5, tab, wf, mw):
    mb = p[z, C_MB]
    s = p[z, C_S]
    a = p[z, C_A]
    sci = p[z, C_SCI]
    # (inlined into the zone step: the scalar path is one call on scalars, no array arguments
    # whose reference counts a call would pay for every zone; the arrays go only to ``_slow``)
    r = _scalar(K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5, mb, s, a, sci, p[z, C_FLAGDIL], p[z, C_TANDIL])
    if r[0] >= 0:
        return r
    return _slow(p, z, K, G, r[1], r[2], r[3], r[4], r[5], r[6], mb, s, a, sci, s * sci / mb, wf, mw, r[0])


@njit(cache=True)
def _scalar(K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5, mb, s, a, sci, flag, tandil):
    """The elastic trial, the yield test and the scalar returns (``_fast``) of ``update``: (code,
    t0..t5, dsp), code < 0 (``_fast``'s) with t the trial where ``_slow`` must finish."""
    s0, s1, s2, s3, s4, s5 = hooke(K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5)
    if not (mb > 0.0 and sci > 0.0 and a > 0.0 and s >= 0.0):
        return 0, s0, s1, s2, s3, s4, s5, 0.0          # (refused by the host; never cycled)
    st = s * sci / mb
    # clearly elastic from the closed-form principal values (no arrays), with a margin far above
    # their round-off; what this cannot tell goes to the exact test of the return
    m, l1, l2, l3 = _dev_principal(s0, s1, s2, s3, s4, s5)
    margin = 1e-7 * (3.0 * abs(m) + abs(l1) + abs(l3) + sci)
    x0 = max(-(m + l3), 0.0)                      # σ3 of the trial, compression positive, >= 0
    q0, n0 = hb_strength(x0, mb, s, a, sci)       # the envelope's tangent there
    if m + l3 - st < -margin and -(m + l1) - (q0 + n0 * (-(m + l3) - x0)) < -margin:
        return 0, s0, s1, s2, s3, s4, s5, 0.0
    r = _fast(flag, tandil, K, G, s0, s1, s2, s3, s4, s5, m, l1, l2, l3, x0, q0, n0, mb, s, a, sci, st)
    code = r[0]
    if code < 0 and G > 0.0:
        scale = abs(m + l1) + abs(m + l2) + abs(m + l3) + sci
        mar = FAST_MARGIN * scale
        nps = _nps(flag, tandil, n0)
        a1 = K + 4.0 * G / 3.0
        a2 = K - 2.0 * G / 3.0
        # a trial with p3 > 0 starts on the envelope's line: its corner and edge returns there
        if (code == -1 or code == -4) and m + l3 > mar and st > mar and q0 - (n0 - 1.0) * st > mar:
            rl = line_return(s0, s1, s2, s3, s4, s5, m, l1, l2, l3, n0, q0, st, nps, a1, a2, mar)
            if rl[0] != -1:
                return rl
        # edges on the curve (also from trials in tension), one projector
        if code == -1 or code == -2 or code == -3:
            re = edge_sum_return(s0, s1, s2, s3, s4, s5, m, l1, l2, l3, nps, a1, a2, mb, s, a, sci, st,
                                 RTOL * scale, mar, EDGE_REL, MAXIT)
            if re[0] >= 0:
                return re
    return r


@njit(cache=True)
def _slow(p, z, K, G, s0, s1, s2, s3, s4, s5, mb, s, a, sci, st, wf, mw, code):
    """What ``_scalar`` leaves (its code): the edge return (-2), the shear return with close
    values (-3), the line's returns (-4 two cut-offs, -5 ``_hoek_line``) on ``principal_axes``'
    values and projectors (Jacobi for close values, as the general path), rotated back by
    ``zone_mohr._rotate_back`` (chunk scratch as the general path's: trial wf[0:6], projectors
    wf[12:24], values wf[24:27], new values wf[27:30]); else the general path."""
    if code == -4 or code == -5:
        # (the line's corners, edges and cut-offs on Jacobi's axes: ``_hoek_line``)
        t = wf[0:6]
        t[0] = s0; t[1] = s1; t[2] = s2; t[3] = s3; t[4] = s4; t[5] = s5
        lam = wf[24:27]
        pr = wf[12:24]
        principal_axes(t, lam, pr, mw[6])
        mar = FAST_MARGIN * (abs(lam[0]) + abs(lam[1]) + abs(lam[2]) + sci)
        q0, n0 = hb_strength(0.0, mb, s, a, sci)
        bits = -1
        n1 = n2 = n3 = 0.0
        if lam[2] > mar and st > mar and q0 - (n0 - 1.0) * st > mar and G > 0.0:
            bits, n1, n2, n3, _kind = line_values(lam[0], lam[1], lam[2], n0, q0, st,
                                                  _nps(p[z, C_FLAGDIL], p[z, C_TANDIL], n0),
                                                  K + 4.0 * G / 3.0, K - 2.0 * G / 3.0, mar)
        if bits >= 0:
            sn = wf[27:30]
            sn[0] = n1; sn[1] = n2; sn[2] = n3
            bits, dsp = _rotate_back(t, lam, pr, sn, bits)
            t0 = t[0]; t1 = t[1]; t2 = t[2]; t3 = t[3]; t4 = t[4]; t5 = t[5]
            wf[0] = math.nan
            return bits, t0, t1, t2, t3, t4, t5, dsp
    if code == -2 or code == -3:
        t = wf[0:6]
        t[0] = s0; t[1] = s1; t[2] = s2; t[3] = s3; t[4] = s4; t[5] = s5
        lam = wf[24:27]
        pr = wf[12:24]
        principal_axes(t, lam, pr, mw[6])
        p1 = lam[0]
        p2 = lam[1]
        p3 = lam[2]
        scale = abs(p1) + abs(p2) + abs(p3) + sci
        tol = RTOL * scale
        mar = FAST_MARGIN * scale
        _q0, n0 = hb_strength(max(-p3, 0.0), mb, s, a, sci)
        nps = _nps(p[z, C_FLAGDIL], p[z, C_TANDIL], n0)
        a1 = K + 4.0 * G / 3.0
        a2 = K - 2.0 * G / 3.0
        ok = False
        edge = code == -2
        n1 = p1; n2 = p2; n3 = p3
        if code == -3 and p3 - st < -mar:
            ok, lamf = _plane(p1, p3, nps, a1, a2, mb, s, a, sci, tol, mar)
            if ok:
                g2 = a1 - a2
                dmin = min((p3 - p2) / (g2 * nps), (p2 - p1) / g2)
                if lamf < (1.0 - EDGE_REL) * dmin:
                    n1 = p1 - lamf * (a2 * nps - a1)
                    n2 = p2 - lamf * a2 * (nps - 1.0)
                    n3 = p3 - lamf * (a1 * nps - a2)
                    ok = n3 <= st - mar
                else:
                    ok = False
                    edge = lamf > (1.0 + EDGE_REL) * dmin
        if edge and p3 - st < -mar:
            ok, n1, n2, n3 = _edge_values(p1, p2, p3, nps, a1, a2, mb, s, a, sci, st, tol, mar)
        if ok:
            sn = wf[27:30]
            sn[0] = n1; sn[1] = n2; sn[2] = n3
            bits, dsp = _rotate_back(t, lam, pr, sn, SHEAR_NOW)
            t0 = t[0]; t1 = t[1]; t2 = t[2]; t3 = t[3]; t4 = t[4]; t5 = t[5]
            wf[0] = math.nan
            return bits, t0, t1, t2, t3, t4, t5, dsp
    return _general(p, z, K, G, s0, s1, s2, s3, s4, s5, mb, s, a, sci, st, wf, mw)


@njit(cache=True)
def update_general(p, h, z, K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5, tab, wf, mw):
    """``update`` by the general path alone (for the tests)."""
    s0, s1, s2, s3, s4, s5 = hooke(K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5)
    mb = p[z, C_MB]
    s = p[z, C_S]
    a = p[z, C_A]
    sci = p[z, C_SCI]
    return _general(p, z, K, G, s0, s1, s2, s3, s4, s5, mb, s, a, sci, s * sci / mb, wf, mw)


@njit(cache=True)
def _general(p, z, K, G, s0, s1, s2, s3, s4, s5, mb, s, a, sci, st, wf, mw):
    """The return of the trial s0..s5 on arrays (every case): the yield test on
    ``principal_axes``' values, then Newton's method as repeated ``zone_mohr.mohr_plastic``
    returns onto the tangent at the σ3 of the previous result (the module text)."""
    # the chunk scratch: trial t = wf[0:6], working copy wf[6:12], projectors wf[12:24],
    # principal values wf[24:27]; wf[0] is left NaN so that no cache of another model matches
    t = wf[0:6]
    t[0] = s0; t[1] = s1; t[2] = s2; t[3] = s3; t[4] = s4; t[5] = s5
    lam = wf[24:27]
    pr = wf[12:24]
    principal_axes(t, lam, pr, mw[6])
    pmin = lam[0]
    pmax = lam[2]
    scale = abs(lam[0]) + abs(lam[1]) + abs(lam[2]) + sci
    tol = RTOL * scale
    # yield test on the envelope (tension first: left of -σt the curve is not used)
    elastic = pmax - st <= tol
    if elastic:
        q, _n = hb_strength(-pmax, mb, s, a, sci)
        elastic = -pmin - q <= tol
    if elastic:
        wf[0] = math.nan
        return 0, s0, s1, s2, s3, s4, s5, 0.0
    # dilation, fixed from the trial state
    _c0, tphi0 = _tangent(-pmax, mb, s, a, sci)
    phic = math.atan(tphi0)
    flag = p[z, C_FLAGDIL]
    if flag < 0.0:
        psi = phic
    elif flag > 0.0:
        psi = flag * phic
    else:
        psi = math.atan(p[z, C_TANDIL])
    if psi > phic:
        psi = phic
    tpsi = math.tan(psi)
    u = wf[6:12]
    x = -pmax                       # linearisation point σ3 (compression positive)
    bits = 0
    dsp = 0.0
    for _it in range(MAXIT):
        coh, tphi = _tangent(x, mb, s, a, sci)
        u[0] = s0; u[1] = s1; u[2] = s2; u[3] = s3; u[4] = s4; u[5] = s5
        bits, dsp = mohr_plastic(u, K, G, coh, tphi, st, tpsi, mw)
        n1 = _dot(pr, 0, u[0], u[1], u[2], u[3], u[4], u[5])
        n3 = _dot(pr, 6, u[0], u[1], u[2], u[3], u[4], u[5])
        n2 = (u[0] + u[1] + u[2]) - n1 - n3
        lo = min(n1, min(n2, n3))
        hi = max(n1, max(n2, n3))
        q, _n = hb_strength(-hi, mb, s, a, sci)
        f = -lo - q
        xn = -hi
        if (bits & SHEAR_NOW) != 0:
            if abs(f) <= tol:
                break
        elif f <= tol:
            break
        if abs(max(xn, 0.0) - max(x, 0.0)) <= 1e-15 * scale:
            break                   # (the linearisation point no longer moves)
        x = xn
    t0 = u[0]; t1 = u[1]; t2 = u[2]; t3 = u[3]; t4 = u[4]; t5 = u[5]
    wf[0] = math.nan
    return bits, t0, t1, t2, t3, t4, t5, dsp
