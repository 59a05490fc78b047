"""``it.blockarray``: block values of the bound model as numpy arrays, one row per block (row order of
``it.block.list()``; ``ids()`` names the rows).

Getters return read-only views of the model's own arrays (zero copy; ``dec3d.itasca._live.LiveArray``):
they follow the model through `model cycle`, and raise ``StaleError`` once blocks are made or deleted or
the model is replaced (`model new`, `model restore`). Setters take an array of exactly the getter's shape,
numbers only, every value finite. (Itasca's 3DEC has ``itasca.blockarray``; names follow its
``zonearray``/``gridpointarray`` pattern where 3DEC's are not documented.)

=================  ===========  ==========  =======================================
function           shape        dtype       unit / meaning
=================  ===========  ==========  =======================================
ids()              (n,)         int64       block id
pos()              (n, 3)       float64     centroid [m]
vel()              (n, 3)       float64     velocity [m/s]
rvel()             (n, 3)       float64     angular velocity [rad/s]
disp()             (n, 3)       float64     accumulated displacement [m]
vol()              (n,)         float64     volume [m³]
mass()             (n,)         float64     mass [kg]
density()          (n,)         float64     density [kg/m³]
force_app()        (n, 3)       float64     applied force [N]
fixity()           (n,)         uint8       fixity bits (1, 2, 4 velocity; 8, 16, 32 rotation)
hidden()           (n,)         bool        hidden flag
in_group(g, slot)  (n,)         bool        in group g (any slot when slot is None) — a copy
=================  ===========  ==========  =======================================
"""
from __future__ import annotations

import numpy as np

from ._bind import Model
from ._live import LiveArray, live, plain, put
from ._objects import api_of, slot_name


def _v(key: str, model):
    return live(api_of(model), "blocks", key, "blockarray")


def ids(model: Model | None = None) -> LiveArray:
    return _v("id", model)


def pos(model: Model | None = None) -> LiveArray:
    return _v("centroid", model)


def vel(model: Model | None = None) -> LiveArray:
    return _v("velocity", model)


def rvel(model: Model | None = None) -> LiveArray:
    return _v("spin", model)


def disp(model: Model | None = None) -> LiveArray:
    return _v("disp", model)


def vol(model: Model | None = None) -> LiveArray:
    return _v("volume", model)


def mass(model: Model | None = None) -> LiveArray:
    return _v("mass", model)


def density(model: Model | None = None) -> LiveArray:
    return _v("density", model)


def force_app(model: Model | None = None) -> LiveArray:
    return _v("fapp", model)


def fixity(model: Model | None = None) -> LiveArray:
    return _v("fixity", model)


def hidden(model: Model | None = None) -> LiveArray:
    return _v("hidden", model)


def in_group(name: str, slot=None, model: Model | None = None) -> np.ndarray:
    """Boolean (n,): the blocks in group ``name`` (in ``slot``; any slot when omitted)."""
    st = api_of(model).session.model
    b = st.blocks
    code = st.groups.code(name)
    if code < 0:
        return np.zeros(b.n, dtype=bool)
    if slot is None:
        return np.any(b["group"] == code, axis=1)
    col = st.groups.slot_index(b, slot_name(slot))
    if col < 0:
        raise ValueError(f"there is no group slot '{slot}' (slots: {', '.join(st.groups.slot_names('blocks'))})")
    return b["group"][:, col] == code


def set_vel(value, model: Model | None = None) -> None:
    """Set every block's velocity [m/s]: shape (n, 3), finite."""
    put(api_of(model), "blocks", "velocity", value, "blockarray.set_vel")


def set_rvel(value, model: Model | None = None) -> None:
    """Set every block's angular velocity [rad/s]: shape (n, 3), finite."""
    put(api_of(model), "blocks", "spin", value, "blockarray.set_rvel")


def set_force_app(value, model: Model | None = None) -> None:
    """Set every block's applied force [N] (as `block apply force`): shape (n, 3), finite."""
    put(api_of(model), "blocks", "fapp", value, "blockarray.set_force_app")


def set_density(value, model: Model | None = None) -> None:
    """Set every block's density [kg/m³]: shape (n,), finite and > 0; masses and inertias follow."""
    from ..geometry.mass import update_mass_properties

    api = api_of(model)
    st = api.session.model
    a = plain(value)
    if a.shape != (st.blocks.n,):
        raise ValueError(f"blockarray.set_density: expected an array of shape ({st.blocks.n},), got {a.shape}")
    if not np.all(np.isfinite(a)) or np.any(a <= 0):
        bad = int(np.flatnonzero(~np.isfinite(a) | (a <= 0))[0])
        raise ValueError(f"blockarray.set_density: a density is a finite number > 0; row {bad} holds {a[bad]}")
    st.blocks["density"][:] = a
    update_mass_properties(st, np.arange(st.blocks.n))
