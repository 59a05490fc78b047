"""Pore pressure in the joints (3DEC's `block water …` and `block contact apply pore-pressure`).

Every sub-contact carries a pore pressure ``pp`` [Pa] (sub-contact field; positive pushes the two
blocks apart). As in 3DEC the contact forces the joint laws keep (``fn``, ``fs``) are *effective*:
the pressure acts on the two faces as a force of its own, F = p·A′ along the contact normal (on B
along n, on A the negative; field ``ppf``), added to each sub-contact's force on B after its joint law
(``kernels.water.pore_forces`` in the rigid cycle, ``kernels.water.mixed_pore_forces`` where a zoned
side takes it on its gridpoints). So every joint model works on σn′ = σn − p without knowing
it: at equilibrium the load on the joint is carried by fn + p·A′, and the joint opens when p reaches
the total normal stress (σn′ = 0). A′ (``kernels.water.pressure_areas``) are the weights of the exact
integral of a linearly varying pressure over the contact polygon; the sub-contacts' own areas (lumps
of the joint stiffness) are not, and gave a crack's water force 45 % high. A pressure that is not
linear over one contact (a water table crossing it) is sampled at the points: cut the blocks at the
water line for an exact force.

The pressure is worked out from its sources, never carried as state of its own (so a sub-contact
made again at a detection gets the same pressure as the one it replaces):

    p(s) = ρw |g| h(s)  +  p_apply(contact of s)

with h the depth of the sub-contact's point below the water table along gravity (`block water
plane normal … origin …`, `block water density ρw`; zero above the table), plus p0 + g·x where
`block insitu pore-pressure p0 gradient g` was given, and p_apply the sum of
the `block contact apply pore-pressure` values given to the contact (contact field ``pp_apply``,
carried by the pair through detections). ``refresh`` writes ``pp`` from these after every detection
and whenever a source changes; it is a no-op (and ``pp`` stays zero) while the model has no water.
Settings: ``model.settings.mechanical["water"]`` = {"density": ρw, "plane": [nx, ny, nz, ox, oy, oz]
or None} (plain JSON, saved with the model).
"""
from __future__ import annotations

import numpy as np

from dec3d.errors import CommandError
from dec3d.kernels.water import pressure_areas
from dec3d.units import suffix


def water_settings(model) -> dict:
    """The model's water settings (made empty on first use)."""
    mech = model.settings.mechanical
    w = mech.get("water")
    if not isinstance(w, dict):
        w = mech["water"] = {"density": 0.0, "plane": None}
    return w


def has_water(model) -> bool:
    """Whether any pressure source is defined (a water table or applied contact pressures)."""
    w = model.settings.mechanical.get("water")
    if isinstance(w, dict) and (w.get("plane") is not None or w.get("applied") or w.get("insitu")):
        return True
    return False


def table_pressure(pos, density, plane, gravity) -> np.ndarray:
    """ρw |g| h at points pos (k, 3): h the distance along gravity from the point up to the water
    table (the plane through o with normal n), zero above it. A table along gravity (n ⟂ g) or no
    gravity gives zero everywhere."""
    pos = np.asarray(pos, dtype=np.float64).reshape(-1, 3)
    g = np.asarray(gravity, dtype=np.float64)
    gm = float(np.linalg.norm(g))
    if plane is None or gm == 0.0 or density <= 0.0:
        return np.zeros(len(pos))
    n = np.asarray(plane[:3], dtype=np.float64)
    n = n / np.linalg.norm(n)
    o = np.asarray(plane[3:], dtype=np.float64)
    up = -g / gm
    cos = float(n @ up)
    if abs(cos) < 1e-12:
        return np.zeros(len(pos))
    h = ((o - pos) @ n) / cos            # x + h·up lies on the plane
    return density * gm * np.maximum(h, 0.0)


def refresh(eng) -> None:
    """Write every sub-contact's ``pp`` from the sources (module docstring). Called after every
    detection and by the commands that change a source."""
    m = eng.model
    ss = eng.subcontacts
    if "fluid" in m.settings.configure:
        from .flownet import active, after_detection
        if active(m):
            after_detection(eng)        # (the flow knots' pressures: physics.flownet)
            return
        if "pp" in ss and ss.n:         # (flow switched off: the flow pressures go, the sources' come back)
            ss["pp"][...] = 0.0
            ss["ppf"][...] = 0.0
    if not isinstance(m.settings.mechanical.get("water"), dict):
        return                  # (a dry model: nothing was ever set, the pressures are the fields' zeros)
    if "pp" not in ss or not has_water(m):
        if "pp" in ss and ss.n:
            ss["pp"][...] = 0.0
            ss["ppf"][...] = 0.0
        return
    w = water_settings(m)
    cs = eng.contacts
    p = table_pressure(ss["pos"], float(w.get("density", 0.0)), w.get("plane"), m.settings.gravity)
    ins = w.get("insitu")
    if ins and ss.n:
        p = p + ins[0] + ss["pos"] @ np.asarray(ins[1:], dtype=np.float64)
    if ss.n:
        p = p + cs["pp_apply"][ss["contact"]]
    if not np.all(np.isfinite(p)):
        raise CommandError("a pore pressure is not finite (water density, gravity and table give "
                           f"{p[~np.isfinite(p)][0]!r}): refused before it reaches a contact force")
    ss["pp"][...] = p
    pa = np.empty(ss.n)
    if ss.n:
        pressure_areas(cs["sub_start"], cs["sub_count"], cs["normal"], ss["pos"], ss["area"], pa)
    ss["ppf"][...] = p * pa
    w["stamp"] = _stamp(m)


def _stamp(model) -> list:
    """What the pressures were worked out from (compared by ``refresh_if_stale``)."""
    w = water_settings(model)
    plane = w.get("plane")
    return [float(w.get("density", 0.0)), None if plane is None else [float(x) for x in plane],
            [float(g) for g in model.settings.gravity], int(w.get("applied", 0)), w.get("insitu")]


def refresh_if_stale(eng) -> None:
    """``refresh`` when a source changed since the pressures were last worked out (gravity given
    after the water table, say); called before every run. Otherwise the pressures stay as the last
    detection left them, so a run split in two takes the steps of one run."""
    m = eng.model
    if has_water(m) and water_settings(m).get("stamp") != _stamp(m):
        refresh(eng)


def total_normal_force(ss) -> np.ndarray:
    """fn + p·A′ (the force the two faces push each other with, water included) [N]; fn alone
    while the store has no pressures."""
    if "ppf" not in ss or not ss.n or not np.any(ss["ppf"]):
        return ss["fn"]
    return ss["fn"] + ss["ppf"]


def set_insitu(model, p0: float, gradient) -> None:
    """`block insitu pore-pressure p0 gradient gx gy gz`: p0 + g·x on every sub-contact (taken up by the
    next refresh: before the next cycle, or now if the contacts exist)."""
    g = [0.0, 0.0, 0.0] if gradient is None else [float(x) for x in gradient]
    water_settings(model)["insitu"] = [float(p0)] + g


def describe(model) -> str:
    """`block water list`."""
    w = water_settings(model)
    plane = w.get("plane")
    if plane is None:
        return f"water: density {w.get('density', 0.0):g}{suffix(model, 'density')}, no water table"
    n, o = plane[:3], plane[3:]
    return (f"water: density {w.get('density', 0.0):g}{suffix(model, 'density')}, table through ({o[0]:g}, {o[1]:g}, {o[2]:g}) "
            f"normal ({n[0]:g}, {n[1]:g}, {n[2]:g})")

