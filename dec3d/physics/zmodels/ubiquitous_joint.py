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
from dec3d.kernels.zmodels import ubiquitous_joint as kernel
from dec3d.physics.cmodels import ELASTIC, MOHR_STRENGTH, Prop, angle, coulomb_reduce, coulomb_rules, zmodel

JC, JTF, JT, JTD = kernel.P_JCOHESION, kernel.P_JTANFRIC, kernel.P_JTENSION, kernel.P_JTANDIL


def ubiquitous_check(p, ids):
    """The matrix's rules and the plane's (Itasca's): dilation <= friction; a tension above
    c / tan φ is used as that value (a warning)."""
    problems, warnings = coulomb_rules(p, ids)
    more, warn = coulomb_rules(p, ids, (JC, JTF, JT, JTD), ("joint-cohesion", "joint-friction", "joint-tension",
                                                             "joint-dilation"))
    return problems + more, warnings + warn


def ubiquitous_reduce(p, F):
    """Rows ``p`` with the matrix's and the plane's strengths divided by F (c/F, tan φ/F, σt/F,
    tan ψ at most the reduced tan φ)."""
    q = p.copy()
    coulomb_reduce(q, F)
    coulomb_reduce(q, F, (JC, JTF, JT, JTD))
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
