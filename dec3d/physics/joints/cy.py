"""Host of joint model ``cyjm``, 3DEC's continuously yielding joint model (kernel:
``dec3d/kernels/joints/cy.py``; equations and sources there).

Model name `cyjm` and the keywords `kn-initial`, `ks-initial`, `exponent-normal`, `exponent-shear`,
`friction`, `friction-initial`, `roughness` as 3DEC 7's command reference lists them (summarised in
shared/reference/3dec_command_reference.md, section 7; `cy` and `continuously-yielding` are accepted
too). With both exponents 0 the stiffnesses are the plain kn, ks [Pa/m]; otherwise `kn-initial`,
`ks-initial` are the multipliers a_n, a_s of kn = a_n σn^e_n, ks = a_s σn^e_s [Pa^(1−e)/m]."""
import math

import numpy as np

from dec3d.kernels.joints import cy as kernel
from dec3d.physics.jmodels import Prop, jmodel


def _deg(name, column, doc, **kw) -> Prop:
    """An angle kept in radians (the mobilised friction decays in the angle, not its tangent).
    Bounds as mohr's `friction` ([0, 90]; command keywords are checked by name)."""
    return Prop(name, column, doc, "deg", math.radians, math.degrees, hi=90.0, **kw)


def reduce(rows, factor, associated):
    """`model factor-of-safety`: tan φ0 and tan φ divided by F (the columns hold the angles in radians;
    an unset initial friction, NaN, keeps following φ). The model has no cohesion, tension or dilation."""
    for col in (kernel.P_PHI0, kernel.P_PHI):
        rows[:, col] = np.arctan(np.tan(rows[:, col]) / factor)


jmodel(kernel, "continuously yielding joint: friction mobilised from the initial toward the intrinsic angle "
       "with plastic shear displacement, stiffnesses kn = a_n σn^e_n, ks = a_s σn^e_s "
       "(3DEC's `cyjm`, Cundall & Lemos 1990)", [
           Prop("kn-initial", 0, "normal stiffness multiplier a_n (kn = a_n σn^e_n; with e_n = 0 the stiffness)",
                "Pa/m"),
           Prop("ks-initial", 1, "shear stiffness multiplier a_s (ks = a_s σn^e_s; with e_s = 0 the stiffness)",
                "Pa/m"),
           Prop("exponent-normal", kernel.P_EN, "normal stiffness exponent e_n (< 1: the closure integral is finite)",
                "", hi=1.0, hi_open=True),
           Prop("exponent-shear", kernel.P_ES, "shear stiffness exponent e_s", "", hi=1.0, hi_open=True),
           _deg("friction", kernel.P_PHI, "intrinsic friction angle φ, the limit of the mobilised friction"),
           _deg("friction-initial", kernel.P_PHI0, "initial (mobilised) friction angle φ0 (default: the friction "
                "angle, no softening)", default=math.nan, fallback="friction"),
           Prop("roughness", kernel.P_R, "joint roughness R: plastic shear displacement over which φm − φ falls "
                "by the factor e", "m", required=True),
       ], aliases=("cy", "continuously-yielding"), reduce=reduce)
