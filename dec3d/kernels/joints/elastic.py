"""Joint model ``elastic``: linear elastic joint that carries no tension (3DEC's ``elastic``)."""
from __future__ import annotations

from numba import njit

from ._common import P_KN, P_KS, ST_SLIP, elastic_trial

NAME = "elastic"
CODE = 0          # kept in save files: never renumber
NCOLS = 2         # property columns read: kn, ks
NHIST = 0
HIST_NAMES = ()


@njit(cache=True, inline="always")
def law(p, c, h, s, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state):
    """Elastic trial; an opening joint (tensile normal force) carries nothing."""
    fn, fs0, fs1, fs2, un, us0, us1, us2 = elastic_trial(p[c, P_KN], p[c, P_KS], area, dun, dus0, dus1, dus2, un,
                                                         udil, fs0, fs1, fs2, us0, us1, us2)
    if fn < 0.0:
        return 0.0, 0.0, 0.0, 0.0, un, udil, us0, us1, us2, state & ~ST_SLIP
    return fn, fs0, fs1, fs2, un, udil, us0, us1, us2, state & ~ST_SLIP
