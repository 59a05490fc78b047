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
from dec3d.kernels.zmodels import strain_softening as kernel
from dec3d.physics.cmodels import ELASTIC, MOHR_STRENGTH, P_SRF, coulomb_reduce, coulomb_rules, table, zmodel


def ssoft_check(p, ids):
    """The Mohr-Coulomb rules on the constant strengths (Itasca's): dilation <= friction; a tension
    above c / tan φ is used as that value (a warning). Tabled values are the user's to choose."""
    const = p[:, kernel.P_TABLE_FRICTION] <= 0
    return coulomb_rules(p, ids, dilation_rows=const & (p[:, kernel.P_TABLE_DILATION] <= 0),
                         tension_rows=const & (p[:, kernel.P_TABLE_TENSION] <= 0)
                         & (p[:, kernel.P_TABLE_COHESION] <= 0))


def ssoft_reduce(p, F):
    """Rows ``p`` reduced by F (``model factor-of-safety``): the constant strengths c/F, tan φ/F,
    σt/F, tan ψ at most the reduced tan φ (as mohr-coulomb's), and F in P_SRF, by which the kernel
    divides the strengths it reads from tables."""
    q = p.copy()
    coulomb_reduce(q, F)
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
