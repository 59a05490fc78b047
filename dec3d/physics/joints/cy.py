"""Host of joint model ``cy``, 3DEC's continuously yielding joint model (kernel:
``dec3d/kernels/joints/cy.py``; equations and sources there).

Model name `cy` and the property keywords are 3DEC 7's style (its theory page "Continuously Yielding
Joint Model In 3DEC" was not in the reference store, only the overview
https://www.itascacg.com/3dec-joint-constitutive-models: the keywords are unverified against the
page; the old syntax used names such as jif and jrough). With both exponents 0
the stiffnesses are the plain kn, ks [Pa/m]; otherwise `stiffness-normal`/`stiffness-shear` are the
multipliers a_n, a_s of kn = a_n σn^e_n, ks = a_s σn^e_s [Pa^(1−e)/m]."""
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
    an unset intrinsic friction, NaN, keeps following φ0). The model has no cohesion, tension or dilation."""
    for col in (kernel.P_PHI0, kernel.P_PHI):
        rows[:, col] = np.arctan(np.tan(rows[:, col]) / factor)


jmodel(kernel, "continuously yielding joint: friction mobilised from the initial toward the intrinsic angle "
       "with plastic shear displacement, stiffnesses kn = a_n σn^e_n, ks = a_s σn^e_s "
       "(3DEC's `cy`, Cundall & Lemos 1990)", [
           Prop("stiffness-normal", 0, "normal stiffness multiplier a_n (kn = a_n σn^e_n)", "Pa/m"),
           Prop("stiffness-shear", 1, "shear stiffness multiplier a_s (ks = a_s σn^e_s)", "Pa/m"),
           Prop("exponent-normal", kernel.P_EN, "normal stiffness exponent e_n (< 1: the closure integral is finite)",
                "",
                hi=1.0, hi_open=True),
           Prop("exponent-shear", kernel.P_ES, "shear stiffness exponent e_s", "", hi=1.0, hi_open=True),
           _deg("friction", kernel.P_PHI0, "initial (mobilised) friction angle φ0"),
           _deg("friction-intrinsic", kernel.P_PHI, "intrinsic friction angle φ, the limit of the mobilised "
                "friction (default: the friction angle, no softening)", default=math.nan, fallback="friction"),
           Prop("roughness", kernel.P_R, "joint roughness R: plastic shear displacement over which φm − φ falls "
                "by the factor e", "m", required=True),
       ], aliases=("continuously-yielding",), reduce=reduce)
