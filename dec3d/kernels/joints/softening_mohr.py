"""Joint model ``softening-mohr``: 3DEC's Softening-Healing Mohr-Coulomb joint model — the Coulomb
strength falls from peak to residual over a critical slip distance and returns to peak when slipping
stops; tension cut-off with no softening and no healing; dilation as ``mohr``.

Source: Itasca, "Softening-Healing Mohr-Coulomb Joint Model In 3DEC", 3DEC theory manual,
https://docs.itascacg.com/itasca900/3dec/docproject/source/theory/softhealmc/softhealmc.html
(also https://docs.itascacg.com/3dec700/3dec/docproject/source/theory/softhealmc/softhealmc.html and
Itasca Denver, "New Joint Models", https://www.itascadenver.com/software/new-joint-models):
"When the joint starts slipping, the shear strength evolves from the peak value to the residual
value over a user-specified critical slip distance D_c. When slipping stops, the shear strength
recovers instantaneously to the peak value ... There is no softening or healing for the tensile
forces. The tensile strength drops instantaneously when the strength is exceeded ... and remains at
the residual value". Linear softening (the page's first formulation):

  S_F = S_peak − (S_peak − S_resid) u_s^p / D_c   for u_s^p < D_c,   S_resid beyond,
  S_peak = c A + Fⁿ tan φ,  S_resid = c_r A + Fⁿ tan φ_r   (in force: stresses × A)

with u_s^p "the plastic shear displacement (slip) since the start of slipping", set back to 0 when
slipping stops (healing on, the default; off: u_s^p is kept and keeps growing with later slip).
The page's second, non-linear formulation (exponent `alpha`) is not implemented: its formula is not
in the text we could read; `alpha` is therefore not a property of this model.

Explicit update, one step: the limit is S_F at the slip reached before the step; the plastic slip of
the step is the excess of the elastic trial over it, (|Fˢ_trial| − S_F)/(ks A); u_s^p grows by that.
The energy dissipated by a slip Δ is then ∫ S_F du over it to within one step's slip.

Tension: T before any failure, the residual T_r after the first (tensile or shear) failure, as
``mohr`` (3DEC theory Eqs. 36-38). An open joint carries nothing and is not slipping: it heals.

Dilation: as ``mohr`` (only while slipping, up to `dilation-zero`). Itasca Denver's page says "Dilation (ψ)
behaves in the same way as cohesion or friction", but the model has no residual dilation keyword to soften
towards, so ψ is kept constant here.

History h[s, 0]: u_s^p [m] ("slip", the page's read-only `slip`; the page's other read-only value,
`friction-current`, is not kept: it is atan of the interpolated tan φ at that slip).
"""
from __future__ import annotations

import math

from numba import njit

from ._common import P_KN, P_KS, ST_FAILED, ST_SLIP, ST_TENSION, elastic_trial, slip_dilation

NAME = "softening-mohr"
CODE = 4          # kept in save files: never renumber
LEGACY_CODE = 2   # 3DEC 4/5 `change jcons=2` (dec3d translate)
P_TANF = 2        # tan φ (peak)
P_TANF_RES = 3    # residual tan φ (NaN: the peak value)
P_COH = 4         # peak cohesion c [Pa]
P_COH_RES = 5     # residual cohesion c_r [Pa]
P_TEN = 6         # tensile strength T [Pa]
P_TEN_RES = 7     # residual tensile strength T_r [Pa]
P_TANDIL = 8      # tan ψ
P_ZDIL = 9        # shear displacement at which dilation stops [m] (0: never)
P_DC = 10         # critical slip distance D_c [m] (> 0; NaN until set)
P_HEAL = 11       # healing: 1 on (default), 0 off
NCOLS = 12
H_SLIP = 0        # u_s^p [m]
NHIST = 1
HIST_NAMES = ("slip",)


@njit(cache=True, inline="always")
def law(p, c, h, s, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state):
    """Elastic trial, then the tension limit and the softened Coulomb limit."""
    kn = p[c, P_KN]
    ks = p[c, P_KS]
    tf = p[c, P_TANF]
    tfr = p[c, P_TANF_RES]
    if tfr != tfr:                         # NaN: residual friction = peak friction
        tfr = tf
    heal = p[c, P_HEAL] != 0.0
    fn, fs0, fs1, fs2, un, us0, us1, us2 = elastic_trial(kn, ks, area, dun, dus0, dus1, dus2, un, udil,
                                                         fs0, fs1, fs2, us0, us1, us2)
    failed = (state & ST_FAILED) != 0
    t = p[c, P_TEN_RES] if failed else p[c, P_TEN]
    state = state & ~(ST_SLIP | ST_TENSION)
    up = h[s, H_SLIP]
    if fn < -t * area:                     # tensile failure: no softening, no healing of T
        if heal and up != 0.0:
            h[s, H_SLIP] = 0.0
        return 0.0, 0.0, 0.0, 0.0, un, udil, us0, us1, us2, state | ST_FAILED | ST_TENSION
    coh = p[c, P_COH]
    tfu = tf
    if up > 0.0:                           # softened: r of the way to residual, all of it from D_c on
        dc = p[c, P_DC]
        r = up / dc if up < dc else 1.0    # (a D_c not > 0: at the first slip)
        coh += (p[c, P_COH_RES] - coh) * r
        tfu += (tfr - tf) * r
    fsmax = coh * area + fn * tfu
    if fsmax < 0.0:
        fsmax = 0.0
    fsm = math.sqrt(fs0 * fs0 + fs1 * fs1 + fs2 * fs2)
    if fsm <= fsmax:                       # not slipping: the strength heals to peak
        if heal and up != 0.0:
            h[s, H_SLIP] = 0.0
        return fn, fs0, fs1, fs2, un, udil, us0, us1, us2, state
    kA = ks * area
    if kA > 0.0:
        h[s, H_SLIP] = up + (fsm - fsmax) / kA
    rr = fsmax / fsm
    fs0 *= rr
    fs1 *= rr
    fs2 *= rr
    state = state | ST_SLIP | ST_FAILED
    udil, fn = slip_dilation(kn, area, p[c, P_TANDIL], p[c, P_ZDIL], dus0, dus1, dus2, us0, us1, us2, udil, fn)
    return fn, fs0, fs1, fs2, un, udil, us0, us1, us2, state
