"""20-node bricks (kernels/feblock.py) against an independent numpy twin, and the analytical
checks: patch tests, rigid motion, force and moment balance, HRZ mass, explicit relaxation of a
uniaxial bar and of the FE-block text's cantilever (003_*, "Verification: Cantilever Beam").

The twin never calls the kernels. Its node table is built from the 8 corners and the 12 edges
(mid-edge node = midpoint of its edge's corners, edges in the order of the corrected Table 1 of
shared/seeds/ERRATA.md) and checked against the corrected table written out; its shape
functions are the generic serendipity formulas evaluated on that table, their derivatives by the
complex step (exact to round-off), its quadrature numpy's Gauss-Legendre points, its forces
-sum w det J B^T sigma with an explicit 6 x 60 B matrix (the text's Eq. 6-7).
"""
import itertools

import numpy as np
import pytest

from dec3d.kernels.feblock import (FACES, feb_body_force, feb_forces, feb_gauss_positions,
                                   feb_lumped_mass, feb_slave_forces, feb_slave_interp, feb_step,
                                   feb_stiffness, feb_volume, quad8_traction_loads, shape20)

# ----------------------------------------------------------------------------- the twin
CORNERS = [(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1), (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)]
EDGES = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)]
TABLE = np.array(CORNERS + [tuple((np.array(CORNERS[i]) + CORNERS[j]) / 2) for i, j in EDGES], float)

# the corrected Table 1 (ERRATA.md, section 003), nodes 9-20
ERRATA_MID = [(0, -1, -1), (1, 0, -1), (0, 1, -1), (-1, 0, -1), (0, -1, 1), (1, 0, 1), (0, 1, 1), (-1, 0, 1),
              (-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]


def twin_n(y):
    """The 20 shape functions at y (real or complex)."""
    out = []
    for c in TABLE:
        if np.all(c != 0):
            v = (1 + c[0] * y[0]) * (1 + c[1] * y[1]) * (1 + c[2] * y[2]) * (c @ y - 2) / 8
        else:
            k = int(np.flatnonzero(c == 0)[0])
            o = [j for j in range(3) if j != k]
            v = (1 - y[k] ** 2) * (1 + c[o[0]] * y[o[0]]) * (1 + c[o[1]] * y[o[1]]) / 4
        out.append(v)
    return np.array(out)


def twin_dn(y, h=1e-30):
    d = np.empty((20, 3))
    for k in range(3):
        yc = np.array(y, complex)
        yc[k] += 1j * h
        d[:, k] = twin_n(yc).imag / h
    return d


def twin_rule(nq):
    x, w = np.polynomial.legendre.leggauss(nq)
    pts, wts = [], []
    for k, j, i in itertools.product(range(nq), repeat=3):      # y1 fastest
        pts.append(np.array([x[i], x[j], x[k]]))
        wts.append(w[i] * w[j] * w[k])
    return pts, wts


def d_matrix(K, G):
    D = np.zeros((6, 6))
    D[:3, :3] = K - 2 * G / 3
    D[:3, :3] += 2 * G * np.eye(3)
    D[3:, 3:] = G * np.eye(3)
    return D


def b_matrix(x, y):
    """B (6, 60) for xx yy zz 2xy 2xz 2yz and det J at y; x (20, 3)."""
    dn = twin_dn(y)
    J = x.T @ dn
    gn = np.linalg.solve(J.T, dn.T).T
    B = np.zeros((6, 60))
    for a in range(20):
        gx, gy, gz = gn[a]
        B[:, 3 * a:3 * a + 3] = [[gx, 0, 0], [0, gy, 0], [0, 0, gz], [gy, gx, 0], [gz, 0, gx], [0, gz, gy]]
    return B, np.linalg.det(J)


def twin_step(x, v, K, G, dt, s0, nq):
    """Gauss-point stresses s0 + D B v dt and element forces -sum w detJ B^T sigma."""
    D = d_matrix(K, G)
    f = np.zeros(60)
    sig = []
    vol = 0.0
    mean = np.zeros(6)
    for g, (p, w) in enumerate(zip(*twin_rule(nq))):
        B, dj = b_matrix(x, p)
        s = s0[g] + D @ (B @ v.ravel() * dt)
        sig.append(s)
        f -= w * dj * B.T @ s
        vol += w * dj
        mean += w * dj * s
    return np.array(sig), mean / vol, f.reshape(20, 3)


def twin_stiffness(x, K, G, nq):
    D = d_matrix(K, G)
    Ke = np.zeros((60, 60))
    for p, w in zip(*twin_rule(nq)):
        B, dj = b_matrix(x, p)
        Ke += w * dj * B.T @ D @ B
    return Ke


def twin_consistent_mass(x, rho, nq=4):
    M = np.zeros((20, 20))
    for p, w in zip(*twin_rule(nq)):
        n = twin_n(p)
        _, dj = b_matrix(x, p)
        M += rho * w * dj * np.outer(n, n)
    return M


def brick(a=1.0, b=1.0, c=1.0, origin=(0, 0, 0)):
    return (TABLE + 1) / 2 * [a, b, c] + origin


def distorted(seed=1, amp=0.08):
    """A unit brick with every node moved at random: curved edges, faces not planar."""
    rng = np.random.default_rng(seed)
    return brick() + rng.uniform(-amp, amp, (20, 3))


def one(x):
    return np.ascontiguousarray(x, float), np.arange(20, dtype=np.int64)[None, :], np.array([0], np.int64)


# ----------------------------------------------------------------------------- shape functions
def test_twin_table_is_the_corrected_table_and_the_kernel_functions_match_it():
    assert np.array_equal(TABLE[8:], np.array(ERRATA_MID, float))
    n, dn = np.empty(20), np.empty((20, 3))
    for a in range(20):                                  # Kronecker delta at the nodes
        shape20(*TABLE[a], n, dn)
        assert np.allclose(n, np.eye(20)[a], atol=1e-15)
    rng = np.random.default_rng(0)
    for y in rng.uniform(-1, 1, (25, 3)):
        shape20(*y, n, dn)
        assert abs(n.sum() - 1) < 1e-14                  # partition of unity
        assert np.abs(dn.sum(axis=0)).max() < 1e-14
        assert np.allclose(n, twin_n(y), rtol=0, atol=1e-14)
        assert np.allclose(dn, twin_dn(y), rtol=0, atol=1e-13)
        # derivative consistency: N is reproduced by its gradient to second order
        h = 1e-6
        for k in range(3):
            e = np.zeros(3)
            e[k] = h
            n1, n2 = np.empty(20), np.empty(20)
            shape20(*(y + e), n1, np.empty((20, 3)))
            shape20(*(y - e), n2, np.empty((20, 3)))
            assert np.allclose((n1 - n2) / (2 * h), dn[:, k], atol=1e-8)


# ----------------------------------------------------------------------------- step against the twin
@pytest.mark.parametrize("nq", [2, 3])
@pytest.mark.parametrize("seed", [1, 2])
def test_step_matches_twin(nq, seed):
    rng = np.random.default_rng(seed + 10)
    x = distorted(seed)
    pos, nodes, rows = one(x)
    vel = rng.normal(size=(20, 3))
    K, G, dt = 3.0e9, 1.5e9, 1e-4
    gs = np.zeros((1, 27, 6))
    gs[0, :nq ** 3] = rng.normal(scale=1e5, size=(nq ** 3, 6))
    s0 = gs[0].copy()
    st = np.zeros((1, 6))
    f = np.zeros((20, 3))
    assert feb_step(pos, vel, nodes, rows, np.array([K]), np.array([G]), dt, gs, st, f, nq) == -1
    sig, mean, ft = twin_step(x, vel, K, G, dt, s0, nq)
    scale_s = np.abs(sig).max()
    scale_f = np.abs(ft).max()
    assert np.abs(gs[0, :nq ** 3] - sig).max() < 1e-10 * scale_s
    assert np.abs(st[0] - mean).max() < 1e-10 * scale_s
    assert np.abs(f - ft).max() < 1e-10 * scale_f
    assert np.all(gs[0, nq ** 3:] == s0[nq ** 3:])       # unused points untouched
    f2 = np.zeros((20, 3))
    assert feb_forces(pos, nodes, rows, gs, f2, nq) == -1
    assert np.abs(f2 - ft).max() < 1e-10 * scale_f


@pytest.mark.parametrize("nq", [2, 3])
def test_force_is_minus_k_u_from_zero_stress(nq):
    x = distorted(3)
    pos, nodes, rows = one(x)
    vel = np.random.default_rng(4).normal(size=(20, 3))
    K, G, dt = 2e9, 1e9, 1e-3
    f = np.zeros((20, 3))
    feb_step(pos, vel, nodes, rows, np.array([K]), np.array([G]), dt, np.zeros((1, 27, 6)), np.zeros((1, 6)), f, nq)
    Ke = twin_stiffness(x, K, G, nq)
    expect = -(Ke @ (vel * dt).ravel()).reshape(20, 3)
    assert np.abs(f - expect).max() < 1e-10 * np.abs(expect).max()


@pytest.mark.parametrize("nq", [2, 3])
def test_stiffness_bound_matches_twin_row_sums(nq):
    x = distorted(5)
    pos, nodes, rows = one(x)
    K, G = 2e9, 1e9
    kd = np.zeros(20)
    assert feb_stiffness(pos, nodes, rows, np.array([K]), np.array([G]), kd, nq) == -1
    Ke = twin_stiffness(x, K, G, nq)
    rs = np.abs(Ke).sum(axis=1).reshape(20, 3).max(axis=1)
    assert np.allclose(kd, rs, rtol=1e-10)
    # Gershgorin: the largest eigenvalue is below the largest row bound
    assert np.linalg.eigvalsh(Ke).max() <= kd.max() * (1 + 1e-12)


def test_inverted_element_is_skipped_and_reported():
    x = brick()
    x[[0, 6]] = x[[6, 0]]                                  # swap two opposite corners: det J < 0 somewhere
    pos, nodes, rows = one(x)
    gs = np.zeros((1, 27, 6))
    st = np.zeros((1, 6))
    f = np.zeros((20, 3))
    vel = np.ones((20, 3))
    assert feb_step(pos, vel, nodes, rows, np.array([1e9]), np.array([1e9]), 1.0, gs, st, f, 2) == 0
    assert not gs.any() and not f.any()
    assert feb_volume(pos, nodes, rows, np.zeros(1)) == 0
    assert feb_lumped_mass(pos, nodes, rows, np.ones(1), np.zeros(20)) == 0


# ----------------------------------------------------------------------------- patch tests, balance
def _linear_field(x, A, c):
    return x @ A.T + c


@pytest.mark.parametrize("nq", [2, 3])
def test_one_distorted_element_reproduces_uniform_stress(nq):
    """F2 of the issue: mid-edge nodes moved, faces not planar; a linear velocity field on the
    nodes gives the same stress at every Gauss point to 1e-8 relative."""
    x = distorted(7, amp=0.12)
    pos, nodes, rows = one(x)
    A = np.array([[1.0, 0.3, -0.2], [0.1, -0.5, 0.4], [0.2, 0.6, 0.8]])
    vel = _linear_field(x, A, np.array([0.3, -0.1, 0.2]))
    K, G, dt = 5e9, 3e9, 1e-3
    gs = np.zeros((1, 27, 6))
    st = np.zeros((1, 6))
    assert feb_step(pos, vel, nodes, rows, np.array([K]), np.array([G]), dt, gs, st, np.zeros((20, 3)), nq) == -1
    e = 0.5 * (A + A.T) * dt
    lam = K - 2 * G / 3
    s = lam * np.trace(e) * np.eye(3) + 2 * G * e
    expect = np.array([s[0, 0], s[1, 1], s[2, 2], s[0, 1], s[0, 2], s[1, 2]])
    assert np.abs(gs[0, :nq ** 3] - expect).max() < 1e-8 * np.abs(expect).max()
    assert np.abs(st[0] - expect).max() < 1e-8 * np.abs(expect).max()


def patch_mesh(n=2, shift=(0.13, -0.09, 0.11)):
    """n^3 elements filling the unit cube, the inner corner nodes moved by ``shift`` (scaled),
    mid-edge nodes at the midpoints of straight edges. Returns pos, nodes (ne, 20), interior mask."""
    grid = {}
    pts = []

    def node(p):
        key = tuple(np.round(np.asarray(p) * 2 * n).astype(int))
        if key not in grid:
            grid[key] = len(pts)
            pts.append(np.asarray(p, float))
        return grid[key]

    cor = np.array([(i, j, k) for i in range(n + 1) for j in range(n + 1) for k in range(n + 1)], float) / n
    moved = {}
    for c in cor:
        inner = np.all((c > 0) & (c < 1))
        moved[tuple(c)] = c + (np.array(shift) / n if inner else 0)
    elems = []
    for i, j, k in itertools.product(range(n), repeat=3):
        base = np.array([i, j, k], float) / n
        cx = [moved[tuple(base + (np.array(CORNERS[a]) + 1) / 2 / n)] for a in range(8)]
        ids = [node(base + (np.array(CORNERS[a]) + 1) / 2 / n) for a in range(8)]
        xs = {ids[a]: cx[a] for a in range(8)}
        for a, b in EDGES:
            key_pt = base + ((np.array(CORNERS[a]) + CORNERS[b]) / 2 + 1) / 2 / n
            r = node(key_pt)
            xs[r] = (cx[a] + cx[b]) / 2
            ids.append(r)
        elems.append(ids)
        for r, p in xs.items():
            pts[r] = p
    pos = np.array(pts)
    ref = np.array([np.array(k) / (2 * n) for k in sorted(grid, key=grid.get)])
    interior = np.all((ref > 1e-9) & (ref < 1 - 1e-9), axis=1)
    return pos, np.array(elems, np.int64), interior


@pytest.mark.parametrize("nq", [2, 3])
def test_patch_of_elements_uniform_stress_and_balanced_interior_nodes(nq):
    pos, nodes, interior = patch_mesh()
    ne = len(nodes)
    rows = np.arange(ne, dtype=np.int64)
    assert interior.sum() == 7                             # the centre corner and its six mid-edge nodes
    vol = np.zeros(ne)
    assert feb_volume(pos, nodes, rows, vol) == -1 and abs(vol.sum() - 1) < 1e-12
    A = np.array([[0.7, -0.2, 0.1], [0.4, 0.2, -0.3], [0.0, 0.5, -0.6]])
    vel = _linear_field(pos, A, np.zeros(3))
    K, G, dt = 4e9, 2e9, 1e-3
    gs = np.zeros((ne, 27, 6))
    st = np.zeros((ne, 6))
    f = np.zeros((len(pos), 3))
    assert feb_step(pos, vel, nodes, rows, np.full(ne, K), np.full(ne, G), dt, gs, st, f, nq) == -1
    ref = gs[0, 0]
    assert np.abs(gs[:, :nq ** 3] - ref).max() < 1e-9 * np.abs(ref).max()
    fmax = np.abs(f).max()
    assert np.abs(f[interior]).max() < 1e-10 * fmax


def test_rigid_motion_gives_no_strain():
    x = distorted(8, amp=0.1)
    pos, nodes, rows = one(x)
    w = np.array([0.3, -0.7, 0.5])
    vel = np.cross(w, x) + np.array([1.0, 2.0, -3.0])
    for nq in (2, 3):
        gs = np.zeros((1, 27, 6))
        f = np.zeros((20, 3))
        feb_step(pos, vel, nodes, rows, np.array([1e9]), np.array([1e9]), 1e-3, gs, np.zeros((1, 6)), f, nq)
        assert np.abs(gs).max() < 1e-12 * 1e9 * 1e-3 and np.abs(f).max() < 1e-3


@pytest.mark.parametrize("nq", [2, 3])
def test_forces_balance_and_have_no_moment(nq):
    x = distorted(9, amp=0.1)
    pos, nodes, rows = one(x)
    gs = np.random.default_rng(2).normal(scale=1e6, size=(1, 27, 6))
    f = np.zeros((20, 3))
    assert feb_forces(pos, nodes, rows, gs, f, nq) == -1
    scale = np.abs(f).max()
    assert np.abs(f.sum(axis=0)).max() < 1e-11 * scale
    assert np.abs(np.cross(x, f).sum(axis=0)).max() < 1e-11 * scale


# ----------------------------------------------------------------------------- mass, loads, slaves
def test_hrz_mass_positive_and_total_and_twin():
    rho = 2500.0
    for x in (brick(2.0, 1.0, 0.5), distorted(11, amp=0.1)):
        pos, nodes, rows = one(x)
        m = np.zeros(20)
        assert feb_lumped_mass(pos, nodes, rows, np.array([rho]), m) == -1
        M = twin_consistent_mass(x, rho, 3)        # the kernel's stated rule (exact for the brick only)
        total = M.sum()                                    # rho V
        d = np.diag(M)
        assert np.all(m > 0)
        assert abs(m.sum() - total) < 1e-12 * total
        assert np.allclose(m, d * total / d.sum(), rtol=1e-10)
        v = np.zeros(1)
        feb_volume(pos, nodes, rows, v)
        assert abs(total - rho * v[0]) < 1e-10 * total
    # rectangular brick: the errata's fractions, and why row sums are not used
    x = brick(2.0, 1.0, 0.5)
    pos, nodes, rows = one(x)
    m = np.zeros(20)
    feb_lumped_mass(pos, nodes, rows, np.array([rho]), m)
    Mt = rho * 1.0
    assert np.allclose(m[:8] / Mt, 0.0282, atol=5e-5) and np.allclose(m[8:] / Mt, 0.0645, atol=5e-5)
    rowsum = twin_consistent_mass(x, rho).sum(axis=1)
    assert np.allclose(rowsum[:8], -Mt / 8) and np.allclose(rowsum[8:], Mt / 6)


def test_body_force_matches_twin():
    rho, g = 2000.0, np.array([0.5, -1.0, -9.81])
    for x in (brick(1.0, 2.0, 3.0), distorted(12, amp=0.1)):
        pos, nodes, rows = one(x)
        f = np.zeros((20, 3))
        assert feb_body_force(pos, nodes, rows, np.array([rho]), g, f) == -1
        ext = np.zeros(20)
        for p, w in zip(*twin_rule(3)):                    # the kernel's stated rule
            _, dj = b_matrix(x, p)
            ext += w * dj * twin_n(p)
        assert np.allclose(f, rho * np.outer(ext, g), rtol=1e-10, atol=1e-9)
    x = brick(1.0, 2.0, 3.0)
    pos, nodes, rows = one(x)
    f = np.zeros((20, 3))
    feb_body_force(pos, nodes, rows, np.array([1.0]), np.array([0, 0, -1.0]), f)
    assert np.allclose(f[:8, 2], 6.0 / 8) and np.allclose(f[8:, 2], -6.0 / 6)


def test_face_traction_loads_match_twin_surface_integral():
    x = distorted(13, amp=0.1)
    pos = np.ascontiguousarray(x)
    t = np.array([[1e5, -2e5, 3e5]])
    for face in range(6):
        quad = FACES[face][None, :].astype(np.int64)
        f = np.zeros((20, 3))
        quad8_traction_loads(pos, quad, t, f)
        # twin: the 20-node functions on the face y_k = +-1, 3-point Gauss (the kernel's rule) in the other two
        k = [2, 2, 1, 1, 0, 0][face]
        sgn = [-1, 1, -1, 1, -1, 1][face]
        o = [j for j in range(3) if j != k]
        xg, wg = np.polynomial.legendre.leggauss(3)
        ext = np.zeros(20)
        for i, j in itertools.product(range(3), repeat=2):
            y = np.zeros(3)
            y[k] = sgn
            y[o[0]], y[o[1]] = xg[i], xg[j]
            dx = x.T @ twin_dn(y)
            ext += wg[i] * wg[j] * np.linalg.norm(np.cross(dx[:, o[0]], dx[:, o[1]])) * twin_n(y)
        expect = np.outer(ext, t[0])
        assert np.abs(f - expect).max() < 1e-10 * np.abs(expect).max()
    # flat square face: -A/12 at corners, A/3 at mid-edge nodes, exact
    pos = np.ascontiguousarray(brick(2.0, 2.0, 1.0))
    f = np.zeros((20, 3))
    quad8_traction_loads(pos, FACES[1][None, :].astype(np.int64), np.array([[0, 0, 1.0]]), f)
    assert np.allclose(f[FACES[1][:4], 2], -4.0 / 12) and np.allclose(f[FACES[1][4:], 2], 4.0 / 3)
    assert abs(f.sum() - 4.0) < 1e-12


def test_slave_nodes_follow_masters_and_forces_go_back_balanced():
    x = distorted(14, amp=0.1)
    slave_y = [(0, 0, -1), (0, 0, 1), (0, -1, 0), (0, 1, 0), (-1, 0, 0), (1, 0, 0), (0, 0, 0)]
    arr = np.vstack([x, np.zeros((7, 3))])
    nodes = np.arange(20, dtype=np.int64)[None, :]
    slaves = np.arange(20, 27, dtype=np.int64)[None, :]
    feb_slave_interp(nodes, slaves, np.array([0], np.int64), arr)
    for s, y in enumerate(slave_y):
        assert np.allclose(arr[20 + s], twin_n(np.array(y, float)) @ x, atol=1e-14)
    f = np.zeros((27, 3))
    f[20:] = np.random.default_rng(3).normal(size=(7, 3))
    tot, mom = f.sum(axis=0), np.cross(arr, f).sum(axis=0)
    feb_slave_forces(nodes, slaves, np.array([0], np.int64), f)
    assert not f[20:].any()
    assert np.allclose(f.sum(axis=0), tot, atol=1e-13)
    assert np.allclose(np.cross(arr, f).sum(axis=0), mom, atol=1e-13)


def test_gauss_positions():
    x = distorted(15)
    pos, nodes, rows = one(x)
    out = np.zeros((1, 27, 3))
    feb_gauss_positions(pos, nodes, rows, out, 3)
    for g, (p, _) in enumerate(zip(*twin_rule(3))):
        assert np.allclose(out[0, g], twin_n(p) @ x, atol=1e-14)


# ----------------------------------------------------------------------------- explicit relaxation loops
def beam_mesh(nx, ny, nz, L, B, H):
    """Regular mesh of nx ny nz 20-node elements in [0,L]x[0,B]x[0,H]; nodes shared."""
    grid = {}
    pts = []
    elems = []
    for i, j, k in itertools.product(range(nx), range(ny), range(nz)):
        ids = []
        for c in TABLE:
            key = (2 * i + 1 + int(c[0]), 2 * j + 1 + int(c[1]), 2 * k + 1 + int(c[2]))
            if key not in grid:
                grid[key] = len(pts)
                pts.append((key[0] * L / (2 * nx), key[1] * B / (2 * ny), key[2] * H / (2 * nz)))
            ids.append(grid[key])
        elems.append(ids)
    return np.array(pts, float), np.array(elems, np.int64)


def relax(pos, nodes, K, G, fext, fixmask, nq, tol=1e-9, maxsteps=200000, check=200, fixed=None):
    """Small-strain dynamic relaxation: masses from the stiffness bound (dt = 1), local damping
    0.8 (3DEC's default), until the largest unbalanced force is below tol times the applied load
    (or for exactly ``fixed`` steps). Returns displacements, element stresses and the step count."""
    ne = len(nodes)
    rows = np.arange(ne, dtype=np.int64)
    kd = np.zeros(len(pos))
    assert feb_stiffness(pos, nodes, rows, np.full(ne, K), np.full(ne, G), kd, nq) == -1
    m = kd / 2.0 * 1.1                               # dt = 1 <= 2 sqrt(m / k)
    vel = np.zeros_like(pos)
    disp = np.zeros_like(pos)
    gs = np.zeros((ne, 27, 6))
    st = np.zeros((ne, 6))
    bulk, shear = np.full(ne, K), np.full(ne, G)
    fscale = np.abs(fext).max()
    for step in range(1, maxsteps + 1):
        f = fext.copy()
        feb_step(pos, vel, nodes, rows, bulk, shear, 1.0, gs, st, f, nq)
        f[fixmask] = 0.0
        if step % check == 0 and np.abs(f).max() < tol * fscale:
            return disp, st, step
        f -= 0.8 * np.abs(f) * np.sign(vel)
        vel += f / m[:, None]
        vel[fixmask] = 0.0
        disp += vel
    raise AssertionError("did not converge")


@pytest.mark.parametrize("nq", [2, 3])
def test_uniaxial_bar(nq):
    E, nu, sig = 1e6, 0.25, 1e3
    K, G = E / (3 * (1 - 2 * nu)), E / (2 * (1 + nu))
    L = 4.0
    pos, nodes = beam_mesh(4, 1, 1, L, 1.0, 1.0)
    fext = np.zeros_like(pos)
    # traction on the x = L faces of the last element (face y1 = +1: FACES[5])
    quads = nodes[[3]][:, FACES[5]]
    quad8_traction_loads(pos, quads, np.array([[sig, 0.0, 0.0]]), fext)
    assert abs(fext[:, 0].sum() - sig) < 1e-9
    fix = np.zeros_like(pos, bool)               # symmetry planes x = 0, y = 0, z = 0
    fix[:, 0] = pos[:, 0] < 1e-9
    fix[:, 1] = pos[:, 1] < 1e-9
    fix[:, 2] = pos[:, 2] < 1e-9
    disp, st, _ = relax(pos, nodes, K, G, fext, fix, nq)
    eps = sig / E
    assert np.allclose(disp[:, 0], eps * pos[:, 0], atol=1e-6 * eps * L)
    assert np.allclose(disp[:, 1], -nu * eps * pos[:, 1], atol=1e-6 * eps * L)
    assert np.allclose(disp[:, 2], -nu * eps * pos[:, 2], atol=1e-6 * eps * L)
    assert np.allclose(st[:, 0], sig, rtol=1e-6) and np.abs(st[:, 1:]).max() < 1e-5 * sig


# CalculiX 2.20 C3D20 (3x3x3) tip deflections of the F1 beam, by number of elements
CCX = {10: 0.3996, 5: 0.3963, 2: 0.3745}


@pytest.mark.parametrize("nx", [10, 5, 2])
def test_cantilever_3x3x3_against_beam_theory_and_calculix(nx):
    """The text's fem_beam.dat: 1 x 1 x 10 m, E = 1 MPa, nu = 0.2, 100 N shared by the three
    top-edge tip nodes, root fixed. WL^3/(3EI) = 0.400 m."""
    E, nu, W, L = 1e6, 0.2, 100.0, 10.0
    K, G = E / (3 * (1 - 2 * nu)), E / (2 * (1 + nu))
    pos, nodes = beam_mesh(nx, 1, 1, L, 1.0, 1.0)
    fext = np.zeros_like(pos)
    tip = np.flatnonzero((abs(pos[:, 0] - L) < 1e-9) & (abs(pos[:, 2] - 1) < 1e-9))
    assert len(tip) == 3
    fext[tip, 2] = -W / 3
    fix = np.zeros_like(pos, bool)
    fix[pos[:, 0] < 1e-9] = True
    disp, _, _ = relax(pos, nodes, K, G, fext, fix, 3, tol=1e-7, check=500)
    p = np.flatnonzero(np.all(abs(pos - [L, 1, 1]) < 1e-9, axis=1))[0]
    u = -disp[p, 2]
    assert abs(u - CCX[nx]) < 0.002 * CCX[nx], u
    if nx == 10:
        theory = W * L ** 3 / (3 * E / 12)
        assert abs(theory - 0.4) < 1e-12 and abs(u - theory) < 0.01 * theory


def _global_stiffness(pos, nodes, K, G, nq):
    n, ne = len(pos), len(nodes)
    rows = np.arange(ne, dtype=np.int64)
    Kg = np.zeros((3 * n, 3 * n))
    for j in range(3 * n):
        v = np.zeros((n, 3))
        v.flat[j] = 1.0
        f = np.zeros((n, 3))
        feb_step(pos, v, nodes, rows, np.full(ne, K), np.full(ne, G), 1.0, np.zeros((ne, 27, 6)),
                 np.zeros((ne, 6)), f, nq)
        Kg[:, j] = -f.ravel()
    return Kg


def test_one_element_thick_2x2x2_has_a_free_end_zero_energy_mode_that_point_loads_excite():
    """Why the 2x2x2 cantilever below is loaded by a uniform end traction: with one element
    through the thickness the reduced rule leaves one zero-energy mode (the free end face's
    corners moving in and out), and the text's three top-edge point loads have a component on
    it, so an explicit run without hourglass control (``feblock_hg``, tested in
    test_feblock_hourglass.py) drifts along it without bound. A uniform traction on the end face is
    orthogonal to it. The 3x3x3 rule has no such mode."""
    E, nu = 1e6, 0.2
    K, G = E / (3 * (1 - 2 * nu)), E / (2 * (1 + nu))
    pos, nodes = beam_mesh(1, 1, 1, 10.0, 1.0, 1.0)
    free = np.repeat(pos[:, 0] > 1e-9, 3)
    point = np.zeros_like(pos)
    point[(abs(pos[:, 0] - 10) < 1e-9) & (abs(pos[:, 2] - 1) < 1e-9), 2] = -100.0 / 3
    trac = np.zeros_like(pos)
    quad8_traction_loads(pos, nodes[:, FACES[5]], np.array([[0.0, 0.0, -100.0]]), trac)
    for nq, nnull in ((2, 1), (3, 0)):
        Kf = _global_stiffness(pos, nodes, K, G, nq)[np.ix_(free, free)]
        w, V = np.linalg.eigh(Kf)
        z = V[:, w < 1e-10 * w.max()]
        assert z.shape[1] == nnull
        if nnull:
            assert np.abs(z.T @ point.ravel()[free]).max() > 10.0          # of a 100 N load
            assert np.abs(z.T @ trac.ravel()[free]).max() < 1e-7         # round-off of the eigenvector


def test_cantilever_2x2x2_within_one_percent_and_no_drift():
    """2x2x2 (the text's default), ten elements, tip load as a uniform end shear of 100 N: the
    deflection is within 1 % of WL^3/(3EI) = 0.4 m, and running 2x and 4x the steps it took to
    converge changes it by less than 0.1 %."""
    E, nu, W, L = 1e6, 0.2, 100.0, 10.0
    K, G = E / (3 * (1 - 2 * nu)), E / (2 * (1 + nu))
    pos, nodes = beam_mesh(10, 1, 1, L, 1.0, 1.0)
    fext = np.zeros_like(pos)
    quad8_traction_loads(pos, nodes[[9]][:, FACES[5]], np.array([[0.0, 0.0, -W]]), fext)
    fix = np.zeros_like(pos, bool)
    fix[pos[:, 0] < 1e-9] = True
    p = np.flatnonzero(np.all(abs(pos - [L, 1, 1]) < 1e-9, axis=1))[0]
    disp, _, steps = relax(pos, nodes, K, G, fext, fix, 2, tol=1e-7, check=500)
    u = [-disp[p, 2]]
    for mult in (2, 4):
        disp, _, _ = relax(pos, nodes, K, G, fext, fix, 2, fixed=mult * steps)
        u.append(-disp[p, 2])
    assert abs(u[0] - 0.4) < 0.01 * 0.4, u
    assert abs(u[1] - u[0]) < 1e-3 * u[0] and abs(u[2] - u[0]) < 1e-3 * u[0], u


@pytest.mark.parametrize("nq", [2, 3])
def test_parallel_step_is_bit_identical_to_serial_for_any_thread_count(nq):
    import numba

    from dec3d.kernels.feblock import feb_node_lists, feb_step_parallel

    pos, nodes = beam_mesh(6, 3, 2, 6.0, 3.0, 2.0)
    rng = np.random.default_rng(21)
    pos = pos + rng.uniform(-0.05, 0.05, pos.shape)
    ne = len(nodes)
    rows = np.arange(ne, dtype=np.int64)[::-1].copy()             # any order
    vel = rng.normal(size=pos.shape)
    K, G = np.full(ne, 3e9), np.full(ne, 2e9)
    gs0 = rng.normal(scale=1e5, size=(ne, 27, 6))
    ref_gs, ref_s, ref_f = gs0.copy(), np.zeros((ne, 6)), np.ones_like(pos)
    assert feb_step(pos, vel, nodes, rows, K, G, 1e-4, ref_gs, ref_s, ref_f, nq) == -1
    nstart, nent = feb_node_lists(len(pos), nodes, rows)
    old = numba.get_num_threads()
    try:
        for th in sorted({1, min(2, numba.config.NUMBA_NUM_THREADS)}):
            numba.set_num_threads(th)
            gs, s, f = gs0.copy(), np.zeros((ne, 6)), np.ones_like(pos)
            fe, ok = np.empty((ne, 20, 3)), np.empty(ne, np.bool_)
            assert feb_step_parallel(pos, vel, nodes, rows, K, G, 1e-4, gs, s, f, nq, fe, ok, nstart, nent) == -1
            assert np.array_equal(gs, ref_gs) and np.array_equal(s, ref_s) and np.array_equal(f, ref_f)
    finally:
        numba.set_num_threads(old)


def test_fe_bench_runs_and_prints_its_figures():
    """bench/fe_bench.py on a tiny mesh (no timing asserted)."""
    import os
    import subprocess
    import sys

    from conftest import ROOT

    out = subprocess.run([sys.executable, str(ROOT / "bench" / "fe_bench.py"), "--n", "8", "--steps", "1",
                          "--threads", "1"], capture_output=True, text=True, timeout=300, cwd=ROOT,
                         env={**os.environ, "PYTHONPATH": os.pathsep.join(
                             [str(ROOT)] + [p for p in [os.environ.get("PYTHONPATH")] if p])})
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    assert lines[0].startswith("machine: ") and "elem-cyc/s" in lines[1]
    rows = [ln.split() for ln in lines[2:]]
    assert [r[0] for r in rows] == ["8", "8"] and [r[2] for r in rows] == ["2x2x2", "3x3x3"]
    assert all(float(r[5]) > 0 and float(r[6]) > 1000 for r in rows)
