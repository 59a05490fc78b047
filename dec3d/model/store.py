"""Growable struct-of-arrays store: the one container shape of every entity.

A store holds named numpy arrays that share a leading *capacity* dimension. Rows
``0 .. n-1`` are live; rows beyond are spare room. Appending past the capacity
doubles it (``grow``); deleting rows is ``compact(keep)``, which packs the live rows
in their original order and returns the old-row -> new-row remap (``-1`` for rows
that went away) so that other stores can fix their indices.

Kernels get arrays, never stores: ``store.live("pos")`` is a view of the live rows.
A view goes stale when the store grows; take it again after any append.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Field:
    """One column family of a store: trailing shape, dtype and the value of a fresh row."""

    shape: tuple[int, ...] = ()
    dtype: type | np.dtype = np.float64
    fill: object = 0


class Store:
    """Named arrays with a leading capacity dimension and ``n`` live rows."""

    def __init__(self, name: str, fields: dict[str, Field], capacity: int = 16):
        self.name = name
        self.n = 0
        self._fields: dict[str, Field] = {}
        self._data: dict[str, np.ndarray] = {}
        self._capacity = max(1, int(capacity))
        self._retired: dict[str, tuple[np.ndarray, int]] = {}   # arrays ``install`` replaced (and their rows in use)
        self._dirty: dict[str, int] = {}
        for key, spec in fields.items():
            self.add_field(key, spec)

    # ----------------------------------------------------------------- schema
    @property
    def capacity(self) -> int:
        return self._capacity

    @property
    def fields(self) -> dict[str, Field]:
        return dict(self._fields)

    def add_field(self, key: str, spec: Field) -> None:
        """Add a column family; existing rows get the fill value. Re-adding is an error."""
        if key in self._fields:
            raise KeyError(f"store '{self.name}' already has a field '{key}'")
        arr = np.empty((self._capacity, *spec.shape), dtype=spec.dtype)
        arr[...] = spec.fill
        self._fields[key] = spec
        self._data[key] = arr

    def resize_field(self, key: str, shape: tuple[int, ...]) -> None:
        """Change the trailing shape of a field (e.g. one more group slot), keeping overlap."""
        spec = self._fields[key]
        old = self._data[key]
        new = np.empty((self._capacity, *shape), dtype=spec.dtype)
        new[...] = spec.fill
        common = tuple(slice(0, min(a, b)) for a, b in zip(old.shape[1:], shape))
        new[(slice(None), *common)] = old[(slice(None), *common)]
        self._fields[key] = Field(tuple(shape), spec.dtype, spec.fill)
        self._data[key] = new

    # ----------------------------------------------------------------- access
    def __contains__(self, key: str) -> bool:
        return key in self._data

    def full(self, key: str) -> np.ndarray:
        """The whole array, spare rows included."""
        return self._data[key]

    def live(self, key: str) -> np.ndarray:
        """A view of the live rows of one field."""
        return self._data[key][: self.n]

    def __getitem__(self, key: str) -> np.ndarray:
        return self.live(key)

    def __len__(self) -> int:
        return self.n

    # ------------------------------------------------------------- resizing
    def grow(self, min_capacity: int) -> None:
        """Make room for at least ``min_capacity`` rows, doubling the capacity."""
        if min_capacity <= self._capacity:
            return
        cap = self._capacity
        while cap < min_capacity:
            cap *= 2
        for key, spec in self._fields.items():
            old = self._data[key]
            new = np.empty((cap, *old.shape[1:]), dtype=old.dtype)
            new[: self.n] = old[: self.n]
            new[self.n:] = spec.fill
            self._data[key] = new
        self._capacity = cap

    def append(self, count: int) -> slice:
        """Add ``count`` rows filled with each field's fill value; return their slice."""
        count = int(count)
        start = self.n
        self.grow(start + count)
        for key, spec in self._fields.items():
            self._data[key][start:start + count] = spec.fill
        self.n = start + count
        return slice(start, start + count)

    def blank(self, count: int, keys) -> dict[str, np.ndarray]:
        """Arrays, not filled, for the fields ``keys`` of a store of ``count`` rows (the capacity
        doubled as ``grow`` would until they fit), to be written and handed to ``install``: a
        caller can build the new rows from the old ones without a copy. The arrays an earlier
        ``install`` replaced are handed out again when their capacity fits (no new memory)."""
        cap = self._capacity
        while cap < count:
            cap *= 2
        out = {}
        for key in keys:
            spec = self._fields[key]
            old, dirty = self._retired.pop(key, (None, 0))
            if old is not None and old.shape == (cap, *spec.shape) and old.dtype == spec.dtype:
                out[key] = old
            else:
                out[key] = np.empty((cap, *spec.shape), dtype=spec.dtype)
                dirty = cap
            self._dirty[key] = dirty        # rows from which on all are the fill value
        return out

    def install(self, count: int, arrays: dict[str, np.ndarray]) -> None:
        """Make ``count`` rows live, the fields in ``arrays`` (from ``blank``, their first ``count``
        rows written) taking those arrays; the other fields' rows and every spare row get the fill
        value (as ``clear`` then ``append(count)``, without filling the rows given). The arrays
        replaced are kept for the next ``blank``."""
        count = int(count)
        cap = self._capacity
        while cap < count:
            cap *= 2
        for key, spec in self._fields.items():
            arr = arrays.get(key)
            if arr is None:
                if cap == self._capacity:
                    arr = self._data[key]
                    arr[: max(count, self.n)] = spec.fill
                else:
                    arr = np.empty((cap, *spec.shape), dtype=spec.dtype)
                    arr[...] = spec.fill
            else:
                if arr.shape != (cap, *spec.shape) or arr.dtype != spec.dtype:
                    raise ValueError(f"store '{self.name}': field '{key}' needs shape {(cap, *spec.shape)} "
                                     f"{np.dtype(spec.dtype)}, got {arr.shape} {arr.dtype}")
                arr[count:self._dirty.pop(key, cap)] = spec.fill
                self._retired[key] = (self._data[key], self.n)
            self._data[key] = arr
        self._capacity = cap
        self.n = count

    def compact(self, keep: np.ndarray) -> np.ndarray:
        """Drop the live rows where ``keep`` is False, keeping order.

        Returns ``remap`` (int64, length of the old ``n``): new row of each old row, or -1.
        Spare rows are reset to the fill value so that stale data never leaks back in.
        """
        keep = np.asarray(keep, dtype=bool)
        if keep.shape != (self.n,):
            raise ValueError(f"keep mask has shape {keep.shape}, store '{self.name}' has {self.n} rows")
        remap = np.full(self.n, -1, dtype=np.int64)
        rows = np.flatnonzero(keep)
        remap[rows] = np.arange(rows.size, dtype=np.int64)
        if rows.size != self.n:
            for key, spec in self._fields.items():
                arr = self._data[key]
                arr[: rows.size] = arr[rows]
                arr[rows.size: self.n] = spec.fill
        self.n = int(rows.size)
        return remap

    def clear(self) -> None:
        self.compact(np.zeros(self.n, dtype=bool))

    # ------------------------------------------------------------ save/load
    def to_arrays(self) -> dict[str, np.ndarray]:
        """The live rows of every field, C-contiguous (for save files). Views where the rows already are
        contiguous (most fields): copy them before the store changes if they must outlive that."""
        return {key: np.ascontiguousarray(self._data[key][: self.n]) for key in self._fields}

    def load_arrays(self, arrays: dict[str, np.ndarray]) -> None:
        """Replace the contents by ``arrays`` (each with the same number of rows)."""
        sizes = {a.shape[0] for a in arrays.values()}
        if len(sizes) > 1:
            raise ValueError(f"store '{self.name}': arrays of different lengths {sorted(sizes)}")
        n = sizes.pop() if sizes else 0
        for key, arr in arrays.items():
            if key not in self._fields:
                raise KeyError(f"store '{self.name}' has no field '{key}'")
            spec = self._fields[key]
            if arr.shape[1:] != spec.shape:
                self.resize_field(key, arr.shape[1:])
        self.n = 0
        self.grow(n)
        for key, spec in self._fields.items():
            self._data[key][...] = spec.fill
            if key in arrays:
                self._data[key][:n] = arrays[key]
        self.n = n
