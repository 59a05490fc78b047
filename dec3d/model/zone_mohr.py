"""Mohr-Coulomb zone properties: unit conversions and the check before cycling.

``zones.prop`` keeps cohesion [Pa] (``ZP_COHESION``), tensile strength [Pa] (``ZP_TENSION``)
and the *tangents* of the friction and dilation angles (``ZP_TANFRIC``, ``ZP_TANDIL``); users
give the angles in degrees (3DEC/FLAC3D ``friction``, ``dilation``), converted with
``angle_to_tangent``. The elastic columns (bulk, shear, density) must be set as for elastic
zones; the check covers them too.

Rules (Itasca, FLAC3D/3DEC "Mohr-Coulomb Model" page,
https://docs.itascacg.com/itasca920/common/models/mohr/doc/modelmohr.html): cohesion >= 0,
0 <= friction < 90 degrees, 0 <= dilation <= friction (the non-associated flow rule with
psi <= phi; psi = phi is associated), tension >= 0. A tensile strength above the apex of the
shear cone, c / tan(phi), is not an error: the model uses the apex value instead (Itasca's
sigma_t_max) and the check says so as a warning.
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import Dec3dError
from .zones import ZP_BULK, ZP_COHESION, ZP_DENSITY, ZP_SHEAR, ZP_TANDIL, ZP_TANFRIC, ZP_TENSION


def angle_to_tangent(deg) -> np.ndarray | float:
    """tan of an angle given in degrees (``friction``/``dilation`` keywords -> prop columns).
    Raises ValueError outside 0 <= deg < 90 (the command layer reports it with its location)."""
    a = np.asarray(deg, dtype=float)
    if not np.all(np.isfinite(a)) or np.any(a < 0.0) or np.any(a >= 90.0):
        raise ValueError(f"angle must be at least 0 and less than 90 degrees (got {deg})")
    t = np.tan(np.radians(a))
    return float(t) if t.ndim == 0 else t


def tangent_to_angle(t) -> np.ndarray | float:
    """The inverse, for listing: degrees from a tangent column."""
    a = np.degrees(np.arctan(np.asarray(t, dtype=float)))
    return float(a) if a.ndim == 0 else a


def _which(ids, bad: np.ndarray) -> str:
    rows = np.flatnonzero(bad)
    shown = ", ".join(str(int(ids[r])) for r in rows[:5])
    more = f" and {len(rows) - 5} more" if len(rows) > 5 else ""
    return f"{len(rows)} zone(s) ({shown}{more})"


def mohr_props_check(prop_rows: np.ndarray, ids=None, error=Dec3dError) -> list[str]:
    """Check the Mohr-Coulomb columns of ``prop_rows`` (n, NZPROP), one row per Mohr-Coulomb
    zone; ``ids`` (n,) the zone ids used in messages (default 1..n). Raises ``error`` (a
    Dec3dError subclass, e.g. the engine's RunError) naming the zones and the property for:
    bulk, shear or density not > 0 (the elastic part), cohesion < 0, friction < 0 or >= 90 degrees (tangent negative, infinite or NaN), dilation < 0
    or above friction, tension < 0, any value not finite. Returns warnings (strings) for
    tensions above c / tan(phi) (the model uses the apex value)."""
    p = np.atleast_2d(np.asarray(prop_rows, dtype=float))
    ids = np.arange(1, len(p) + 1) if ids is None else np.asarray(ids)
    c, tf, t, td = p[:, ZP_COHESION], p[:, ZP_TANFRIC], p[:, ZP_TENSION], p[:, ZP_TANDIL]
    problems = []
    for name, col in (("bulk", ZP_BULK), ("shear", ZP_SHEAR), ("density", ZP_DENSITY)):
        bad = ~np.isfinite(p[:, col]) | (p[:, col] <= 0.0)
        if bad.any():
            problems.append(f"{name} must be > 0: {_which(ids, bad)}")
    for name, col, rule in (("cohesion", c, "must be a finite value >= 0 Pa"),
                            ("tension", t, "must be a finite value >= 0 Pa"),
                            ("friction", tf, "must be at least 0 and less than 90 degrees"),
                            ("dilation", td, "must be at least 0 and less than 90 degrees")):
        bad = ~np.isfinite(col) | (col < 0.0)
        if bad.any():
            problems.append(f"{name} {rule}: {_which(ids, bad)}")
    if not problems:
        bad = td > tf * (1.0 + 1e-12)
        if bad.any():
            problems.append(f"dilation must not exceed friction: {_which(ids, bad)}")
    if problems:
        raise error("Mohr-Coulomb zone properties: " + "; ".join(problems)
                    + " (set them with `block zone property cohesion|friction|tension|dilation`)")
    warnings = []
    with np.errstate(divide="ignore"):
        apex = np.where(tf > 0.0, c / np.where(tf > 0.0, tf, 1.0), math.inf)
    over = t > apex
    if over.any():
        warnings.append(f"tension above c/tan(friction) in {_which(ids, over)}: the apex value c/tan(friction) "
                        "is used as the tensile strength")
    return warnings
