"""``it.block.face``: block faces (polygons, counter-clockwise seen from outside).

A face's id is its row in the model's face store + 1, as FISH's block.face.* take it: it stays valid
until blocks are made, cut, deleted or zoned (then a ``Face`` raises ``StaleError``; find it again
through ``Block.faces()``). (3DEC's Python face names are not documented; FLAC3D's pattern is used.)
"""
from __future__ import annotations

from typing import Iterator

import numpy as np

from .._bind import Model
from .._objects import RowEntity, api_of, group_of, in_group


class Face(RowEntity):
    __slots__ = ()
    kind = "block.face.Face"
    store_name = "faces"
    what = "face"

    def id(self) -> int:
        self._row()
        return int(self._id)

    def block(self):
        from . import Block

        r = self._row()
        return Block(self._api, int(self._state.blocks["id"][int(self._state.faces["block"][r])]))

    def pos(self) -> np.ndarray:
        """Area centroid [m]."""
        return self._state.faces["centroid"][self._row()].copy()

    def normal(self) -> np.ndarray:
        """Unit outward normal."""
        return self._state.faces["normal"][self._row()].copy()

    def area(self) -> float:
        """Area [m²]."""
        return float(self._state.faces["area"][self._row()])

    def group(self, slot=None) -> str:
        return group_of(self._state, self._state.faces, self._row(), slot)

    def in_group(self, name: str, slot=None) -> bool:
        return in_group(self._state, self._state.faces, self._row(), name, slot)


def count(model: Model | None = None) -> int:
    return int(api_of(model).session.model.faces.n)


def list(model: Model | None = None) -> Iterator[Face]:  # noqa: A001 - Itasca's name
    api = api_of(model)
    return iter([Face(api, i + 1) for i in range(api.session.model.faces.n)])


def find(ident: int, model: Model | None = None) -> Face | None:
    api = api_of(model)
    return Face(api, int(ident)) if 1 <= int(ident) <= api.session.model.faces.n else None
