"""Joint model ``barton-bandis``: Barton's peak shear strength with Bandis' hyperbolic normal
closure (not a 3DEC built-in; the names are ours).

Peak shear strength (Barton 1973, "Review of a new shear-strength criterion for rock joints",
Eng. Geol. 7, 287-332; Barton & Choubey 1977, "The shear strength of rock joints in theory and
practice", Rock Mech. 10, 1-54):

  τp = σn tan φp,   φp = φr + JRC log10(JCS/σn)   [degrees]

with two limits of the empirical law's range: φp ≤ 70° (Barton & Choubey 1977 cap the peak angle
at 70° for low σn/JCS, where log10(JCS/σn) → ∞ as σn → 0), and the roughness term not below
zero (σn ≥ JCS, beyond the criterion's range: φp = φr).

Post-peak: at the first shear failure of a sub-contact (|τ| > τp) the mobilised roughness drops
to zero at once: the strength becomes the residual σn tan φr (Barton's mobilised JRC at large
displacement), the sub-contact is marked failed and keeps the residual strength after.

Normal closure (Bandis, Lumsden & Barton 1983, "Fundamentals of rock joint deformation",
IJRMMS 20(6), 249-268), the hyperbola

  σn = kni v / (1 − v/vm),   kn = dσn/dv = kni / (1 − v/vm)²

with v = −(uⁿ − u_dil) the closure (≥ 0), kni the initial normal stiffness and vm the maximum
closure. The hyperbola is followed up to v = 0.99 vm (σn = 99 kni vm, kn = 10⁴ kni there) and
continues with that tangent beyond: stress and stiffness stay finite for any closure, and the
closure stays below vm while σn < 199 kni vm; 10⁴ kni is the largest stiffness the law reaches
(``stiffness_bound``: the automatic time step and the mass scaling take it). An open joint
(v ≤ 0) carries nothing; no tensile strength. Shear stiffness ks constant (column 1).
No dilation (u_dil unchanged); JRC, JCS are not scale-corrected (give the field-scale values).

History h[s, :3]: closure v [m], normal stress σn [Pa], mobilised friction angle [deg]
(φp, or φr once failed: the angle the strength uses now).
"""
from __future__ import annotations

import math

from numba import njit

from ._common import P_KN, P_KS, ST_FAILED, ST_SLIP

NAME = "barton-bandis"
CODE = 6          # kept in save files: never renumber
P_JRC = 2         # joint roughness coefficient JRC
P_JCS = 3         # joint wall compressive strength JCS [Pa]
P_PHIR = 4        # residual friction angle φr [deg]
P_VM = 5          # maximum closure vm [m]
NCOLS = 6
H_V = 0
H_SN = 1
H_PHI = 2
NHIST = 3
HIST_NAMES = ("closure", "normal-stress", "friction-mobilized")
#: closure followed on the hyperbola, as a fraction of vm
VCAP = 0.99
#: Barton & Choubey's upper limit of the peak friction angle [deg]
PHI_CAP = 70.0


@njit(cache=True, inline="always")
def closure_stress(kni, vm, v):
    """(σn, kn) at closure v: the Bandis hyperbola up to VCAP vm, its tangent there beyond."""
    if v <= 0.0:
        return 0.0, kni
    if not vm > 0.0:                       # no maximum closure given: linear
        return kni * v, kni
    vc = VCAP * vm
    if v <= vc:
        q = 1.0 - v / vm
        return kni * v / q, kni / (q * q)
    q = 1.0 - VCAP
    kc = kni / (q * q)
    return kni * vc / q + kc * (v - vc), kc


@njit(cache=True, inline="always")
def peak_angle(jrc, jcs, phir, sn):
    """φp [deg] = φr + JRC log10(JCS/σn), roughness term ≥ 0, at most 70° (φr if φr is above)."""
    if sn <= 0.0:
        a = PHI_CAP
    else:
        lg = math.log10(jcs / sn) if jcs > 0.0 else 0.0
        if lg < 0.0:
            lg = 0.0
        a = phir + jrc * lg
        if a > PHI_CAP:
            a = PHI_CAP
    if a < phir:
        a = phir
    return a


@njit(cache=True, inline="always")
def stiffness(p, c, h, s):
    """Current kn from the hyperbola at the stored closure, ks constant [Pa/m]."""
    sn, kn = closure_stress(p[c, P_KN], p[c, P_VM], h[s, H_V])
    return kn, p[c, P_KS]


@njit(cache=True, inline="always")
def stiffness_bound(p, c):
    """The largest kn the law reaches: the hyperbola's tangent at VCAP vm, kni/(1 − VCAP)² (10⁴ kni;
    kni without a maximum closure), and ks [Pa/m]: the time step holds for any closure a load reaches."""
    kni = p[c, P_KN]
    if not p[c, P_VM] > 0.0:
        return kni, p[c, P_KS]
    q = 1.0 - VCAP
    return kni / (q * q), p[c, P_KS]


@njit(cache=True, inline="always")
def law(p, c, h, s, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state):
    """Normal stress from the closure; elastic shear trial, limited by the peak (intact) or the
    residual (failed) strength."""
    un += dun
    us0 += dus0
    us1 += dus1
    us2 += dus2
    state = state & ~ST_SLIP
    v = -(un - udil)
    h[s, H_V] = v if v > 0.0 else 0.0
    sn, kn = closure_stress(p[c, P_KN], p[c, P_VM], v)
    h[s, H_SN] = sn
    phir = p[c, P_PHIR]
    failed = (state & ST_FAILED) != 0
    phi = phir if failed else peak_angle(p[c, P_JRC], p[c, P_JCS], phir, sn)
    h[s, H_PHI] = phi
    if sn <= 0.0 or area <= 0.0:           # open: carries nothing
        return 0.0, 0.0, 0.0, 0.0, un, udil, us0, us1, us2, state
    ks = p[c, P_KS]
    fs0 -= ks * area * dus0
    fs1 -= ks * area * dus1
    fs2 -= ks * area * dus2
    fn = sn * area
    fsmax = fn * math.tan(math.radians(phi))
    fsm = math.sqrt(fs0 * fs0 + fs1 * fs1 + fs2 * fs2)
    if fsm > fsmax:
        if not failed:                     # peak passed: the residual strength from this step on
            state = state | ST_FAILED
            h[s, H_PHI] = phir
            fsmax = fn * math.tan(math.radians(phir))
        r = fsmax / fsm
        fs0 *= r
        fs1 *= r
        fs2 *= r
        state = state | ST_SLIP
    return fn, fs0, fs1, fs2, un, udil, us0, us1, us2, state
