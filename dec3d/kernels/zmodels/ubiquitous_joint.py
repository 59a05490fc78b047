"""Zone model ``ubiquitous-joint``: Itasca's ubiquitous-joint model, a Mohr-Coulomb matrix with
one orientation of weakness (weak plane).

Source: Itasca, FLAC3D/3DEC documentation, "Ubiquitous-Joint Model",
https://docs.itascacg.com/itasca900/common/models/ubiquit/doc/modelubiquit.html, and its
property page https://docs.itascacg.com/pfc600/common/models/ubiquit/doc/propubiquit.html
(``joint-cohesion``, ``joint-friction``, ``joint-tension``, ``joint-dilation``, ``dip``,
``dip-direction``; "the joint tension limit used in the model is the minimum of the input
tension and c_j / tan φ_j").

Itasca's algorithm: general (matrix) failure first, with the Mohr-Coulomb corrections (here
``zone_mohr``'s return, as ``mohr.py``); the new stresses σ^O are then analysed for failure on
the weak plane. Itasca's local axes have x' down the dip, y' horizontal in the plane and z' the
unit normal n; the plane sees σ = σ_3'3' = n·σn and τ = (σ_1'3'² + σ_2'3'²)^½ = |σn − σ n|
(only the shear traction vector t_s = σn − σ n enters, so x' and y' are never formed). Tension
positive, the composite criterion of the plane:

    shear     f_s = τ + σ tan φ_j − c_j          (yield when f_s > 0)
    tension   f_t = σ − σ_t^j,  σ_t^j = min(joint-tension, c_j / tan φ_j)  (0 when φ_j = c_j = 0)

with potentials g_s = τ + σ tan ψ_j (non-associated) and g_t = σ (associated), and Itasca's
elastic law of the plane's generalized components: τ = 2G γ (γ = (ε_1'3'² + ε_2'3'²)^½, tensor
components), σ_3'3' and the in-plane normal stresses by α1 = K + 4G/3, α2 = K − 2G/3. Shear
return (λs = f_s / (2G + α1 tan φ_j tan ψ_j)): τ ← τ − 2G λs, σ ← σ − α1 tan ψ_j λs,
σ_1'1', σ_2'2' −= α2 tan ψ_j λs. Tension return (λt = f_t / α1): σ ← σ_t^j, σ_1'1', σ_2'2' −=
α2 λt, τ kept. Itasca picks the return by comparing f_s / (1 + tan² φ_j)^½ with f_t (shear when
f_s > 0 and it is the larger: the trial lies above the bisector of the two lines through the
corner, the h function of the Mohr-Coulomb model). Where that single return leaves the other
criterion violated (a tension return keeping τ above the corner's τ^P = c_j − σ_t^j tan φ_j, or
a shear return past σ_t^j or to τ < 0), dec3d returns to the corner (σ_t^j, τ^P) with both
multipliers, λs = (τ − τ^P) / 2G, λt = (σ − σ_t^j − α1 tan ψ_j λs) / α1; if those are not both
>= 0, the other single return (the three regions tile the outside of the plane's envelope, so
one of them is consistent). In global axes the correction is

    Δσ = −α2 μ I − (α1 − α2) μ n nᵀ − (2G λs / τ) (t_s nᵀ + n t_sᵀ),   μ = λs tan ψ_j + λt.

State bits: the matrix's 1 shear / 2 tension and the plane's 16 shear / 32 tension (``_common``).
No history. The plane's normal does not rotate with the zone in large strain (Itasca rotates it).

Orientation (3DEC 7+ axes: x east, y north, z up; ``dec3d/geometry/planes.py``): dip δ down from
the horizontal, dip direction α clockwise from north (+y) seen from above; upward unit normal
n = (sin δ sin α, sin δ cos α, cos δ).

Columns: the shared Mohr-Coulomb ones, and from P_OWN on joint cohesion, tan joint friction,
joint tension, tan joint dilation, dip [degrees], dip direction [degrees]. Chunk scratch ``wf``:
wf[16:22] the trial handed to the general Mohr-Coulomb return (as ``mohr.py``); wf[22] = CODE
when wf[23:25] hold the dip and dip direction that the normal wf[25:28] was made from (CODE = 5
is no value another model's scratch there takes by chance: hoek-brown keeps projector entries,
within ±1, in wf[12:24]); ``mohr.py``'s cache wf[0:15] is left as it was (the zone-model contract).
"""
import math

from numba import njit

from ..zone_mohr import mohr_constants, mohr_plastic, mohr_scalar
from ._common import (JOINT_SHEAR_NOW, JOINT_TENSION_NOW, P_COHESION, P_OWN, P_TANDIL, P_TANFRIC, P_TENSION,
                      hooke)

NAME = "ubiquitous-joint"
CODE = 5          # kept in save files: never renumber
P_JCOHESION = P_OWN
P_JTANFRIC = P_OWN + 1
P_JTENSION = P_OWN + 2
P_JTANDIL = P_OWN + 3
P_DIP = P_OWN + 4
P_DIPDIR = P_OWN + 5
NCOLS = P_OWN + 6
NHIST = 0
HIST_NAMES = ()
PLASTIC = True

_RAD = math.pi / 180.0


@njit(cache=True, inline="always")
def plane_normal(dip, dipdir):
    """Upward unit normal of the plane with dip and dip direction [degrees] (module text)."""
    d = dip * _RAD
    a = dipdir * _RAD
    sd = math.sin(d)
    return sd * math.sin(a), sd * math.cos(a), math.cos(d)


@njit(cache=True)
def joint_return(s0, s1, s2, s3, s4, s5, nx, ny, nz, K, G, cj, tfj, tenj, tdj):
    """The weak plane's check and return of the stress s0..s5 (xx yy zz xy xz yz) for the plane
    of unit normal n: (bits, t0..t5, μ) with bits 0 / JOINT_SHEAR_NOW / JOINT_TENSION_NOW, the new
    stress and μ = λs tan ψ_j + λt (the mean stress falls by K μ). Strengths: c_j, tan φ_j, the
    joint tension (capped here), tan ψ_j."""
    if tfj > 0.0:
        if cj / tfj < tenj:
            tenj = cj / tfj
    elif cj == 0.0:
        tenj = 0.0
    # traction on the plane, its normal and shear parts
    tx = s0 * nx + s3 * ny + s4 * nz
    ty = s3 * nx + s1 * ny + s5 * nz
    tz = s4 * nx + s5 * ny + s2 * nz
    sig = tx * nx + ty * ny + tz * nz
    ux = tx - sig * nx
    uy = ty - sig * ny
    uz = tz - sig * nz
    tau = math.sqrt(ux * ux + uy * uy + uz * uz)
    fs = tau + sig * tfj - cj
    ft = sig - tenj
    tol = 1e-10 * (abs(sig) + tau + cj + abs(tenj))
    if fs <= tol and ft <= tol:
        return 0, s0, s1, s2, s3, s4, s5, 0.0
    a1 = K + 4.0 * G / 3.0
    a2 = K - 2.0 * G / 3.0
    g2 = 2.0 * G
    taup = cj - tenj * tfj               # the corner's shear stress (>= 0)
    shear_first = fs > tol and fs / math.sqrt(1.0 + tfj * tfj) >= ft
    ls = 0.0
    lt = 0.0
    ok = False
    for attempt in range(3):
        # 0: Itasca's plane; 1: the corner; 2: the other plane
        if attempt == 1:
            ls = (tau - taup) / g2
            lt = (sig - tenj - a1 * tdj * ls) / a1
            ok = ls >= -1e-12 * (abs(tau) + taup) / g2 and lt >= -1e-12 * (abs(sig) + abs(tenj)) / a1
            if ok:
                ls = max(ls, 0.0)
                lt = max(lt, 0.0)
                break
            continue
        use_shear = shear_first if attempt == 0 else not shear_first
        if use_shear:
            ls = fs / (g2 + a1 * tfj * tdj)
            lt = 0.0
            ok = ls > 0.0 and tau - g2 * ls >= -tol and sig - a1 * tdj * ls - tenj <= tol
        else:
            ls = 0.0
            lt = ft / a1
            ok = lt > 0.0 and tau + tenj * tfj - cj <= tol
        if ok:
            break
    if not ok:
        # (not met: the three returns tile the outside of the envelope) the corner, clamped
        ls = max((tau - taup) / g2, 0.0)
        lt = max((sig - tenj - a1 * tdj * ls) / a1, 0.0)
    bits = 0
    if ls > 0.0:
        bits |= JOINT_SHEAR_NOW
    if lt > 0.0:
        bits |= JOINT_TENSION_NOW
    mu = ls * tdj + lt
    iso = -a2 * mu
    nn = -(a1 - a2) * mu
    f = g2 * ls / tau if tau > 0.0 else 0.0       # the fraction of τ taken off
    if f > 1.0:                                     # (never past τ = 0)
        f = 1.0
    s0 += iso + nn * nx * nx - 2.0 * f * ux * nx
    s1 += iso + nn * ny * ny - 2.0 * f * uy * ny
    s2 += iso + nn * nz * nz - 2.0 * f * uz * nz
    s3 += nn * nx * ny - f * (ux * ny + nx * uy)
    s4 += nn * nx * nz - f * (ux * nz + nx * uz)
    s5 += nn * ny * nz - f * (uy * nz + ny * uz)
    return bits, s0, s1, s2, s3, s4, s5, mu


@njit(cache=True)
def update(p, h, z, K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5, tab, wf, mw):
    s0, s1, s2, s3, s4, s5 = hooke(K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5)
    # the matrix: Mohr-Coulomb (as mohr.py)
    coh = p[z, P_COHESION]
    tf = p[z, P_TANFRIC]
    ten = p[z, P_TENSION]
    td = p[z, P_TANDIL]
    # (the constants are made here, not kept in wf[0:15]: that is mohr-coulomb's cache)
    npf, csn, ft, nps, a1, a2, sp, ap, den = mohr_constants(K, G, coh, tf, ten, td)
    code, s0, s1, s2, s3, s4, s5, dp = mohr_scalar(s0, s1, s2, s3, s4, s5, coh, npf, csn, ft, nps, a1, a2, sp,
                                                   ap, den)
    if code < 0:
        s = wf[16:22]
        s[0] = s0; s[1] = s1; s[2] = s2; s[3] = s3; s[4] = s4; s[5] = s5
        code, dp = mohr_plastic(s, K, G, coh, tf, ten, td, mw)
        s0 = s[0]; s1 = s[1]; s2 = s[2]; s3 = s[3]; s4 = s[4]; s5 = s[5]
    # the weak plane
    dip = p[z, P_DIP]
    dd = p[z, P_DIPDIR]
    if wf[22] != CODE or wf[23] != dip or wf[24] != dd:
        nx, ny, nz = plane_normal(dip, dd)
        wf[22] = CODE; wf[23] = dip; wf[24] = dd
        wf[25] = nx; wf[26] = ny; wf[27] = nz
    jb, s0, s1, s2, s3, s4, s5, mu = joint_return(s0, s1, s2, s3, s4, s5, wf[25], wf[26], wf[27], K, G,
                                                  p[z, P_JCOHESION], p[z, P_JTANFRIC], p[z, P_JTENSION],
                                                  p[z, P_JTANDIL])
    return code | jb, s0, s1, s2, s3, s4, s5, dp + K * mu
