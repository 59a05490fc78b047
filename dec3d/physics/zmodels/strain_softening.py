"""Host of zone model ``strain-softening`` (kernel: ``dec3d/kernels/zmodels/strain_softening.py``).

Itasca, FLAC3D/3DEC "Strain-Softening/Hardening Mohr-Coulomb (SSoft) Model" page
(https://docs.itascacg.com/itasca900/common/models/ssoft/doc/modelssoft.html): the Mohr-Coulomb
properties, and ``table-cohesion``, ``table-friction``, ``table-dilation`` (c, φ [°], ψ [°] as
functions of the plastic shear strain κs, ``strain-shear-plastic``) and ``table-tension`` (σt as a
function of the plastic tensile strain κt, ``strain-tension-plastic``). A property with a table
follows the table; one without keeps its constant value. Rules as ``mohr-coulomb``'s for the
constant values (dilation <= friction where neither has a table). Strength reduction (``model
factor-of-safety``): the constant strengths as ``mohr-coulomb`` (c/F, tan φ/F, σt/F), and F kept in
the zone's P_SRF column, by which the kernel divides the strengths it reads from tables.
"""
import numpy as np

from dec3d.kernels.zmodels import strain_softening as kernel
from dec3d.physics.cmodels import (ELASTIC, MOHR_STRENGTH, P_COHESION, P_SRF, P_TANDIL, P_TANFRIC, P_TENSION, table,
                                   which_zones, zmodel)


def ssoft_check(p, ids):
    """The Mohr-Coulomb rules on the constant strengths (Itasca's): dilation <= friction; a tension
    above c / tan φ is used as that value (a warning). Tabled values are the user's to choose."""
    problems, warnings = [], []
    c, tf, t, td = p[:, P_COHESION], p[:, P_TANFRIC], p[:, P_TENSION], p[:, P_TANDIL]
    bad = (td > tf * (1.0 + 1e-12)) & (p[:, kernel.P_TABLE_DILATION] <= 0) & (p[:, kernel.P_TABLE_FRICTION] <= 0)
    if bad.any():
        problems.append(f"dilation must not exceed friction: {which_zones(ids, bad)}")
    with np.errstate(divide="ignore", invalid="ignore"):
        apex = np.where(tf > 0.0, c / np.where(tf > 0.0, tf, 1.0), np.inf)
    over = (t > apex) & (p[:, kernel.P_TABLE_TENSION] <= 0) & (p[:, kernel.P_TABLE_COHESION] <= 0) \
        & (p[:, kernel.P_TABLE_FRICTION] <= 0)
    if over.any():
        warnings.append(f"tension above c/tan(friction) in {which_zones(ids, over)}: the apex value "
                        "c/tan(friction) is used as the tensile strength")
    return problems, warnings


def ssoft_reduce(p, F):
    """Rows ``p`` reduced by F (``model factor-of-safety``): the constant strengths c/F, tan φ/F,
    σt/F, tan ψ at most the reduced tan φ (as mohr-coulomb's), and F in P_SRF, by which the kernel
    divides the strengths it reads from tables."""
    q = p.copy()
    q[:, P_COHESION] /= F
    q[:, P_TANFRIC] /= F
    q[:, P_TENSION] /= F
    q[:, P_TANDIL] = np.minimum(q[:, P_TANDIL], q[:, P_TANFRIC])
    q[:, P_SRF] = F
    return q


zmodel(kernel, "Mohr-Coulomb whose cohesion, friction, dilation soften or harden with the plastic shear "
       "strain and tension with the plastic tensile strain, by tables (Itasca's strain-softening model)",
       ELASTIC + MOHR_STRENGTH + [
           table("table-cohesion", kernel.P_TABLE_COHESION, "table of cohesion [Pa] vs plastic shear strain κs"),
           table("table-friction", kernel.P_TABLE_FRICTION,
                 "table of friction angle [degrees] vs plastic shear strain κs"),
           table("table-dilation", kernel.P_TABLE_DILATION,
                 "table of dilation angle [degrees] vs plastic shear strain κs"),
           table("table-tension", kernel.P_TABLE_TENSION,
                 "table of tensile strength [Pa] vs plastic tensile strain κt"),
       ],
       check=ssoft_check, reduce=ssoft_reduce)
