"""Elastic 10-node (higher-order) tetrahedral zones: Gauss-point strains and stresses,
nodal forces by integration of the Gauss-point stresses, lumped masses, nodal stiffness.

3DEC theory text (000_*), "Higher-Order Tetrahedral Elements": ``block zone generate
high-order-tetra`` adds a node at the midpoint of every zone edge, giving quadratic
displacement interpolation; "for the 10-node tetrahedra, there are 4 Gauss points, where
strains and stresses are calculated"; "nodal forces are obtained from the Gauss point stresses
by numerical integration, so that the stiffness matrix is not calculated"; the constitutive
model is applied at each Gauss point every step. The text gives neither the shape functions,
the quadrature nor a mass lumping for these zones; what is used here is standard finite-element
practice (Zienkiewicz & Taylor, The Finite Element Method, vol. 1, tetrahedral elements;
Hughes 1987 for the quadrature and for HRZ lumping), named where used.

Node order (``zones.gp``): corners 0-3, then the mid-edge nodes of edges 01 12 20 03 13 23.
With volume coordinates L0..L3 (L0 = 1 - xi1 - xi2 - xi3, Lk = xi_k), the shape functions are
N_i = L_i (2 L_i - 1) at corner i and N = 4 L_i L_j at the node of edge ij (isoparametric:
the same functions map the reference tetrahedron to the zone's current positions).

Quadrature: the symmetric 4-point rule for tetrahedra (exact for quadratics), Gauss point g
at L_g = a, the other three L = b, a = 0.5854101966249685, b = 0.1381966011250105 (a = (5 + 3
sqrt 5)/20, b = (5 - sqrt 5)/20), weight 1/24 each in the reference volume 1/6. Gauss point g
is the one nearest corner g; ``gstress[z, g]`` is its stress (xx yy zz xy xz yz, tension
positive) and ``stress[z]`` the mean of the four.

Sign convention as ``kernels/zone_step.zone_step``: ``force[r]`` accumulates the force the
zone exerts on gridpoint r, the negative of the internal-force vector, -int B^T sigma dV.

Zones must be positively oriented (corners 0-3 right-handed, as the mesher makes them). Every
kernel that integrates over zones skips a zone whose det J is not positive at a Gauss point (inverted or flat), so no NaN
or infinity reaches the stores, and returns the first such zone row (-1 if none) for the host
to report as an error naming the zone.
"""
import numpy as np
from numba import njit, prange

from .gather import node_lists as gather_lists
from .gather import node_sums, scatter

GA = 0.5854101966249685     # (5 + 3 sqrt 5) / 20
GB = 0.1381966011250105     # (5 - sqrt 5) / 20
GW = 1.0 / 24.0             # weight of each point (reference tetrahedron volume 1/6)

#: HRZ fractions of the zone mass for a straight-edged 10-node tetrahedron (see tet10_lumped_mass)
HRZ_CORNER = 1.0 / 36.0
HRZ_MID = 4.0 / 27.0

@njit(cache=True)
def ref_derivs():
    """dN_a/dxi_k at the 4 Gauss points: array (4, 10, 3). Returns a new array."""
    d = np.zeros((4, 10, 3))
    ei = np.array([0, 1, 2, 0, 1, 2])   # corners (i, j) of the edge of mid-edge node 4 + e
    ej = np.array([1, 2, 0, 3, 3, 3])
    for g in range(4):
        L = np.full(4, GB)
        L[g] = GA
        # dN/dL_m for every node, then dN/dxi_k = dN/dL_k - dN/dL_0 (L0 = 1 - sum xi)
        dl = np.zeros((10, 4))
        for i in range(4):
            dl[i, i] = 4.0 * L[i] - 1.0
        for e in range(6):
            dl[4 + e, ei[e]] = 4.0 * L[ej[e]]
            dl[4 + e, ej[e]] = 4.0 * L[ei[e]]
        for a in range(10):
            for k in range(3):
                d[g, a, k] = dl[a, k + 1] - dl[a, 0]
    return d


@njit(cache=True)
def _grad_n(pos, nodes, dxi, dn):
    """Cartesian shape-function gradients at one Gauss point: fills dn (10, 3) with dN_a/dx_j
    from dxi (10, 3) = dN_a/dxi_k and the nodal positions. Returns det J (signed); when it is
    not positive, dn is left as it was.
    Scalars only (no temporary arrays: this runs 4 times per zone per step)."""
    # J[i, k] = dx_i / dxi_k
    j00 = 0.0; j01 = 0.0; j02 = 0.0
    j10 = 0.0; j11 = 0.0; j12 = 0.0
    j20 = 0.0; j21 = 0.0; j22 = 0.0
    for a in range(10):
        p = pos[nodes[a]]
        d0 = dxi[a, 0]; d1 = dxi[a, 1]; d2 = dxi[a, 2]
        j00 += p[0] * d0; j01 += p[0] * d1; j02 += p[0] * d2
        j10 += p[1] * d0; j11 += p[1] * d1; j12 += p[1] * d2
        j20 += p[2] * d0; j21 += p[2] * d1; j22 += p[2] * d2
    c00 = j11 * j22 - j12 * j21
    c01 = j12 * j20 - j10 * j22
    c02 = j10 * j21 - j11 * j20
    det = j00 * c00 + j01 * c01 + j02 * c02
    if not det > 0.0:            # inverted, flat or NaN: the caller skips the zone
        return det
    r = 1.0 / det
    # inverse: i{k}{i} = dxi_k / dx_i
    i00 = c00 * r
    i10 = c01 * r
    i20 = c02 * r
    i01 = (j02 * j21 - j01 * j22) * r
    i11 = (j00 * j22 - j02 * j20) * r
    i21 = (j01 * j20 - j00 * j21) * r
    i02 = (j01 * j12 - j02 * j11) * r
    i12 = (j02 * j10 - j00 * j12) * r
    i22 = (j00 * j11 - j01 * j10) * r
    for a in range(10):
        d0 = dxi[a, 0]; d1 = dxi[a, 1]; d2 = dxi[a, 2]
        dn[a, 0] = d0 * i00 + d1 * i10 + d2 * i20
        dn[a, 1] = d0 * i01 + d1 * i11 + d2 * i21
        dn[a, 2] = d0 * i02 + d1 * i12 + d2 * i22
    return det


@njit(cache=True)
def _zone_grads(pos, nodes, dref, dn4, wd4):
    """Shape-function gradients dn4 (4, 10, 3) and weights w det J (4,) at the 4 Gauss points
    of one zone. False when det J is not positive at some point (inverted or flat zone: the
    mesher makes positively oriented zones, corners 0-3 right-handed)."""
    for g in range(4):
        det = _grad_n(pos, nodes, dref[g], dn4[g])
        if not det > 0.0:
            return False
        wd4[g] = GW * det
    return True


@njit(cache=True)
def _zone_force(dn4, wd4, s4, fz):
    """fz[a] = -sum_g wd4[g] s4[g] . dn4[g, a]: the force of one zone on each of its nodes
    (s4 (4, 6) Gauss-point stresses), summed over g in order. Fills fz (10, 3)."""
    for a in range(10):
        fz[a, 0] = 0.0
        fz[a, 1] = 0.0
        fz[a, 2] = 0.0
    for g in range(4):
        s = s4[g]
        wd = wd4[g]
        dn = dn4[g]
        for a in range(10):
            fz[a, 0] -= wd * (s[0] * dn[a, 0] + s[3] * dn[a, 1] + s[4] * dn[a, 2])
            fz[a, 1] -= wd * (s[3] * dn[a, 0] + s[1] * dn[a, 1] + s[5] * dn[a, 2])
            fz[a, 2] -= wd * (s[4] * dn[a, 0] + s[5] * dn[a, 1] + s[2] * dn[a, 2])


@njit(cache=True, inline="always")
def vel_grad(dn, vel, nodes):
    """The velocity gradient L[i, j] = dv_i/dx_j at one Gauss point (dn (10, 3) the shape-function
    gradients there), summed over the nodes in order: (l00, l01, l02, l10, …, l22)."""
    l00 = 0.0; l01 = 0.0; l02 = 0.0
    l10 = 0.0; l11 = 0.0; l12 = 0.0
    l20 = 0.0; l21 = 0.0; l22 = 0.0
    for a in range(10):
        v = vel[nodes[a]]
        l00 += v[0] * dn[a, 0]; l01 += v[0] * dn[a, 1]; l02 += v[0] * dn[a, 2]
        l10 += v[1] * dn[a, 0]; l11 += v[1] * dn[a, 1]; l12 += v[1] * dn[a, 2]
        l20 += v[2] * dn[a, 0]; l21 += v[2] * dn[a, 1]; l22 += v[2] * dn[a, 2]
    return l00, l01, l02, l10, l11, l12, l20, l21, l22


@njit(cache=True)
def _zone_step(z, pos, vel, gp, bulk, shear, dt, gstress, stress, dref, dn4, wd4, nodes, fz):
    """Stress update and nodal forces (into fz (10, 3)) of zone row z. False, changing
    nothing, when the zone is inverted or flat."""
    for a in range(10):
        nodes[a] = gp[z, a]
    if not _zone_grads(pos, nodes, dref, dn4, wd4):
        return False
    lam = bulk[z] - 2.0 * shear[z] / 3.0
    g2 = 2.0 * shear[z]
    for c in range(6):
        stress[z, c] = 0.0
    for g in range(4):
        l00, l01, l02, l10, l11, l12, l20, l21, l22 = vel_grad(dn4[g], vel, nodes)
        exx = l00 * dt; eyy = l11 * dt; ezz = l22 * dt
        exy = 0.5 * (l01 + l10) * dt
        exz = 0.5 * (l02 + l20) * dt
        eyz = 0.5 * (l12 + l21) * dt
        ev = exx + eyy + ezz
        s = gstress[z, g]
        s[0] += lam * ev + g2 * exx
        s[1] += lam * ev + g2 * eyy
        s[2] += lam * ev + g2 * ezz
        s[3] += g2 * exy
        s[4] += g2 * exz
        s[5] += g2 * eyz
        for c in range(6):
            stress[z, c] += 0.25 * s[c]
    _zone_force(dn4, wd4, gstress[z], fz)
    return True


@njit(cache=True)
def tet10_step(pos, vel, gp, rows, bulk, shear, dt, gstress, stress, force):
    """One elastic step of the 10-node zones in ``rows``.

    pos, vel (nv, 3): gridpoint positions (current) and velocities; gp (nz, 10) node rows;
    rows (k,) int64 zone rows to update; bulk, shear (nz,) moduli by zone row [Pa]; dt [s];
    gstress (nz, 4, 6), stress (nz, 6) [Pa]; force (nv, 3) [N].
    At each Gauss point g: grad v = sum_a v_a (x) grad N_a (isoparametric, Jacobian from pos),
    strain increment = sym(grad v) dt, gstress[z, g] += lambda tr(de) I + 2 G de (the text's
    Eq. 59 with the 3-term volumetric strain of the errata). Then stress[z] = mean over g, and
    force[gp[z, a]] -= sum_g w det J_g sigma_g . grad N_a(g), zone by zone in the order of rows.
    Modifies gstress, stress, force. A zone whose det J is not positive at a Gauss point
    (inverted or flat) is left untouched, so no NaN spreads; the first such row is returned
    (-1 if none) for the caller to report.
    """
    dref = ref_derivs()
    dn4 = np.empty((4, 10, 3))
    wd4 = np.empty(4)
    nodes = np.empty(10, np.int64)
    fz = np.empty((10, 3))
    bad = -1
    for kk in range(rows.shape[0]):
        z = rows[kk]
        if not _zone_step(z, pos, vel, gp, bulk, shear, dt, gstress, stress, dref, dn4, wd4, nodes, fz):
            if bad < 0:
                bad = z
            continue
        scatter(force, nodes, fz)
    return bad


@njit(cache=True)
def tet10_forces(pos, gp, rows, gstress, force):
    """Nodal forces of the Gauss-point stresses as they are, no stress update (for a state
    just set, e.g. in-situ stresses): force[gp[z, a]] -= sum_g w det J_g sigma_g . grad N_a(g).
    Modifies force; returns the first zone row skipped as inverted or flat, -1 if none."""
    dref = ref_derivs()
    dn4 = np.empty((4, 10, 3))
    wd4 = np.empty(4)
    nodes = np.empty(10, np.int64)
    fz = np.empty((10, 3))
    bad = -1
    for kk in range(rows.shape[0]):
        z = rows[kk]
        for a in range(10):
            nodes[a] = gp[z, a]
        if not _zone_grads(pos, nodes, dref, dn4, wd4):
            if bad < 0:
                bad = z
            continue
        _zone_force(dn4, wd4, gstress[z], fz)
        scatter(force, nodes, fz)
    return bad


#: zones per task of the parallel pass (scratch arrays are made once per task)
CHUNK = 256


@njit(cache=True, parallel=True)
def tet10_zone_pass(pos, vel, gp, rows, bulk, shear, dt, gstress, stress, zf, ok):
    """The zone half of ``tet10_step_parallel``, in parallel over chunks of rows (each zone
    writes only its own rows): stress update, and zf[k] (10, 3) = the force of zone rows[k] on
    each of its nodes; ok[k] = False for an inverted or flat zone (left untouched)."""
    n = rows.shape[0]
    nchunk = (n + CHUNK - 1) // CHUNK
    for c in prange(nchunk):
        dref = ref_derivs()
        dn4 = np.empty((4, 10, 3))
        wd4 = np.empty(4)
        nodes = np.empty(10, np.int64)
        for kk in range(c * CHUNK, min(n, (c + 1) * CHUNK)):
            ok[kk] = _zone_step(rows[kk], pos, vel, gp, bulk, shear, dt, gstress, stress,
                                dref, dn4, wd4, nodes, zf[kk])


@njit(cache=True)
def node_lists(nv, gp, rows):
    """Per gridpoint, the (zone, node) entries that add to it, in a fixed order (CSR): the
    entries of gridpoint r are nent[nstart[r]:nstart[r + 1]], each 10 k + a (node a of zone
    rows[k]), ascending: the order of the serial scatter of ``tet10_step``
    (``kernels/gather.node_lists``). Made once per mesh. Returns (nstart (nv + 1,), nent
    (10 k,)) int64."""
    return gather_lists(nv, np.arange(nv), gp, rows, 10)


@njit(cache=True)
def tet10_step_parallel(pos, vel, gp, rows, bulk, shear, dt, gstress, stress, force,
                        zf, ok, nstart, nent):
    """``tet10_step`` on several threads, bit for bit the same result whatever the thread
    count (and the same as ``tet10_step``): a parallel zone pass into the scratch zf
    (len(rows), 10, 3) [N] and ok (len(rows),) bool, then fixed-order sums per gridpoint over
    the lists of ``node_lists(len(force), gp, rows)``. Returns the first inverted or flat zone
    row in the order of rows (-1 none); such zones are left untouched."""
    tet10_zone_pass(pos, vel, gp, rows, bulk, shear, dt, gstress, stress, zf, ok)
    node_sums(force, zf, ok, nstart, nent)
    for kk in range(rows.shape[0]):
        if not ok[kk]:
            return rows[kk]
    return -1


@njit(cache=True)
def tet10_volume(pos, gp, rows, volume):
    """Zone volumes by the 4-point rule, sum_g w det J_g (exact for straight edges).
    Writes volume[z] for z in rows (0 for an inverted or flat zone); returns the first such
    row, -1 if none."""
    dref = ref_derivs()
    dn4 = np.empty((4, 10, 3))
    wd4 = np.empty(4)
    nodes = np.empty(10, np.int64)
    bad = -1
    for kk in range(rows.shape[0]):
        z = rows[kk]
        for a in range(10):
            nodes[a] = gp[z, a]
        if not _zone_grads(pos, nodes, dref, dn4, wd4):
            volume[z] = 0.0
            if bad < 0:
                bad = z
            continue
        volume[z] = wd4[0] + wd4[1] + wd4[2] + wd4[3]
    return bad


@njit(cache=True)
def tet10_lumped_mass(pos, gp, rows, density, mass):
    """Lumped gridpoint masses of 10-node zones, added to mass[gp] (density by zone row).

    The 3DEC text prescribes no lumping for these zones (its "one third of the tetrahedra
    masses" rule is for 4-node zones). Row sums of the consistent mass matrix are negative at
    the corners (-M/20 each, +M/5 at mid-edge nodes), so HRZ diagonal scaling is used
    (Hinton, Rock & Zienkiewicz 1976; Hughes 1987, section 7.3.2): each node gets the
    consistent diagonal int rho N_a^2 dV scaled so that the masses sum to the zone mass. For a
    straight-edged zone these fractions are fixed, M/36 per corner and 4M/27 per mid-edge node,
    all positive; they are applied to M = rho V with V from the same 4-point rule as the forces
    (exact for straight edges; for edges curved by large strain the straight-edge fractions are
    kept). Modifies mass; returns the first zone row skipped as inverted or flat, -1 if none.
    """
    dref = ref_derivs()
    dn4 = np.empty((4, 10, 3))
    wd4 = np.empty(4)
    nodes = np.empty(10, np.int64)
    bad = -1
    for kk in range(rows.shape[0]):
        z = rows[kk]
        for a in range(10):
            nodes[a] = gp[z, a]
        if not _zone_grads(pos, nodes, dref, dn4, wd4):
            if bad < 0:
                bad = z
            continue
        m = density[z] * (wd4[0] + wd4[1] + wd4[2] + wd4[3])
        for a in range(4):
            mass[nodes[a]] += HRZ_CORNER * m
        for a in range(4, 10):
            mass[nodes[a]] += HRZ_MID * m
    return bad


@njit(cache=True)
def add_stiffness_bound(dng, wd, lam, G, nd, K, kdiag):
    """kdiag[nd[a]] += the largest absolute row sum of node a's three rows of the element
    stiffness K = sum_g wd[g] B_g^T D B_g (isotropic elastic, Lame lam and G), from the Cartesian
    shape-function gradients dng (ng, n, 3); K (3 n, 3 n) is scratch. Shared by the 10-node
    zones and the 20-node FE blocks (``tet10_stiffness``, ``feblock.feb_stiffness``)."""
    n = dng.shape[1]
    K[:, :] = 0.0
    for g in range(wd.shape[0]):
        dn = dng[g]
        w = wd[g]
        # block ab of B^T D B: lambda g_a g_b^T + G g_b g_a^T + G (g_a . g_b) I, g = grad N
        for a in range(n):
            for b in range(n):
                dot = dn[a, 0] * dn[b, 0] + dn[a, 1] * dn[b, 1] + dn[a, 2] * dn[b, 2]
                for i in range(3):
                    for j in range(3):
                        kij = lam * dn[a, i] * dn[b, j] + G * dn[b, i] * dn[a, j]
                        if i == j:
                            kij += G * dot
                        K[3 * a + i, 3 * b + j] += w * kij
    for a in range(n):
        best = 0.0
        for i in range(3):
            rs = 0.0
            for col in range(3 * n):
                rs += abs(K[3 * a + i, col])
            if rs > best:
                best = rs
        kdiag[nd[a]] += best


@njit(cache=True)
def tet10_stiffness(pos, gp, rows, bulk, shear, kdiag):
    """Nodal stiffness measure k_i of the text's Eq. (84)-(85) (dt_n = 2 min sqrt(m_i / k_i))
    for 10-node zones, added to kdiag[gp].

    The text's Eq. (86) is written for 4-node zones; for 10-node zones this uses a bound that
    is safe by construction: the element stiffness K = sum_g w det J B^T D B (never used for
    forces, only here) and, per node a, the largest absolute row sum of its three rows. Summed
    over zones it bounds the global row sums, so by Gershgorin's theorem the largest
    eigenvalue of M^-1 K is at most max_i k_i / m_i for any diagonal mass, and the explicit
    step is stable at dt <= 2 min sqrt(m_i / k_i). Modifies kdiag; returns the first zone row
    skipped as inverted or flat, -1 if none.
    """
    dref = ref_derivs()
    dn4 = np.empty((4, 10, 3))
    wd4 = np.empty(4)
    nodes = np.empty(10, np.int64)
    K = np.empty((30, 30))
    bad = -1
    for kk in range(rows.shape[0]):
        z = rows[kk]
        for a in range(10):
            nodes[a] = gp[z, a]
        if not _zone_grads(pos, nodes, dref, dn4, wd4):
            if bad < 0:
                bad = z
            continue
        add_stiffness_bound(dn4, wd4, bulk[z] - 2.0 * shear[z] / 3.0, shear[z], nodes, K, kdiag)
    return bad


@njit(cache=True)
def add_body_force(wd, shp, rho, gvec, nd, force):
    """force[nd[a]] += rho gvec sum_g wd[g] shp[g, a]: the consistent gravity load int rho N_a g dV
    of one element from the weights w det J wd (ng,) and shape values shp (ng, n) at its
    integration points. Shared by ``tet10_body_force`` and ``feblock.feb_body_force``."""
    for a in range(shp.shape[1]):
        w = 0.0
        for g in range(wd.shape[0]):
            w += wd[g] * shp[g, a]
        w *= rho
        r = nd[a]
        force[r, 0] += w * gvec[0]
        force[r, 1] += w * gvec[1]
        force[r, 2] += w * gvec[2]


@njit(cache=True)
def tet10_body_force(pos, gp, rows, density, gvec, force):
    """Consistent nodal forces of gravity on 10-node zones, added to force[gp]:
    F_a = rho g int N_a dV, by the 4-point rule (exact for straight edges).

    The FE-block text (003_*, "Gravity Forces", Eq. 8: F_I = int N_I g dV, evaluated
    numerically), which the 3DEC text names as the model of its 10-node zones. Unlike the
    masses these loads are not all positive: for a straight-edged zone of weight W each corner
    gets -W/20 and each mid-edge node W/5; with them a quadratic zone reproduces the linear
    stress of a self-weight column exactly (lumped HRZ loads do not). density (nz,) [kg/m3] by
    zone row, gvec (3,) [m/s2]. Modifies force; returns the first zone row skipped as inverted
    or flat, -1 if none."""
    dref = ref_derivs()
    dn4 = np.empty((4, 10, 3))
    wd4 = np.empty(4)
    nodes = np.empty(10, np.int64)
    shp = np.empty((4, 10))
    ei = np.array([0, 1, 2, 0, 1, 2])
    ej = np.array([1, 2, 0, 3, 3, 3])
    for g in range(4):           # N_a at Gauss point g: L_g = a, the others b
        for i in range(4):
            li = GA if i == g else GB
            shp[g, i] = li * (2.0 * li - 1.0)
        for e in range(6):
            i = ei[e]
            j = ej[e]
            li = GA if i == g else GB
            lj = GA if j == g else GB
            shp[g, 4 + e] = 4.0 * li * lj
    bad = -1
    for kk in range(rows.shape[0]):
        z = rows[kk]
        for a in range(10):
            nodes[a] = gp[z, a]
        if not _zone_grads(pos, nodes, dref, dn4, wd4):
            if bad < 0:
                bad = z
            continue
        add_body_force(wd4, shp, density[z], gvec, nodes, force)
    return bad


@njit(cache=True)
def tri6_traction_loads(pos, tri, traction, force):
    """Consistent nodal forces of a uniform traction on the 6-node faces of 10-node zones:
    force[tri[f, a]] += traction[f] int N_a dA (the FE-block text's Eq. 8 and 9 applied to a
    surface load: nodal forces are the load weighted by the shape functions).

    tri (k, 6): corners 0-2 then the mid-edge nodes of edges 01 12 20; traction (k, 3) [Pa],
    constant over the face. Quadratic triangle N_i = L_i (2 L_i - 1), N_ij = 4 L_i L_j,
    integrated with the 3-point rule (L = 2/3, 1/6, 1/6; weight 1/6 each in the reference area
    1/2; exact for flat faces with straight edges, where it gives 0 at the corners and A/3 at
    each mid-edge node). Splitting the face in 4 triangles and sharing each by thirds (the
    4-node way) would instead give A/12 and A/4, and a 10-node mesh would then not carry a
    uniform stress exactly. Modifies force."""
    n = np.empty(6)
    d1 = np.empty(6)
    d2 = np.empty(6)
    for f in range(tri.shape[0]):
        for q in range(3):
            L0 = 1.0 / 6.0; L1 = 1.0 / 6.0; L2 = 1.0 / 6.0
            if q == 0:
                L0 = 2.0 / 3.0
            elif q == 1:
                L1 = 2.0 / 3.0
            else:
                L2 = 2.0 / 3.0
            n[0] = L0 * (2.0 * L0 - 1.0); n[1] = L1 * (2.0 * L1 - 1.0); n[2] = L2 * (2.0 * L2 - 1.0)
            n[3] = 4.0 * L0 * L1; n[4] = 4.0 * L1 * L2; n[5] = 4.0 * L2 * L0
            # dN/dxi1 (xi1 = L1) and dN/dxi2 (xi2 = L2), with L0 = 1 - xi1 - xi2
            d1[0] = -(4.0 * L0 - 1.0); d1[1] = 4.0 * L1 - 1.0; d1[2] = 0.0
            d1[3] = 4.0 * (L0 - L1); d1[4] = 4.0 * L2; d1[5] = -4.0 * L2
            d2[0] = -(4.0 * L0 - 1.0); d2[1] = 0.0; d2[2] = 4.0 * L2 - 1.0
            d2[3] = -4.0 * L1; d2[4] = 4.0 * L1; d2[5] = 4.0 * (L0 - L2)
            t1x = 0.0; t1y = 0.0; t1z = 0.0; t2x = 0.0; t2y = 0.0; t2z = 0.0
            for a in range(6):
                p = pos[tri[f, a]]
                t1x += d1[a] * p[0]; t1y += d1[a] * p[1]; t1z += d1[a] * p[2]
                t2x += d2[a] * p[0]; t2y += d2[a] * p[1]; t2z += d2[a] * p[2]
            cx = t1y * t2z - t1z * t2y
            cy = t1z * t2x - t1x * t2z
            cz = t1x * t2y - t1y * t2x
            da = np.sqrt(cx * cx + cy * cy + cz * cz) / 6.0
            for a in range(6):
                r = tri[f, a]
                w = da * n[a]
                force[r, 0] += w * traction[f, 0]
                force[r, 1] += w * traction[f, 1]
                force[r, 2] += w * traction[f, 2]


@njit(cache=True)
def tet10_gauss_positions(pos, gp, rows, out):
    """Positions of the 4 Gauss points of the zones in rows: out[z, g] = sum_a N_a(g) x_a
    (out (nz, 4, 3)), for stresses that vary in space (in-situ gradients), histories and
    output at the points where the stresses live. Modifies out."""
    ei = np.array([0, 1, 2, 0, 1, 2])
    ej = np.array([1, 2, 0, 3, 3, 3])
    for kk in range(rows.shape[0]):
        z = rows[kk]
        for g in range(4):
            x = 0.0; y = 0.0; w = 0.0
            for a in range(10):
                if a < 4:
                    li = GA if a == g else GB
                    n = li * (2.0 * li - 1.0)
                else:
                    li = GA if ei[a - 4] == g else GB
                    lj = GA if ej[a - 4] == g else GB
                    n = 4.0 * li * lj
                p = pos[gp[z, a]]
                x += n * p[0]; y += n * p[1]; w += n * p[2]
            out[z, g, 0] = x
            out[z, g, 1] = y
            out[z, g, 2] = w
