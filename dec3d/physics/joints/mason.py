"""Host of joint model ``mason`` (kernel: ``dec3d/kernels/joints/mason.py``, which gives the
equations and their sources). Property keywords as MASON's README lists them
(github.com/yopi1838/mason_constitutive_model, README.md, "Input properties"), except the
optional damage tables ``table-dt`` / ``table-ds``.

The SAFEGO decks (github.com/yopi1838/Hanze_SAFEGO) assign the plugin under its build names:
``mason_v6``, ``mason_v7`` and ``mason_v8`` with exactly these keywords (their CLAUDE.md: v7 only
adds the internal ``nlimit1``/``nlimit2``, left at their defaults by ANALYSIS_PART_I_MASON.dat),
so they are aliases; ``mason_debug2`` is set with four more keywords whose meaning MASON's
documentation does not give, so it is refused rather than silently run without them."""
import math

import numpy as np

from dec3d.kernels.joints import mason as kernel
from dec3d.physics.jmodels import STIFFNESS, Prop, angle, jmodel

_DEBUG2 = ("'mason_debug2' is a development build of the MASON plugin whose property set differs from "
           "MASON's documented one: it takes nlimit1, nlimit2, mult_base and mult_dc_gain, which the MASON "
           "documentation does not define (dec3d's 'mason' has no such properties); assign 'mason' and drop them")



def _reduce(prop, factor, associated):
    """`model factor-of-safety`: the Coulomb and tension strengths (peak and residual) divided by F, as
    for ``mohr`` (tan φ/F, c/F, ft/F; the dilatancy then at most the reduced friction, or equal to it
    when associated); the compression cap and the fracture energies are kept."""
    for col in (kernel.P_TANF, kernel.P_COH, kernel.P_FT, kernel.P_TANF_RES, kernel.P_COH_RES, kernel.P_FT_RES):
        prop[:, col] = prop[:, col] / factor
    if associated:
        prop[:, kernel.P_TANDIL] = prop[:, kernel.P_TANF]
    else:
        prop[:, kernel.P_TANDIL] = np.minimum(prop[:, kernel.P_TANDIL], prop[:, kernel.P_TANF])


jmodel(kernel, "MASON masonry joint: tension cut-off, Coulomb with cohesion and dilatancy, elliptical "
       "compression cap, fracture-energy softening, secant damage in tension (Lourenço & Rots 1997 surfaces)",
       STIFFNESS + [
           Prop("stiffness-initial", kernel.P_KN0, "initial normal stiffness kn0: compression and closed cracks "
                "(default: stiffness-normal)", "Pa/m", default=math.nan, fallback="stiffness-normal"),
           Prop("tension", kernel.P_FT, "tensile strength ft", "Pa"),
           Prop("cohesion", kernel.P_COH, "cohesion c", "Pa"),
           angle("friction", kernel.P_TANF, "peak friction angle φ"),
           angle("dilation", kernel.P_TANDIL, "initial dilatancy angle ψ₀"),
           Prop("dilation-zero", kernel.P_SDIL, "normal stress at which dilatancy vanishes σ_ψ0 (0: no limit)", "Pa"),
           Prop("delta", kernel.P_DELTA, "dilatancy decay with plastic slip δ", "1/m", default=2.0),
           Prop("g_i", kernel.P_GI, "mode-I fracture energy (tensile softening)", "J/m^2", lo_open=True,
                required=True),
           Prop("g_ii", kernel.P_GII, "mode-II fracture energy (cohesion and friction softening)", "J/m^2",
                lo_open=True, required=True),
           Prop("compression", kernel.P_FC, "compressive strength fc of the cap (0: no cap)", "Pa"),
           Prop("g_c", kernel.P_GC, "compressive fracture energy (post-peak)", "J/m^2", lo_open=True,
                required=True),
           Prop("peak_ratio", kernel.P_NPEAK, "closure at peak compressive strength / elastic-limit closure n",
                "", lo=1.0, default=1.0),
           Prop("cn", kernel.P_CN, "cap ellipse: linear normal-stress coefficient", "Pa", lo=None),
           Prop("cnn", kernel.P_CNN, "cap ellipse: σ² coefficient", "", lo_open=True, default=1.0),
           Prop("css", kernel.P_CSS, "cap ellipse: τ² coefficient", "", default=1.0),
           angle("friction-residual", kernel.P_TANF_RES, "residual friction angle φ_r (default: friction)",
                 default=math.nan, fallback="friction"),
           Prop("cohesion-residual", kernel.P_COH_RES, "residual cohesion c_r", "Pa"),
           Prop("tension-residual", kernel.P_FT_RES, "residual tensile strength ft_r", "Pa"),
           Prop("comp-residual", kernel.P_FC_RES, "residual compressive strength fc_r", "Pa"),
       ],
       aliases=("mason_v6", "mason_v7", "mason_v8"),
       refused={"mason_debug2": _DEBUG2}, reduce=_reduce)
