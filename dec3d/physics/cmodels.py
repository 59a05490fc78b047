"""Zone constitutive models: the registry, and the host files of the models (``physics/zmodels``).

A zone model is two files: its kernel ``dec3d/kernels/zmodels/<name>.py`` (the update of one zone,
its code, columns and history; see that package's text) and its host
``dec3d/physics/zmodels/<name>.py``, which calls ``zmodel`` once with the kernel module, the
model's property keywords (each with the ``zones.prop`` column it fills and how a user value
becomes a column value: angles in degrees → tangents, table names → table numbers), and, where
the model needs them, a check of its properties before cycling, the strength reduction of
``model factor-of-safety`` and the moduli its mass scaling takes. The same declaration drives
``block zone cmodel assign`` (model names), ``block zone property`` (keywords, ranges, units,
which zones take a property), the command reference, the check when cycling starts, save
files (known codes), VTK and FISH (history names).

Columns 0-7 are shared (``kernels.zmodels._common``: bulk, shear, density, cohesion, tan friction,
tension, tan dilation, strength-reduction factor): a shared property set on a zone whose model
does not declare it is still kept (it waits there for a later ``cmodel assign``, as decks that set
moduli before the model expect). Columns from ``P_OWN`` on are each model's own: a model's own
property is set only on the zones of the models that declare it, and assigning a model resets
those columns to its defaults and zeroes the zone's history (the stress is kept).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from dec3d.config import DENSITY_LIMIT, MODULUS_LIMIT
from dec3d.io.state import register_known
from dec3d.physics.modelprops import ModelProp, atan_deg, tan_deg
from dec3d.kernels.zmodels import MODELS as KERNELS
from dec3d.kernels.zmodels import NZPROP, P_OWN
from dec3d.kernels.zmodels._common import (P_BULK, P_COHESION, P_DENSITY, P_SHEAR, P_SRF, P_TANDIL, P_TANFRIC,
                                           P_TENSION)

__all__ = ["MOHR_COLUMNS", "MOHR_NAMES", "coulomb_reduce", "coulomb_rules", "ALL_PROPS", "MODEL_BY_CODE", "Prop", "ZONE_MODELS", "ZoneModel", "angle", "table", "zmodel",
           "ELASTIC", "MOHR_STRENGTH", "P_BULK", "P_SHEAR", "P_DENSITY", "P_COHESION", "P_TANFRIC", "P_TENSION",
           "P_TANDIL", "P_SRF", "P_OWN", "NZPROP", "which_zones"]


@dataclass(frozen=True)
class Prop(ModelProp):
    """One property keyword of a zone model: ``block zone property <name> <value>`` (``ModelProp``;
    ``default`` is the column value when the model is assigned, own columns only)."""
    #: "number", "angle" (degrees kept as a tangent) or "table" (a table's name or number,
    #: kept as its index + 1 in the model's list of zone tables; 0 none)
    kind: str = "number"


def angle(name, column, doc, hi=90.0, hi_open=True, **kw) -> Prop:
    """An angle in degrees in [0, hi), kept as its tangent."""
    return Prop(name, column, doc, "deg", tan_deg, atan_deg, hi=hi, hi_open=hi_open, kind="angle", **kw)


def table(name, column, doc) -> Prop:
    """A table reference (the ``table`` command's id or name)."""
    return Prop(name, column, doc, None, float, float, 0.0, None, None, kind="table")


#: the shared properties: elastic moduli and density (``young``/``poisson`` are converted to
#: bulk and shear by ``block zone property`` for every model that declares bulk and shear)
ELASTIC = [Prop("bulk", P_BULK, "bulk modulus K", "Pa", lo=0.0, lo_open=True, hi=MODULUS_LIMIT),
           Prop("shear", P_SHEAR, "shear modulus G", "Pa", lo=0.0, lo_open=True, hi=MODULUS_LIMIT),
           Prop("density", P_DENSITY, "mass density", "kg/m³", lo=0.0, lo_open=True, hi=DENSITY_LIMIT)]
#: the Mohr-Coulomb strength (shared columns, read by every Mohr-Coulomb-like model)
MOHR_STRENGTH = [Prop("cohesion", P_COHESION, "cohesion c", "Pa"),
                 angle("friction", P_TANFRIC, "friction angle φ"),
                 Prop("tension", P_TENSION, "tensile strength σt (capped at c/tan φ)", "Pa"),
                 angle("dilation", P_TANDIL, "dilation angle ψ ≤ φ")]


#: the columns of the shared Mohr-Coulomb strength (c, tan φ, σt, tan ψ) and their keywords
MOHR_COLUMNS = (P_COHESION, P_TANFRIC, P_TENSION, P_TANDIL)
MOHR_NAMES = ("c", "friction", "tension", "dilation")     # (c: as the warnings have always said)


def coulomb_rules(p, ids, cols=MOHR_COLUMNS, names=MOHR_NAMES, dilation_rows=None, tension_rows=None):
    """(problems, warnings) of one Coulomb strength in columns ``cols`` (c, tan φ, σt, tan ψ, named
    ``names``) of rows ``p`` (Itasca's Mohr-Coulomb rules): a dilation above the friction is refused;
    a tension above the apex c/tan φ is used as the apex value, with a warning. ``dilation_rows`` /
    ``tension_rows``: the rows each rule applies to (default all; strain-softening leaves out the
    rows whose values come from tables)."""
    c, tf, t, td = (p[:, k] for k in cols)
    problems, warnings = [], []
    bad = td > tf * (1.0 + 1e-12)
    if dilation_rows is not None:
        bad &= dilation_rows
    if bad.any():
        problems.append(f"{names[3]} must not exceed {names[1]}: {which_zones(ids, bad)}")
    with np.errstate(divide="ignore", invalid="ignore"):
        apex = np.where(tf > 0.0, c / np.where(tf > 0.0, tf, 1.0), np.inf)
    over = t > apex
    if tension_rows is not None:
        over &= tension_rows
    if over.any():
        warnings.append(f"{names[2]} above {names[0]}/tan({names[1]}) in {which_zones(ids, over)}: the apex value "
                        f"{names[0]}/tan({names[1]}) is used as the tensile strength")
    return problems, warnings


def coulomb_reduce(q, F, cols=MOHR_COLUMNS) -> None:
    """One Coulomb strength of rows ``q`` divided by F in place (``model factor-of-safety``, as
    FLAC3D and 3DEC reduce it): c/F, tan φ/F, σt/F, and tan ψ at most the reduced tan φ."""
    c, tf, t, td = cols
    q[:, c] /= F
    q[:, tf] /= F
    q[:, t] /= F
    q[:, td] = np.minimum(q[:, td], q[:, tf])


def which_zones(ids, bad: np.ndarray, blocks=None) -> str:
    """'n zone(s) (id, id, … and k more)' for the rows where ``bad`` holds, with 'of blocks …'
    when the zones' block ids ``blocks`` are given."""
    rows = np.flatnonzero(bad)
    shown = ", ".join(str(int(ids[r])) for r in rows[:5])
    more = f" and {len(rows) - 5} more" if len(rows) > 5 else ""
    where = ""
    if blocks is not None:
        bs = sorted(set(int(b) for b in np.asarray(blocks)[rows]))
        where = " of blocks " + ", ".join(str(b) for b in bs[:10]) + (f" … ({len(bs)} blocks)" if len(bs) > 10 else "")
    return f"{len(rows)} zone(s){where} ({shown}{more})"


@dataclass
class ZoneModel:
    name: str
    code: int
    doc: str
    kernel: object
    props: dict[str, Prop] = field(default_factory=dict)
    #: check(prop_rows (n, NZPROP), ids (n,)) -> (problems, warnings): cross-property rules
    #: before cycling (each property's own range is checked by the registry)
    check: Callable | None = None
    #: reduce(prop_rows (n, NZPROP), F) -> rows with the strengths divided by F (``model
    #: factor-of-safety``); None: the model has no strength to reduce
    reduce: Callable | None = None
    #: moduli(prop_rows) -> (K (n,), G (n,)) for the mass scaling and time step; None: columns 0, 1
    moduli: Callable | None = None
    #: other names ``block zone cmodel assign`` takes for this model
    aliases: tuple[str, ...] = ()

    @property
    def hist_names(self) -> tuple[str, ...]:
        return tuple(self.kernel.HIST_NAMES)

    @property
    def plastic(self) -> bool:
        return bool(self.kernel.PLASTIC)

    def own(self) -> list[Prop]:
        return [p for p in self.props.values() if p.column >= P_OWN]

    def assign_row(self, rows: np.ndarray) -> None:
        """Own columns of ``rows`` (k, NZPROP) to this model's defaults, in place."""
        rows[:, P_OWN:] = 0.0
        for p in self.own():
            rows[:, p.column] = p.default

    def value(self, row: np.ndarray, name: str) -> float:
        p = self.props[name]
        return p.from_column(row[p.column])

    def bulk_shear(self, prop_rows: np.ndarray):
        if self.moduli is not None:
            return self.moduli(prop_rows)
        return prop_rows[:, P_BULK], prop_rows[:, P_SHEAR]

    def problems(self, prop_rows: np.ndarray, ids, blocks=None) -> tuple[list[str], list[str]]:
        """(problems, warnings) of the zones ``prop_rows`` of this model before cycling: every
        property in its range (in user units), then the model's own ``check``; ``ids`` the zone
        ids, ``blocks`` their block ids (named in the messages when given)."""
        out: list[str] = []
        seen = set()
        for p in self.props.values():
            if p.kind == "table" or p.column in seen:       # (a second name of a column: checked once)
                continue
            seen.add(p.column)
            col = prop_rows[:, p.column]
            with np.errstate(all="ignore"):
                v = np.array([p.from_column(x) for x in col]) if p.kind == "angle" else col
                bad = ~np.isfinite(v)
                if p.lo is not None:
                    bad |= (v <= p.lo) if p.lo_open else (v < p.lo)
                if p.hi is not None:
                    bad |= (v >= p.hi) if p.hi_open else (v > p.hi)
            if bad.any():
                unset = " (not set)" if p.default == 0.0 and (col[bad] == 0.0).all() else ""
                out.append(f"{p.name} {_range_text(p)}{unset}: {which_zones(ids, bad, blocks)}")
        warns: list[str] = []
        if not out and self.check is not None:
            more, warns = self.check(prop_rows, ids)
            out += more
        return out, warns


def _range_text(p: Prop) -> str:
    lo = "" if p.lo is None else (f"> {p.lo:g}" if p.lo_open else f">= {p.lo:g}")
    hi = "" if p.hi is None else (f"< {p.hi:g}" if p.hi_open else f"<= {p.hi:g}")
    rule = " and ".join(x for x in (lo, hi) if x) or "finite"
    return f"must be {rule}" + (f" {p.units}" if p.units else "")


ZONE_MODELS: dict[str, ZoneModel] = {}
MODEL_BY_CODE: dict[int, ZoneModel] = {}


def zmodel(kernel, doc: str, props: list[Prop], check=None, reduce=None, moduli=None,
           aliases: tuple[str, ...] = ()) -> ZoneModel:
    """Register a zone model: ``kernel`` is its module in ``dec3d/kernels/zmodels`` (name, code)."""
    name, code = kernel.NAME, kernel.CODE
    if name in ZONE_MODELS or code in MODEL_BY_CODE:
        raise ValueError(f"zone model '{name}' (code {code}) registered twice")
    for p in props:
        if not 0 <= p.column < max(kernel.NCOLS, P_OWN):
            raise ValueError(f"zone model '{name}': property {p.name} in column {p.column}, the kernel reads "
                             f"{kernel.NCOLS}")
        for other in ZONE_MODELS.values():
            q = other.props.get(p.name)
            if q is not None and p.column < P_OWN and q.column != p.column:
                raise ValueError(f"zone model '{name}': shared property {p.name} in column {p.column}, "
                                 f"'{other.name}' has it in {q.column}")
    m = ZoneModel(name, code, doc, kernel, {p.name: p for p in props}, check, reduce, moduli, tuple(aliases))
    ZONE_MODELS[name] = m
    MODEL_BY_CODE[code] = m
    register_known(zone_models={name}, zone_model_codes={code})      # what a save file may name
    return m


def _load_hosts() -> None:
    """Import every host file of ``physics/zmodels`` (each registers its model) and check that
    each zone-model kernel has its host."""
    import importlib
    import pkgutil

    from dec3d.physics import zmodels

    for info in pkgutil.iter_modules(zmodels.__path__):
        if not info.name.startswith("_"):
            importlib.import_module(f"{zmodels.__name__}.{info.name}")
    missing = [k.NAME for k in KERNELS if k.NAME not in ZONE_MODELS]
    if missing:
        raise ImportError(f"zone-model kernels without a host file in dec3d/physics/zmodels: {missing}")


_load_hosts()

#: model names ``block zone cmodel assign`` takes (aliases too), with null
MODEL_NAMES: dict[str, int] = {"null": 0}
for _m in ZONE_MODELS.values():
    MODEL_NAMES[_m.name] = _m.code
    for _a in _m.aliases:
        MODEL_NAMES[_a] = _m.code
#: every property keyword of every model, first declaration wins (shared ones agree)
ALL_PROPS: dict[str, Prop] = {}
for _m in sorted(ZONE_MODELS.values(), key=lambda m: m.code):
    for _p in _m.props.values():
        ALL_PROPS.setdefault(_p.name, _p)


def models_with(prop: str) -> list[ZoneModel]:
    """The models that declare property ``prop``."""
    return [m for m in ZONE_MODELS.values() if prop in m.props]
