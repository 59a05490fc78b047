"""Plane orientation in 3DEC's convention (3DEC 7+): x east, y north, z up.

Dip δ is measured down from the horizontal (0..π/2), dip direction α clockwise from
north (+y) seen from above. The unit normal pointing up out of the plane is

    n = (sin δ sin α, sin δ cos α, cos δ)

and the dip vector (down the line of steepest descent) is
(cos δ sin α, cos δ cos α, −sin δ). Angles are radians here: degrees are converted
where a command reads them.
"""
from __future__ import annotations

import math

import numpy as np

#: components this close to 0 or ±1 come from sin/cos of round angles: snap them
_TRIG_NOISE = 1e-15


def _clean(v: np.ndarray) -> np.ndarray:
    """Remove the trigonometric round-off of multiples of 90°, then renormalise.

    sin(π) is 1.2e-16, not 0: left alone, a vertical joint set would be tilted by that
    much and axis-aligned cuts would not land on round coordinates.
    """
    v = np.array(v, dtype=np.float64)
    v[np.abs(v) < _TRIG_NOISE] = 0.0
    return v / np.linalg.norm(v)


def dip_normal(dip: float, dip_direction: float) -> np.ndarray:
    """Unit upward normal (3,) of a plane with the given dip and dip direction [rad]."""
    sd, cd = math.sin(dip), math.cos(dip)
    sa, ca = math.sin(dip_direction), math.cos(dip_direction)
    return _clean(np.array([sd * sa, sd * ca, cd]))


def dip_vector(dip: float, dip_direction: float) -> np.ndarray:
    """Unit vector (3,) pointing down the dip of the plane (also a tunnel's axis)."""
    sd, cd = math.sin(dip), math.cos(dip)
    sa, ca = math.sin(dip_direction), math.cos(dip_direction)
    return _clean(np.array([cd * sa, cd * ca, -sd]))


def normal_to_dip(normal) -> tuple[float, float]:
    """Dip and dip direction [rad] of the plane with the given normal (either sign)."""
    n = np.asarray(normal, dtype=np.float64)
    n = n / np.linalg.norm(n)
    if n[2] < 0:
        n = -n
    dip = math.acos(min(1.0, n[2]))
    dd = math.atan2(n[0], n[1]) % (2 * math.pi) if dip > 0 else 0.0
    return dip, dd


def plane_basis(normal) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors (3,) spanning the plane normal to ``normal``, right-handed with it."""
    n = np.asarray(normal, dtype=np.float64)
    n = n / np.linalg.norm(n)
    helper = np.array([0.0, 0.0, 1.0]) if abs(n[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    u = np.cross(helper, n)
    u /= np.linalg.norm(u)
    return u, np.cross(n, u)
