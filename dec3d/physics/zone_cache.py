"""What the zone stepper derives from the model, kept from one command to the next.

Every ``model cycle`` / ``model solve`` makes its own ``ZoneStepper`` (``physics.zones``). Most
of what it derives depends only on the mesh and the zones' models and properties — the property
checks and the moduli, the plans of the 4-node step (``kernels.zone_elastic.ElasticPlan``), the
real lumped masses, the zones' node stiffness (on the positions it is worked out on: in small
strain the positions, which the step leaves as they are; in large strain those of the last
detection step) — and at 1e6 zones making them again cost 0.3-0.5 s per command, paid by
every `model cycle 10` of a deck's FISH loop. The engine keeps a ``StepperCache`` (its
``_zcache``) and the stepper takes these parts from it when what they were made from is the same.

Nothing is trusted to say that an input changed: the cache keeps an exact copy of every input
(``see``: the zones' block, model, properties, node lists, overlay and set numbers, the links,
the positions the masses and stiffness are worked out on, the thread count, ...) and compares
the model's arrays with it bit for bit (same shape, dtype and bytes; ``same``) at each command
(the zones' properties, 160 B per zone, are kept as runs of equal rows, ``Runs``: a few rows
for a whole model whose properties were set by group or block).
An input that differs gets a new version; a derived entry (``get``) is made again unless the
versions of all it was made from are those it was made with. Whatever is cheap to derive (the
held components, applied velocities, the tables, quiet boundaries, body loads, gravity loads of
10-node zones, the grout stiffness of cables, the totals over linked gridpoints) is made again
at every command. Models with FE blocks take no cache (their stepper is made anew). Entries
hold arrays the stepper shares: the stepper copies those it changes (masses, stiffness).

The environment variable ``DEC3D_NO_STEPPER_CACHE=1`` (read at import) or ``ENABLED = False``
turns it off: every command then derives everything anew (tests compare the two, bench/
cycle_setup_bench.py times them).
"""
from __future__ import annotations

import itertools
import os

import numpy as np

#: the cache is used (``DEC3D_NO_STEPPER_CACHE=1`` at import, or False here: every command
#: derives everything anew)
ENABLED = os.environ.get("DEC3D_NO_STEPPER_CACHE", "").strip() in ("", "0")

_MISSING = object()
_COUNT = itertools.count(1)


def _bits(a: np.ndarray) -> np.ndarray:
    """``a`` seen as unsigned integers of its item size (bitwise comparison: NaN payloads and
    the sign of zero count); other dtypes as they are."""
    if a.dtype.kind in "fc" and a.dtype.itemsize in (1, 2, 4, 8):
        return a.view(f"u{a.dtype.itemsize}")
    return a


def same(a, b) -> bool:
    """``a`` and ``b`` are the same value: arrays of one shape and dtype with the same bytes, or
    equal scalars / tuples of one type (``a`` may be kept ``Runs``)."""
    if isinstance(a, Runs):
        return a.same(b)
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        if not (isinstance(a, np.ndarray) and isinstance(b, np.ndarray)):
            return False
        if a.shape != b.shape or a.dtype != b.dtype:
            return False
        return bool(np.array_equal(_bits(a), _bits(b)))
    if isinstance(a, tuple) or isinstance(b, tuple):
        return (type(a) is type(b) and len(a) == len(b)
                and all(same(x, y) for x, y in zip(a, b)))
    return type(a) is type(b) and a == b


#: most runs of equal rows ``Runs`` keeps (beyond: a plain copy)
MAX_RUNS = 256


class Runs:
    """An exact copy of a 2-D array kept as runs of equal rows (the zones' properties: a few
    distinct rows, set per group or block, for 1e6 zones): the start of each run and its row, in
    the bits of ``_bits``. ``of`` gives None when the array has more than MAX_RUNS runs."""

    def __init__(self, shape, dtype, starts, rows):
        self.shape, self.dtype, self.starts, self.rows = shape, dtype, starts, rows

    @classmethod
    def of(cls, a: np.ndarray):
        if a.ndim != 2 or not len(a):
            return None
        bits = _bits(a)
        new = np.flatnonzero((bits[1:] != bits[:-1]).any(axis=1)) + 1
        if len(new) >= MAX_RUNS:
            return None
        starts = np.concatenate(([0], new, [len(a)])).astype(np.int64)
        return cls(a.shape, a.dtype, starts, bits[starts[:-1]].copy())

    def same(self, a) -> bool:
        if not isinstance(a, np.ndarray) or a.shape != self.shape or a.dtype != self.dtype:
            return False
        bits = _bits(a)
        st = self.starts
        return all(bool((bits[st[i]:st[i + 1]] == self.rows[i]).all()) for i in range(len(st) - 1))


def _copy(x):
    if isinstance(x, tuple):
        return tuple(_copy(y) for y in x)
    return np.array(x, copy=True) if isinstance(x, np.ndarray) else x


class StepperCache:
    """Versioned copies of a zone stepper's inputs and the entries derived from them. ``off``:
    keeps nothing (every ``get`` builds)."""

    def __init__(self, off: bool = False):
        self.off = off
        #: name -> exact copy of the input as last seen
        self.kept: dict = {}
        #: name (input or entry) -> version: a new number whenever it changes
        self.version: dict = {}
        #: entry key -> (versions of its inputs when made, value)
        self.entries: dict = {}
        #: entries taken from the cache / made, since it was made (for tests and the bench)
        self.hits: list = []
        self.builds: list = []
        #: inputs seen and entries made or taken in this command (``begin``)
        self.now: set = set()

    def begin(self) -> None:
        """A new command: every input must be seen again before an entry made from it is taken."""
        self.now = set()
        for log in (self.hits, self.builds):     # (bookkeeping: the last commands' only, in a long FISH loop)
            if len(log) > 4096:
                del log[:-1024]

    def see(self, name: str, value, runs: bool = False) -> None:
        """The input ``name`` is ``value`` now: a new version when it differs from the kept copy.
        ``runs``: keep a 2-D array as runs of equal rows (``Runs``) when it has few."""
        if self.off:
            return
        self.now.add(name)
        old = self.kept.get(name, _MISSING)
        if old is _MISSING or not same(old, value):
            kept = Runs.of(value) if runs else None
            self.kept[name] = kept if kept is not None else _copy(value)
            self.version[name] = next(_COUNT)

    def get(self, key: str, deps: tuple, build, keep=None, valid=None):
        """The entry ``key`` made by ``build()`` from the inputs (or entries) ``deps``: the kept one
        when every dep has the version it was made with (and ``valid(value)``, when given, says
        it still fits what else it was made from), else made now (and kept unless ``keep(value)``
        says no). Each dep must have been ``see``-n (or made) in this command."""
        if self.off or not ENABLED:
            self.builds.append(key)
            return build()
        missing = [d for d in deps if d not in self.now]
        if missing:
            raise AssertionError(f"stepper cache: {key} needs {missing}, not seen in this command")
        self.now.add(key)
        vers = tuple(self.version[d] for d in deps)
        e = self.entries.get(key)
        if e is not None and e[0] == vers and (valid is None or valid(e[1])):
            self.hits.append(key)
            return e[1]
        self.entries.pop(key, None)
        self.builds.append(key)
        value = build()
        if keep is None or keep(value):
            self.entries[key] = (vers, value)
        self.version[key] = next(_COUNT)
        return value

def stepper_cache(eng) -> StepperCache:
    """The engine's cache for its zone stepper, begun for a new command; a cache that keeps
    nothing when the cache is off or the model has FE blocks."""
    from dec3d.model.feblocks import has_feblocks

    model = eng.model
    if not ENABLED or has_feblocks(model):
        eng._zcache = None
        return StepperCache(off=True)
    c = getattr(eng, "_zcache", None)
    if c is None or c.kept.get("_model") is not model:
        c = eng._zcache = StepperCache()
        c.kept["_model"] = model
    c.begin()
    return c
