"""Zone constitutive-model kernels, one file per model, found by listing this folder.

A model's kernel file (any ``<name>.py`` here not starting with ``_``) declares

- ``NAME``: the model name (``block zone cmodel assign NAME``),
- ``CODE``: its integer code, kept in ``zones.cmodel`` and in save files (never renumbered),
- ``NCOLS``: how many columns of ``zones.prop`` it reads (columns 0-7 are shared by every model,
  ``_common.P_*``; from ``P_OWN`` on each model's own),
- ``NHIST``, ``HIST_NAMES``: its per-zone history entries (``zones.hist[z, :NHIST]``, zero when
  the model is assigned; saved, restored, written to VTK and readable from FISH by name),
- ``PLASTIC``: whether the model may yield (plastic-state counts; Rayleigh damping takes its zones
  as elastic), and ``CORRECTS`` (optional, default ``PLASTIC``): whether its update may return a
  mean-stress correction dsp that the step must average (its third sweep, nodal mixed
  discretization Eqs. 73-76): the plastic models, and the anisotropic elastic ones, whose deviatoric
  strain makes a mean stress that NMD must average to keep the stiffness symmetric,
- ``update(p, h, z, K, G, d0..d5, s0..s5, tab, wf, mw)``: a numba function of one zone, given the
  property rows ``p`` (nz, NZPROP) and history rows ``h`` (nz, NZHIST) of the zones and its row
  ``z``, its bulk and shear moduli K, G [Pa] (those the mass scaling uses), the strain increment
  d0..d5 of the step (xx yy zz xy xz yz; shear as tensor components, half the engineering strain;
  the volumetric part already averaged by the mixed discretization), the stress s0..s5 at the
  start of the step (rotated in large strain; tension positive, Pa), the ``Tables`` bundle ``tab``,
  a float scratch ``wf`` (NWORK,) kept between the zones of one chunk of the step (NaN at the start
  of each chunk; ``mohr-coulomb`` keeps the constants of its return there, keyed by wf[0:6], so any
  other model that writes ``wf`` leaves wf[0] NaN when it returns) and the Mohr-Coulomb return's
  scratch ``mw`` (``zone_mohr.mohr_work``);
  returning ``(bits, t0..t5, dsp)``: the "now" plastic bits (``_common``: 1 shear, 2 tension,
  16/32 the weak plane; 0 elastic), the new stress, and dsp = mean(trial) − mean(new), the
  trial being s + D:d with K and G (K times the plastic volumetric strain increment; 0 elastic).

Its host file of the same name in ``dec3d/physics/zmodels`` declares the user-facing properties.
``zone_update(code, ...)`` calls the update of the model with that code: a chain of small numba
functions, one per model, built here at import from the files found, so adding a model adds two
files and edits none. The zone step calls ``zone_update_for(models, code, ...)`` instead, whose
chain holds only the models of the literal mask ``models`` (``model_mask``): each deck compiles
(once, cached) the updates it uses. ``dec3d.kcache`` hashes this folder with the other kernels.
"""
from __future__ import annotations

import importlib
import pkgutil

from numba import njit, types
from numba.extending import overload

from ._common import NWORK, NZHIST, NZPROP, P_OWN, Tables, make_tables, merge_state, no_tables, table_value

__all__ = ["CODES", "CORRECTING_CODES", "MODELS", "model_mask", "zone_update_for", "NWORK", "NZHIST", "NZPROP", "P_OWN", "PLASTIC_CODES", "Tables", "make_tables",
           "merge_state", "no_tables", "table_value", "zone_update"]


def _find():
    mods = []
    for info in pkgutil.iter_modules(__path__):
        if info.name.startswith("_"):
            continue
        mods.append(importlib.import_module(f"{__name__}.{info.name}"))
    mods.sort(key=lambda m: m.CODE)
    codes = [m.CODE for m in mods]
    names = [m.NAME for m in mods]
    if len(set(codes)) != len(codes) or len(set(names)) != len(names) or 0 in codes:
        raise ImportError(f"zone-model kernels: codes {codes} / names {names} must be unique, and 0 is null")
    for m in mods:
        if m.NCOLS > NZPROP or m.NHIST > NZHIST or len(m.HIST_NAMES) != m.NHIST:
            raise ImportError(f"zone model '{m.NAME}': {m.NCOLS} columns (at most {NZPROP}), {m.NHIST} history "
                              f"entries (at most {NZHIST}) named {m.HIST_NAMES}")
    return mods


MODELS = tuple(_find())
#: code of each zone model by name
CODES = {m.NAME: m.CODE for m in MODELS}
#: codes of the models that may yield
PLASTIC_CODES = frozenset(m.CODE for m in MODELS if m.PLASTIC)
#: codes of the models whose update may return a mean-stress correction (the step's third sweep)
CORRECTING_CODES = frozenset(m.CODE for m in MODELS if getattr(m, "CORRECTS", m.PLASTIC))


def _link(i, models=MODELS):
    """``zone_update`` from model i of ``models`` on: its update when the code matches, else the
    next link; the last link answers every other code (null zones are never stepped; codes are
    checked when a model is assigned)."""
    code = models[i].CODE
    upd = models[i].update
    if i == len(models) - 1:
        @njit(inline="always")
        def last(model, p, h, z, K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5, tab, wf, mw):
            return upd(p, h, z, K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5, tab, wf, mw)
        return last
    rest = _link(i + 1, models)

    @njit(inline="always")
    def link(model, p, h, z, K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5, tab, wf, mw):
        if model == code:
            return upd(p, h, z, K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5, tab, wf, mw)
        return rest(model, p, h, z, K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5, tab, wf, mw)
    return link


zone_update = _link(0)


def model_mask(codes, correct: bool = False) -> int:
    """The bit mask of a set of model codes (bit c for code c; code 0, null, is never stepped), as
    ``zone_update_for`` and the zone step take it; bit 0 set when ``correct`` (some model returns a
    mean-stress correction: the step's third sweep)."""
    mask = 1 if correct else 0
    for c in codes:
        if int(c):
            mask |= 1 << int(c)
    return mask


def zone_update_for(models, model, p, h, z, K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5, tab, wf, mw):
    """``zone_update`` compiled for the models of the mask ``models`` only (a literal integer in the
    caller, ``model_mask``): a kernel that steps elastic zones compiles Hooke, not the plastic
    returns of every model in the folder. Numba picks the chain when it types the call."""
    raise NotImplementedError("zone_update_for is called from numba kernels only")


_CHAINS: dict = {}


@overload(zone_update_for, inline="always", jit_options={"cache": True})
def _zone_update_for(models, model, p, h, z, K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5, tab, wf, mw):
    if not isinstance(models, types.IntegerLiteral):
        return None
    mask = int(models.literal_value)
    chain = _CHAINS.get(mask)
    if chain is None:
        chosen = tuple(m for m in MODELS if (mask >> m.CODE) & 1) or MODELS[:1]
        chain = _CHAINS[mask] = _link(0, chosen)

    def impl(models, model, p, h, z, K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5, tab, wf, mw):
        return chain(model, p, h, z, K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5, tab, wf, mw)
    return impl
