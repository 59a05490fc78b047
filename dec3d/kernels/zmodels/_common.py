"""What every zone-model kernel shares: the shared property columns, plastic-state bits, the
tables bundle and its interpolation, the scratch sizes.

Property columns 0-7 mean the same for every model (the moduli, density and the Mohr-Coulomb
strength, which several models read); columns from ``P_OWN`` on are each model's own (the same
column means different things in different models, as joint-model columns do).
"""
from __future__ import annotations

from collections import namedtuple

import numpy as np
from numba import njit

from ..zones import (JOINT_SHEAR_NOW, JOINT_SHEAR_PAST, JOINT_TENSION_NOW, JOINT_TENSION_PAST,  # noqa: F401
                     SHEAR_NOW, SHEAR_PAST, TENSION_NOW, TENSION_PAST)

#: shared property columns of ``zones.prop`` (SI; angles kept as tangents)
P_BULK = 0
P_SHEAR = 1
P_DENSITY = 2
P_COHESION = 3
P_TANFRIC = 4
P_TENSION = 5
P_TANDIL = 6
#: strength-reduction factor F of ``model factor-of-safety`` for models whose strengths come from
#: tables (0 or 1: none); models with constant strengths are reduced in their columns instead
P_SRF = 7
#: first column a model may use for its own properties
P_OWN = 8
#: columns of ``zones.prop``
NZPROP = 20
#: history entries per zone (``zones.hist``); a model uses the first NHIST
NZHIST = 4
#: per-chunk float scratch handed to ``update`` (``wf``): kept between the zones of one chunk
NWORK = 32

#: plastic-state bits (``zones.state``, defined in ``kernels/zones.py``): a model's update returns
#: "now" bits; the step keeps the "past" bits (now << 2) as well (``merge_state``)
PAST = SHEAR_PAST | TENSION_PAST | JOINT_SHEAR_PAST | JOINT_TENSION_PAST

#: the tables a model may read (``table`` command), flattened: table t has points
#: (x[start[t] + i], y[start[t] + i]) for i < count[t], x increasing. A property column names a
#: table as t + 1 (0: no table).
Tables = namedtuple("Tables", "x y start count")


def no_tables() -> Tables:
    """An empty tables bundle (typed as the engine's)."""
    return Tables(np.zeros(0), np.zeros(0), np.zeros(0, np.int64), np.zeros(0, np.int64))


def make_tables(points) -> Tables:
    """Tables bundle from a list of (xs, ys) sequences (each with increasing xs)."""
    counts = np.array([len(xs) for xs, _ in points], np.int64)
    start = np.zeros(len(points), np.int64)
    if len(points):
        start[1:] = np.cumsum(counts)[:-1]
    x = np.concatenate([np.asarray(xs, float) for xs, _ in points]) if points else np.zeros(0)
    y = np.concatenate([np.asarray(ys, float) for _, ys in points]) if points else np.zeros(0)
    return Tables(np.ascontiguousarray(x), np.ascontiguousarray(y), start, counts)


@njit(cache=True, inline="always")
def table_value(tab, t, xq):
    """Table t (0-based) at xq: linear interpolation between its points, the end values held
    outside them (as FISH's ``table(t, x)``); 0 for an empty table."""
    n = tab.count[t]
    if n == 0:
        return 0.0
    b = tab.start[t]
    x = tab.x
    y = tab.y
    if xq <= x[b]:
        return y[b]
    if xq >= x[b + n - 1]:
        return y[b + n - 1]
    lo = 0
    hi = n - 1
    while hi - lo > 1:                 # x[b+lo] < xq < x[b+hi]
        mid = (lo + hi) // 2
        if x[b + mid] <= xq:
            lo = mid
        else:
            hi = mid
    x0 = x[b + lo]
    x1 = x[b + hi]
    return y[b + lo] + (y[b + hi] - y[b + lo]) * (xq - x0) / (x1 - x0)


@njit(cache=True, inline="always")
def merge_state(old, now):
    """New ``zones.state``: the now bits of this step, the past bits of before and of now."""
    return (old & PAST) | now | (now << 2)


@njit(cache=True, inline="always")
def hooke(K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5):
    """s + D : d for isotropic elasticity (3DEC text Eq. 59 with the three-term Δε_v of the
    errata; d3..d5 tensor shear components)."""
    ev = d0 + d1 + d2
    lam = K - 2.0 * G / 3.0
    s0 += lam * ev + 2.0 * G * d0
    s1 += lam * ev + 2.0 * G * d1
    s2 += lam * ev + 2.0 * G * d2
    s3 += 2.0 * G * d3
    s4 += 2.0 * G * d4
    s5 += 2.0 * G * d5
    return s0, s1, s2, s3, s4, s5
