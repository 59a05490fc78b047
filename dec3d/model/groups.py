"""Group names and slots.

Every store that can be grouped has an int32 field ``group`` of shape ``(capacity, nslots)``:
the code of the group each row belongs to in each slot, ``-1`` for none. Codes index one
name table shared by all stores; slot names are kept per store. A range ``group 'x'`` is then
one vectorised comparison against an integer.

As in 3DEC, names compare case-insensitively and keep the spelling first given; an entity
belongs to at most one group per slot; a group given without a slot goes to slot 'Default'.
"""
from __future__ import annotations

import numpy as np

from .store import Field, Store

DEFAULT_SLOT = "Default"
GROUP_FIELD = "group"


def group_field(nslots: int = 1) -> Field:
    return Field((nslots,), np.int32, -1)


class GroupTable:
    """Names of groups (shared) and of slots (per store)."""

    def __init__(self) -> None:
        self.names: list[str] = []
        self._code: dict[str, int] = {}
        self.slots: dict[str, list[str]] = {}

    # ---------------------------------------------------------------- groups
    def code(self, name: str, create: bool = False) -> int:
        """Code of a group name; ``-1`` when unknown and not created."""
        key = name.lower()
        if key in self._code:
            return self._code[key]
        if not create:
            return -1
        self._code[key] = len(self.names)
        self.names.append(name)
        return self._code[key]

    def name(self, code: int) -> str:
        return self.names[code] if code >= 0 else ""

    # ----------------------------------------------------------------- slots
    def slot_names(self, store: str) -> list[str]:
        return self.slots.setdefault(store, [DEFAULT_SLOT])

    def slot_index(self, store: Store, slot: str | None, create: bool = False) -> int:
        """Column of ``slot`` in ``store``'s group field; ``-1`` when unknown and not created.

        Creating a slot widens the store's group field by one column.
        """
        names = self.slot_names(store.name)
        slot = DEFAULT_SLOT if slot is None else slot
        for i, s in enumerate(names):
            if s.lower() == slot.lower():
                return i
        if not create:
            return -1
        names.append(slot)
        store.resize_field(GROUP_FIELD, (len(names),))
        return len(names) - 1

    # ------------------------------------------------------------ assignment
    def assign(self, store: Store, rows, name: str, slot: str | None = None) -> None:
        """Put ``rows`` of ``store`` in group ``name`` (replacing their group in that slot)."""
        col = self.slot_index(store, slot, create=True)
        store.full(GROUP_FIELD)[rows, col] = self.code(name, create=True)

    def remove(self, store: Store, rows, name: str, slot: str | None = None) -> None:
        """Take ``rows`` out of group ``name``: in ``slot`` if given, else in every slot."""
        code = self.code(name)
        if code < 0:
            return
        g = store.full(GROUP_FIELD)
        cols = range(g.shape[1]) if slot is None else [self.slot_index(store, slot)]
        rows = np.arange(store.n)[rows]
        for c in cols:
            if c < 0:
                continue
            sel = rows[g[rows, c] == code]
            g[sel, c] = -1

    # -------------------------------------------------------------- save/load
    def to_dict(self) -> dict:
        return {"names": list(self.names), "slots": {k: list(v) for k, v in sorted(self.slots.items())}}

    @classmethod
    def from_dict(cls, d: dict) -> "GroupTable":
        t = cls()
        for name in d.get("names", []):
            if t.code(name) >= 0:
                raise ValueError(f"group name '{name}' appears twice")
            t.code(name, create=True)
        t.slots = {k: list(v) for k, v in d.get("slots", {}).items()}
        return t
