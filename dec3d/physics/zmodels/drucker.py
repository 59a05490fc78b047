"""Host of zone model ``drucker-prager`` (kernel: ``dec3d/kernels/zmodels/drucker.py``, where the
formulation and its source are).

Keywords (Itasca's Drucker-Prager model; the names as Itasca's published FLAC3D/3DEC model source
declares the model's properties: ``friction-drucker``, ``cohesion-drucker``, ``dilation-drucker``,
``tension``, with the elastic ``bulk``, ``shear``, ``young``, ``poisson``; documentation page
"Drucker-Prager Model", https://docs.itascacg.com/itasca920/common/models/drucker/doc/modeldrucker.html):

    friction-drucker   q_φ, the slope of the shear criterion f_s = τ + q_φ σ − k_φ (>= 0)
    cohesion-drucker   k_φ [Pa], its intercept (>= 0)
    dilation-drucker   q_ψ, the slope of the shear potential g_s = τ + q_ψ σ (>= 0)
    tension            σ^t [Pa], the tension cut-off on the mean stress (shared column)

A tension above the apex k_φ / q_φ is used as the apex value (a warning, as for Mohr-Coulomb).

Strength reduction: none. Itasca's "Strength Reduction Procedure in FLAC3D and 3DEC" page
(https://docs.itascacg.com/flac3d700/common/docproject/source/manual/program_guide/methodology/factorofsafety/strengthreduction.html)
names the models whose strengths ``model factor-of-safety`` reduces automatically: Mohr-Coulomb,
ubiquitous-joint and Hoek-Brown; it says nothing of how Drucker-Prager constants would be
reduced, so ``reduce`` is None here.
"""
import numpy as np

from dec3d.kernels.zmodels import drucker as kernel
from dec3d.physics.cmodels import ELASTIC, MOHR_STRENGTH, P_TENSION, Prop, which_zones, zmodel

P_QPHI, P_KPHI, P_QPSI = kernel.P_QPHI, kernel.P_KPHI, kernel.P_QPSI

_TENSION = [q for q in MOHR_STRENGTH if q.name == "tension"]

PROPS = ELASTIC + [
    Prop("friction-drucker", P_QPHI, "material constant q_φ of f_s = τ + q_φ σ − k_φ (τ = √J2, σ mean stress)",
         ""),
    Prop("cohesion-drucker", P_KPHI, "material constant k_φ of the shear criterion", "Pa"),
    Prop("dilation-drucker", P_QPSI, "material constant q_ψ of the shear potential g_s = τ + q_ψ σ", ""),
] + _TENSION


def drucker_check(p, ids):
    """Cross-property rules: the tension cut-off above the apex k_φ/q_φ is capped (a warning)."""
    qf, kf, t = p[:, P_QPHI], p[:, P_KPHI], p[:, P_TENSION]
    with np.errstate(divide="ignore", invalid="ignore"):
        apex = np.where(qf > 0.0, kf / np.where(qf > 0.0, qf, 1.0), np.inf)
    over = t > apex
    warnings = []
    if over.any():
        warnings.append(f"tension above cohesion-drucker/friction-drucker in {which_zones(ids, over)}: the apex "
                        "value k_phi/q_phi is used as the tensile strength")
    return [], warnings


zmodel(kernel, "Drucker-Prager shear yield (τ + q_φ σ = k_φ) with tension cut-off, non-associated flow "
       "(Itasca's model)", PROPS, check=drucker_check)
