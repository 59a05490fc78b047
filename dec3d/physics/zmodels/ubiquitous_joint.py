"""Host of zone model ``ubiquitous-joint`` (kernel: ``dec3d/kernels/zmodels/ubiquitous_joint.py``).

Properties as Itasca's property page of the model
(https://docs.itascacg.com/pfc600/common/models/ubiquit/doc/propubiquit.html): the Mohr-Coulomb
matrix (bulk, shear, cohesion, friction, tension, dilation) and the weak plane's
``joint-cohesion``, ``joint-friction``, ``joint-tension``, ``joint-dilation``, ``dip``,
``dip-direction`` (degrees; 3DEC 7+ axes x east, y north, z up: dip down from the horizontal, dip
direction clockwise from +y). Itasca's ``normal``/``normal-x|y|z`` and ``flag-brittle`` are not
provided. Rules: the matrix's as ``mohr-coulomb``; joint cohesion and tension >= 0, 0 <= joint
friction < 90°, joint dilation <= joint friction (Itasca's checks); a joint tension above
c_j / tan φ_j is used as that value (a warning). Strength reduction: the matrix as
``mohr-coulomb`` and the plane alike (c_j/F, tan φ_j/F, σ_t^j/F, tan ψ_j at most tan φ_j/F), as
Itasca scales both.
"""
import numpy as np

from dec3d.kernels.zmodels import ubiquitous_joint as kernel
from dec3d.physics.cmodels import ELASTIC, MOHR_STRENGTH, Prop, angle, which_zones, zmodel
from dec3d.physics.zmodels.mohr import mohr_check, mohr_reduce

JC, JTF, JT, JTD = kernel.P_JCOHESION, kernel.P_JTANFRIC, kernel.P_JTENSION, kernel.P_JTANDIL


def ubiquitous_check(p, ids):
    """The matrix's rules (``mohr_check``) and the plane's: joint dilation <= joint friction;
    joint tension above c_j / tan φ_j is a warning."""
    problems, warnings = mohr_check(p, ids)
    c, tf, t, td = p[:, JC], p[:, JTF], p[:, JT], p[:, JTD]
    bad = td > tf * (1.0 + 1e-12)
    if bad.any():
        problems.append(f"joint-dilation must not exceed joint-friction: {which_zones(ids, bad)}")
    with np.errstate(divide="ignore", invalid="ignore"):
        apex = np.where(tf > 0.0, c / np.where(tf > 0.0, tf, 1.0), np.inf)
    over = t > apex
    if over.any():
        warnings.append(f"joint-tension above joint-cohesion/tan(joint-friction) in {which_zones(ids, over)}: "
                        "that value is used as the joint's tensile strength")
    return problems, warnings


def ubiquitous_reduce(p, F):
    """Rows ``p`` with the matrix's and the plane's strengths divided by F."""
    q = mohr_reduce(p, F)
    q[:, JC] /= F
    q[:, JTF] /= F
    q[:, JT] /= F
    q[:, JTD] = np.minimum(q[:, JTD], q[:, JTF])
    return q


zmodel(kernel, "Mohr-Coulomb matrix with one weak plane of Coulomb strength with tension cut-off "
       "(Itasca's ubiquitous-joint model)",
       ELASTIC + MOHR_STRENGTH + [
           Prop("joint-cohesion", JC, "cohesion c_j of the weak plane", "Pa"),
           angle("joint-friction", JTF, "friction angle φ_j of the weak plane"),
           Prop("joint-tension", JT, "tensile strength σ_t^j of the weak plane (capped at c_j/tan φ_j)", "Pa"),
           angle("joint-dilation", JTD, "dilation angle ψ_j ≤ φ_j of the weak plane"),
           Prop("dip", kernel.P_DIP, "dip of the weak plane, down from the horizontal", "degrees", hi=90.0),
           Prop("dip-direction", kernel.P_DIPDIR, "dip direction of the weak plane, clockwise from +y (north)",
                "degrees", hi=360.0, hi_open=True),
       ],
       check=ubiquitous_check, reduce=ubiquitous_reduce)
