"""``it.block.subcontact``: the sub-contacts (the points where contact forces act).

A ``Subcontact`` is named by its contact's two block ids and its index in that contact (from 0). Values
as dec3d stores them: normal force compression positive [N], shear force on block B [N], normal
displacement (opening positive, from the initial gap) [m], accumulated shear displacement [m].
"""
from __future__ import annotations

from typing import Iterator

import numpy as np

from .._bind import Model
from .._objects import Entity, api_of, fish_call


class Subcontact(Entity):
    __slots__ = ()
    kind = "block.subcontact.Subcontact"

    def _ptr(self):
        from ...fish.contact_intrinsics import ContactPtr

        return ContactPtr("subcontact", self._id)

    def _call(self, name):
        from .contact import _stores

        self._model()
        _stores(self._api)              # detected again first when the blocks changed
        return fish_call(self._api, name, self._ptr())

    def id(self) -> tuple[int, int, int]:
        """(block A id, block B id, index in the contact)."""
        self.pos()
        return tuple(self._id)

    def contact(self):
        from .contact import Contact

        self.pos()
        return Contact(self._api, tuple(self._id[:2]))

    def pos(self) -> np.ndarray:
        """Position on the common plane [m]."""
        return self._call("block.subcontact.pos")

    def area(self) -> float:
        """Area [m²]."""
        return float(self._call("block.subcontact.area"))

    def force_norm(self) -> float:
        """Normal force [N], compression positive."""
        return float(self._call("block.subcontact.force.norm"))

    def force_shear(self) -> np.ndarray:
        """Shear force on block B [N]."""
        return self._call("block.subcontact.force.shear")

    def disp_norm(self) -> float:
        """Normal displacement [m] (opening positive)."""
        return float(self._call("block.subcontact.disp.norm"))

    def disp_shear(self) -> np.ndarray:
        """Accumulated shear displacement [m]."""
        return self._call("block.subcontact.disp.shear")

    def stress_norm(self) -> float:
        """Normal stress [Pa] (force / area)."""
        return float(self._call("block.subcontact.stress.norm"))

    def state(self) -> int:
        """State bits (0 elastic; slip and tension bits as the joint law sets them)."""
        return int(self._call("block.subcontact.state"))


def count(model: Model | None = None) -> int:
    from .contact import _stores

    _, ss = _stores(api_of(model))
    return 0 if ss is None else int(ss.n)


def list(model: Model | None = None) -> Iterator[Subcontact]:  # noqa: A001 - Itasca's name
    """Every sub-contact, contact by contact."""
    api = api_of(model)
    return iter([Subcontact(api, tuple(p.key)) for p in fish_call(api, "block.subcontact.list")])
