"""Joint model ``bilinear-mohr``: 3DEC's Bilinear Mohr-Coulomb joint model — two Coulomb envelopes
for the peak strength and two for the residual strength, each pair switching at a normal-stress
threshold; failure states, tension cut-off and dilation as the ``mohr`` model.

Source: Itasca, "Bilinear Mohr-Coulomb Joint Model In 3DEC", 3DEC theory manual,
https://docs.itascacg.com/itasca900/3dec/docproject/source/theory/bilinear/bilinearmc.html
(also http://docs.itascacg.com/flac3d700/3dec/docproject/source/theory/bilinear/bilinearmc.html):
"two different shear strength envelopes ... the failure envelope changes when a critical level of
normal stress is exceeded. By default, the normal stress threshold is automatically calculated at the
intersection of the two failure envelopes ... Both the peak and residual shear strengths can have
bilinear envelopes and there may be different normal stress thresholds for the peak and the residual
... dilation angle changes when the residual normal stress threshold is exceeded"; "Subcontact
failure state are the same as for the Mohr-Coulomb Joint Model".

  σⁿ = Fⁿ / A (0 when A = 0)
  threshold σᶜ = (c₁ − c₂) / (tan φ₂ − tan φ₁) unless given (`nstress`); +∞ for parallel envelopes
    (envelope 1 everywhere); the residual threshold likewise from the residual envelopes
    (`nstress-residual`)
  intact: Fˢmax = c₁ A + Fⁿ tan φ₁ for σⁿ < σᶜ, c₂ A + Fⁿ tan φ₂ otherwise; Tmax = −T A
  failed (at the first tensile or shear failure, as ``mohr``, 3DEC theory Eqs. 36-39): the
    residual envelopes (c₁ʳ, φ₁ʳ below σᶜʳ, c₂ʳ, φ₂ʳ above) and the residual tension
  dilation while slipping as ``mohr`` (Eqs. 41-43), with ψ₁ below σᶜʳ and ψ₂ above.

Residual friction angles and ψ₂ left unset hold NaN: the kernel reads them as φ₁, φ₂, ψ₁ (the
page's defaults), so setting the peak value later moves them too.
"""
from __future__ import annotations

import math

from numba import njit

from ._common import P_KN, P_KS, ST_FAILED, ST_SLIP, ST_TENSION, elastic_trial, slip_dilation

NAME = "bilinear-mohr"
CODE = 3          # kept in save files: never renumber
P_TANF = 2        # tan φ₁ (below σᶜ)
P_TANF2 = 3       # tan φ₂ (above σᶜ)
P_TANF_RES = 4    # residual tan φ₁ (NaN: tan φ₁)
P_TANF2_RES = 5   # residual tan φ₂ (NaN: tan φ₂)
P_COH = 6         # c₁ [Pa]
P_COH2 = 7        # c₂ [Pa]
P_COH_RES = 8     # residual c₁ [Pa]
P_COH2_RES = 9    # residual c₂ [Pa]
P_TANDIL = 10     # tan ψ₁ (below σᶜʳ)
P_TANDIL2 = 11    # tan ψ₂ (above σᶜʳ; NaN: tan ψ₁)
P_ZDIL = 12       # shear displacement at which dilation stops [m] (0: never)
P_TEN = 13        # tensile strength [Pa]
P_TEN_RES = 14    # residual tensile strength [Pa]
P_NSTRESS = 15    # peak threshold σᶜ [Pa] (NaN: the intersection of the peak envelopes)
P_NSTRESS_RES = 16  # residual threshold σᶜʳ [Pa] (NaN: the intersection of the residual envelopes)
NCOLS = 17
NHIST = 0         # the failed bit of the shared state is all the model remembers
HIST_NAMES = ()


@njit(cache=True, inline="always")
def threshold(given, c1, tf1, c2, tf2):
    """The normal stress where envelope 2 takes over [Pa]: ``given`` unless NaN, else where
    c₁ + σ tan φ₁ = c₂ + σ tan φ₂ (the page's σᶜ = (c₁ − c₂)/(tan φ₂ − tan φ₁)); +∞ when the
    envelopes are parallel (envelope 1 holds at every stress)."""
    if given == given:
        return given
    d = tf2 - tf1
    if d == 0.0:
        return math.inf
    return (c1 - c2) / d


@njit(cache=True, inline="always")
def _nan_or(x, fallback):
    return fallback if x != x else x


@njit(cache=True, inline="always")
def law(p, c, h, s, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state):
    """Elastic trial, then the tension limit and the bilinear Coulomb limit in force."""
    kn = p[c, P_KN]
    tf1 = p[c, P_TANF]
    tf2 = p[c, P_TANF2]
    tf1r = _nan_or(p[c, P_TANF_RES], tf1)
    tf2r = _nan_or(p[c, P_TANF2_RES], tf2)
    c1r = p[c, P_COH_RES]
    c2r = p[c, P_COH2_RES]
    fn, fs0, fs1, fs2, un, us0, us1, us2 = elastic_trial(kn, p[c, P_KS], area, dun, dus0, dus1, dus2, un, udil,
                                                         fs0, fs1, fs2, us0, us1, us2)
    failed = (state & ST_FAILED) != 0
    t = p[c, P_TEN_RES] if failed else p[c, P_TEN]
    state = state & ~(ST_SLIP | ST_TENSION)
    if fn < -t * area:                     # tensile failure (as mohr, Eq. 38)
        return 0.0, 0.0, 0.0, 0.0, un, udil, us0, us1, us2, state | ST_FAILED | ST_TENSION
    sn = fn / area if area > 0.0 else 0.0
    snr = threshold(p[c, P_NSTRESS_RES], c1r, tf1r, c2r, tf2r)
    if failed:
        if sn < snr:
            fsmax = c1r * area + fn * tf1r
        else:
            fsmax = c2r * area + fn * tf2r
    else:
        if sn < threshold(p[c, P_NSTRESS], p[c, P_COH], tf1, p[c, P_COH2], tf2):
            fsmax = p[c, P_COH] * area + fn * tf1
        else:
            fsmax = p[c, P_COH2] * area + fn * tf2
    if fsmax < 0.0:
        fsmax = 0.0
    fsm = math.sqrt(fs0 * fs0 + fs1 * fs1 + fs2 * fs2)
    if fsm > fsmax:                        # shear failure (Eq. 39): the residual envelope from now on
        if not failed:
            state = state | ST_FAILED
            if sn < snr:
                fsmax = c1r * area + fn * tf1r
            else:
                fsmax = c2r * area + fn * tf2r
            if fsmax < 0.0:
                fsmax = 0.0
        r = fsmax / fsm if fsm > 0.0 else 0.0
        fs0 *= r
        fs1 *= r
        fs2 *= r
        state = state | ST_SLIP
        tandil = p[c, P_TANDIL]
        if sn >= snr:
            tandil = _nan_or(p[c, P_TANDIL2], tandil)
        udil, fn = slip_dilation(kn, area, tandil, p[c, P_ZDIL], dus0, dus1, dus2, us0, us1, us2, udil, fn)
    return fn, fs0, fs1, fs2, un, udil, us0, us1, us2, state
