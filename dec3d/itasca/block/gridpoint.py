"""``it.block.gridpoint``: gridpoints (the vertices of rigid blocks and the nodes of zoned blocks, as in
3DEC). A gridpoint's id is its vertex row + 1, as FISH's block.gp.* take it; it stays valid until blocks
are made, deleted or zoned. Values as FISH block.gp.*: a vertex of a rigid block reads the block's motion
there. (Method names follow FLAC3D's ``itasca.gridpoint``: pos, vel, disp, force_unbal.)
"""
from __future__ import annotations

from typing import Iterator

import numpy as np

from .._bind import Model
from .._objects import RowEntity, api_of, fish_call, vec3


class Gridpoint(RowEntity):
    __slots__ = ()
    kind = "block.gridpoint.Gridpoint"
    store_name = "vertices"
    what = "gridpoint"

    def id(self) -> int:
        return int(self._fish("block.gp.id"))

    def block(self):
        from . import Block

        return Block(self._api, int(self._fish("block.gp.block")))

    def pos(self) -> np.ndarray:
        """Position [m]."""
        return self._fish("block.gp.pos")

    def vel(self) -> np.ndarray:
        """Velocity [m/s]."""
        return self._fish("block.gp.vel")

    def disp(self) -> np.ndarray:
        """Displacement [m]."""
        return self._fish("block.gp.disp")

    def force_unbal(self) -> np.ndarray:
        """Unbalanced force of the last step [N] (zoned blocks; zero for a rigid vertex)."""
        return self._fish("block.gp.force")

    def zoned(self) -> bool:
        return bool(self._fish("block.gp.zoned"))


def count(model: Model | None = None) -> int:
    return int(fish_call(api_of(model), "block.gp.num"))


def list(model: Model | None = None) -> Iterator[Gridpoint]:  # noqa: A001 - Itasca's name
    api = api_of(model)
    return iter([Gridpoint(api, int(i)) for i in fish_call(api, "block.gp.list")])


def find(ident: int, model: Model | None = None) -> Gridpoint | None:
    api = api_of(model)
    return Gridpoint(api, int(ident)) if fish_call(api, "block.gp.find", int(ident)) else None


def near(pos, model: Model | None = None) -> Gridpoint | None:
    api = api_of(model)
    p = vec3(pos, "gridpoint.near")
    i = fish_call(api, "block.gp.near", *(float(c) for c in p))
    return Gridpoint(api, int(i)) if i else None
