"""What every joint-law kernel shares: the property columns every model has, the sub-contact
state bits, and the elastic trial step (3DEC theory Eqs. 24-27).

A joint model's kernel file (a sibling of this one, see ``__init__``) reads its own columns
from the property row; columns 0 and 1 are the stiffnesses of every model (the time step and
the density scaling read them as the stiffness of a model that has no ``stiffness`` hook)."""
from __future__ import annotations

import math

from numba import njit

P_KN = 0          # normal stiffness kn [Pa/m]
P_KS = 1          # shear stiffness ks [Pa/m]

ST_FAILED = 1
ST_SLIP = 2
ST_TENSION = 4
#: set on a sub-contact made at a detection: its uⁿ is its own gap at the current positions,
#: which already hold the motion of the step just taken, so its first update adds no
#: displacement increment (cleared by that update, before the law is called)
ST_NEW = 8

#: history columns of every sub-contact (``subcontacts.hist``): a model uses the first ``NHIST``
NJHIST = 8


@njit(cache=True, inline="always")
def slip_dilation(kn, area, tandil, zdil, dus0, dus1, dus2, us0, us1, us2, udil, fn):
    """Dilation of a slipping sub-contact (3DEC theory Eqs. 41-43): Δu_dil = ±|ΔUˢ| tan ψ, + when
    ΔUˢ is along the accumulated shear displacement uˢ, − against it, none once |uˢ| exceeds the
    dilation-zero limit ``zdil`` (0: no limit); the normal force grows by kn A Δu_dil.
    Returns (udil, fn)."""
    dmag = math.sqrt(dus0 * dus0 + dus1 * dus1 + dus2 * dus2)
    if tandil != 0.0 and dmag > 0.0:
        usm = math.sqrt(us0 * us0 + us1 * us1 + us2 * us2)
        if zdil <= 0.0 or usm <= zdil:
            sgn = 1.0 if (dus0 * us0 + dus1 * us1 + dus2 * us2) >= 0.0 else -1.0
            ddil = sgn * dmag * tandil     # Eq. (42), direction-dependent
            udil += ddil
            fn += kn * area * ddil         # Eq. (43)
    return udil, fn


@njit(cache=True, inline="always")
def constant_stiffness(p, c, h, s):
    """The stiffness of a model that has no hook of its own: columns 0, 1 of its row [Pa/m]."""
    return p[c, P_KN], p[c, P_KS]


@njit(cache=True, inline="always")
def elastic_trial(kn, ks, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2):
    """Accumulate the displacements and take the elastic force increment: uⁿ += ΔUⁿ, uˢ += ΔUˢ,
    Fˢ −= ks A ΔUˢ (Eqs. 25, 27), Fⁿ = −kn A (uⁿ − u_dil) (Eq. 24 integrated; compression
    positive). Returns (Fn, Fs0, Fs1, Fs2, un, us0, us1, us2)."""
    un += dun
    us0 += dus0
    us1 += dus1
    us2 += dus2
    fs0 -= ks * area * dus0
    fs1 -= ks * area * dus1
    fs2 -= ks * area * dus2
    fn = -kn * area * (un - udil)
    return fn, fs0, fs1, fs2, un, us0, us1, us2
