"""Host of joint model ``mohr`` (kernel: ``dec3d/kernels/joints/mohr.py``)."""
import math

from dec3d.kernels.joints import mohr as kernel
from dec3d.physics.fos import reduce_rows
from dec3d.physics.jmodels import STIFFNESS, Prop, angle, jmodel

jmodel(kernel, "Coulomb slip with tension cut-off, cohesion and tension lost at first failure, "
       "residual values and dilation (3DEC theory Eqs. 33-43 with the errata)", STIFFNESS + [
           angle("friction", kernel.P_TANF, "friction angle φ (90: never slips)", hi_open=False),
           Prop("cohesion", kernel.P_COH, "cohesion c", "Pa"),
           Prop("tension", kernel.P_TEN, "tensile strength T", "Pa"),
           angle("dilation", kernel.P_TANDIL, "dilation angle ψ"),
           Prop("dilation-zero", kernel.P_ZDIL, "shear displacement at which dilation stops (0: never)", "m"),
           angle("friction-residual", kernel.P_TANF_RES, "residual friction angle (default: the friction angle)",
                 hi_open=False, default=math.nan, fallback="friction"),
           Prop("cohesion-residual", kernel.P_COH_RES, "residual cohesion", "Pa"),
           Prop("tension-residual", kernel.P_TEN_RES, "residual tensile strength", "Pa"),
       ], reduce=reduce_rows)
