"""``it.block.zone``: the zones of deformable blocks (3DEC's ``itasca.block.zone``; method names follow
FLAC3D's ``itasca.zone``: pos, vol, stress, gridpoints, model, prop). Stresses tension positive [Pa].
"""
from __future__ import annotations

from typing import Iterator

import numpy as np

from .._bind import Model
from .._objects import Entity, api_of, fish_call

_COMP = ("xx", "yy", "zz", "xy", "xz", "yz")


class Zone(Entity):
    __slots__ = ()
    kind = "block.zone.Zone"

    def id(self) -> int:
        return int(self._fish("block.zone.id"))

    def block(self):
        from . import Block

        return Block(self._api, int(self._fish("block.zone.block")))

    def pos(self) -> np.ndarray:
        """Centroid [m]."""
        return self._fish("block.zone.pos")

    def vol(self) -> float:
        """Volume [m³]."""
        return float(self._fish("block.zone.vol"))

    def stress(self) -> np.ndarray:
        """Stress tensor (3, 3) [Pa], tension positive."""
        xx, yy, zz, xy, xz, yz = (float(self._fish(f"block.zone.stress.{c}")) for c in _COMP)
        return np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])

    def state(self) -> int:
        return int(self._fish("block.zone.state"))

    def model(self) -> str:
        """The constitutive model's name."""
        return str(self._fish("block.zone.model"))

    def prop(self, name: str) -> float:
        """A property of the zone's model (in the units `block zone property` takes)."""
        return self._fish("block.zone.prop", name)

    def gridpoints(self) -> tuple:
        from .gridpoint import Gridpoint

        st = self._model()
        zs = st.stores["zones"]
        rows = np.flatnonzero(zs["id"] == self._id)
        if rows.size == 0:
            raise ValueError(f"there is no zone with id {self._id}")
        r = int(rows[0])
        return tuple(Gridpoint(self._api, int(g) + 1) for g in zs["gp"][r][: int(zs["nnode"][r])])


def count(model: Model | None = None) -> int:
    return int(fish_call(api_of(model), "block.zone.num"))


def list(model: Model | None = None) -> Iterator[Zone]:  # noqa: A001 - Itasca's name
    api = api_of(model)
    return iter([Zone(api, int(i)) for i in fish_call(api, "block.zone.list")])


def find(ident: int, model: Model | None = None) -> Zone | None:
    api = api_of(model)
    return Zone(api, int(ident)) if fish_call(api, "block.zone.find", int(ident)) else None
