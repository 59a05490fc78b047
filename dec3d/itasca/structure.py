"""``it.structure``: structural elements of the bound model — cables (``dec3d.model.cables``).

``it.structure.cable``: the cable elements; ``it.structure.node``: their nodes. Ids as FISH struct.* and
`structure cable list` give them (from 1). Names follow Itasca's FLAC3D ``itasca.structure`` pattern
(3DEC's are not documented): Cable.force_axial(), Node.pos(), disp(), vel(), force_unbal().
"""
from __future__ import annotations

import types
from typing import Iterator

import numpy as np

from ._bind import Model
from ._objects import Entity, api_of


def _ids(api, store):
    st = api.session.model.stores.get(store)
    return [] if st is None else [int(i) for i in st["id"]]


class Cable(Entity):
    __slots__ = ()
    kind = "structure.cable.Cable"

    def id(self) -> int:
        self.force_axial()
        return int(self._id)

    def force_axial(self) -> float:
        """Axial force [N], tension positive."""
        return float(self._fish("struct.cable.force.axial"))

    def yielded(self) -> bool:
        """True when the element has yielded in tension or compression (FISH struct.cable.yield)."""
        return bool(self._fish("struct.cable.yield"))


class Node(Entity):
    __slots__ = ()
    kind = "structure.node.Node"

    def id(self) -> int:
        self.pos()
        return int(self._id)

    def pos(self) -> np.ndarray:
        return self._fish("struct.node.pos")

    def disp(self) -> np.ndarray:
        return self._fish("struct.node.disp")

    def vel(self) -> np.ndarray:
        return self._fish("struct.node.vel")

    def force_unbal(self) -> np.ndarray:
        return self._fish("struct.node.force.unbal")


def _module(name, cls, store):
    def count(model: Model | None = None) -> int:
        return len(_ids(api_of(model), store))

    def list_(model: Model | None = None) -> Iterator:
        api = api_of(model)
        return iter([cls(api, i) for i in _ids(api, store)])

    def find(ident: int, model: Model | None = None):
        api = api_of(model)
        return cls(api, int(ident)) if int(ident) in _ids(api, store) else None

    mod = types.ModuleType(f"dec3d.itasca.structure.{name}", f"Structural {name}s: count(), list(), find(id).")
    mod.count, mod.list, mod.find = count, list_, find
    setattr(mod, cls.__name__, cls)
    return mod


cable = _module("cable", Cable, "cable_segments")
node = _module("node", Node, "cable_nodes")

__all__ = ["cable", "node", "Cable", "Node"]
