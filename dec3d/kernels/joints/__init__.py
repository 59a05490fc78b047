"""Joint-law kernels, one file per joint model, found by listing this folder.

A model's kernel file (any ``<name>.py`` here not starting with ``_``) declares

- ``NAME``: the model name (``block contact jmodel assign NAME``),
- ``CODE``: its integer code, kept in the contacts store and in save files (never renumbered),
- ``NCOLS``: how many property columns it reads (columns 0, 1 are kn, ks for every model),
- ``law(p, c, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state)``: a numba
  function of one sub-contact, given the property rows ``p`` and its row ``c`` (the
  contact; a row view per call cost 17 % of the cycle), area, normal and shear displacement
  increments and its state (shear force already rotated with the plane, Eq. 23), returning
  ``(Fn, Fs0, Fs1, Fs2, un, udil, us0, us1, us2, state)``.

Its host file of the same name in ``dec3d/physics/joints`` declares the user-facing properties.
``joint_law(code, ...)`` calls the law of the model with that code; it is a chain of small numba
functions, one per model, built here at import from the files found, so adding a model adds two
files and edits none. (Compiled into the callers ``jointlaw.subcontact_update`` and
``gpcontact``; the chain links are not cached themselves, because they are closures sharing one
name, the callers are; ``dec3d.kcache`` hashes this folder with the rest of the kernels, so a
new model recompiles them.)
"""
from __future__ import annotations

import importlib
import pkgutil

from numba import njit

from ._common import P_KN, P_KS, ST_FAILED, ST_NEW, ST_SLIP, ST_TENSION

__all__ = ["CODES", "MODELS", "NPROP", "P_KN", "P_KS", "ST_FAILED", "ST_NEW", "ST_SLIP", "ST_TENSION", "joint_law"]


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
        def last(model, p, c, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state):
            return law(p, c, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state)
        return last
    rest = _link(i + 1)

    @njit(inline="always")
    def link(model, p, c, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state):
        if model == code:
            return law(p, c, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state)
        return rest(model, p, c, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state)
    return link


joint_law = _link(0)
