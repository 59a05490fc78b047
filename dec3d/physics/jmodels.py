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

from dataclasses import dataclass, field

import numpy as np

from dec3d.io.state import register_known
from dec3d.physics.modelprops import ModelProp, atan_deg, tan_deg

from dec3d.kernels.joints import MODELS as KERNELS
from dec3d.kernels.joints import NPROP, P_KN, P_KS


@dataclass(frozen=True)
class Prop(ModelProp):
    """A joint model's property (``ModelProp``: name, column, units, conversions, range)."""
    #: property whose value this one shows while it holds NaN (unset residual friction: the friction)
    fallback: str | None = None


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

    def row(self, values: dict[str, float] | None = None) -> np.ndarray:
        """Kernel property row with every column at its default, then ``values`` applied."""
        r = np.zeros(NPROP)
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


def jmodel(kernel, doc: str, props: list[Prop]) -> JointModel:
    """Register a joint model: ``kernel`` is its module in ``dec3d/kernels/joints`` (name, code)."""
    name, code = kernel.NAME, kernel.CODE
    if name in JOINT_MODELS or code in MODEL_BY_CODE:
        raise ValueError(f"joint model '{name}' (code {code}) registered twice")
    for p in props:
        if not 0 <= p.column < kernel.NCOLS:
            raise ValueError(f"joint model '{name}': property {p.name} in column {p.column}, the kernel reads "
                             f"{kernel.NCOLS}")
    m = JointModel(name, code, doc, {p.name: p for p in props})
    JOINT_MODELS[name] = m
    MODEL_BY_CODE[code] = m
    register_known(joint_models={name}, joint_model_codes={code})     # what a save file may name
    return m


#: the stiffnesses every model has (columns 0, 1 of every kernel)
STIFFNESS = [Prop("stiffness-normal", P_KN, "normal stiffness kn", "Pa/m"),
             Prop("stiffness-shear", P_KS, "shear stiffness ks", "Pa/m")]


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
