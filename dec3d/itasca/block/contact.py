"""``it.block.contact``: the contacts between blocks (Itasca's ``itasca.block.contact``).

Contacts are found again at every detection, so a ``Contact`` is named by its two block ids (A < B),
as FISH names it; a contact that has gone (its blocks separated) raises ValueError. Lists are made with
the contacts up to date (detected first when the blocks changed). Values: normal force compression
positive [N]; shear force on block B [N]; normal from A to B. 3DEC gives contacts numeric ids; dec3d's
``find`` takes the two block ids instead, and ``Contact.id()`` returns the pair.
"""
from __future__ import annotations

from typing import Iterator

import numpy as np

from .._bind import Model
from .._objects import Entity, api_of, fish_call, group_of, in_group


class Contact(Entity):
    """A contact between two blocks."""

    __slots__ = ("_p",)
    kind = "block.contact.Contact"

    def __init__(self, api: Model, ident, hint: int = -1):
        from ...fish.contact_intrinsics import ContactPtr

        super().__init__(api, tuple(ident))
        self._p = ContactPtr("contact", self._id, hint)      # FISH's pointer: keeps its last row as a hint

    def _ptr(self):
        return self._p

    def _call(self, name, *args):
        self._model()
        _stores(self._api)              # detected again first when the blocks changed
        return fish_call(self._api, name, self._ptr(), *args)

    def _row(self):
        from ...fish.contact_intrinsics import _contact_row

        self._model()
        _stores(self._api)
        try:
            return _contact_row(self._api.session.fish_rt, self._ptr(), "Contact")
        except Exception as exc:          # FishValueError: the contact is gone
            raise ValueError(getattr(exc, "message", str(exc)).replace("`", "")) from None

    def id(self) -> tuple[int, int]:
        """The ids of its two blocks (A < B)."""
        self._row()
        return tuple(self._id)

    def end1(self):
        """Block A (the lower id)."""
        from . import Block

        self._row()
        return Block(self._api, int(self._id[0]))

    def end2(self):
        """Block B."""
        from . import Block

        self._row()
        return Block(self._api, int(self._id[1]))

    def pos(self) -> np.ndarray:
        """Reference point on the common plane [m]."""
        return self._call("block.contact.pos")

    def normal(self) -> np.ndarray:
        """Unit normal from block A to block B."""
        return self._call("block.contact.normal")

    def force_norm(self) -> float:
        """Normal force [N], the sum over its sub-contacts, compression positive."""
        return float(self._call("block.contact.force.norm"))

    def force_shear(self) -> np.ndarray:
        """Shear force on block B [N], the sum over its sub-contacts."""
        return self._call("block.contact.force.shear")

    def force(self) -> np.ndarray:
        """Total force of block A on block B [N]: force_norm · normal + force_shear."""
        return self.force_norm() * self.normal() + self.force_shear()

    def area(self) -> float:
        """Contact area [m²]: the sum of its sub-contacts' areas."""
        cs, r = self._row()
        ss = self._state.stores["subcontacts"]
        s0, n = int(cs["sub_start"][r]), int(cs["sub_count"][r])
        return float(ss["area"][s0:s0 + n].sum())

    def gap(self) -> float:
        """Gap at the last detection [m] (negative: overlap)."""
        cs, r = self._row()
        return float(cs["gap"][r])

    def subcontacts(self) -> tuple:
        """Its sub-contacts (``it.block.subcontact.Subcontact``)."""
        from .subcontact import Subcontact

        cs, r = self._row()
        return tuple(Subcontact(self._api, (*self._id, k)) for k in range(int(cs["sub_count"][r])))

    def prop(self, name: str) -> float:
        """A joint property by its `block contact property` name."""
        return self._call("block.contact.prop", name)

    def group(self, slot=None) -> str:
        cs, r = self._row()
        return group_of(self._state, cs, r, slot)

    def in_group(self, name: str, slot=None) -> bool:
        cs, r = self._row()
        return in_group(self._state, cs, r, name, slot)


def _stores(api):
    from ...fish.contact_intrinsics import _stores as st

    return st(api.session.fish_rt, current=True)


def count(model: Model | None = None) -> int:
    """Number of contacts (detected first when the blocks changed)."""
    cs, _ = _stores(api_of(model))
    return 0 if cs is None else int(cs.n)


def list(model: Model | None = None) -> Iterator[Contact]:  # noqa: A001 - Itasca's name
    """Every contact, in the engine's order (by block ids)."""
    api = api_of(model)
    cs, _ = _stores(api)
    if cs is None:
        return iter(())
    return iter([Contact(api, (int(a), int(b)), r) for r, (a, b) in enumerate(zip(cs["ida"], cs["idb"]))])


def find(b1: int, b2: int, model: Model | None = None) -> Contact | None:
    """The contact between blocks ``b1`` and ``b2`` (ids, either order), or None."""
    for b in (b1, b2):
        if type(b) is bool or not isinstance(b, (int, np.integer)):
            raise TypeError(f"block.contact.find takes two block ids (integers), not {b!r}")
    api = api_of(model)
    hit = fish_call(api, "block.contact.find", int(b1), int(b2))
    return Contact(api, tuple(hit.key)) if hit else None
