"""Joint constitutive models: one registration per model (``@jmodel``-style declarations).

A model declares its name, the kernel code the force update dispatches on
(``kernels.jointlaw``), and its property names with the kernel column each one fills
and how a user value becomes a column value (angles in degrees → tangents). The same
declaration drives ``block contact property`` checking, the command reference and the
save file (contacts keep ``jmodel`` code and ``prop`` row).

Columns left unset hold their declared default; ``friction-residual`` left unset holds
NaN, which the kernel reads as "the peak friction" so that setting `friction` later moves
the residual friction with it, as 3DEC does.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from dec3d.io.state import register_known

from dec3d.kernels.jointlaw import (MODEL_ELASTIC, MODEL_MOHR, NPROP, P_COH, P_COH_RES, P_KN, P_KS, P_TANDIL,
                                    P_TANF, P_TANF_RES, P_TEN, P_TEN_RES, P_ZDIL)


def _tan_deg(v: float) -> float:
    return math.tan(math.radians(v))


def _atan_deg(v: float) -> float:
    return math.degrees(math.atan(v))


@dataclass(frozen=True)
class Prop:
    name: str
    column: int
    doc: str
    units: str | None = None
    to_column: Callable[[float], float] = float
    from_column: Callable[[float], float] = float
    default: float = 0.0
    #: valid user values: [lo, hi], `hi_open` excludes hi (angles below 90°); None: unbounded
    lo: float | None = 0.0
    hi: float | None = None
    hi_open: bool = False


def _angle(name, column, doc, hi_open=True, **kw) -> Prop:
    """An angle property: degrees in [0, 90), kept as its tangent. Above 90° the tangent turns
    negative (a block would slide that 30° holds)."""
    return Prop(name, column, doc, "deg", _tan_deg, _atan_deg, hi=90.0, hi_open=hi_open, **kw)


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
        if name == "friction-residual" and x != x:
            x = row[self.props["friction"].column]
        return p.from_column(x)


JOINT_MODELS: dict[str, JointModel] = {}
MODEL_BY_CODE: dict[int, JointModel] = {}


def jmodel(name: str, code: int, doc: str, props: list[Prop]) -> JointModel:
    """Register a joint model."""
    if name in JOINT_MODELS or code in MODEL_BY_CODE:
        raise ValueError(f"joint model '{name}' (code {code}) registered twice")
    m = JointModel(name, code, doc, {p.name: p for p in props})
    JOINT_MODELS[name] = m
    MODEL_BY_CODE[code] = m
    register_known(joint_models={name}, joint_model_codes={code})     # what a save file may name
    return m


_STIFF = [Prop("stiffness-normal", P_KN, "normal stiffness kn", "Pa/m"),
          Prop("stiffness-shear", P_KS, "shear stiffness ks", "Pa/m")]

jmodel("elastic", MODEL_ELASTIC, "linear elastic joint, no tension (3DEC's `elastic`)", _STIFF)

jmodel("mohr", MODEL_MOHR, "Coulomb slip with tension cut-off, cohesion and tension lost at first failure, "
       "residual values and dilation (3DEC theory Eqs. 33-43 with the errata)", _STIFF + [
           _angle("friction", P_TANF, "friction angle φ (90: never slips)", hi_open=False),
           Prop("cohesion", P_COH, "cohesion c", "Pa"),
           Prop("tension", P_TEN, "tensile strength T", "Pa"),
           _angle("dilation", P_TANDIL, "dilation angle ψ"),
           Prop("dilation-zero", P_ZDIL, "shear displacement at which dilation stops (0: never)", "m"),
           _angle("friction-residual", P_TANF_RES, "residual friction angle (default: the friction angle)",
                  hi_open=False, default=math.nan),
           Prop("cohesion-residual", P_COH_RES, "residual cohesion", "Pa"),
           Prop("tension-residual", P_TEN_RES, "residual tensile strength", "Pa"),
       ])

#: every property name of every model (command keywords)
ALL_PROPS: tuple[str, ...] = tuple(dict.fromkeys(p for m in JOINT_MODELS.values() for p in m.props))
ANGLE_PROPS = tuple(p.name for m in JOINT_MODELS.values() for p in m.props.values() if p.units == "deg")
