"""Host of zone model ``anisotropic`` (transversely isotropic elasticity; kernel:
``dec3d/kernels/zmodels/anisotropic.py``; the law, the axes and their sources:
``dec3d/kernels/zmodels/_elastic_aniso.py``).

Keywords (Itasca, "Anisotropic (Transversely) Elastic Model" page and its property list,
http://docs.itascacg.com/flac3d700/common/models/aniso/doc/modelaniso.html): ``young-plane`` E
and ``young-normal`` E' (> 0), ``poisson-plane`` ν and ``poisson-normal`` ν', ``shear-normal``
G' (> 0), ``dip`` and ``dip-direction`` of the plane of isotropy (degrees); ``density``.
G = E / (2 (1 + ν)) is worked out. Itasca's ``normal``/``normal-x|y|z`` alternatives are not
taken.

Before cycling the compliance must be positive definite; ``moduli``: K + 4G/3 is the largest
eigenvalue of the stiffness in Mandel form (``bound_moduli``'s module text).
"""
import numpy as np

from dec3d.kernels.zmodels import anisotropic as kernel
from dec3d.kernels.zmodels._elastic_aniso import admissible, bound_moduli
from dec3d.physics.cmodels import ELASTIC, Prop, which_zones, zmodel

k = kernel

PROPS = [q for q in ELASTIC if q.name == "density"] + [
    Prop("young-plane", k.P_E, "Young's modulus E in the plane of isotropy", "Pa", lo=0.0, lo_open=True),
    Prop("young-normal", k.P_EN, "Young's modulus E' normal to the plane of isotropy", "Pa", lo=0.0, lo_open=True),
    Prop("poisson-plane", k.P_NU, "Poisson's ratio ν: contraction in the plane under tension in the plane",
         "", lo=None, hi=None),
    Prop("poisson-normal", k.P_NUN, "Poisson's ratio ν': contraction in the plane under tension normal to it",
         "", lo=None, hi=None),
    Prop("shear-normal", k.P_GN, "shear modulus G' of the planes normal to the plane of isotropy", "Pa",
         lo=0.0, lo_open=True),
    Prop("dip", k.P_DIP, "dip of the plane of isotropy (anisotropic) or (1', 2') plane (orthotropic), degrees",
         "deg", lo=0.0, hi=90.0),
    Prop("dip-direction", k.P_DD, "its dip direction, degrees clockwise from +y", "deg",
         lo=None, hi=None),
]


def _constants(p):
    """The orthotropic constants of the transversely isotropic ones (G12 = E / 2(1 + ν))."""
    e, en, nu, nun, gn = p[:, k.P_E], p[:, k.P_EN], p[:, k.P_NU], p[:, k.P_NUN], p[:, k.P_GN]
    with np.errstate(divide="ignore", invalid="ignore"):
        g12 = np.where(nu > -1.0, e / (2.0 * (1.0 + nu)), 0.0)
    return e, e, en, nu, nun, nun, g12, gn, gn


def ti_check(p, ids):
    """Problems: zones whose compliance is not positive definite."""
    bad = ~admissible(*_constants(p))
    if bad.any():
        return [f"compliance not positive definite (it needs poisson-plane > -1 and 1 - poisson-plane - "
                f"2 poisson-normal² young-plane/young-normal > 0): {which_zones(ids, bad)}"], []
    return [], []


zmodel(kernel, "transversely isotropic linear elasticity, plane of isotropy by dip and dip-direction "
       "(Itasca's model)", PROPS, check=ti_check, moduli=lambda p: bound_moduli(*_constants(p)))
