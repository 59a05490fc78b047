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

Its host file of the same name in ``dec3d/physics/joints`` declares the user-facing properties.
``joint_law(code, ...)`` calls the law of the model with that code and ``joint_stiffness(code,
...)`` its stiffness; each is a chain of small numba functions, one per model, built here at
import from the files found, so adding a model adds two files and edits none. (Compiled into
the callers ``jointlaw.subcontact_update``, ``gpcontact``, ``energy``, ``rayleigh``; the chain
links are not cached themselves, because they are closures sharing one name, the callers are;
``dec3d.kcache`` hashes this folder with the rest of the kernels, so a new model recompiles them.)
"""
from __future__ import annotations

import importlib
import pkgutil

from numba import njit

from ._common import NJHIST, P_KN, P_KS, ST_FAILED, ST_NEW, ST_SLIP, ST_TENSION, constant_stiffness

__all__ = ["CODES", "MODELS", "NJHIST", "NPROP", "P_KN", "P_KS", "ST_FAILED", "ST_NEW", "ST_SLIP", "ST_TENSION", "joint_law", "joint_stiffness"]


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
    for m in mods:
        if not 0 <= m.NHIST <= NJHIST or len(m.HIST_NAMES) != m.NHIST:
            raise ImportError(f"joint model {m.NAME}: NHIST {m.NHIST} must be at most {NJHIST}, with one name "
                              f"each in HIST_NAMES")
    return mods


MODELS = tuple(_find())
#: code of each joint model by name
CODES = {m.NAME: m.CODE for m in MODELS}
#: property columns of the widest model (the contacts store's ``prop`` width)
NPROP = max(m.NCOLS for m in MODELS)


def _link(i):
    """``joint_law`` from model i on: its law when the code matches, else the next link; the
    last link answers every other code (codes are checked when a model is assigned)."""
    code = MODELS[i].CODE
    law = MODELS[i].law
    if i == len(MODELS) - 1:
        @njit(inline="always")
        def last(model, p, c, h, s, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state):
            return law(p, c, h, s, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state)
        return last
    rest = _link(i + 1)

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


joint_law = _link(0)
joint_stiffness = _stiffness_link(0)
