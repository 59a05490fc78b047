"""20-node bricks (kernels/feblock*.py) against the independent numpy twin of tests/feblock_twin.py,
and the analytical checks on one element or a small patch: patch tests, rigid motion, force and
moment balance, HRZ mass, consistent body and face loads, slave nodes. The explicit relaxation of
a bar and of the FE-block text's cantilever are in tests/test_feblock_beams.py.
"""
import itertools

import numpy as np
import pytest
from feblock_twin import (CORNERS, EDGES, ERRATA_MID, TABLE, b_matrix, brick, distorted, one, twin_consistent_mass,
                          twin_dn, twin_n, twin_rule, twin_step, twin_stiffness)

from dec3d.kernels.feblock import (FACES, feb_body_force, feb_forces, feb_gauss_positions,
                                   feb_lumped_mass, feb_slave_forces, feb_slave_interp, feb_step,
                                   feb_stiffness, feb_volume, quad8_traction_loads, shape20)
from dec3d.kernels.feblock_jac import grad_n, jac_inv


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


def test_jacobian_kernels_match_numpy_on_the_twin():
    """``feblock_jac``: det J, J^-1 and the Cartesian derivatives at points of a distorted element
    against numpy (J = x^T dN/dy from the twin's complex-step derivatives, numpy's det and inv);
    an inverted element gives det J <= 0 and leaves the outputs untouched."""
    x = distorted(seed=4, amp=0.1)
    for y in ([0.3, -0.7, 0.1], [-1.0, 0.0, 1.0], [0.77, 0.77, -0.77]):
        d = twin_dn(np.array(y))
        J = x.T @ d
        ji = np.zeros((3, 3))
        dn = np.zeros((20, 3))
        det = jac_inv(x, d, ji)
        assert abs(det - np.linalg.det(J)) < 1e-13 * abs(det)
        assert np.allclose(ji, np.linalg.inv(J), rtol=0, atol=1e-12 * np.abs(ji).max())
        assert grad_n(x, d, dn) == det
        assert np.allclose(dn, d @ np.linalg.inv(J), rtol=0, atol=1e-12 * np.abs(dn).max())
    xi = brick()
    xi[[0, 6]] = xi[[6, 0]]
    d = twin_dn(np.array([-0.9, -0.9, -0.9]))
    assert np.linalg.det(xi.T @ d) < 0
    ji = np.full((3, 3), 7.0)
    dn = np.full((20, 3), 7.0)
    assert jac_inv(xi, d, ji) <= 0 and grad_n(xi, d, dn) <= 0
    assert (ji == 7.0).all() and (dn == 7.0).all()


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
