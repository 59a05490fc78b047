"""The base of the object API: an entity of one model state, read through dec3d's FISH intrinsics.

FISH already knows how to find a block, zone, gridpoint, face, contact or cable node of the model and
read its values (``dec3d.fish.*_intrinsics``); the Python objects call the same functions, so both
languages read the same numbers and report the same bad input (a wrong id: ``ValueError`` with FISH's
message). Vectors come back as numpy arrays of shape (3,) (Itasca gives its own ``vec3``; both index
as v[0], v[1], v[2] and unpack as x, y, z).
"""
from __future__ import annotations

import numpy as np

from ._bind import Handle, Model, current


def fish_call(api: Model, name: str, *args):
    """The FISH intrinsic ``name`` on ``api``'s model; FISH's value errors become ``ValueError``."""
    from ..fish.intrinsics import INTRINSICS
    from ..fish.values import FishValueError, Vec

    rt = api.session.fish_rt
    try:
        v = INTRINSICS[name].fn(rt, *args)
    except FishValueError as exc:
        raise ValueError(exc.message.replace("`", "")) from None
    if type(v) is Vec:
        return np.array([v.x, v.y, v.z], dtype=float)
    return v


def api_of(model: Model | None) -> Model:
    return current() if model is None else model


def vec3(v, what: str) -> np.ndarray:
    """A vector argument: three finite numbers (ValueError otherwise)."""
    try:
        a = np.asarray(v, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"{what}: expected three numbers, got {v!r}") from None
    if a.shape != (3,):
        raise ValueError(f"{what}: expected three numbers (x, y, z), got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{what}: every component must be finite, got {a.tolist()}")
    return a


def slot_name(slot) -> str | None:
    if slot is None:
        return None
    if isinstance(slot, int) and not isinstance(slot, bool):
        return None if slot == 0 else str(slot)        # Itasca: slot 0 is the default one
    if not isinstance(slot, str):
        raise TypeError(f"a group slot is a name (or a number), not a {type(slot).__name__}")
    return slot


def group_of(state, store, row: int, slot) -> str:
    """The group name of ``row`` of ``store`` in ``slot`` ('' when none); ValueError for an unknown slot."""
    s = slot_name(slot)
    col = state.groups.slot_index(store, s)
    if col < 0:
        have = ", ".join(state.groups.slot_names(store.name))
        raise ValueError(f"there is no group slot '{s}' (slots: {have})")
    return state.groups.name(int(store["group"][row, col]))


def in_group(state, store, row: int, name: str, slot) -> bool:
    if not isinstance(name, str):
        raise TypeError(f"a group name is a string, not a {type(name).__name__}")
    s = slot_name(slot)
    code = state.groups.code(name)
    if code < 0:
        return False
    if s is None and slot is None:
        return bool(np.any(store["group"][row] == code))
    col = state.groups.slot_index(store, s)
    return col >= 0 and int(store["group"][row, col]) == code


def groups_of(state, store, row: int) -> dict[str, str]:
    """{slot: group} of ``row`` (slots where it has a group)."""
    out = {}
    for col, s in enumerate(state.groups.slot_names(store.name)):
        code = int(store["group"][row, col]) if col < store["group"].shape[1] else -1
        if code >= 0:
            out[s] = state.groups.name(code)
    return out


class Entity(Handle):
    """An entity found by its id (FISH's value for it) in one model state."""

    __slots__ = ("_id",)
    kind = "entity"

    def __init__(self, api: Model, ident):
        super().__init__(api)
        self._id = ident

    def _fish(self, name: str, *args):
        self._model()
        return fish_call(self._api, name, self._id, *args)

    def __eq__(self, other):
        return type(other) is type(self) and other._id == self._id and other._state is self._state

    def __hash__(self):
        return hash((type(self).__name__, self._id, id(self._state)))

    def __repr__(self):
        return f"<itasca.{self.kind} {self._id}>"


class RowEntity(Entity):
    """An entity whose id is its row + 1 in a store (faces, gridpoints, as FISH numbers them): valid while
    that store keeps its rows; after rows are made or deleted it raises ``StaleError``."""

    __slots__ = ("_arr", "_n")
    store_name = ""
    what = ""

    def __init__(self, api: Model, ident):
        super().__init__(api, int(ident))
        st = api.session.model.store(self.store_name)
        self._arr, self._n = st.full("pos" if "pos" in st else "block"), st.n

    def _row(self) -> int:
        from ._bind import StaleError

        st = self._model().store(self.store_name)
        if st.full("pos" if "pos" in st else "block") is not self._arr or st.n != self._n:
            raise StaleError(f"{self.what} {self._id}: the model's {self.store_name} changed since it was found "
                             "(blocks made, cut, deleted or zoned); find it again")
        if not 1 <= self._id <= st.n:
            raise ValueError(f"there is no {self.what} {self._id}")
        return self._id - 1

    def _fish(self, name: str, *args):
        self._row()
        return fish_call(self._api, name, self._id, *args)
