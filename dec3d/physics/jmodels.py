"""Joint constitutive models: the registry, and the host files of the models (``physics/joints``).

A joint model is two files: its kernel ``dec3d/kernels/joints/<name>.py`` (the law, its code and
its columns) and its host ``dec3d/physics/joints/<name>.py``, which calls ``jmodel`` once with the
kernel module and the model's property names with the kernel column each one fills
and how a user value becomes a column value (angles in degrees → tangents). The same
declaration drives ``block contact property`` checking, the command reference and the
save file (contacts keep ``jmodel`` code and ``prop`` row).

Columns left unset hold their declared default; a property with a ``fallback`` (mohr's
``friction-residual``) left unset holds NaN, which the kernel reads as "the peak friction" so that setting `friction` later moves
the residual friction with it, as 3DEC does.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from dec3d.io.state import register_known
from dec3d.physics.modelprops import ModelProp, atan_deg, tan_deg

from dec3d.kernels.joints import MODELS as KERNELS
from dec3d.kernels.joints import NJHIST, NPROP, P_KN, P_KS
from dec3d.kernels.jointlaw import raise_to_bound, subcontact_stiffness


@dataclass(frozen=True)
class Prop(ModelProp):
    """A joint model's property (``ModelProp``: name, column, units, conversions, range)."""
    #: property whose value this one shows while it holds NaN (unset residual friction: the friction)
    fallback: str | None = None
    #: the model cannot run without it: its column holds NaN until set, and cycling stops naming
    #: the contacts that lack it (``missing``)
    required: bool = False

    def __post_init__(self):
        super().__post_init__()
        if self.required:
            object.__setattr__(self, "default", math.nan)


def angle(name, column, doc, hi_open=True, **kw) -> Prop:
    """An angle property: degrees in [0, 90), kept as its tangent. Above 90° the tangent turns
    negative (a block would slide that 30° holds)."""
    return Prop(name, column, doc, "deg", tan_deg, atan_deg, hi=90.0, hi_open=hi_open, **kw)


# friction 90 is a 3DEC idiom for "never slips" (shared decks use it): tan 90° in floating point is
# 1.6e16, finite, so 90 itself is accepted for the friction angles; the dilation angle stays below 90


@dataclass
class JointModel:
    name: str
    code: int
    doc: str
    props: dict[str, Prop] = field(default_factory=dict)
    #: names of its history entries (the kernel's ``HIST_NAMES``: VTK arrays, FISH)
    hist_names: tuple[str, ...] = ()
    #: ``reduce(rows, F, associated)``: divide the strengths of property rows (k, NPROP) by F in place
    #: (``model factor-of-safety``); None: the model has no strength to reduce
    reduce: object = None

    def row(self, values: dict[str, float] | None = None, width: int = NPROP) -> np.ndarray:
        """Kernel property row with every column at its default, then ``values`` applied; ``width``
        columns (the contacts store's, at least the model's own; zero beyond the model's)."""
        r = np.zeros(width)
        for p in self.props.values():
            r[p.column] = p.default
        if values:
            self.apply(r, values)
        return r

    def apply(self, rows: np.ndarray, values: dict[str, float]) -> None:
        """Write user values (user units) into one row (NPROP,) or many rows (k, NPROP)."""
        for k, v in values.items():
            p = self.props[k]
            rows[..., p.column] = p.to_column(float(v))

    def value(self, row: np.ndarray, name: str) -> float:
        p = self.props[name]
        x = row[p.column]
        if p.fallback is not None and x != x:
            x = row[self.props[p.fallback].column]
        return p.from_column(x)


JOINT_MODELS: dict[str, JointModel] = {}
MODEL_BY_CODE: dict[int, JointModel] = {}
#: other names a model answers to (``jmodel assign``, ``material-table ... jmodel``): alias → model
ALIASES: dict[str, str] = {}
#: names refused with a reason (e.g. a plugin version whose properties differ from ours): name → message
REFUSED: dict[str, str] = {}


def jmodel(kernel, doc: str, props: list[Prop], aliases=(), refused=None, reduce=None) -> JointModel:
    """Register a joint model: ``kernel`` is its module in ``dec3d/kernels/joints`` (name, code).
    ``aliases``: other names that mean this model; ``refused``: {name: why} for names that look
    like it but are not (they stop with that message); ``reduce(rows, F, associated)``: its
    strengths divided by F in property rows (k, NPROP), in place, for `model factor-of-safety`."""
    name, code = kernel.NAME, kernel.CODE
    if name in JOINT_MODELS or code in MODEL_BY_CODE:
        raise ValueError(f"joint model '{name}' (code {code}) registered twice")
    for a in (*aliases, *(refused or {})):
        if a in JOINT_MODELS or a in ALIASES or a in REFUSED:
            raise ValueError(f"joint model '{name}': the name '{a}' is taken")
    for p in props:
        if not 0 <= p.column < kernel.NCOLS:
            raise ValueError(f"joint model '{name}': property {p.name} in column {p.column}, the kernel reads "
                             f"{kernel.NCOLS}")
    m = JointModel(name, code, doc, {p.name: p for p in props}, tuple(kernel.HIST_NAMES), reduce)
    JOINT_MODELS[name] = m
    MODEL_BY_CODE[code] = m
    ALIASES.update({a: name for a in aliases})
    REFUSED.update(refused or {})
    register_known(joint_models={name}, joint_model_codes={code})     # what a save file may name
    return m


#: the stiffnesses every model has (columns 0, 1 of every kernel)
STIFFNESS = [Prop("stiffness-normal", P_KN, "normal stiffness kn", "Pa/m"),
             Prop("stiffness-shear", P_KS, "shear stiffness ks", "Pa/m")]


#: codes of the models whose kernel has a ``stiffness`` hook
_HOOKED = np.array(sorted(k.CODE for k in KERNELS if hasattr(k, "stiffness")), dtype=np.int64)
#: codes of the models whose kernel has a ``stiffness_bound`` hook
_BOUNDED = np.array(sorted(k.CODE for k in KERNELS if hasattr(k, "stiffness_bound")), dtype=np.int64)


def changing_stiffness(cs) -> bool:
    """Whether a contact's joint model answers its own stiffness (``stiffness`` hook): its stiffness
    then changes with the joint's state, and the time step and the masses are worked out again at
    every detection."""
    return bool(cs.n) and bool(np.isin(cs["jmodel"], _HOOKED).any())


def stiffness(cs, ss, prop=None) -> tuple[np.ndarray, np.ndarray]:
    """(kn, ks) (ns,) [Pa/m]: every sub-contact's current stiffness as its joint model gives it
    (the kernel's ``stiffness`` hook; columns 0, 1 for a model without one). ``cs``, ``ss``: the
    contacts and sub-contacts stores; ``prop`` (nc, NPROP) other property rows than the store's.
    The one place the engine asks for a joint stiffness."""
    n = ss.n
    p = cs["prop"] if prop is None else prop
    if not changing_stiffness(cs):          # constant stiffnesses: columns 0, 1
        c = ss["contact"]
        return p[c, P_KN], p[c, P_KS]
    kn, ks = np.empty(n), np.empty(n)
    hist = ss["hist"]
    if hist.shape[1] < NJHIST:          # (no history columns yet: a model just assigned, before its first run)
        hist = np.zeros((n, NJHIST))
    if n:
        subcontact_stiffness(cs["jmodel"], np.ascontiguousarray(cs["prop"] if prop is None else prop), ss["contact"],
                             hist, kn, ks)
    return kn, ks


def contact_stiffness(cs, ss) -> tuple[np.ndarray, np.ndarray]:
    """(kn, ks) (nc,) [Pa/m] per contact, for the time step and the mass scaling: the larger of its
    row's columns 0, 1 and the stiffest of its sub-contacts now (``stiffness``), so that a joint
    softer now than its stated stiffness does not lengthen the step it may need again; for a model
    that declares the largest stiffness it reaches (``stiffness_bound``), that: a joint that
    stiffens with its closure (barton-bandis) under a load applied at once outruns a step worked
    out from its stiffness now before the next detection works it out again."""
    kn = cs["prop"][:, P_KN].copy()
    ks = cs["prop"][:, P_KS].copy()
    if ss.n:
        skn, sks = stiffness(cs, ss)
        np.maximum.at(kn, ss["contact"], skn)
        np.maximum.at(ks, ss["contact"], sks)
    if _BOUNDED.size and changing_stiffness(cs) and np.isin(cs["jmodel"], _BOUNDED).any():
        raise_to_bound(cs["jmodel"], np.ascontiguousarray(cs["prop"]), kn, ks)
    return kn, ks


def missing(cs, rows) -> str | None:
    """A message naming the contacts that lack a required property (``Prop.required``) and that
    property, or None. ``rows``: the property rows in force (nc, NPROP); only contacts with
    sub-contacts count."""
    used = cs["sub_count"] > 0
    for code in np.unique(cs["jmodel"][used]):
        m = MODEL_BY_CODE[int(code)]
        on = used & (cs["jmodel"] == code)
        for p in m.props.values():
            if not p.required:
                continue
            bad = on & np.isnan(rows[:, p.column])
            if bad.any():
                k = np.flatnonzero(bad)
                pairs = ", ".join(f"{int(cs['ida'][i])}-{int(cs['idb'][i])}" for i in k[:5])
                more = f" and {len(k) - 5} more" if len(k) > 5 else ""
                return (f"joint model '{m.name}' needs property '{p.name}': {len(k)} contact(s) lack it "
                        f"(between blocks {pairs}{more}); set it with `block contact property {p.name} …` "
                        "or `block contact material-table default property …`")
    return None


def _load_hosts() -> None:
    """Import every host file of ``physics/joints`` (each registers its model) and check that
    each joint-law kernel has its host."""
    import importlib
    import pkgutil

    from dec3d.physics import joints

    for info in pkgutil.iter_modules(joints.__path__):
        if not info.name.startswith("_"):
            importlib.import_module(f"{joints.__name__}.{info.name}")
    missing = [k.NAME for k in KERNELS if k.NAME not in JOINT_MODELS]
    if missing:
        raise ImportError(f"joint-law kernels without a host file in dec3d/physics/joints: {missing}")


_load_hosts()

#: every property name of every model (command keywords)
ALL_PROPS: tuple[str, ...] = tuple(dict.fromkeys(p for m in JOINT_MODELS.values() for p in m.props))
ANGLE_PROPS = tuple(p.name for m in JOINT_MODELS.values() for p in m.props.values() if p.units == "deg")
