"""Host of zone model ``orthotropic`` (kernel: ``dec3d/kernels/zmodels/orthotropic.py``; the law,
the axes and their sources: ``dec3d/kernels/zmodels/_elastic_aniso.py``).

Keywords (Itasca, "Orthotropic Elastic Model" page,
https://docs.itascacg.com/pfc700/common/models/ortho/doc/modelortho.html, and the property names
of Itasca's published model source): ``young-1``, ``young-2``, ``young-3`` (E_i > 0),
``poisson-12``, ``poisson-13``, ``poisson-23`` (ν_ij: contraction along i' under tension along
j'), ``shear-12``, ``shear-13``, ``shear-23`` (G_ij > 0), ``dip`` (0-90°), ``dip-direction``
(clockwise from +y), ``rotation`` (of 1' from the dip vector, counter-clockwise about the upward
normal 3'), all in degrees; ``density``. Itasca's alternatives to dip and dip direction
(``normal``, ``normal-x|y|z``) are not taken: the twelve own columns hold the nine constants and
three angles.

Before cycling the compliance must be positive definite (the Poisson's ratios compatible with the
Young's moduli); each modulus is checked > 0 by its range. ``moduli``: K + 4G/3 is the largest
eigenvalue of the stiffness in Mandel form, a bound on the zone's acoustic tensor (``bound_moduli``'s
module text), so the explicit step stays stable.
"""
from dec3d.kernels.zmodels import orthotropic as kernel
from dec3d.kernels.zmodels._elastic_aniso import admissible, bound_moduli
from dec3d.physics.cmodels import ELASTIC, Prop, which_zones, zmodel

k = kernel


def _modulus(name, col, doc):
    return Prop(name, col, doc, "Pa", lo=0.0, lo_open=True)


def _ratio(name, col, doc):
    return Prop(name, col, doc, "", lo=None, hi=None)


PROPS = [q for q in ELASTIC if q.name == "density"] + [
    _modulus("young-1", k.P_E1, "Young's modulus E1 along local 1'"),
    _modulus("young-2", k.P_E2, "Young's modulus E2 along local 2'"),
    _modulus("young-3", k.P_E3, "Young's modulus E3 along local 3'"),
    _ratio("poisson-12", k.P_NU12, "Poisson's ratio ν12: contraction along 1' under tension along 2'"),
    _ratio("poisson-13", k.P_NU13, "Poisson's ratio ν13: contraction along 1' under tension along 3'"),
    _ratio("poisson-23", k.P_NU23, "Poisson's ratio ν23: contraction along 2' under tension along 3'"),
    _modulus("shear-12", k.P_G12, "shear modulus G12 of the (1', 2') plane"),
    _modulus("shear-13", k.P_G13, "shear modulus G13 of the (1', 3') plane"),
    _modulus("shear-23", k.P_G23, "shear modulus G23 of the (2', 3') plane"),
    Prop("dip", k.P_DIP, "dip of the plane of isotropy (anisotropic) or (1', 2') plane (orthotropic), degrees",
         "deg", lo=0.0, hi=90.0),
    Prop("dip-direction", k.P_DD, "its dip direction, degrees clockwise from +y", "deg",
         lo=None, hi=None),
    Prop("rotation", k.P_ROT, "angle of 1' from the dip vector, degrees counter-clockwise about the upward normal 3'",
         "deg", lo=None, hi=None),
]


def _constants(p):
    return (p[:, k.P_E1], p[:, k.P_E2], p[:, k.P_E3], p[:, k.P_NU12], p[:, k.P_NU13], p[:, k.P_NU23],
            p[:, k.P_G12], p[:, k.P_G13], p[:, k.P_G23])


def ortho_check(p, ids):
    """Problems: zones whose compliance is not positive definite."""
    bad = ~admissible(*_constants(p))
    if bad.any():
        return [f"compliance not positive definite (Poisson's ratios incompatible with the Young's moduli): "
                f"{which_zones(ids, bad)}"], []
    return [], []


zmodel(kernel, "orthotropic linear elasticity in local axes set by dip, dip-direction and rotation (Itasca's model)",
       PROPS, check=ortho_check, moduli=lambda p: bound_moduli(*_constants(p)))
