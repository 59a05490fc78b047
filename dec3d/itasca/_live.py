"""Read-only views of store arrays that know when they went stale.

``live(api, store, key)`` gives the live rows of a store field as a ``LiveArray``: a numpy array over the
model's own memory (zero copy, ``flags.writeable`` False) whose every read first checks that the model
state, the store's array and its row count are still those it was taken from. Cycling changes values in
place, so a view taken before `model cycle` shows the values after it; `model new`, `model restore`, or
rows made or deleted (which reallocate or shift the store) make it raise ``StaleError`` — never old data.

Results of arithmetic on a view are plain arrays (copies); ``np.asarray(view)`` gives a plain array over
the same memory without the check (numpy gives subclasses no hook there).

Setters (``put``) check the shape (exactly the store's: no broadcasting), the dtype (numbers) and that
every value is finite, then write into the store.
"""
from __future__ import annotations

import numpy as np

from ._bind import Model, StaleError


class LiveArray(np.ndarray):
    """A read-only, checked view of model data (see the module docstring)."""

    _check = None

    def __array_finalize__(self, obj):
        self._check = getattr(obj, "_check", None)

    def _ok(self):
        c = self._check
        if c is not None:
            c()

    def __getitem__(self, key):
        self._ok()
        out = super().__getitem__(key)
        return out

    def __array_ufunc__(self, ufunc, method, *inputs, **kwargs):
        args = []
        for x in inputs:
            if isinstance(x, LiveArray):
                x._ok()
                x = x.view(np.ndarray)
            args.append(x)
        if "out" in kwargs:
            kwargs["out"] = tuple(o.view(np.ndarray) if isinstance(o, LiveArray) else o for o in kwargs["out"])
        return getattr(ufunc, method)(*args, **kwargs)

    def __array_function__(self, func, types, args, kwargs):
        def plain(x):
            if isinstance(x, LiveArray):
                x._ok()
                return x.view(np.ndarray)
            if isinstance(x, (list, tuple)):
                return type(x)(plain(v) for v in x)
            return x
        return func(*plain(args), **{k: plain(v) for k, v in kwargs.items()})

    def __repr__(self):
        self._ok()
        return repr(self.view(np.ndarray))

    def __str__(self):
        self._ok()
        return str(self.view(np.ndarray))

    def __iter__(self):
        self._ok()
        return iter(self.view(np.ndarray))

    def __len__(self):
        self._ok()
        return super().__len__()

    def __reduce__(self):
        self._ok()
        return self.view(np.ndarray).copy().__reduce__()

    def tolist(self):
        self._ok()
        return self.view(np.ndarray).tolist()

    def copy(self, order="C"):
        self._ok()
        return np.array(self.view(np.ndarray), order=order, copy=True)

    def __float__(self):
        self._ok()
        return float(self.view(np.ndarray))

    def __int__(self):
        self._ok()
        return int(self.view(np.ndarray))


def _checker(api: Model, store_name: str, key: str, what: str):
    state = api.session.model
    store = state.store(store_name)
    full, n = store.full(key), store.n

    def check():
        now = api.session.model
        if now is not state:
            raise StaleError(f"this {what} array belongs to a model state that is gone (`model new` or "
                             "`model restore` ran since it was taken); take it again")
        try:
            st = now.store(store_name)
        except KeyError:
            st = None
        if st is not store or st.full(key) is not full or st.n != n:
            m = st.n if st is not None else 0
            raise StaleError(f"this {what} array is out of date: the model's {store_name} changed since it was "
                             f"taken ({n} rows then, {m} now); take it again")
    return check


def live(api: Model, store_name: str, key: str, what: str, cols=None) -> LiveArray:
    """The live rows of field ``key`` of a store (columns ``cols`` of the trailing axis when given), as a
    checked read-only view."""
    store = api.session.model.store(store_name)
    base = store.live(key)
    if cols is not None:
        base = base[..., cols]
    view = base.view(LiveArray)
    view.flags.writeable = False
    view._check = _checker(api, store_name, key, what)
    return view


def plain(x) -> np.ndarray:
    """A setter's value as a float64 array (TypeError for anything that is not numbers)."""
    try:
        a = np.asarray(x)
    except Exception as exc:                          # ragged lists and the like
        raise TypeError(f"expected an array of numbers: {exc}") from None
    if a.dtype == object or not (np.issubdtype(a.dtype, np.number) or a.dtype == np.bool_):
        raise TypeError(f"expected an array of numbers, got dtype {a.dtype}")
    return a.astype(np.float64)


def put(api: Model, store_name: str, key: str, value, what: str, shape_tail=None) -> None:
    """Write ``value`` into the live rows of a store field after checking shape (no broadcast), numbers
    and finiteness."""
    store = api.session.model.store(store_name)
    target = store.live(key)
    tail = target.shape[1:] if shape_tail is None else shape_tail
    want = (store.n, *tail)
    a = plain(value)
    if a.shape != want:
        one = {"blocks": "block", "vertices": "gridpoint", "zones": "zone"}.get(store_name, store_name)
        raise ValueError(f"{what}: expected an array of shape {want} (one row per {one}), got {a.shape}")
    bad = ~np.isfinite(a)
    if bad.any():
        row = int(np.argwhere(bad)[0][0])
        raise ValueError(f"{what}: row {row} holds a value that is not finite ({a[row].tolist()})")
    target[...] = a.reshape(target.shape)
