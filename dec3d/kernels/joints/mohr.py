"""Joint model ``mohr``: Coulomb slip with tension cut-off; cohesion and tension are lost at the
first failure (residual values then hold), dilation while slipping (3DEC theory Eqs. 33-43,
Eq. 35 as corrected in ERRATA).

  intact: Tmax = −T A (Eq. 34), Fˢmax = c A + Fⁿ tan φ (Eq. 35)
  Fⁿ < Tmax → Fⁿ = Fˢ = 0, failed (Eq. 38); |Fˢ| > Fˢmax → scaled to the limit, failed,
  slipping (Eq. 39); after failure c, T are the residual values (default 0) and φ the residual
  friction (Eqs. 36-37); dilation only while slipping, Δu_dil = ±|ΔUˢ| tan ψ, + when ΔUˢ is along
  the accumulated shear displacement, − against it, none once |uˢ| exceeds the dilation-zero
  limit (0: no limit) (Eqs. 41-43).
"""
from __future__ import annotations

import math

from numba import njit

from ._common import P_KN, P_KS, ST_FAILED, ST_SLIP, ST_TENSION, elastic_trial, slip_dilation

NAME = "mohr"
CODE = 1          # kept in save files: never renumber
LEGACY_CODE = 1   # 3DEC 4/5 `change jcons=1` (dec3d translate)
P_TANF = 2        # tan φ
P_COH = 3         # cohesion c [Pa]
P_TEN = 4         # tensile strength T [Pa]
P_TANDIL = 5      # tan ψ
P_ZDIL = 6        # shear displacement at which dilation stops [m] (0: never)
P_TANF_RES = 7    # residual tan φ (NaN: the peak value)
P_COH_RES = 8     # residual cohesion [Pa]
P_TEN_RES = 9     # residual tensile strength [Pa]
NCOLS = 10
NHIST = 0         # no history beyond the shared sub-contact state
HIST_NAMES = ()


@njit(cache=True, inline="always")
def law(p, c, h, s, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state):
    """Elastic trial, then the Coulomb and tension limits."""
    kn = p[c, P_KN]
    tanf_r = p[c, P_TANF_RES]
    if tanf_r != tanf_r:                   # NaN: residual friction = peak friction
        tanf_r = p[c, P_TANF]
    fn, fs0, fs1, fs2, un, us0, us1, us2 = elastic_trial(kn, p[c, P_KS], area, dun, dus0, dus1, dus2, un, udil,
                                                         fs0, fs1, fs2, us0, us1, us2)
    failed = (state & ST_FAILED) != 0
    coh = p[c, P_COH_RES] if failed else p[c, P_COH]
    t = p[c, P_TEN_RES] if failed else p[c, P_TEN]
    tf = tanf_r if failed else p[c, P_TANF]
    state = state & ~(ST_SLIP | ST_TENSION)
    if fn < -t * area:                     # Eq. (38): tensile failure
        return 0.0, 0.0, 0.0, 0.0, un, udil, us0, us1, us2, state | ST_FAILED | ST_TENSION
    fsmax = coh * area + fn * tf           # Eq. (35)
    if fsmax < 0.0:
        fsmax = 0.0
    fsm = math.sqrt(fs0 * fs0 + fs1 * fs1 + fs2 * fs2)
    if fsm > fsmax:                        # Eq. (39): shear failure
        if not failed:
            state = state | ST_FAILED
            fsmax = p[c, P_COH_RES] * area + fn * tanf_r
            if fsmax < 0.0:
                fsmax = 0.0
        r = fsmax / fsm if fsm > 0.0 else 0.0
        fs0 *= r
        fs1 *= r
        fs2 *= r
        state = state | ST_SLIP
        udil, fn = slip_dilation(kn, area, p[c, P_TANDIL], p[c, P_ZDIL], dus0, dus1, dus2, us0, us1, us2, udil, fn)
    return fn, fs0, fs1, fs2, un, udil, us0, us1, us2, state
