"""``it.structure``: structural elements of the bound model — cables and hybrid bolts
(``dec3d.model.cables``, ``dec3d.model.dowels``) and beams (``dec3d.model.beams``).

``it.structure.cable``: the cable elements (hybrid bolts' too); ``it.structure.beam``: the beam elements;
``it.structure.node``: the nodes of both and of the liners (one id space); ``it.structure.dowel``: the hybrid bolts' dowels
at the joints they cross. Ids as FISH struct.* and `structure … list` give them (from 1). Names follow
Itasca's FLAC3D ``itasca.structure`` pattern (3DEC's are not documented): Cable.force_axial(),
Beam.force(end), moment(end), force_axial(), Node.pos(), disp(), vel(), force_unbal(), Dowel.force(),
disp(), state().
"""
from __future__ import annotations

import types
from typing import Iterator

import numpy as np

from ._bind import Model
from ._objects import Entity, api_of


def _ids(api, stores):
    """Ids of the rows of ``stores`` (a store name, or several sharing one id space: cable and beam nodes)."""
    out = []
    for store in (stores,) if isinstance(stores, str) else stores:
        st = api.session.model.stores.get(store)
        out += [] if st is None else [int(i) for i in st["id"]]
    return sorted(out)


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

    def state(self) -> int:
        """State bits (``struct.cable.state``): 32 once the element has ruptured."""
        return int(self._fish("struct.cable.state"))

    def ruptured(self) -> bool:
        """Whether the element broke at its ``tensile-failure-strain`` (it carries nothing since)."""
        return bool(self.state() & 32)


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


class Beam(Entity):
    __slots__ = ()
    kind = "structure.beam.Beam"

    def id(self) -> int:
        self.force_axial()
        return int(self._id)

    def force_axial(self) -> float:
        """Axial force [N], tension positive."""
        return float(self._fish("struct.beam.force.axial"))

    def force(self, end: int = 1) -> np.ndarray:
        """Force the node at ``end`` (1 or 2) puts on the element, in the element's axes (x axial) [N]."""
        return self._fish("struct.beam.force", end)

    def moment(self, end: int = 1) -> np.ndarray:
        """Moment the node at ``end`` (1 or 2) puts on the element, in its axes (x: torsion) [N·m]."""
        return self._fish("struct.beam.moment", end)


class Dowel(Entity):
    __slots__ = ()
    kind = "structure.dowel.Dowel"

    def id(self) -> int:
        self.state()
        return int(self._id)

    def force(self) -> float:
        """Magnitude of the dowel's shear force [N]."""
        return float(self._fish("struct.hybrid.dowel.force"))

    def disp(self) -> float:
        """Magnitude of the shear displacement across the bolt at the dowel [m]."""
        return float(self._fish("struct.hybrid.dowel.disp"))

    def state(self) -> int:
        """Bits: 1 yielding now, 2 yielded in the past, 4 ruptured."""
        return int(self._fish("struct.hybrid.dowel.state"))


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
node = _module("node", Node, ("cable_nodes", "beam_nodes", "liner_nodes"))
beam = _module("beam", Beam, "beam_elements")
dowel = _module("dowel", Dowel, "cable_dowels")

__all__ = ["cable", "node", "beam", "dowel", "Cable", "Node", "Beam", "Dowel"]
