"""Host of joint model ``softening-mohr`` (kernel: ``dec3d/kernels/joints/softening_mohr.py``).

Property keywords as 3DEC's page gives them (Itasca, "Softening-Healing Mohr-Coulomb Joint Model In
3DEC", https://docs.itascacg.com/itasca900/3dec/docproject/source/theory/softhealmc/softhealmc.html);
`alpha` (the non-linear formulation) is left out: see the kernel. Its read-only `slip` is the history
entry of the same name. Names shared with ``mohr`` keep mohr's ranges and docs (the command layer checks and documents a
keyword once whatever the model)."""
import math

import numpy as np

from dec3d.kernels.joints import softening_mohr as kernel
from dec3d.physics.jmodels import STIFFNESS, Prop, angle, jmodel


def reduce(rows, factor, associated):
    """`model factor-of-safety`: peak and residual cohesion, tan φ and tension divided by F (a NaN
    residual friction keeps following the reduced peak); D_c is a length and stays. Dilation as mohr's
    (``fos.reduce_rows``): associated, tan ψ = the reduced tan φ; otherwise kept but never above it."""
    for col in (kernel.P_TANF, kernel.P_TANF_RES, kernel.P_COH, kernel.P_COH_RES, kernel.P_TEN, kernel.P_TEN_RES):
        rows[:, col] = rows[:, col] / factor
    if associated:
        rows[:, kernel.P_TANDIL] = rows[:, kernel.P_TANF]
    else:
        rows[:, kernel.P_TANDIL] = np.minimum(rows[:, kernel.P_TANDIL], rows[:, kernel.P_TANF])


jmodel(kernel, "Coulomb slip whose cohesion and friction fall linearly from peak to residual over the critical "
       "slip distance dc and heal when slipping stops; tension cut-off (3DEC's Softening-Healing Mohr-Coulomb)",
       STIFFNESS + [
           angle("friction", kernel.P_TANF, "friction angle φ (90: never slips)", hi_open=False),
           angle("friction-residual", kernel.P_TANF_RES, "residual friction angle (default: the friction angle)",
                 hi_open=False, default=math.nan, fallback="friction"),
           Prop("cohesion", kernel.P_COH, "cohesion c", "Pa"),
           Prop("cohesion-residual", kernel.P_COH_RES, "residual cohesion", "Pa"),
           Prop("tension", kernel.P_TEN, "tensile strength T", "Pa"),
           Prop("tension-residual", kernel.P_TEN_RES, "residual tensile strength", "Pa"),
           angle("dilation", kernel.P_TANDIL, "dilation angle ψ"),
           Prop("dilation-zero", kernel.P_ZDIL, "shear displacement at which dilation stops (0: never)", "m"),
           Prop("dc", kernel.P_DC, "critical slip distance D_c over which the strength falls to residual", "m",
                lo_open=True, required=True),
           Prop("healing", kernel.P_HEAL, "1: the strength returns to peak when slipping stops (default); "
                "0: no healing", "", hi=1.0, default=1.0),
       ], reduce=reduce)
