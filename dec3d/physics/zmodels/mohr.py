"""Host of zone model ``mohr-coulomb`` (kernel: ``dec3d/kernels/zmodels/mohr.py``).

Rules (Itasca, FLAC3D/3DEC "Mohr-Coulomb Model" page): cohesion >= 0, 0 <= friction < 90°,
0 <= dilation <= friction, tension >= 0; a tension above the apex c/tan φ is used as the apex
value (a warning, not an error). Strength reduction (``model factor-of-safety``, as FLAC3D and
3DEC reduce it): c/F, tan φ/F, σt/F; the dilation angle is kept below the reduced friction.
"""
from dec3d.kernels.zmodels import mohr as kernel
from dec3d.physics.cmodels import ELASTIC, MOHR_STRENGTH, coulomb_reduce, coulomb_rules, zmodel


def mohr_reduce(p, F):
    """The Mohr-Coulomb strength of rows ``p`` divided by F."""
    q = p.copy()
    coulomb_reduce(q, F)
    return q


zmodel(kernel, "Mohr-Coulomb shear yield with tension cut-off and non-associated flow (Itasca's model)",
       ELASTIC + MOHR_STRENGTH, check=coulomb_rules, reduce=mohr_reduce)
