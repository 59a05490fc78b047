"""Host of zone model ``mohr-coulomb`` (kernel: ``dec3d/kernels/zmodels/mohr.py``).

Rules (Itasca, FLAC3D/3DEC "Mohr-Coulomb Model" page): cohesion >= 0, 0 <= friction < 90°,
0 <= dilation <= friction, tension >= 0; a tension above the apex c/tan φ is used as the apex
value (a warning, not an error). Strength reduction (``model factor-of-safety``, as FLAC3D and
3DEC reduce it): c/F, tan φ/F, σt/F; the dilation angle is kept below the reduced friction.
"""
import numpy as np

from dec3d.kernels.zmodels import mohr as kernel
from dec3d.physics.cmodels import (ELASTIC, MOHR_STRENGTH, P_COHESION, P_TANDIL, P_TANFRIC, P_TENSION,
                                   which_zones, zmodel)


def mohr_check(p, ids):
    """Cross-property rules of the Mohr-Coulomb strength (shared by the models built on it)."""
    problems, warnings = [], []
    c, tf, t, td = p[:, P_COHESION], p[:, P_TANFRIC], p[:, P_TENSION], p[:, P_TANDIL]
    bad = td > tf * (1.0 + 1e-12)
    if bad.any():
        problems.append(f"dilation must not exceed friction: {which_zones(ids, bad)}")
    with np.errstate(divide="ignore", invalid="ignore"):
        apex = np.where(tf > 0.0, c / np.where(tf > 0.0, tf, 1.0), np.inf)
    over = t > apex
    if over.any():
        warnings.append(f"tension above c/tan(friction) in {which_zones(ids, over)}: the apex value "
                        "c/tan(friction) is used as the tensile strength")
    return problems, warnings


def mohr_reduce(p, F):
    """The Mohr-Coulomb strength of rows ``p`` divided by F (c, tan φ, σt; tan ψ at most tan φ/F)."""
    q = p.copy()
    q[:, P_COHESION] /= F
    q[:, P_TANFRIC] /= F
    q[:, P_TENSION] /= F
    q[:, P_TANDIL] = np.minimum(q[:, P_TANDIL], q[:, P_TANFRIC])
    return q


zmodel(kernel, "Mohr-Coulomb shear yield with tension cut-off and non-associated flow (Itasca's model)",
       ELASTIC + MOHR_STRENGTH, check=mohr_check, reduce=mohr_reduce)
