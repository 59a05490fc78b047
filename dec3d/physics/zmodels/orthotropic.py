"""Host of zone model ``orthotropic`` (kernel: ``dec3d/kernels/zmodels/orthotropic.py``, where the
law, the axes and their sources are).

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
Young's moduli); each modulus is checked > 0 by its range.

Mass scaling and time step (``moduli``): the engine scales masses with the P-wave modulus
M = K + 4G/3 of an isotropic zone, which bounds u·Q(n)·u for unit vectors u, n, Q(n) the
acoustic tensor Q_ik = C_ijkl n_j n_l (the nodal stiffness of a zone is V Q(∇N) in that
sense). For any C, u·Q(n)·u = ε : C : ε with ε = sym(u ⊗ n), and |ε|² = (1 + (u·n)²)/2 ≤ 1, so
u·Q(n)·u ≤ Λ, the largest eigenvalue of C as a map of symmetric tensors (the 6×6 stiffness in
Mandel form, shears scaled by √2). Λ does not depend on the axes' orientation; in the local axes
the Mandel stiffness is block diagonal, so Λ = max(λ_max(normal 3×3 block), 2 G12, 2 G13,
2 G23). ``moduli`` returns G = max(G12, G13, G23) and K = Λ − 4G/3 (≥ 2G/3 > 0), so that
K + 4G/3 = Λ: never softer than the zone, hence a stable step. For isotropic constants Λ =
max(3K, 2G) ≥ K + 4G/3, a step at most sqrt(Λ / (K + 4G/3)) smaller than the elastic model's.
"""
import numpy as np

from dec3d.kernels.zmodels import orthotropic as kernel
from dec3d.physics.cmodels import ELASTIC, Prop, which_zones, zmodel

k = kernel
_DENSITY = [q for q in ELASTIC if q.name == "density"]


def _pos(name, col, doc):
    return Prop(name, col, doc, "Pa", lo=0.0, lo_open=True)


def _ratio(name, col, doc):
    return Prop(name, col, doc, None, lo=None, hi=None)


def orientation_props(dip_col, dd_col, rot_col=None, plane="the (1', 2') plane"):
    """dip, dip-direction (and rotation) keywords, degrees kept as degrees."""
    out = [Prop("dip", dip_col, f"dip of {plane}, degrees down from the horizontal", "deg", lo=0.0, hi=90.0),
           Prop("dip-direction", dd_col, f"dip direction of {plane}, degrees clockwise from +y", "deg",
                lo=None, hi=None)]
    if rot_col is not None:
        out.append(Prop("rotation", rot_col, "angle of 1' from the dip vector, degrees counter-clockwise about the "
                        "upward normal 3'", "deg", lo=None, hi=None))
    return out


PROPS = _DENSITY + [
    _pos("young-1", k.P_E1, "Young's modulus E1 along local 1'"),
    _pos("young-2", k.P_E2, "Young's modulus E2 along local 2'"),
    _pos("young-3", k.P_E3, "Young's modulus E3 along local 3'"),
    _ratio("poisson-12", k.P_NU12, "Poisson's ratio ν12: contraction along 1' under tension along 2'"),
    _ratio("poisson-13", k.P_NU13, "Poisson's ratio ν13: contraction along 1' under tension along 3'"),
    _ratio("poisson-23", k.P_NU23, "Poisson's ratio ν23: contraction along 2' under tension along 3'"),
    _pos("shear-12", k.P_G12, "shear modulus G12 of the (1', 2') plane"),
    _pos("shear-13", k.P_G13, "shear modulus G13 of the (1', 3') plane"),
    _pos("shear-23", k.P_G23, "shear modulus G23 of the (2', 3') plane"),
] + orientation_props(k.P_DIP, k.P_DD, k.P_ROT)


def normal_compliance(e1, e2, e3, n12, n13, n23):
    """Normal 3×3 blocks (n, 3, 3) of the local compliances (the kernel's law)."""
    s = np.zeros((len(e1), 3, 3))
    with np.errstate(divide="ignore", invalid="ignore"):
        s[:, 0, 0] = 1.0 / e1
        s[:, 1, 1] = 1.0 / e2
        s[:, 2, 2] = 1.0 / e3
        s[:, 0, 1] = s[:, 1, 0] = -n12 / e2
        s[:, 0, 2] = s[:, 2, 0] = -n13 / e3
        s[:, 1, 2] = s[:, 2, 1] = -n23 / e3
    return s


def positive_definite(s):
    """Rows whose (n, 3, 3) symmetric block is finite and positive definite."""
    ok = np.isfinite(s).all(axis=(1, 2))
    out = np.zeros(len(s), bool)
    if ok.any():
        out[ok] = np.linalg.eigvalsh(s[ok]).min(axis=1) > 0.0
    return out


def bound_moduli(e1, e2, e3, n12, n13, n23, g12, g13, g23):
    """(K, G) with K + 4G/3 = Λ, the largest Mandel eigenvalue of the stiffness (module text);
    0 for rows whose compliance is not admissible (refused before cycling)."""
    s = normal_compliance(e1, e2, e3, n12, n13, n23)
    good = positive_definite(s) & (g12 > 0) & (g13 > 0) & (g23 > 0)
    K = np.zeros(len(e1))
    G = np.zeros(len(e1))
    if good.any():
        cn = np.linalg.inv(s[good])
        lam = np.linalg.eigvalsh(cn).max(axis=1)
        gmax = np.maximum(np.maximum(g12[good], g13[good]), g23[good])
        lam = np.maximum(lam, 2.0 * gmax)
        G[good] = gmax
        K[good] = lam - 4.0 * gmax / 3.0
    return K, G


def ortho_constants(p):
    return (p[:, k.P_E1], p[:, k.P_E2], p[:, k.P_E3], p[:, k.P_NU12], p[:, k.P_NU13], p[:, k.P_NU23],
            p[:, k.P_G12], p[:, k.P_G13], p[:, k.P_G23])


def compliance_check(constants, ids):
    """Problems: zones whose compliance is not positive definite."""
    e1, e2, e3, n12, n13, n23 = constants[:6]
    bad = ~positive_definite(normal_compliance(e1, e2, e3, n12, n13, n23))
    if bad.any():
        return [f"compliance not positive definite (Poisson's ratios incompatible with the Young's moduli): "
                f"{which_zones(ids, bad)}"]
    return []


def ortho_check(p, ids):
    return compliance_check(ortho_constants(p), ids), []


def ortho_moduli(p):
    return bound_moduli(*ortho_constants(p))


zmodel(kernel, "orthotropic linear elasticity in local axes set by dip, dip-direction and rotation (Itasca's model)",
       PROPS, check=ortho_check, moduli=ortho_moduli)
