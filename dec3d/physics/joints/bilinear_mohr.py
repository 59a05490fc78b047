"""Host of joint model ``bilinear-mohr`` (kernel: ``dec3d/kernels/joints/bilinear_mohr.py``).

Property keywords as 3DEC's page gives them (Itasca, "Bilinear Mohr-Coulomb Joint Model In 3DEC",
https://docs.itascacg.com/itasca900/3dec/docproject/source/theory/bilinear/bilinearmc.html, Table 1).
Names shared with ``mohr`` (friction, cohesion, tension, dilation, ...) keep mohr's ranges and docs: the command
layer checks and documents a keyword once whatever the model (friction 90 stays the 3DEC idiom for
"never slips"); the meaning per model (φ₁ below the threshold, ...) is in the one-line doc and the kernel."""
import math

import numpy as np

from dec3d.kernels.joints import bilinear_mohr as kernel
from dec3d.physics.jmodels import STIFFNESS, Prop, angle, jmodel


def reduce(rows, factor, associated):
    """`model factor-of-safety`: every cohesion, tan φ and tensile strength of both envelopes, peak
    and residual, divided by F (a NaN residual friction keeps following its reduced peak). The
    automatic thresholds move with them unchanged ((c₁ − c₂)/F over (tan φ₂ − tan φ₁)/F); given ones
    are normal stresses, not strengths, and stay. Dilation as mohr's (``fos.reduce_rows``): associated,
    tan ψ₁, tan ψ₂ = the reduced tan φ₁, tan φ₂; otherwise each kept but never above them."""
    for col in (kernel.P_TANF, kernel.P_TANF2, kernel.P_TANF_RES, kernel.P_TANF2_RES, kernel.P_COH, kernel.P_COH2,
                kernel.P_COH_RES, kernel.P_COH2_RES, kernel.P_TEN, kernel.P_TEN_RES):
        rows[:, col] = rows[:, col] / factor
    psi2 = np.where(np.isnan(rows[:, kernel.P_TANDIL2]), rows[:, kernel.P_TANDIL], rows[:, kernel.P_TANDIL2])
    if associated:
        rows[:, kernel.P_TANDIL] = rows[:, kernel.P_TANF]
        rows[:, kernel.P_TANDIL2] = rows[:, kernel.P_TANF2]
    else:
        rows[:, kernel.P_TANDIL] = np.minimum(rows[:, kernel.P_TANDIL], rows[:, kernel.P_TANF])
        rows[:, kernel.P_TANDIL2] = np.minimum(psi2, rows[:, kernel.P_TANF2])


jmodel(kernel, "two Coulomb envelopes (peak and residual) switching at a normal-stress threshold, tension "
       "cut-off, cohesion and tension lost at first failure, dilation (3DEC's Bilinear Mohr-Coulomb)", STIFFNESS + [
           angle("friction", kernel.P_TANF, "friction angle φ (90: never slips)", hi_open=False),
           angle("friction-2", kernel.P_TANF2, "friction angle φ₂ above the threshold σᶜ", hi_open=False),
           angle("friction-residual", kernel.P_TANF_RES, "residual friction angle (default: the friction angle)",
                 hi_open=False, default=math.nan, fallback="friction"),
           angle("f2-residual", kernel.P_TANF2_RES, "residual friction angle above σᶜʳ (default: friction-2)",
                 hi_open=False, default=math.nan, fallback="friction-2"),
           Prop("cohesion", kernel.P_COH, "cohesion c", "Pa"),
           Prop("cohesion-2", kernel.P_COH2, "cohesion c₂ above σᶜ", "Pa"),
           Prop("cohesion-residual", kernel.P_COH_RES, "residual cohesion", "Pa"),
           Prop("c2-residual", kernel.P_COH2_RES, "residual cohesion above σᶜʳ", "Pa"),
           angle("dilation", kernel.P_TANDIL, "dilation angle ψ"),
           angle("dilation-2", kernel.P_TANDIL2, "dilation angle ψ₂ above σᶜʳ (default: dilation)",
                 default=math.nan, fallback="dilation"),
           Prop("dilation-zero", kernel.P_ZDIL, "shear displacement at which dilation stops (0: never)", "m"),
           Prop("tension", kernel.P_TEN, "tensile strength T", "Pa"),
           Prop("tension-residual", kernel.P_TEN_RES, "residual tensile strength", "Pa"),
           Prop("nstress", kernel.P_NSTRESS, "normal-stress threshold σᶜ of the peak envelopes (default: where "
                "they intersect, (c₁ − c₂)/(tan φ₂ − tan φ₁))", "Pa", default=math.nan),
           Prop("nstress-residual", kernel.P_NSTRESS_RES, "normal-stress threshold σᶜʳ of the residual envelopes "
                "and of the dilation angle (default: where the residual envelopes intersect)", "Pa",
                default=math.nan),
       ], reduce=reduce)
