"""Per-zone pieces of 4-node tetrahedral zones: strain increment, Hooke, nodal forces (used by the
Mohr-Coulomb return's callers and the tests' twin of the zone step; the engine's step is
``kernels/zone_step.py``).

3DEC theory text, deformable blocks (000_*, "zone strain rates and stresses", "nodal forces"):
the velocity gradient of a constant-strain tetrahedron follows from Gauss's divergence theorem,
grad v = -(1/3V) sum_n v^n n^(n) S^(n), where face (n) is the face opposite node n, n^(n) its unit
outward normal and S^(n) its area; the nodal force of a zone is the contour integral
f^n = (1/3) sigma . n^(n) S^(n). Stresses are tension positive, order xx yy zz xy xz yz.
"""
from numba import njit

#: plastic-state bits of ``zones.state``: the "now" bits a zone model's update returns, the "past"
#: bits the step keeps (now << 2); 16/32 (64/128) are a ubiquitous-joint zone's weak plane
SHEAR_NOW = 1
TENSION_NOW = 2
SHEAR_PAST = 4
TENSION_PAST = 8
JOINT_SHEAR_NOW = 16
JOINT_TENSION_NOW = 32
JOINT_SHEAR_PAST = 64
JOINT_TENSION_PAST = 128


@njit(cache=True)
def _face_vector(a, b, c, opp):
    """Area vector (normal * area) of triangle abc, oriented away from point opp."""
    ux = b[0] - a[0]; uy = b[1] - a[1]; uz = b[2] - a[2]
    wx = c[0] - a[0]; wy = c[1] - a[1]; wz = c[2] - a[2]
    nx = 0.5 * (uy * wz - uz * wy)
    ny = 0.5 * (uz * wx - ux * wz)
    nz = 0.5 * (ux * wy - uy * wx)
    d = (opp[0] - a[0]) * nx + (opp[1] - a[1]) * ny + (opp[2] - a[2]) * nz
    if d > 0.0:
        nx = -nx; ny = -ny; nz = -nz
    return nx, ny, nz


@njit(cache=True, inline="always")
def tet_kinematics(pos, vel, gp, z, dt, av, de, w):
    """Strain increment of 4-node zone ``z`` (the face vectors of Gauss's theorem above): fills
    ``av`` (4, 3) with the area vectors n^(n) S^(n) of the faces opposite nodes 0-3 (outward),
    ``de`` (6,) with sym(grad v) dt in the order xx yy zz xy xz yz and ``w`` (3,) with the spin
    increment skw(grad v) dt, components 01 02 12 (Eq. 58's rotation rate times dt). Returns
    the volume."""
    for n in range(4):
        i1 = gp[z, (n + 1) % 4]; i2 = gp[z, (n + 2) % 4]; i3 = gp[z, (n + 3) % 4]
        ax, ay, az = _face_vector(pos[i1], pos[i2], pos[i3], pos[gp[z, n]])
        av[n, 0] = ax; av[n, 1] = ay; av[n, 2] = az
    p0 = pos[gp[z, 0]]; p1 = pos[gp[z, 1]]; p2 = pos[gp[z, 2]]; p3 = pos[gp[z, 3]]
    vol = abs((p1[0] - p0[0]) * ((p2[1] - p0[1]) * (p3[2] - p0[2]) - (p2[2] - p0[2]) * (p3[1] - p0[1]))
              - (p1[1] - p0[1]) * ((p2[0] - p0[0]) * (p3[2] - p0[2]) - (p2[2] - p0[2]) * (p3[0] - p0[0]))
              + (p1[2] - p0[2]) * ((p2[0] - p0[0]) * (p3[1] - p0[1]) - (p2[1] - p0[1]) * (p3[0] - p0[0]))) / 6.0
    g00 = 0.0; g01 = 0.0; g02 = 0.0; g10 = 0.0; g11 = 0.0; g12 = 0.0; g20 = 0.0; g21 = 0.0; g22 = 0.0
    for n in range(4):
        r = gp[z, n]
        v0 = vel[r, 0]; v1 = vel[r, 1]; v2 = vel[r, 2]
        s0 = av[n, 0]; s1 = av[n, 1]; s2 = av[n, 2]
        g00 -= v0 * s0; g01 -= v0 * s1; g02 -= v0 * s2
        g10 -= v1 * s0; g11 -= v1 * s1; g12 -= v1 * s2
        g20 -= v2 * s0; g21 -= v2 * s1; g22 -= v2 * s2
    f = dt / (3.0 * vol)
    de[0] = g00 * f; de[1] = g11 * f; de[2] = g22 * f
    de[3] = 0.5 * (g01 + g10) * f; de[4] = 0.5 * (g02 + g20) * f; de[5] = 0.5 * (g12 + g21) * f
    w[0] = 0.5 * (g01 - g10) * f; w[1] = 0.5 * (g02 - g20) * f; w[2] = 0.5 * (g12 - g21) * f
    return vol


@njit(cache=True, inline="always")
def tet_add_forces(gp, z, av, s, w, force):
    """Add the nodal forces w (1/3) sigma . n^(n) S^(n) of zone ``z`` with stress ``s`` (6,)
    and face area vectors ``av`` (4, 3) (from ``tet_kinematics``) to ``force`` (sign as
    the text's contour integral)."""
    w3 = w / 3.0
    for n in range(4):
        r = gp[z, n]
        force[r, 0] += (s[0] * av[n, 0] + s[3] * av[n, 1] + s[4] * av[n, 2]) * w3
        force[r, 1] += (s[3] * av[n, 0] + s[1] * av[n, 1] + s[5] * av[n, 2]) * w3
        force[r, 2] += (s[4] * av[n, 0] + s[5] * av[n, 1] + s[2] * av[n, 2]) * w3


@njit(cache=True, inline="always")
def hooke_increment(s, de, bulk, shear):
    """s (6,) += D : de for isotropic elasticity (Eq. 59 of the 3DEC text, three-term Δε_v)."""
    ev = de[0] + de[1] + de[2]
    lam = bulk - 2.0 * shear / 3.0
    for k in range(3):
        s[k] += lam * ev + 2.0 * shear * de[k]
    for k in range(3, 6):
        s[k] += 2.0 * shear * de[k]
