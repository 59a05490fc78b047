"""Anisotropic linear elasticity shared by the zone models ``orthotropic`` and ``anisotropic``
(transversely isotropic, the orthotropic law with E1 = E2, ν13 = ν23, G13 = G23,
G12 = E1/2(1 + ν12)): the update in local axes and, for their hosts, the admissibility of the
constants and the moduli of the mass scaling. Not a model (the leading underscore keeps it out of
the model list); the two models' files import it, neither imports the other's.

Source: Itasca, FLAC3D/3DEC documentation, "Orthotropic Elastic Model" (FLAC3D Theory and
Background, Constitutive Models), https://docs.itascacg.com/pfc700/common/models/ortho/doc/modelortho.html
(after Lekhnitskii 1981), and "Anisotropic (Transversely) Elastic Model",
http://docs.itascacg.com/flac3d700/common/models/aniso/doc/modelaniso.html. In the local axes the
strain-stress law is

    ε'11 = σ'11/E1 − ν12 σ'22/E2 − ν13 σ'33/E3          2ε'12 = σ'12/G12
    ε'22 = −ν12 σ'11/E2 + σ'22/E2 − ν23 σ'33/E3         2ε'13 = σ'13/G13
    ε'33 = −ν13 σ'11/E3 − ν23 σ'22/E3 + σ'33/E3         2ε'23 = σ'23/G23

(ν_ij the lateral contraction along i' under tension along j'; the compliance is symmetric, so
ν21/E1 = ν12/E2 and so on). The stiffness is its inverse: the normal 3×3 block inverted (by
cofactors), the shears σ'_ij = 2 G_ij ε'_ij (ε' tensor components: d3..d5 of the step are
half the engineering strains).

Orientation (Itasca's convention, "Orientation Conventions" page; the same as
``dec3d.geometry.planes``): x east, y north, z up; dip δ down from the horizontal, dip direction
α clockwise from +y seen from above. The (1', 2') plane is the plane of that dip and dip
direction; with its dip vector d = (cos δ sin α, cos δ cos α, −sin δ), its upward normal
n = (sin δ sin α, sin δ cos α, cos δ) and b = n × d = (−cos α, sin α, 0), the local axes are

    1' = cos ρ d + sin ρ b,   2' = n × 1' = cos ρ b − sin ρ d,   3' = n

ρ the ``rotation`` from the dip vector towards b, counter-clockwise seen from the tip of n
(Itasca's model composes the same three turns: about z to the dip direction, about the new y
down the dip, about the new z by the rotation). So dip 0, dip direction 0, rotation 0 puts 1'
along +y, 2' along −x, 3' along +z; dip 90, dip direction 90 puts 3' along +x and 1' along −z.

The update rotates the strain increment into the local axes (ε' = R ε Rᵀ, the rows of R the
local axes in global components), applies the local stiffness, rotates the stress increment
back (Δσ = Rᵀ Δσ' R) and adds it. The rotation and the stiffness are worked out on every call
(the 12 own columns hold the nine constants and three angles, in degrees). A zone whose
compliance is not positive definite (the host refuses it before cycling) keeps its stress.

Nodal mixed discretization. The step hands the update a strain increment whose volumetric part
ē is averaged over the zones around each gridpoint (NMD, or a hexahedral set's mean). For an
isotropic law that keeps the assembled stiffness symmetric (the mean stress K ē acts on the
zone's own volumetric strain; volume times averaging is a symmetric operator), but an
anisotropic C couples the two parts: the deviatoric stress takes the averaged ē while the mean
stress would take the zone's own deviatoric strain unaveraged, a non-symmetric stiffness under
which the damped explicit scheme grows oscillations (a cube of these zones under a face load
blew up after some 1500 steps with NMD on, and was exact with it off). The cure used here: the
mean stress made by the deviatoric part of d, q = tr(C : dev d)/3, is averaged as the plastic
mean-stress correction is (3DEC theory text, NMD Eqs. 74-76): the update returns dsp = −q, and the
step's averaging sweep replaces q in the zone's mean stress by its average. The transposed
couplings then match, the stiffness is symmetric again, and for isotropic constants q = 0, the
step of the elastic model. So the models declare CORRECTS (they need that sweep) and not PLASTIC
(they never yield: their bits stay 0). With NMD off and outside hexahedral sets the sweep changes nothing.

Mass scaling and time step (``bound_moduli``, the hosts' ``moduli``): the engine scales masses
with the P-wave modulus M = K + 4G/3 of an isotropic zone, which bounds u·Q(n)·u for unit vectors
u, n, Q(n) the acoustic tensor Q_ik = C_ijkl n_j n_l (the nodal stiffness of a zone is V Q(∇N) in
that sense). For any C, u·Q(n)·u = ε : C : ε with ε = sym(u ⊗ n), and |ε|² = (1 + (u·n)²)/2 ≤ 1,
so u·Q(n)·u ≤ Λ, the largest eigenvalue of C as a map of symmetric tensors (the 6×6 stiffness
in Mandel form, shears scaled by √2). Λ does not depend on the axes' orientation; in the local
axes the Mandel stiffness is block diagonal, so Λ = max(λ_max(normal 3×3 block), 2 G12, 2 G13,
2 G23). ``bound_moduli`` returns G = max(G12, G13, G23) and K = Λ − 4G/3 (≥ 2G/3 > 0), so that
K + 4G/3 = Λ: never softer than the zone, hence a stable step. For isotropic constants
Λ = max(3K, 2G) ≥ K + 4G/3, a step at most sqrt(Λ / (K + 4G/3)) smaller than the elastic model's.
"""
import math

import numpy as np
from numba import njit


@njit(cache=True)
def local_axes(dip, ddir, rot):
    """Rows of R (the local axes 1', 2', 3' in global components) for dip, dip direction and
    rotation in degrees: a1x, a1y, a1z, a2x, a2y, a2z, a3x, a3y, a3z."""
    dr = math.radians(dip)
    ar = math.radians(ddir)
    rr = math.radians(rot)
    sd = math.sin(dr)
    cd = math.cos(dr)
    sa = math.sin(ar)
    ca = math.cos(ar)
    sr = math.sin(rr)
    cr = math.cos(rr)
    dx = cd * sa; dy = cd * ca; dz = -sd          # dip vector
    bx = -ca; by = sa; bz = 0.0                   # n × d
    return (cr * dx + sr * bx, cr * dy + sr * by, cr * dz + sr * bz,
            cr * bx - sr * dx, cr * by - sr * dy, cr * bz - sr * dz,
            sd * sa, sd * ca, cd)


@njit(cache=True, inline="always")
def _qform(ax, ay, az, bx, by, bz, t0, t1, t2, t3, t4, t5):
    """a · T · b for the symmetric T (xx yy zz xy xz yz)."""
    return (ax * (t0 * bx + t3 * by + t4 * bz) + ay * (t3 * bx + t1 * by + t5 * bz)
            + az * (t4 * bx + t5 * by + t2 * bz))


@njit(cache=True)
def _sandwich(a1x, a1y, a1z, a2x, a2y, a2z, a3x, a3y, a3z, t0, t1, t2, t3, t4, t5):
    """A T Aᵀ (xx yy zz xy xz yz) for the rows a1, a2, a3 of A and the symmetric T."""
    return (_qform(a1x, a1y, a1z, a1x, a1y, a1z, t0, t1, t2, t3, t4, t5),
            _qform(a2x, a2y, a2z, a2x, a2y, a2z, t0, t1, t2, t3, t4, t5),
            _qform(a3x, a3y, a3z, a3x, a3y, a3z, t0, t1, t2, t3, t4, t5),
            _qform(a1x, a1y, a1z, a2x, a2y, a2z, t0, t1, t2, t3, t4, t5),
            _qform(a1x, a1y, a1z, a3x, a3y, a3z, t0, t1, t2, t3, t4, t5),
            _qform(a2x, a2y, a2z, a3x, a3y, a3z, t0, t1, t2, t3, t4, t5))


@njit(cache=True)
def ortho_increment(e1, e2, e3, n12, n13, n23, g12, g13, g23, dip, ddir, rot,
                    d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5):
    """(s + C : d, q) for the orthotropic constants in the local axes of (dip, ddir, rot)
    [deg] (the module's text), q the mean of C : dev(d), the mean stress the deviatoric part of d
    makes; s unchanged and q = 0 when the constants are not admissible."""
    if not (e1 > 0.0 and e2 > 0.0 and e3 > 0.0 and g12 > 0.0 and g13 > 0.0 and g23 > 0.0):
        return s0, s1, s2, s3, s4, s5, 0.0
    # normal block of the local compliance and its inverse by cofactors
    c11 = 1.0 / e1; c22 = 1.0 / e2; c33 = 1.0 / e3
    c12 = -n12 / e2; c13 = -n13 / e3; c23 = -n23 / e3
    k11 = c22 * c33 - c23 * c23
    k22 = c11 * c33 - c13 * c13
    k33 = c11 * c22 - c12 * c12
    k12 = c13 * c23 - c12 * c33
    k13 = c12 * c23 - c13 * c22
    k23 = c12 * c13 - c11 * c23
    det = c11 * k11 + c12 * k12 + c13 * k13
    if not (det > 0.0 and k11 > 0.0 and k33 > 0.0):
        return s0, s1, s2, s3, s4, s5, 0.0
    k11 /= det; k22 /= det; k33 /= det; k12 /= det; k13 /= det; k23 /= det
    a1x, a1y, a1z, a2x, a2y, a2z, a3x, a3y, a3z = local_axes(dip, ddir, rot)
    l0, l1, l2, l3, l4, l5 = _sandwich(a1x, a1y, a1z, a2x, a2y, a2z, a3x, a3y, a3z, d0, d1, d2, d3, d4, d5)
    q0 = k11 * l0 + k12 * l1 + k13 * l2
    q1 = k12 * l0 + k22 * l1 + k23 * l2
    q2 = k13 * l0 + k23 * l1 + k33 * l2
    q3 = 2.0 * g12 * l3
    q4 = 2.0 * g13 * l4
    q5 = 2.0 * g23 * l5
    # back to global axes: the columns of R are the rows of Rᵀ
    r0, r1, r2, r3, r4, r5 = _sandwich(a1x, a2x, a3x, a1y, a2y, a3y, a1z, a2z, a3z, q0, q1, q2, q3, q4, q5)
    # mean of C:d less the mean of C:(ev/3) I (traces are the same in both axes)
    ksum = k11 + k22 + k33 + 2.0 * (k12 + k13 + k23)
    qd = (q0 + q1 + q2) / 3.0 - (l0 + l1 + l2) * ksum / 9.0
    return s0 + r0, s1 + r1, s2 + r2, s3 + r3, s4 + r4, s5 + r5, qd


def normal_compliance(e1, e2, e3, n12, n13, n23):
    """Normal 3×3 blocks (n, 3, 3) of the local compliances of arrays of constants."""
    s = np.zeros((len(e1), 3, 3))
    with np.errstate(divide="ignore", invalid="ignore"):
        s[:, 0, 0] = 1.0 / e1
        s[:, 1, 1] = 1.0 / e2
        s[:, 2, 2] = 1.0 / e3
        s[:, 0, 1] = s[:, 1, 0] = -n12 / e2
        s[:, 0, 2] = s[:, 2, 0] = -n13 / e3
        s[:, 1, 2] = s[:, 2, 1] = -n23 / e3
    return s


def admissible(e1, e2, e3, n12, n13, n23, g12, g13, g23):
    """Rows whose compliance is finite and positive definite (the moduli positive)."""
    s = normal_compliance(e1, e2, e3, n12, n13, n23)
    ok = np.isfinite(s).all(axis=(1, 2)) & (g12 > 0) & (g13 > 0) & (g23 > 0)
    out = np.zeros(len(s), bool)
    if ok.any():
        out[ok] = np.linalg.eigvalsh(s[ok]).min(axis=1) > 0.0
    return out


def bound_moduli(e1, e2, e3, n12, n13, n23, g12, g13, g23):
    """(K, G) with K + 4G/3 = Λ, the largest Mandel eigenvalue of the stiffness (module text);
    0 for rows whose constants are not admissible (refused before cycling)."""
    good = admissible(e1, e2, e3, n12, n13, n23, g12, g13, g23)
    K = np.zeros(len(e1))
    G = np.zeros(len(e1))
    if good.any():
        cn = np.linalg.inv(normal_compliance(e1, e2, e3, n12, n13, n23)[good])
        lam = np.linalg.eigvalsh(cn).max(axis=1)
        gmax = np.maximum(np.maximum(g12[good], g13[good]), g23[good])
        G[good] = gmax
        K[good] = np.maximum(lam, 2.0 * gmax) - 4.0 * gmax / 3.0
    return K, G
