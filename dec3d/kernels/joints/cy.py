"""Joint model ``cyjm`` (also ``cy``): the continuously yielding joint model of 3DEC (Cundall & Hart 1984; Cundall &
Lemos 1990, "Numerical analysis of fault instabilities due to stick-slip", in *Mechanics of Jointed
and Faulted Rock*, Balkema, 97-100), as the 3DEC manual describes it: page "Continuously Yielding
Joint Model In 3DEC" (3DEC Theory, joint constitutive models), summarised on
https://www.itascacg.com/3dec-joint-constitutive-models ("3DEC Joint Constitutive Models").
(The theory page itself was not in the reference store; the equations below are the ones of the
published model.)

Stiffness growing with the normal stress (the manual's form):

  kn = a_n σn^e_n,   ks = a_s σn^e_s                                   (a_n, a_s: columns 0, 1)

Normal stress: dσn = kn d(closure) integrated from zero stress at zero closure, so that the joint
is elastic (path-independent) in its normal direction and re-closes where it opened:

  σn = ((1 − e_n) a_n v)^(1/(1 − e_n)),   v = −(uⁿ − u_dil) ≥ 0      (e_n < 1; e_n = 0: σn = a_n v)

(capped at 10³⁰ Pa, so that e_n near 1 cannot overflow to an infinite force).

The joint carries no tension: v ≤ 0 gives σn = 0 and no shear force.

Shear (3DEC/UDEC continuously yielding law), per step, with τ the shear stress along the shear
increment Δuˢ (the stress acting against the motion, |τ| the magnitude of Fˢ/A):

  Δτ = F ks |Δuˢ|,  F = (1 − τ/τm)/(1 − r)  clamped to [0, 1],  τm = σn tan φm
  Δuᵖ = (1 − F)|Δuˢ|                                    (plastic shear displacement)
  dφm = −(φm − φ) duᵖ / R                                (R: roughness, a length)

The last is integrated exactly: φm = φ + (φ0 − φ) exp(−uᵖ/R), so the mobilised friction φm is a
function of the accumulated plastic shear displacement alone (φ0: the initial friction ``friction-initial``,
φ: the intrinsic friction ``friction``). r is 0 at first and is reset to τ/τm when the
shear increment reverses (its dot product with the previous one is negative), so a reversal
starts elastically (F = 1). The stress vector is incremented along Δuˢ: Fˢ −= F ks A Δuˢ.

Our choice where the published law leaves it open: |τ| never exceeds τm. Once τ meets the bound
(the peak: τm falls with φm while τ rises toward it) the stress stays on τm(uᵖ) with F = 0 and
Δuᵖ = |Δuˢ|, and a stress above τm (σn falling) is scaled back to it. Unclamped, F < 0 would let
τ lag above the falling bound (by ~|dτm/du|/ks: 40 % for R = 0.5 mm, ks = 1 GPa/m) with Δuᵖ > |Δuˢ|.

Not implemented: the model's dilation (the normal displacement of the roughness); u_dil is
passed through unchanged. No ``stiffness_bound``: kn = a_n σn^e_n has no largest value short of the
σn cap (10³⁰ Pa), and 3DEC's keywords give no largest normal stress; a load put at once on a joint at
zero stress (kn = 0: the automatic step then follows columns 0, 1, the multipliers a_n, a_s) still
needs `block mechanical timestep` set for the stiffest state the deck reaches (J1 does).

History h[s, :7]: plastic shear displacement uᵖ [m], normal stress σn [Pa], mobilised friction
φm [deg] (the one this step's bound used: from uᵖ before the step; output only), the factor r,
and the unit direction of the previous shear increment (3 components).
"""
from __future__ import annotations

import math

from numba import njit

from ._common import P_KN, P_KS, ST_SLIP

NAME = "cyjm"       # 3DEC's name (its command reference: `block contact jmodel assign cyjm`)
CODE = 2          # kept in save files: never renumber
P_EN = 2          # exponent e_n of the normal stiffness
P_ES = 3          # exponent e_s of the shear stiffness
P_PHI0 = 4        # initial (mobilised) friction φ0 [rad] (NaN: φ, no softening)
P_PHI = 5         # intrinsic friction φ [rad]
P_R = 6           # roughness R [m]
NCOLS = 7
H_UP = 0          # plastic shear displacement [m]
H_SN = 1          # normal stress [Pa]
H_PHIM = 2        # mobilised friction [deg] (output)
H_R = 3           # factor r
H_D0 = 4          # previous shear increment direction, x, y, z
NHIST = 7
#: the normal stress is capped here [Pa] (finite forces for any closure; e_n → 1 makes the power law
#: overflow: with e_n = 0.99 it is (0.01 a_n v)^100)
SN_MAX = 1e30
LOG_SN_MAX = math.log(SN_MAX)
HIST_NAMES = ("plastic-shear", "normal-stress", "friction-mobilized", "reversal-factor",
              "increment-x", "increment-y", "increment-z")


@njit(cache=True, inline="always")
def normal_stress(an, en, v):
    """σn at closure v ≥ 0: the integral of dσ/dv = a_n σ^e_n from σ = 0 at v = 0."""
    if v <= 0.0:
        return 0.0
    if en == 0.0:
        return an * v
    x = (1.0 - en) * an * v
    if x <= 0.0:
        return 0.0
    y = math.log(x) / (1.0 - en)
    if y > LOG_SN_MAX:                     # e_n near 1: the power overflows long before this matters
        return SN_MAX
    return math.exp(y)


@njit(cache=True, inline="always")
def mobilised_friction(p, c, up):
    """φm [rad] after plastic shear displacement up: φ + (φ0 − φ) exp(−up/R)."""
    phi0 = p[c, P_PHI0]
    phi = p[c, P_PHI]
    if phi0 != phi0:                       # NaN: initial friction = intrinsic friction (no softening)
        phi0 = phi
    rr = p[c, P_R]
    if rr > 0.0:
        return phi + (phi0 - phi) * math.exp(-up / rr)
    return phi if up > 0.0 else phi0


@njit(cache=True, inline="always")
def stiffness(p, c, h, s):
    """Current tangent stiffnesses a_n σn^e_n, a_s σn^e_s at the stored normal stress [Pa/m]."""
    sn = h[s, H_SN]
    if sn < 0.0:
        sn = 0.0
    return p[c, P_KN] * sn ** p[c, P_EN], p[c, P_KS] * sn ** p[c, P_ES]


@njit(cache=True, inline="always")
def law(p, c, h, s, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state):
    """Normal stress from the closure, then the continuously yielding shear increment."""
    un += dun
    us0 += dus0
    us1 += dus1
    us2 += dus2
    state = state & ~ST_SLIP
    sn = normal_stress(p[c, P_KN], p[c, P_EN], -(un - udil))
    h[s, H_SN] = sn
    up = h[s, H_UP]
    phim = mobilised_friction(p, c, up)
    h[s, H_PHIM] = math.degrees(phim)
    if sn <= 0.0 or area <= 0.0:           # open (or no area): carries nothing
        return 0.0, 0.0, 0.0, 0.0, un, udil, us0, us1, us2, state
    es = p[c, P_ES]
    ks = p[c, P_KS] * sn ** es if es != 0.0 else p[c, P_KS]
    taum = sn * math.tan(phim)
    # shear stress acting against the motion (Fˢ is the force on B, Fˢ = −ks A uˢ elastically)
    t0 = -fs0 / area
    t1 = -fs1 / area
    t2 = -fs2 / area
    dmag = math.sqrt(dus0 * dus0 + dus1 * dus1 + dus2 * dus2)
    if dmag > 0.0:
        d0 = dus0 / dmag
        d1 = dus1 / dmag
        d2 = dus2 / dmag
        tpar = t0 * d0 + t1 * d1 + t2 * d2
        r = h[s, H_R]
        if d0 * h[s, H_D0] + d1 * h[s, H_D0 + 1] + d2 * h[s, H_D0 + 2] < 0.0:      # reversal
            r = tpar / taum if taum > 0.0 else 0.0
        f = 0.0
        if taum > 0.0:
            den = 1.0 - r
            if den < 1e-12:
                den = 1e-12
            f = (1.0 - tpar / taum) / den
        if f > 1.0:
            f = 1.0
        elif f < 0.0:
            f = 0.0
        t0 += f * ks * dus0
        t1 += f * ks * dus1
        t2 += f * ks * dus2
        up += (1.0 - f) * dmag
        h[s, H_UP] = up
        h[s, H_R] = r
        h[s, H_D0] = d0
        h[s, H_D0 + 1] = d1
        h[s, H_D0 + 2] = d2
        if f < 1.0:
            state = state | ST_SLIP
    tm = math.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
    if tm > taum:                          # never beyond the bounding strength
        k = taum / tm
        t0 *= k
        t1 *= k
        t2 *= k
        state = state | ST_SLIP
    return sn * area, -t0 * area, -t1 * area, -t2 * area, un, udil, us0, us1, us2, state
