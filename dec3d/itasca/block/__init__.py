"""``it.block``: the rigid and deformable blocks of the bound model (Itasca's ``itasca.block``).

    b = it.block.find(1)          # a Block, or None when no block has the id
    b.pos(), b.vel(), b.disp()    # numpy arrays (3,): m, m/s, m
    [b.id() for b in it.block.list()]

Names follow Itasca's 3DEC Python module (``itasca.block``: count, list, find, near, maxid; Block.pos,
vel, disp, vol, mass, group, set_group, in_group, fix ...), and 3DEC's FISH block.* names where the
Python name is not documented (rvel, force_unbal, moment_unbal, force_app, density, hidden): dotted FISH
names become underscores, as Itasca's Python does. Sub-modules: contact, subcontact, face, gridpoint,
zone (and the array modules blockarray, contactarray, gridpointarray, zonearray under ``it``).
"""
from __future__ import annotations

from typing import Iterator

import numpy as np

from .._bind import Model
from .._objects import Entity, api_of, fish_call, group_of, groups_of, in_group, slot_name, vec3

FIX_ALL = 0b111111        # velocity x, y, z and rotation x, y, z (dec3d.model.model: fixity bits)


class Block(Entity):
    """One block (found by its id; ids are never reused)."""

    __slots__ = ("_hint",)
    kind = "block.Block"

    def __init__(self, api: Model, ident: int, hint: int = -1):
        super().__init__(api, ident)
        self._hint = hint

    def _row(self) -> int:
        st = self._model()
        r, ids = self._hint, st.blocks["id"]
        if 0 <= r < len(ids) and ids[r] == self._id:      # the row it had (blocks are rarely deleted)
            return r
        r = int(st.block_rows([self._id])[0])
        if r < 0:
            raise ValueError(f"block {self._id} does not exist any more (deleted since it was found)")
        self._hint = r
        return r

    # ---------------------------------------------------------------- reading
    def id(self) -> int:
        """The block's id (from 1)."""
        self._row()
        return int(self._id)

    def pos(self) -> np.ndarray:
        """Centroid [m], shape (3,)."""
        return self._state.blocks["centroid"][self._row()].copy()

    def vel(self) -> np.ndarray:
        """Velocity of the centroid [m/s], shape (3,)."""
        return self._state.blocks["velocity"][self._row()].copy()

    def rvel(self) -> np.ndarray:
        """Angular velocity [rad/s], shape (3,) (FISH block.rvel)."""
        return self._state.blocks["spin"][self._row()].copy()

    def disp(self) -> np.ndarray:
        """Accumulated centroid displacement [m], shape (3,)."""
        return self._state.blocks["disp"][self._row()].copy()

    def vol(self) -> float:
        """Volume [m³]."""
        return float(self._state.blocks["volume"][self._row()])

    def mass(self) -> float:
        """Mass [kg] (0 until a density is given)."""
        return float(self._state.blocks["mass"][self._row()])

    def density(self) -> float:
        """Density [kg/m³]."""
        return float(self._state.blocks["density"][self._row()])

    def force_app(self) -> np.ndarray:
        """Applied force [N] (`block apply force`), shape (3,)."""
        return self._state.blocks["fapp"][self._row()].copy()

    def force_unbal(self) -> np.ndarray:
        """Out-of-balance force [N]: contacts + applied + weight, as FISH block.force.unbal."""
        self._row()
        return self._fish("block.force.unbal")

    def moment_unbal(self) -> np.ndarray:
        """Out-of-balance moment about the centroid [N·m] (FISH block.moment)."""
        self._row()
        return self._fish("block.moment")

    def hidden(self) -> bool:
        return bool(self._state.blocks["hidden"][self._row()])

    def fix(self) -> bool:
        """True when every velocity and rotation component is fixed (`block fix`)."""
        return (int(self._state.blocks["fixity"][self._row()]) & FIX_ALL) == FIX_ALL

    def fixity(self) -> int:
        """The fixity bits: 1, 2, 4 velocity x, y, z; 8, 16, 32 rotation x, y, z (dec3d's own)."""
        return int(self._state.blocks["fixity"][self._row()])

    def group(self, slot=None) -> str:
        """The block's group in ``slot`` (default slot when omitted; '' when it has none there);
        ValueError for a slot that does not exist."""
        st = self._model()
        return group_of(st, st.blocks, self._row(), slot)

    def groups(self) -> dict[str, str]:
        """{slot: group} of every slot where the block has a group."""
        st = self._model()
        return groups_of(st, st.blocks, self._row())

    def in_group(self, name: str, slot=None) -> bool:
        """True when the block is in group ``name`` (in ``slot``, or in any slot when omitted)."""
        st = self._model()
        return in_group(st, st.blocks, self._row(), name, slot)

    def faces(self) -> tuple:
        """The block's faces (``it.block.face.Face``)."""
        from .face import Face

        r = self._row()
        b = self._state.blocks
        s, n = int(b["face_start"][r]), int(b["face_count"][r])
        return tuple(Face(self._api, i + 1) for i in range(s, s + n))

    def zones(self) -> tuple:
        """The zones of a deformable block (empty for a rigid one)."""
        from .zone import Zone

        r = self._row()
        zs = self._state.stores.get("zones")
        if zs is None or zs.n == 0:
            return ()
        return tuple(Zone(self._api, int(i)) for i in zs["id"][zs["block"] == r])

    def gridpoints(self) -> tuple:
        """The block's vertices / gridpoints (``it.block.gridpoint.Gridpoint``)."""
        from .gridpoint import Gridpoint

        r = self._row()
        return tuple(Gridpoint(self._api, int(v) + 1) for v in np.flatnonzero(self._state.vertices["block"] == r))

    def contacts(self) -> tuple:
        """The contacts this block takes part in."""
        from . import contact

        return tuple(c for c in contact.list(self._api) if self._id in (c.end1().id(), c.end2().id()))

    # ---------------------------------------------------------------- writing
    def set_vel(self, v) -> None:
        """Set the centroid velocity [m/s] (three finite numbers)."""
        a = vec3(v, "Block.set_vel")
        self._state.blocks["velocity"][self._row()] = a

    def set_rvel(self, v) -> None:
        """Set the angular velocity [rad/s]."""
        a = vec3(v, "Block.set_rvel")
        self._state.blocks["spin"][self._row()] = a

    def set_force_app(self, f) -> None:
        """Set the applied force [N] (as `block apply force`)."""
        a = vec3(f, "Block.set_force_app")
        self._state.blocks["fapp"][self._row()] = a

    def set_density(self, d: float) -> None:
        """Set the density [kg/m³] (> 0); mass and inertia follow."""
        from ...model.blocks import set_density

        d = float(d)
        if not np.isfinite(d) or d <= 0:
            raise ValueError(f"Block.set_density: a density is a finite number > 0, not {d}")
        set_density(self._state, np.array([self._row()]), d)

    def set_fix(self, on: bool = True) -> None:
        """Fix (True) or free (False) every velocity and rotation component."""
        r = self._row()
        fx = self._state.blocks["fixity"]
        fx[r] = (int(fx[r]) | FIX_ALL) if on else (int(fx[r]) & ~FIX_ALL)

    def set_group(self, name: str, slot=None) -> None:
        """Put the block in group ``name`` in ``slot`` (default slot when omitted; a new slot is made)."""
        if not isinstance(name, str) or not name.strip():
            raise ValueError(f"Block.set_group: a group name is a non-empty string, not {name!r}")
        st = self._model()
        st.groups.assign(st.blocks, np.array([self._row()]), name, slot_name(slot))

    def remove_group(self, name: str, slot=None) -> None:
        """Take the block out of group ``name``."""
        st = self._model()
        st.groups.remove(st.blocks, np.array([self._row()]), name, slot_name(slot))


# -------------------------------------------------------------------- module functions

def count(model: Model | None = None) -> int:
    """Number of blocks."""
    return int(api_of(model).session.model.blocks.n)


def list(model: Model | None = None) -> Iterator[Block]:  # noqa: A001 - Itasca's name
    """Every block, in row order (an iterator, as Itasca's)."""
    api = api_of(model)
    return iter([Block(api, int(i), r) for r, i in enumerate(api.session.model.blocks["id"])])


def find(ident: int, model: Model | None = None) -> Block | None:
    """The block with id ``ident``, or None when there is none."""
    if type(ident) is bool or not isinstance(ident, (int, np.integer)):
        raise TypeError(f"block.find takes a block id (an integer), not a {type(ident).__name__}")
    api = api_of(model)
    ok = api.session.model.block_rows([int(ident)])[0] >= 0
    return Block(api, int(ident)) if ok else None


def near(pos, model: Model | None = None) -> Block | None:
    """The block whose centroid is nearest ``pos`` (ties: lowest id); None when there are no blocks.
    (dec3d's meaning, as FISH block.near: the distance to the centroid.)"""
    api = api_of(model)
    p = vec3(pos, "block.near")
    i = fish_call(api, "block.near", *(float(c) for c in p))
    return Block(api, int(i)) if i else None


def maxid(model: Model | None = None) -> int:
    """The largest block id in use (0 when there are no blocks)."""
    ids = api_of(model).session.model.blocks["id"]
    return int(ids.max()) if len(ids) else 0


from . import contact, face, gridpoint, subcontact, zone  # noqa: E402  (it.block.contact ...)
from .. import contactarray, gridpointarray, zonearray  # noqa: E402  (3DEC spelling it.block.zonearray ...)

__all__ = ["Block", "count", "list", "find", "near", "maxid", "contact", "subcontact", "face", "gridpoint",
           "zone", "contactarray", "gridpointarray", "zonearray"]
