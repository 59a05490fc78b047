"""10-node tetrahedral zones (kernels/zones_ho.py) against an independent numpy twin, and the
analytical checks: patch test, rigid motion, lumped mass, force balance, an explicit loop.

The twin builds each zone's 30x30 stiffness matrix from shape functions written as plain
polynomials of the volume coordinates, their derivatives by central differences (exact for
quadratics), and the quadrature points from their closed form; it never calls the kernels.
"""
import itertools
import math

import numpy as np
import pytest

from dec3d.kernels.zones_ho import (node_lists, tet10_body_force, tet10_forces,
                                    tet10_gauss_positions, tet10_lumped_mass, tet10_step,
                                    tet10_step_parallel, tet10_stiffness, tet10_volume,
                                    tri6_traction_loads)

EDGES = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]     # zones.gp order of mid-edge nodes


# ----------------------------------------------------------------------------- the twin
def shape(xi):
    """The 10 quadratic shape functions at reference point xi = (L1, L2, L3)."""
    L = [1.0 - xi[0] - xi[1] - xi[2], xi[0], xi[1], xi[2]]
    n = [L[i] * (2 * L[i] - 1) for i in range(4)]
    n += [4 * L[i] * L[j] for i, j in EDGES]
    return np.array(n)


def dshape(xi, h=0.25):
    """dN/dxi (10, 3) by central differences: exact for quadratic polynomials."""
    d = np.empty((10, 3))
    for k in range(3):
        e = np.zeros(3); e[k] = h
        d[:, k] = (shape(xi + e) - shape(xi - e)) / (2 * h)
    return d


def gauss_points():
    s5 = math.sqrt(5.0)
    a, b = (5 + 3 * s5) / 20, (5 - s5) / 20
    pts = []
    for g in range(4):
        L = [b] * 4; L[g] = a
        pts.append(np.array(L[1:]))
    return pts, [1.0 / 24] * 4


def d_matrix(K, G):
    lam = K - 2 * G / 3
    D = np.zeros((6, 6))
    D[:3, :3] = lam
    D[:3, :3] += 2 * G * np.eye(3)
    D[3:, 3:] = G * np.eye(3)        # engineering shear strains
    return D


def b_matrix(x, xi):
    """B (6, 30) for engineering strain (xx yy zz 2xy 2xz 2yz) and |det J| at xi; x (10, 3)."""
    dn = dshape(xi)
    J = x.T @ dn
    gn = np.linalg.solve(J.T, dn.T).T          # gn[a] = J^-T dN_a/dxi
    B = np.zeros((6, 30))
    for a in range(10):
        gx, gy, gz = gn[a]
        B[:, 3 * a:3 * a + 3] = [[gx, 0, 0], [0, gy, 0], [0, 0, gz],
                                 [gy, gx, 0], [gz, 0, gx], [0, gz, gy]]
    return B, abs(np.linalg.det(J))


def twin_stiffness(x, K, G):
    D = d_matrix(K, G)
    pts, w = gauss_points()
    Ke = np.zeros((30, 30))
    for p, wg in zip(pts, w):
        B, dj = b_matrix(x, p)
        Ke += wg * dj * B.T @ D @ B
    return Ke


def twin_step(pos, vel, gp, K, G, dt, gstress, stress, force):
    """Stress increment D B (v dt) per Gauss point; forces -sum w detJ B^T sigma."""
    pts, w = gauss_points()
    for z in range(gp.shape[0]):
        D = d_matrix(K[z], G[z])
        x = pos[gp[z]]
        u = (vel[gp[z]] * dt).ravel()
        f = np.zeros(30)
        for g, (p, wg) in enumerate(zip(pts, w)):
            B, dj = b_matrix(x, p)
            gstress[z, g] += D @ (B @ u)
            f -= wg * dj * B.T @ gstress[z, g]
        stress[z] = gstress[z].mean(axis=0)
        force[gp[z]] += f.reshape(10, 3)


def add_midnodes(points, tets):
    """Corner tetrahedra (m, 4) -> 10-node tetrahedra with shared mid-edge points."""
    pts = [tuple(p) for p in points]
    key = {}
    out = []
    for t in tets:
        row = list(t)
        for i, j in EDGES:
            e = (min(t[i], t[j]), max(t[i], t[j]))
            if e not in key:
                key[e] = len(pts)
                pts.append(tuple(0.5 * (np.asarray(points[t[i]]) + np.asarray(points[t[j]]))))
            row.append(key[e])
        out.append(row)
    return np.array(pts, float), np.array(out, np.int64)


def box_mesh(counts, sizes):
    """A box of counts[0] x counts[1] x counts[2] cells, sizes its edge lengths, each cell cut
    into the 6 Kuhn tetrahedra (conforming across cells), as 10-node zones."""
    nx, ny, nz = counts
    idx = lambda i, j, k: (i * (ny + 1) + j) * (nz + 1) + k
    points = np.array([[i / nx, j / ny, k / nz] for i in range(nx + 1) for j in range(ny + 1)
                       for k in range(nz + 1)]) * np.asarray(sizes, float)
    tets = []
    for i, j, k in itertools.product(range(nx), range(ny), range(nz)):
        for perm in itertools.permutations(range(3)):
            c = np.array([i, j, k]); vs = [idx(*c)]
            for ax in perm:
                c = c.copy(); c[ax] += 1; vs.append(idx(*c))
            p = points[vs]
            if np.linalg.det(p[1:] - p[0]) < 0:
                vs[1], vs[2] = vs[2], vs[1]
            tets.append(vs)
    return add_midnodes(points, np.array(tets))


def cube_mesh(n, size=1.0):
    return box_mesh((n, n, n), (size, size, size))


def random_tets(rng, m, curved=0.0):
    """m separate well-shaped 10-node tetrahedra (perturbed regular ones), optionally with the
    mid-edge nodes moved off the midpoints by `curved` (isoparametric, curved edges)."""
    reg = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], float)
    pts, gps = [], []
    for z in range(m):
        c = reg * (0.5 + rng.random()) + 0.15 * rng.normal(size=(4, 3)) + rng.normal(size=3)
        if np.linalg.det(c[1:] - c[0]) < 0:
            c[[1, 2]] = c[[2, 1]]
        mids = np.array([0.5 * (c[i] + c[j]) for i, j in EDGES]) + curved * rng.normal(size=(6, 3))
        gps.append(np.arange(10) + 10 * z)
        pts.append(np.vstack([c, mids]))
    return np.vstack(pts), np.array(gps, np.int64)


# ----------------------------------------------------------------------------- twin comparison
@pytest.mark.parametrize("curved", [0.0, 0.05])
def test_step_matches_twin(curved):
    rng = np.random.default_rng(11)
    m = 5
    pos, gp = random_tets(rng, m, curved)
    vel = rng.normal(size=pos.shape)
    K = 1e9 * (1 + rng.random(m)); G = 5e8 * (1 + rng.random(m))
    s0 = rng.normal(size=(m, 4, 6)) * 1e5
    rows = np.arange(m, dtype=np.int64)
    dt = 1e-4
    ga, gb = s0.copy(), s0.copy()
    sa, sb = np.zeros((m, 6)), np.zeros((m, 6))
    fa, fb = np.zeros_like(pos), np.zeros_like(pos)
    assert tet10_step(pos, vel, gp, rows, K, G, dt, ga, sa, fa) == -1
    twin_step(pos, vel, gp, K, G, dt, gb, sb, fb)
    scale_s = np.abs(gb).max()
    assert np.abs(ga - gb).max() <= 1e-10 * scale_s
    assert np.abs(sa - sb).max() <= 1e-10 * scale_s
    assert np.abs(fa - fb).max() <= 1e-10 * np.abs(fb).max()


def test_force_is_minus_k_u_from_zero_stress():
    rng = np.random.default_rng(3)
    pos, gp = random_tets(rng, 3)
    vel = rng.normal(size=pos.shape)
    K = np.array([2e9, 3e9, 1e9]); G = np.array([1e9, 0.7e9, 0.4e9])
    dt = 1e-3
    gs = np.zeros((3, 4, 6)); s = np.zeros((3, 6)); f = np.zeros_like(pos)
    tet10_step(pos, vel, gp, np.arange(3, dtype=np.int64), K, G, dt, gs, s, f)
    for z in range(3):
        Ke = twin_stiffness(pos[gp[z]], K[z], G[z])
        expect = -(Ke @ (vel[gp[z]] * dt).ravel()).reshape(10, 3)
        assert np.abs(f[gp[z]] - expect).max() <= 1e-10 * np.abs(expect).max()


def test_only_listed_rows_change():
    rng = np.random.default_rng(5)
    pos, gp = random_tets(rng, 3)
    vel = rng.normal(size=pos.shape)
    gs = np.zeros((3, 4, 6)); s = np.zeros((3, 6)); f = np.zeros_like(pos)
    tet10_step(pos, vel, gp, np.array([1], np.int64), np.full(3, 1e9), np.full(3, 1e9), 1e-3, gs, s, f)
    assert np.abs(gs[1]).max() > 0 and not gs[[0, 2]].any() and not s[[0, 2]].any()
    assert not f[gp[0]].any() and not f[gp[2]].any() and np.abs(f[gp[1]]).max() > 0


def test_parallel_step_is_bit_identical_to_serial_for_any_thread_count():
    import numba
    pos, gp = cube_mesh(5, 1.0)                  # 750 zones: several chunks
    rng = np.random.default_rng(16)
    pos = pos + 0.01 * rng.normal(size=pos.shape)
    m = len(gp)
    pos[gp[300, 3]] = pos[gp[300, :3]].mean(axis=0)          # one flat zone
    rows = np.r_[np.arange(0, 600), np.arange(650, m)].astype(np.int64)   # not all zones
    vel = rng.normal(size=pos.shape)
    K = 1e9 * (1 + rng.random(m)); G = 5e8 * (1 + rng.random(m))
    g0 = rng.normal(size=(m, 4, 6)) * 1e5
    f0 = rng.normal(size=pos.shape)
    ref_g, ref_s, ref_f = g0.copy(), np.zeros((m, 6)), f0.copy()
    bad = tet10_step(pos, vel, gp, rows, K, G, 1e-4, ref_g, ref_s, ref_f)
    assert bad != -1 and np.isfinite(ref_f).all()
    nstart, nent = node_lists(len(pos), gp, rows)
    before = numba.get_num_threads()
    try:
        for nt in sorted({1, before}):
            numba.set_num_threads(nt)
            gs, s, f = g0.copy(), np.zeros((m, 6)), f0.copy()
            zf = np.empty((len(rows), 10, 3)); ok = np.empty(len(rows), np.bool_)
            assert tet10_step_parallel(pos, vel, gp, rows, K, G, 1e-4, gs, s, f, zf, ok, nstart, nent) == bad
            assert np.array_equal(gs, ref_g) and np.array_equal(s, ref_s) and np.array_equal(f, ref_f)
    finally:
        numba.set_num_threads(before)


def test_inverted_or_flat_zone_is_skipped_and_named():
    rng = np.random.default_rng(9)
    pos, gp = random_tets(rng, 3)
    gp[1, [1, 2]] = gp[1, [2, 1]]                # zone 1 inverted (mid-edge nodes follow)
    gp[1, 4:] = gp[1, [6, 5, 4, 7, 9, 8]]   # edges 01 12 20 03 13 23 were 20 12 01 03 23 13
    pos[gp[2, 3]] = pos[gp[2, :3]].mean(axis=0)   # zone 2 flat: apex in the base plane
    pos[gp[2, 7:]] = 0.5 * (pos[gp[2, :3]] + pos[gp[2, 3]])
    m = 3; rows = np.arange(m, dtype=np.int64)
    vel = rng.normal(size=pos.shape)
    gs = np.ones((m, 4, 6)); s = np.zeros((m, 6)); f = np.zeros_like(pos)
    one = np.full(m, 1e9)
    assert tet10_step(pos, vel, gp, rows, one, one, 1e-3, gs, s, f) == 1
    assert np.isfinite(gs).all() and np.isfinite(f).all()
    assert (gs[1:] == 1).all() and not s[1:].any() and not f[gp[1]].any() and not f[gp[2]].any()
    assert np.abs(gs[0] - 1).max() > 0
    assert tet10_step(pos, vel, gp, np.array([2, 0], np.int64), one, one, 1e-3, gs, s, f) == 2
    for kern, args in [(tet10_forces, (gs, np.zeros_like(pos))), (tet10_volume, (np.zeros(m),)),
                       (tet10_lumped_mass, (one, np.zeros(len(pos)))),
                       (tet10_stiffness, (one, one, np.zeros(len(pos)))),
                       (tet10_body_force, (one, np.array([0, 0, -9.81]), np.zeros_like(pos)))]:
        assert kern(pos, gp, rows, *args) == 1
        assert all(np.isfinite(a).all() for a in args)


def test_gauss_positions_match_twin_and_lie_near_their_corner():
    rng = np.random.default_rng(14)
    pos, gp = random_tets(rng, 3, curved=0.05)
    out = np.zeros((3, 4, 3))
    tet10_gauss_positions(pos, gp, np.arange(3, dtype=np.int64), out)
    pts, _ = gauss_points()
    twin = np.array([[shape(q) @ pos[gp[z]] for q in pts] for z in range(3)])
    assert np.abs(out - twin).max() <= 1e-13 * np.abs(twin).max()
    for z in range(3):                        # point g is the one nearest corner g
        d = np.linalg.norm(out[z][:, None, :] - pos[gp[z, :4]][None, :, :], axis=2)
        assert (d.argmin(axis=1) == np.arange(4)).all()


# ----------------------------------------------------------------------------- analytical
def test_patch_test_linear_velocity_uniform_strain():
    """Linear velocity field on a 2x2x2-cube mesh: every Gauss point gets the exact strain and
    stress, and every interior node is in balance."""
    pos, gp = cube_mesh(2, 2.0)
    m = len(gp)
    rng = np.random.default_rng(1)
    A = rng.normal(size=(3, 3)) * 1e-3          # v = A x + c
    vel = pos @ A.T + rng.normal(size=3)
    Kb, G, dt = 3e9, 1.2e9, 0.5
    gs = np.zeros((m, 4, 6)); s = np.zeros((m, 6)); f = np.zeros_like(pos)
    tet10_step(pos, vel, gp, np.arange(m, dtype=np.int64), np.full(m, Kb), np.full(m, G), dt, gs, s, f)
    e = 0.5 * (A + A.T) * dt
    sig = (Kb - 2 * G / 3) * np.trace(e) * np.eye(3) + 2 * G * e
    expect = np.array([sig[0, 0], sig[1, 1], sig[2, 2], sig[0, 1], sig[0, 2], sig[1, 2]])
    scale = np.abs(expect).max()
    assert np.abs(gs - expect).max() <= 1e-12 * scale
    assert np.abs(s - expect).max() <= 1e-12 * scale
    interior = np.all((pos > 1e-9) & (pos < 2.0 - 1e-9), axis=1)
    # the centre corner, the mid-points of the 6 inner cube edges, of the 12 inner face
    # diagonals (face centres) and of the 8 body diagonals (cube centres)
    assert interior.sum() == 1 + 6 + 12 + 8
    assert np.abs(f[interior]).max() <= 1e-12 * np.abs(f).max()
    # virial identity: sum_a x_a (x) f_a = -V sigma for a uniform stress
    vir = pos.T @ f
    assert np.abs(vir + 8.0 * sig).max() <= 1e-11 * 8.0 * scale


def test_same_convention_as_the_4_node_kernel():
    """Under a linear velocity field a straight-edged 10-node zone and the 4-node zone of its
    corners get the same stress, and their forces the same resultant moment tensor
    sum_a x_a (x) f_a = -V sigma: same signs and units as the 4-node zone step (kernels/zone_step.py)."""
    from tests.zone_step_run import elastic_tets as tet_elastic_step
    rng = np.random.default_rng(15)
    pos, gp = random_tets(rng, 2)
    A = rng.normal(size=(3, 3))
    vel = pos @ A.T
    K = np.array([2e9, 1e9]); G = np.array([1e9, 3e8])
    gs = np.zeros((2, 4, 6)); s10 = np.zeros((2, 6)); f10 = np.zeros_like(pos)
    tet10_step(pos, vel, gp, np.arange(2, dtype=np.int64), K, G, 1e-4, gs, s10, f10)
    s4 = np.zeros((2, 6)); f4 = np.zeros_like(pos)
    tet_elastic_step(pos, vel, np.ascontiguousarray(gp[:, :4]), K, G, 1e-4, s4, f4)
    assert np.abs(s10 - s4).max() <= 1e-10 * np.abs(s4).max()
    for z in range(2):
        v10 = pos[gp[z]].T @ f10[gp[z]]
        v4 = pos[gp[z, :4]].T @ f4[gp[z, :4]]
        assert np.abs(v10 - v4).max() <= 1e-10 * np.abs(v4).max()


def test_rigid_motion_gives_no_strain():
    rng = np.random.default_rng(2)
    pos, gp = random_tets(rng, 4, curved=0.05)
    m = len(gp)
    w = rng.normal(size=3)                       # rotation rate, plus a translation
    vel = np.cross(w, pos) + rng.normal(size=3)
    gs = np.zeros((m, 4, 6)); s = np.zeros((m, 6)); f = np.zeros_like(pos)
    Kb = 2e9
    tet10_step(pos, vel, gp, np.arange(m, dtype=np.int64), np.full(m, Kb), np.full(m, 1e9), 1e-3, gs, s, f)
    # compare with the stress one such rate would give if it were a strain rate
    ref = Kb * np.abs(w).max() * 1e-3
    assert np.abs(gs).max() <= 1e-12 * ref
    assert np.abs(f).max() <= 1e-12 * ref * np.abs(pos).max() ** 2


def test_forces_balance_for_any_stress():
    rng = np.random.default_rng(4)
    pos, gp = random_tets(rng, 6, curved=0.08)
    m = len(gp)
    gs = rng.normal(size=(m, 4, 6)) * 1e6
    vel = rng.normal(size=pos.shape)
    f = np.zeros_like(pos); s = np.zeros((m, 6))
    tet10_step(pos, vel, gp, np.arange(m, dtype=np.int64), np.full(m, 1e9), np.full(m, 1e9), 1e-3, gs, s, f)
    for z in range(m):
        fz = f[gp[z]]
        assert np.abs(fz.sum(axis=0)).max() <= 1e-12 * np.abs(fz).max()
    # moments balance too: sum_a x_a x f_a = 0 (the Gauss-point stresses are symmetric)
    for z in range(m):
        mom = np.cross(pos[gp[z]], f[gp[z]]).sum(axis=0)
        assert np.abs(mom).max() <= 1e-11 * np.abs(f[gp[z]]).max() * np.abs(pos).max()
    # tet10_forces gives the same forces for the stresses now held
    f2 = np.zeros_like(pos)
    tet10_forces(pos, gp, np.arange(m, dtype=np.int64), gs, f2)
    assert np.allclose(f2, f, rtol=0, atol=1e-12 * np.abs(f).max())


# ----------------------------------------------------------------------------- mass and stiffness
def monomial_integral(powers, vol):
    """int L0^a L1^b L2^c L3^d dV = a! b! c! d! 3! V / (a+b+c+d+3)! (exact)."""
    num = math.prod(math.factorial(p) for p in powers) * 6
    return num * vol / math.factorial(sum(powers) + 3)


def consistent_mass_tet10(vol, rho):
    """Consistent mass matrix (10x10 scalar) of a straight-edged 10-node tetrahedron, exact,
    from the shape functions expanded as polynomials of the volume coordinates."""
    # each shape function as {powers tuple: coefficient}
    def mono(*idx):
        p = [0, 0, 0, 0]
        for i in idx:
            p[i] += 1
        return tuple(p)
    polys = [{mono(i, i): 2.0, mono(i): -1.0} for i in range(4)]
    polys += [{mono(i, j): 4.0} for i, j in EDGES]
    M = np.zeros((10, 10))
    for a in range(10):
        for b in range(10):
            acc = 0.0
            for pa, ca in polys[a].items():
                for pb, cb in polys[b].items():
                    acc += ca * cb * monomial_integral(tuple(x + y for x, y in zip(pa, pb)), vol)
            M[a, b] = rho * acc
    return M


def test_lumped_mass_is_hrz_positive_and_total():
    rng = np.random.default_rng(6)
    pos, gp = random_tets(rng, 3)
    rho = np.array([2500.0, 2700.0, 1800.0])
    mass = np.zeros(len(pos))
    tet10_lumped_mass(pos, gp, np.arange(3, dtype=np.int64), rho, mass)
    for z in range(3):
        c = pos[gp[z, :4]]
        vol = abs(np.linalg.det(c[1:] - c[0])) / 6
        M = consistent_mass_tet10(vol, rho[z])
        assert abs(M.sum() - rho[z] * vol) <= 1e-12 * rho[z] * vol
        rowsum = M.sum(axis=1)
        assert (rowsum[:4] < 0).all()            # why row-sum lumping is not usable
        hrz = np.diag(M) * (rho[z] * vol / np.trace(M))
        assert np.allclose(mass[gp[z]], hrz, rtol=1e-12)
        assert (mass[gp[z]] > 0).all()
        assert abs(mass[gp[z]].sum() - rho[z] * vol) <= 1e-12 * rho[z] * vol


def test_mesh_mass_and_volume_totals():
    pos, gp = cube_mesh(2, 3.0)
    m = len(gp)
    rows = np.arange(m, dtype=np.int64)
    mass = np.zeros(len(pos)); vol = np.zeros(m)
    tet10_lumped_mass(pos, gp, rows, np.full(m, 2000.0), mass)
    tet10_volume(pos, gp, rows, vol)
    assert (mass > 0).all()
    assert abs(mass.sum() - 2000.0 * 27.0) <= 1e-12 * 2000.0 * 27.0
    assert abs(vol.sum() - 27.0) <= 1e-12 * 27.0 and (vol > 0).all()


def test_stiffness_matches_twin_row_sums_and_bounds_the_spectrum():
    pos, gp = cube_mesh(1, 1.0)
    rng = np.random.default_rng(8)
    pos = pos + 0.03 * rng.normal(size=pos.shape)      # distorted, curved edges
    m = len(gp)
    Kb = 1e9 * (1 + rng.random(m)); G = 4e8 * (1 + rng.random(m))
    kd = np.zeros(len(pos))
    tet10_stiffness(pos, gp, np.arange(m, dtype=np.int64), Kb, G, kd)
    twin = np.zeros(len(pos))
    Kglob = np.zeros((3 * len(pos), 3 * len(pos)))
    for z in range(m):
        Ke = twin_stiffness(pos[gp[z]], Kb[z], G[z])
        twin[gp[z]] += np.abs(Ke).sum(axis=1).reshape(10, 3).max(axis=1)
        dof = (3 * gp[z][:, None] + np.arange(3)).ravel()
        Kglob[np.ix_(dof, dof)] += Ke
    assert np.allclose(kd, twin, rtol=1e-10)
    mass = np.zeros(len(pos))
    tet10_lumped_mass(pos, gp, np.arange(m, dtype=np.int64), np.full(m, 2500.0), mass)
    minv = np.repeat(1.0 / np.sqrt(mass), 3)
    lam_max = np.linalg.eigvalsh(minv[:, None] * Kglob * minv[None, :]).max()
    bound = (kd / mass).max()
    assert lam_max <= bound * (1 + 1e-12)
    assert bound <= 20 * lam_max                         # a bound, not a wild overestimate


# ----------------------------------------------------------------------------- explicit loop
FACES6 = [(0, 1, 2, 4, 5, 6), (0, 1, 3, 4, 8, 7), (1, 2, 3, 5, 9, 8), (2, 0, 3, 6, 7, 9)]
# the 4 faces of a 10-node zone as 6-node triangles: corners, then mid-edge nodes 01 12 20


def faces_on(pos, gp, axis, value):
    """The 6-node zone faces lying on the plane x_axis = value, (k, 6) gridpoint rows."""
    out = []
    for z in range(len(gp)):
        for fc in FACES6:
            nodes = gp[z, list(fc)]
            if np.all(np.abs(pos[nodes, axis] - value) < 1e-12):
                out.append(nodes)
    return np.array(out, np.int64)


def twin_tri6_loads(pos, tri, traction):
    """int N_a dA t by the 3-point rule from its closed form, shape-function derivatives by
    central differences (exact for quadratics)."""
    def n6(x):
        L = [1 - x[0] - x[1], x[0], x[1]]
        return np.array([L[i] * (2 * L[i] - 1) for i in range(3)]
                        + [4 * L[0] * L[1], 4 * L[1] * L[2], 4 * L[2] * L[0]])
    f = np.zeros_like(pos)
    for k, t in enumerate(tri):
        x = pos[t]
        for q in range(3):
            L = np.full(3, 1 / 6); L[q] = 2 / 3
            xi = L[1:]
            h = 0.1
            d = [(n6(xi + h * e) - n6(xi - h * e)) / (2 * h) for e in np.eye(2)]
            da = np.linalg.norm(np.cross(d[0] @ x, d[1] @ x))
            f[t] += np.outer(n6(xi), traction[k]) * da / 6
    return f


@pytest.mark.parametrize("curved", [0.0, 0.05])
def test_tri6_traction_loads_match_twin_and_exact_shares(curved):
    rng = np.random.default_rng(12)
    c = rng.normal(size=(4, 3, 3))
    pos = []
    for t in c:
        mids = np.array([0.5 * (t[i] + t[j]) for i, j in [(0, 1), (1, 2), (2, 0)]])
        pos.append(np.vstack([t, mids + curved * rng.normal(size=(3, 3))]))
    pos = np.vstack(pos)
    tri = np.arange(24, dtype=np.int64).reshape(4, 6)
    trac = rng.normal(size=(4, 3)) * 1e6
    f = np.zeros_like(pos)
    tri6_traction_loads(pos, tri, trac, f)
    ft = twin_tri6_loads(pos, tri, trac)
    assert np.abs(f - ft).max() <= 1e-12 * np.abs(ft).max()
    if curved == 0.0:
        for k, t in enumerate(c):
            area = 0.5 * np.linalg.norm(np.cross(t[1] - t[0], t[2] - t[0]))
            assert np.abs(f[tri[k, :3]]).max() <= 1e-12 * np.abs(trac[k]).max() * area
            assert np.allclose(f[tri[k, 3:]], trac[k] * area / 3, rtol=1e-12, atol=0)


def twin_body_force(pos, gp, rho, gvec):
    pts, w = gauss_points()
    f = np.zeros_like(pos)
    for z in range(len(gp)):
        x = pos[gp[z]]
        for p, wg in zip(pts, w):
            dj = abs(np.linalg.det(x.T @ dshape(p)))
            f[gp[z]] += rho[z] * wg * dj * np.outer(shape(p), gvec)
    return f


@pytest.mark.parametrize("curved", [0.0, 0.05])
def test_body_force_matches_twin_and_exact_shares(curved):
    rng = np.random.default_rng(13)
    pos, gp = random_tets(rng, 4, curved)
    rho = 2000 + 1000 * rng.random(4)
    gvec = np.array([0.3, -1.0, -9.81])
    f = np.zeros_like(pos)
    assert tet10_body_force(pos, gp, np.arange(4, dtype=np.int64), rho, gvec, f) == -1
    ft = twin_body_force(pos, gp, rho, gvec)
    assert np.abs(f - ft).max() <= 1e-12 * np.abs(ft).max()
    if curved == 0.0:              # exact: int N dV = -V/20 at corners, V/5 at mid-edge nodes
        for z in range(4):
            c = pos[gp[z, :4]]
            W = rho[z] * abs(np.linalg.det(c[1:] - c[0])) / 6 * gvec
            M = consistent_mass_tet10(1.0, 1.0)       # int N_a N_b dV for V = 1
            share = M.sum(axis=1)                     # sum_b N_b = 1: int N_a dV / V
            assert np.allclose(share[:4], -1 / 20, rtol=1e-12) and np.allclose(share[4:], 1 / 5, rtol=1e-12)
            assert np.allclose(f[gp[z]], np.outer(share, W), rtol=1e-12, atol=1e-12 * np.abs(W).max())


def relax(pos, gp, Kb, G, fext, fix, tol, alpha=0.8, max_steps=50000):
    """Explicit dynamic relaxation with the kernels alone: density-scaled masses from
    tet10_stiffness (stable at dt = 1 by Eq. 84), local damping, small strain. Returns
    (displacements, Gauss-point stresses, steps)."""
    m = len(gp); rows = np.arange(m, dtype=np.int64)
    K = np.full(m, Kb); Gs = np.full(m, G)
    kd = np.zeros(len(pos))
    tet10_stiffness(pos, gp, rows, K, Gs, kd)
    dt = 1.0
    mass = kd * dt * dt / 4.0 * 1.1
    vel = np.zeros_like(pos); disp = np.zeros_like(pos)
    gs = np.zeros((m, 4, 6)); s = np.zeros((m, 6))
    for step in range(max_steps):
        f = fext.copy()
        tet10_step(pos, vel, gp, rows, K, Gs, dt, gs, s, f)
        if step > 50 and np.abs(f[~fix]).max() < tol:
            return disp, gs, step
        f = f - alpha * np.abs(f) * np.sign(vel)          # local damping (3DEC)
        vel = vel + f * dt / mass[:, None]
        vel[fix] = 0.0
        disp += vel * dt                                     # positions not updated
    pytest.fail("did not converge")


def test_explicit_relaxation_uniaxial_cube():
    """D1 with 10-node zones: a cube on rollers under a top pressure; eps = sigma / E,
    lateral = -nu sigma / E, stress uniform to 1e-6."""
    E, nu, p = 1e9, 0.25, -1e5                   # sigma_zz = p (compression), tension positive
    Kb, G = E / (3 * (1 - 2 * nu)), E / (2 * (1 + nu))
    L = 1.0
    pos0, gp = cube_mesh(2, L)
    top = faces_on(pos0, gp, 2, L)
    assert len(top) == 8
    fext = np.zeros_like(pos0)
    tri6_traction_loads(pos0, top, np.tile([0.0, 0.0, p], (len(top), 1)), fext)
    assert abs(fext[:, 2].sum() - p * L * L) <= 1e-12 * abs(p)
    fix = np.zeros_like(pos0, bool)
    for ax in range(3):
        fix[np.abs(pos0[:, ax]) < 1e-12, ax] = True    # rollers on x=0, y=0, z=0
    disp, gs, steps = relax(pos0, gp, Kb, G, fext, fix, 1e-10 * abs(p) * L * L)
    topn = np.abs(pos0[:, 2] - L) < 1e-12
    side = np.abs(pos0[:, 0] - L) < 1e-12
    assert abs(disp[topn, 2].mean() / L - p / E) <= 1e-6 * abs(p / E)
    assert abs(disp[side, 0].mean() / L + nu * p / E) <= 1e-6 * abs(nu * p / E)
    assert np.ptp(disp[topn, 2]) <= 1e-6 * abs(p / E) * L      # the top stays flat
    assert np.abs(gs[..., 2] - p).max() <= 1e-6 * abs(p)
    assert np.abs(gs[..., [0, 1, 3, 4, 5]]).max() <= 1e-6 * abs(p)


def test_explicit_relaxation_self_weight_column():
    """D2 with 10-node zones and consistent gravity loads (tet10_body_force): H = 10 m,
    rho = 2500, g = 10, E = 10 GPa, nu = 0.25, lateral rollers; sigma_zz = rho g (H - z) at
    every Gauss point and top settlement rho g H^2 / (2 M) = 0.1042 mm, both to 1e-6."""
    E, nu, rho, g, H = 10e9, 0.25, 2500.0, 10.0, 10.0
    Kb, G = E / (3 * (1 - 2 * nu)), E / (2 * (1 + nu))
    Mod = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
    pos0, gp = box_mesh((1, 1, 5), (1.0, 1.0, H))
    m = len(gp)
    fext = np.zeros_like(pos0)
    tet10_body_force(pos0, gp, np.arange(m, dtype=np.int64), np.full(m, rho), np.array([0, 0, -g]), fext)
    assert abs(fext[:, 2].sum() + rho * g * H) <= 1e-12 * rho * g * H
    fix = np.zeros_like(pos0, bool)
    for ax in range(2):
        fix[(np.abs(pos0[:, ax]) < 1e-9) | (np.abs(pos0[:, ax] - 1.0) < 1e-9), ax] = True
    fix[np.abs(pos0[:, 2]) < 1e-9, :] = True
    disp, gs, steps = relax(pos0, gp, Kb, G, fext, fix, 1e-10 * rho * g * H)
    pts, _ = gauss_points()
    zg = np.array([[shape(q) @ pos0[gp[z], 2] for q in pts] for z in range(m)])
    assert np.abs(gs[..., 2] + rho * g * (H - zg)).max() <= 1e-6 * rho * g * H
    settle = -disp[np.abs(pos0[:, 2] - H) < 1e-9, 2]
    expect = rho * g * H * H / (2 * Mod)
    assert abs(expect - 0.1042e-3) < 0.0001e-3
    assert np.abs(settle - expect).max() <= 1e-6 * expect
