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

from ..principal import _dev_principal, principal_axes
from ..zone_mohr import SHEAR_NOW, mohr_plastic
from ._common import P_OWN, hooke

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

#: largest tangent N_φc used (the s = 0 apex, where the curve is vertical)
NPHI_MAX = 1e6
#: Newton iterations at most; convergence: |f| <= RTOL × stress scale
MAXIT = 60
RTOL = 1e-12


@njit(cache=True, inline="always")
def hb_strength(x, mb, s, a, sci):
    """(σ1 at yield, its slope N = dσ1/dσ3) at σ3 = x (compression positive) on the envelope:
    the Hoek-Brown curve for x >= 0, its tangent at 0 for x < 0. N is capped at NPHI_MAX."""
    if x < 0.0:
        if s > 0.0:
            n0 = 1.0 + a * mb * s ** (a - 1.0)
            if n0 > NPHI_MAX:
                n0 = NPHI_MAX
        else:
            n0 = NPHI_MAX
        return sci * s ** a + n0 * x, n0
    base = mb * x / sci + s
    if base > 0.0:
        n = 1.0 + a * mb * base ** (a - 1.0)
        if n > NPHI_MAX:
            n = NPHI_MAX
        return x + sci * base ** a, n
    return x, NPHI_MAX


@njit(cache=True, inline="always")
def _tangent(x, mb, s, a, sci):
    """The Mohr-Coulomb tangent of the envelope at σ3 = max(x, 0): (c_c, tan φc)."""
    if x < 0.0:
        x = 0.0
    q, n = hb_strength(x, mb, s, a, sci)
    rn = math.sqrt(n)
    csn = q - n * x                 # 2 c √N (>= 0: the curve is concave and q(0) >= 0)
    if csn < 0.0:
        csn = 0.0
    return 0.5 * csn / rn, 0.5 * (n - 1.0) / rn


@njit(cache=True, inline="always")
def _dot(p, o, u0, u1, u2, u3, u4, u5):
    """P : u for the projector p[o:o+6] (xx yy zz xy xz yz) and the tensor u."""
    return p[o] * u0 + p[o + 1] * u1 + p[o + 2] * u2 + 2.0 * (p[o + 3] * u3 + p[o + 4] * u4 + p[o + 5] * u5)


@njit(cache=True)
def update(p, h, z, K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5, tab, wf, mw):
    s0, s1, s2, s3, s4, s5 = hooke(K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5)
    mb = p[z, C_MB]
    s = p[z, C_S]
    a = p[z, C_A]
    sci = p[z, C_SCI]
    if not (mb > 0.0 and sci > 0.0 and a > 0.0 and s >= 0.0):
        return 0, s0, s1, s2, s3, s4, s5, 0.0          # (refused by the host; never cycled)
    st = s * sci / mb
    # clearly elastic from the closed-form principal values (no arrays), with a margin far above
    # their round-off; what this cannot tell goes to the exact test below
    m, l1, _l2, l3 = _dev_principal(s0, s1, s2, s3, s4, s5)
    margin = 1e-7 * (3.0 * abs(m) + abs(l1) + abs(l3) + sci)
    if m + l3 - st < -margin:
        q, _n = hb_strength(-(m + l3), mb, s, a, sci)
        if -(m + l1) - q < -margin:
            return 0, s0, s1, s2, s3, s4, s5, 0.0
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
