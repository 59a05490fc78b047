"""Joint-law kernels, one file per joint model, found by listing this folder.

A model's kernel file (any ``<name>.py`` here not starting with ``_``) declares

- ``NAME``: the model name (``block contact jmodel assign NAME``),
- ``CODE``: its integer code, kept in the contacts store and in save files (never renumbered),
- ``NCOLS``: how many property columns it reads (columns 0, 1 are kn, ks for every model),
- ``NHIST``, ``HIST_NAMES``: its per-sub-contact history, ``h[s, :NHIST]`` (≤ ``NJHIST``): zeroed
  when a sub-contact is made without a predecessor and when ``jmodel assign`` gives its contact
  a model, carried over by identity at every detection (a sub-contact made anew on an old
  contact takes the area-weighted mean of that contact's old ones), saved and restored,
  written to the contacts VTK under those names and read from FISH by name;
- ``law(p, c, h, s, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state)``:
  a numba function of one sub-contact s of contact c, given the property rows ``p`` and the
  history rows ``h`` (it reads and writes ``h[s, :NHIST]``; a row view per call cost 17 % of
  the cycle), area, normal and shear displacement increments and its state (shear force
  already rotated with the plane, Eq. 23), returning
  ``(Fn, Fs0, Fs1, Fs2, un, udil, us0, us1, us2, state)``;
- optionally ``stiffness(p, c, h, s) -> (kn, ks)``: the sub-contact's current normal and shear
  stiffness [Pa/m], finite and ≥ 0, wherever the engine needs one (time step, mass scaling,
  strain energy, Rayleigh damping, eigenmodes, zoned contacts). Without it, columns 0 and 1.
- optionally ``stiffness_bound(p, c) -> (kn, ks)``: the largest normal and shear stiffness [Pa/m]
  the law can reach with contact c's properties (finite, ≥ 0), for a model whose stiffness grows
  with its state: the time step and the mass scaling take it instead of the stiffness now, so that
  a load applied at once cannot stiffen the joint beyond what the step was worked out for between
  two detections. Without it, the larger of columns 0, 1 and the stiffness now.

Its host file of the same name in ``dec3d/physics/joints`` declares the user-facing properties.
``joint_law(code, ...)`` calls the law of the model with that code, ``joint_stiffness(code,
...)`` its stiffness and ``joint_stiffness_bound(code, ...)`` its bound; each is a chain of small numba functions, one per model, built here at
import from the files found, so adding a model adds two files and edits none. The rigid cycle
and the zoned-contact pass take the law through ``joint_law_for(mask, …)``: a chain of the models
in use only (``cycle_mask``: theirs, elastic and mohr), compiled once per mask, so that a new law
costs its own decks compile time, not every deck. (The chain links are not cached themselves,
because they are closures sharing one name, the callers are; ``dec3d.kcache`` hashes this folder
with the rest of the kernels, so a new model recompiles them.)
"""
from __future__ import annotations

import importlib
import pkgutil

import numpy as np

from numba import njit, types
from numba.extending import overload

from ._common import NJHIST, P_KN, P_KS, ST_FAILED, ST_NEW, ST_SLIP, ST_TENSION, constant_stiffness

__all__ = ["ALL_MODELS", "BOUNDED_MODELS", "CODES", "COMMON_MODELS", "HISTORY_MODELS", "MODELS", "NJHIST", "NPROP", "P_KN", "P_KS",
           "ST_FAILED", "ST_NEW", "ST_SLIP", "ST_TENSION", "cycle_mask", "joint_law", "joint_law_for",
           "joint_stiffness", "joint_stiffness_bound", "model_mask", "prop_width"]


def _find():
    mods = []
    for info in pkgutil.iter_modules(__path__):
        if info.name.startswith("_"):
            continue
        mods.append(importlib.import_module(f"{__name__}.{info.name}"))
    mods.sort(key=lambda m: m.CODE)
    codes = [m.CODE for m in mods]
    names = [m.NAME for m in mods]
    if len(set(codes)) != len(codes) or len(set(names)) != len(names):
        raise ImportError(f"joint-law kernels: codes {codes} / names {names} must be unique")
    if max(codes) > 62:
        raise ImportError(f"joint-law kernels: codes {codes} must be below 63 (bits of one int64 mask)")
    for m in mods:
        if hasattr(m, "stiffness_bound") and not hasattr(m, "stiffness"):
            raise ImportError(f"joint model {m.NAME}: a stiffness_bound needs a stiffness hook (a model without "
                              f"one is linear: columns 0, 1 are its stiffness and its bound)")
        if not 0 <= m.NHIST <= NJHIST or len(m.HIST_NAMES) != m.NHIST:
            raise ImportError(f"joint model {m.NAME}: NHIST {m.NHIST} must be at most {NJHIST}, with one name "
                              f"each in HIST_NAMES")
    return mods


MODELS = tuple(_find())
#: code of each joint model by name
CODES = {m.NAME: m.CODE for m in MODELS}
#: property columns of the widest model (the most a contacts store's ``prop`` row holds; the store
#: holds only what the models in use read: ``prop_width``)
NPROP = max(m.NCOLS for m in MODELS)


def _link(i, models=MODELS):
    """``joint_law`` from model i of ``models`` on: its law when the code matches, else the next
    link; the last link answers every other code (codes are checked when a model is assigned)."""
    code = models[i].CODE
    law = models[i].law
    if i == len(models) - 1:
        @njit(inline="always")
        def last(model, p, c, h, s, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state):
            return law(p, c, h, s, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state)
        return last
    rest = _link(i + 1, models)

    @njit(inline="always")
    def link(model, p, c, h, s, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state):
        if model == code:
            return law(p, c, h, s, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state)
        return rest(model, p, c, h, s, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state)
    return link


def _stiffness_link(i):
    """``joint_stiffness`` from model i on (as ``_link``)."""
    code = MODELS[i].CODE
    hook = getattr(MODELS[i], "stiffness", constant_stiffness)
    if i == len(MODELS) - 1:
        @njit(inline="always")
        def last(model, p, c, h, s):
            return hook(p, c, h, s)
        return last
    rest = _stiffness_link(i + 1)

    @njit(inline="always")
    def link(model, p, c, h, s):
        if model == code:
            return hook(p, c, h, s)
        return rest(model, p, c, h, s)
    return link


def _bound_link(i):
    """``joint_stiffness_bound`` from model i on (as ``_link``); a model without the hook answers
    columns 0, 1."""
    code = MODELS[i].CODE
    hook = getattr(MODELS[i], "stiffness_bound", _columns)
    if i == len(MODELS) - 1:
        @njit(inline="always")
        def last(model, p, c):
            return hook(p, c)
        return last
    rest = _bound_link(i + 1)

    @njit(inline="always")
    def link(model, p, c):
        if model == code:
            return hook(p, c)
        return rest(model, p, c)
    return link


@njit(cache=True, inline="always")
def _columns(p, c):
    return p[c, P_KN], p[c, P_KS]


joint_law = _link(0)
joint_stiffness = _stiffness_link(0)
joint_stiffness_bound = _bound_link(0)


def model_mask(codes) -> int:
    """The bit mask of a set of joint-model codes (bit c for code c, c < 63), as ``joint_law_for``
    takes it; ``codes`` any iterable, or an integer array (one vectorized pass)."""
    if isinstance(codes, np.ndarray):
        return int(np.bitwise_or.reduce(np.left_shift(np.int64(1), codes.astype(np.int64)))) if codes.size else 0
    mask = 0
    for c in codes:
        mask |= 1 << int(c)
    return mask


#: the mask of every model found (``joint_law_for(ALL_MODELS, …)`` is ``joint_law``)
ALL_MODELS = model_mask(m.CODE for m in MODELS)
#: the mask of the models that keep a history (detection carries ``hist`` only when one is in use)
HISTORY_MODELS = model_mask(m.CODE for m in MODELS if m.NHIST)
#: the mask of the models that declare the largest stiffness they reach (``stiffness_bound``)
BOUNDED_MODELS = model_mask(m.CODE for m in MODELS if hasattr(m, "stiffness_bound"))
#: the models every compiled cycle holds (the two small founding laws): decks of elastic joints, of
#: mohr joints and of both then share one compiled cycle, as before the chain was per mask
COMMON_MODELS = model_mask(m.CODE for m in MODELS if m.NAME in ("elastic", "mohr"))


def prop_width(mask: int) -> int:
    """Property columns the models of the bit mask ``mask`` read: the widest one's ``NCOLS``, at least
    2 (kn, ks, which the engine reads on every contact). The contacts store's ``prop`` is this wide,
    not ``NPROP``: detection copies every contact's row, and MASON's 21 columns on every contact of
    a mohr-only model cost its detection a third more time."""
    w = 2
    for m in MODELS:
        if (mask >> m.CODE) & 1 and m.NCOLS > w:
            w = m.NCOLS
    return w


def cycle_mask(codes) -> int:
    """The mask a kernel is compiled for, for contacts of the joint-model ``codes`` (an int array):
    theirs and ``COMMON_MODELS``."""
    return model_mask(codes) | COMMON_MODELS


def joint_law_for(models, model, p, c, h, s, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2,
                  state):
    """``joint_law`` compiled for the models of the mask ``models`` only (a literal integer in the
    caller, ``model_mask``): a cycle over `mohr` joints compiles mohr's law, not every law in the
    folder (with all of them inlined the rigid cycle took three times as long to compile). Numba
    picks the chain when it types the call; a code outside the mask gets the mask's last law.
    (This body runs only as plain Python, ``NUMBA_DISABLE_JIT``: every model.)"""
    return joint_law(model, p, c, h, s, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state)


_CHAINS: dict = {}


@overload(joint_law_for, inline="always", jit_options={"cache": True})
def _joint_law_for(models, model, p, c, h, s, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2,
                   state):
    if not isinstance(models, types.IntegerLiteral):
        return None
    mask = int(models.literal_value)
    chain = _CHAINS.get(mask)
    if chain is None:
        chosen = tuple(m for m in MODELS if (mask >> m.CODE) & 1) or MODELS[:1]
        chain = _CHAINS[mask] = _link(0, chosen)

    def impl(models, model, p, c, h, s, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state):
        return chain(model, p, c, h, s, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state)
    return impl
