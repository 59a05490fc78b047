"""Hourglass control of 2x2x2 20-node bricks (kernels/feblock_hg.py) against an independent
numpy twin, what it must and must not resist, and the FE-block text's fem_beam.dat (seed 003_*)
run as written: default 2x2x2 integration, one element thick, three point loads on the tip edge.

The twin builds the hourglass stiffness from the test twin of feblock_twin (serendipity
shape functions from the node table, complex-step derivatives, numpy Gauss points), with the
trilinear interpolation written as products of 1-D Lagrange polynomials through the two Gauss
abscissae, and the mean inverse Jacobian from numpy's inverse."""
import io

import numpy as np
import pytest
from conftest import SHARED
from feblock_twin import (b_matrix, beam_mesh, brick, d_matrix, distorted, one, twin_dn, twin_rule,
                          twin_step)

from dec3d.kernels.feblock import feb_node_lists, feb_step, feb_step_parallel, feb_stiffness
from dec3d.kernels.feblock_hg import HOURGLASS

E, NU = 1e6, 0.2
K, G = E / (3 * (1 - 2 * NU)), E / (2 * (1 + NU))
FACE_CENTRES = [np.array(c, float) for c in [(0, 0, -1), (0, 0, 1), (0, -1, 0), (0, 1, 0), (-1, 0, 0), (1, 0, 0)]]


def lagrange2(p, s):
    """Linear Lagrange polynomial through the abscissae +-1/sqrt 3 that is 1 at s, evaluated at p."""
    other = -s
    return (p - other) / (s - other)


def twin_hg_b(x):
    """The six (6, 60) hourglass strain matrices dB_p = B(p) - sum_g l_g(p) B(g) (l_g the
    trilinear Lagrange polynomial of Gauss point g) and the element volume."""
    pts, wts = twin_rule(2)
    vol = sum(w * np.linalg.det(x.T @ twin_dn(p)) for p, w in zip(pts, wts))
    out = []
    for c in FACE_CENTRES:
        B = b_matrix(x, c)[0].copy()
        for p in pts:
            B -= np.prod([lagrange2(c[i], p[i]) for i in range(3)]) * b_matrix(x, p)[0]
        out.append(B)
    return out, vol


def twin_hg_stiffness(x, eps):
    Bs, vol = twin_hg_b(x)
    D = d_matrix(K, G)
    return sum(eps * vol / 6 * B.T @ D @ B for B in Bs)


def twin_k2(x):
    D = d_matrix(K, G)
    Ke = np.zeros((60, 60))
    for p, w in zip(*twin_rule(2)):
        B, dj = b_matrix(x, p)
        Ke += w * dj * B.T @ D @ B
    return Ke


def kernel_k(x, hg):
    """The element stiffness the kernel applies, column by column (unit velocity, dt = 1)."""
    pos, nodes, rows = one(x)
    Ke = np.zeros((60, 60))
    for j in range(60):
        v = np.zeros((20, 3))
        v.flat[j] = 1.0
        f = np.zeros((20, 3))
        assert feb_step(pos, v, nodes, rows, np.array([K]), np.array([G]), 1.0, np.zeros((1, 27, 6)),
                        np.zeros((1, 6)), f, 2, hg) == -1
        Ke[:, j] = -f.ravel()
    return Ke


@pytest.mark.parametrize("seed", [1, 2])
def test_step_with_hourglass_matches_twin(seed):
    """Random velocities and prior stresses (Gauss and hourglass rows) on a distorted element:
    the kernel's Gauss stresses, hourglass stresses and nodal forces are the twin's."""
    x = distorted(seed)
    rng = np.random.default_rng(seed)
    v = rng.normal(size=(20, 3))
    s0 = rng.normal(scale=1e3, size=(27, 6))
    dt, eps = 1e-3, 0.1
    sig, mean, f = twin_step(x, v, K, G, dt, s0, 2)
    D = d_matrix(K, G)
    Bs, vol = twin_hg_b(x)
    hs = []
    for p, B in enumerate(Bs):
        s = s0[8 + p] + eps * D @ (B @ v.ravel() * dt)
        hs.append(s)
        f = f - (vol / 6 * B.T @ s).reshape(20, 3)
    pos, nodes, rows = one(x)
    gs, st, fk = s0[None].copy(), np.zeros((1, 6)), np.zeros((20, 3))
    assert feb_step(pos, v, nodes, rows, np.array([K]), np.array([G]), dt, gs, st, fk, 2, eps) == -1
    assert np.allclose(gs[0, :8], sig, rtol=1e-10, atol=1e-9)
    assert np.allclose(gs[0, 8:14], hs, rtol=1e-10, atol=1e-9)
    assert np.allclose(st[0], mean, rtol=1e-10, atol=1e-9)       # the element stress leaves the hourglass rows out
    assert np.allclose(fk, f, rtol=1e-9, atol=1e-9 * np.abs(f).max())
    assert (gs[0, 14:] == s0[14:]).all()


def test_control_removes_all_six_spurious_modes_and_only_them():
    """One distorted element: 2x2x2 alone has 12 zero-energy modes (6 rigid), with the control 6
    (the rigid motions); the kernel's stiffness is K2 + the twin's hourglass stiffness."""
    x = distorted(3)
    k0, k1 = kernel_k(x, 0.0), kernel_k(x, HOURGLASS)
    assert np.allclose(k1, twin_k2(x) + twin_hg_stiffness(x, HOURGLASS), atol=1e-9 * np.abs(k1).max())
    for kk, nzero in ((k0, 12), (k1, 6)):
        w = np.linalg.eigvalsh(0.5 * (kk + kk.T))
        assert (w < 1e-9 * w.max()).sum() == nzero
        assert w.min() > -1e-9 * w.max()


def test_fields_the_eight_points_integrate_are_left_alone():
    """On a parallelepiped, a velocity field quadratic in x (strain rates linear) gives no
    hourglass stress and the same forces as without control; on a distorted element, so does a
    linear field (uniform strain rate plus rotation: the patch test is untouched)."""
    A = np.array([[1.2, 0.1, 0.0], [0.2, 0.9, 0.1], [0.0, 0.15, 1.1]])
    x = brick() @ A.T + [0.3, -0.2, 0.5]
    rng = np.random.default_rng(5)
    c = rng.normal(size=(3, 10))

    def vfield(p):
        X, Y, Z = p
        mons = np.array([1, X, Y, Z, X * X, Y * Y, Z * Z, X * Y, Y * Z, Z * X])
        return c @ mons
    v = np.array([vfield(p) for p in x])
    pos, nodes, rows = one(x)
    res = []
    for hg in (0.0, 0.1):
        gs, st, f = np.zeros((1, 27, 6)), np.zeros((1, 6)), np.zeros((20, 3))
        feb_step(pos, v, nodes, rows, np.array([K]), np.array([G]), 1e-3, gs, st, f, 2, hg)
        res.append((gs, f))
    assert np.abs(res[1][0][0, 8:14]).max() < 1e-9 * np.abs(res[1][0][0, :8]).max()
    assert np.allclose(res[1][1], res[0][1], rtol=1e-9, atol=1e-9 * np.abs(res[0][1]).max())
    xd = distorted(6)
    L = rng.normal(size=(3, 3))
    v = xd @ L.T + [1.0, -2.0, 0.5]
    pos, nodes, rows = one(xd)
    res = []
    for hg in (0.0, 0.1):
        gs, st, f = np.zeros((1, 27, 6)), np.zeros((1, 6)), np.zeros((20, 3))
        feb_step(pos, v, nodes, rows, np.array([K]), np.array([G]), 1e-3, gs, st, f, 2, hg)
        res.append((gs, f))
    assert np.abs(res[1][0][0, 8:14]).max() < 1e-10 * np.abs(res[1][0][0, :8]).max()
    assert np.allclose(res[1][1], res[0][1], rtol=1e-9, atol=1e-9 * np.abs(res[0][1]).max())


def test_stiffness_bound_includes_the_control():
    """feb_stiffness with hg: per node the largest absolute row sum of K2 + hourglass (twin)."""
    x = distorted(4)
    kt = twin_k2(x) + twin_hg_stiffness(x, HOURGLASS)
    want = np.abs(kt).sum(axis=1).reshape(20, 3).max(axis=1)
    pos, nodes, rows = one(x)
    kd = np.zeros(20)
    assert feb_stiffness(pos, nodes, rows, np.array([K]), np.array([G]), kd, 2, HOURGLASS) == -1
    assert np.allclose(kd, want, rtol=1e-9)


@pytest.mark.parametrize("hg", [0.0, HOURGLASS])
def test_parallel_step_with_control_is_bit_identical(hg):
    import numba

    pos, nodes = beam_mesh(6, 3, 2, 6.0, 3.0, 2.0)
    rng = np.random.default_rng(8)
    pos = pos + rng.uniform(-0.05, 0.05, pos.shape)
    ne = len(nodes)
    rows = np.arange(ne, dtype=np.int64)
    vel = rng.normal(size=pos.shape)
    Kv, Gv = np.full(ne, 3e9), np.full(ne, 2e9)
    gs0 = rng.normal(scale=1e5, size=(ne, 27, 6))
    ref_gs, ref_s, ref_f = gs0.copy(), np.zeros((ne, 6)), np.zeros_like(pos)
    feb_step(pos, vel, nodes, rows, Kv, Gv, 1e-4, ref_gs, ref_s, ref_f, 2, hg)
    nstart, nent = feb_node_lists(len(pos), nodes, rows)
    old = numba.get_num_threads()
    try:
        for th in sorted({1, min(2, numba.config.NUMBA_NUM_THREADS)}):
            numba.set_num_threads(th)
            gs, s, f = gs0.copy(), np.zeros((ne, 6)), np.zeros_like(pos)
            fe, ok = np.empty((ne, 20, 3)), np.empty(ne, np.bool_)
            feb_step_parallel(pos, vel, nodes, rows, Kv, Gv, 1e-4, gs, s, f, 2, fe, ok, nstart, nent, hg)
            assert np.array_equal(gs, ref_gs) and np.array_equal(f, ref_f)
    finally:
        numba.set_num_threads(old)


def _relax_steps(pos, nodes, fext, fix, hg, steps=None, tol=1e-7, check=500, maxsteps=400000):
    """Dynamic relaxation as tests/test_feblock_beams.relax (local damping 0.8, dt = 1, masses
    from the stiffness bound), 2x2x2 with control hg; until converged or for exactly ``steps``."""
    ne = len(nodes)
    rows = np.arange(ne, dtype=np.int64)
    bulk, shear = np.full(ne, K), np.full(ne, G)
    kd = np.zeros(len(pos))
    feb_stiffness(pos, nodes, rows, bulk, shear, kd, 2, hg)
    m = kd / 2.0 * 1.1
    vel, disp = np.zeros_like(pos), np.zeros_like(pos)
    gs, st = np.zeros((ne, 27, 6)), np.zeros((ne, 6))
    for step in range(1, (steps or maxsteps) + 1):
        f = fext.copy()
        feb_step(pos, vel, nodes, rows, bulk, shear, 1.0, gs, st, f, 2, hg)
        f[fix] = 0.0
        if steps is None and step % check == 0 and np.abs(f).max() < tol * np.abs(fext).max():
            return disp, step
        f -= 0.8 * np.abs(f) * np.sign(vel)
        vel += f / m[:, None]
        vel[fix] = 0.0
        disp += vel
    if steps is None:
        raise AssertionError("did not converge")
    return disp, steps


def test_fem_beam_point_loads_2x2x2_converge_within_one_percent_and_do_not_drift():
    """The text's cantilever, ten elements, 2x2x2, 100 N as three equal point loads on the top tip
    edge: with the control the tip deflection is within 1 % of WL^3/(3EI) = 0.4 m, and 2x the
    steps of convergence change it by less than 0.1 % (4x, in the engine: verification/
    FE1_cantilever). Without control the same loads drive the zero-energy mode: after as many
    steps the tip has moved further than the whole answer."""
    pos, nodes = beam_mesh(10, 1, 1, 10.0, 1.0, 1.0)
    fext = np.zeros_like(pos)
    fext[(abs(pos[:, 0] - 10) < 1e-9) & (abs(pos[:, 2] - 1) < 1e-9), 2] = -100.0 / 3
    fix = np.zeros_like(pos, bool)
    fix[pos[:, 0] < 1e-9] = True
    p = np.flatnonzero(np.all(abs(pos - [10, 1, 1]) < 1e-9, axis=1))[0]
    disp, n = _relax_steps(pos, nodes, fext, fix, HOURGLASS)
    u = -disp[p, 2]
    u2 = -_relax_steps(pos, nodes, fext, fix, HOURGLASS, steps=2 * n)[0][p, 2]
    assert abs(u - 0.4) < 0.01 * 0.4, u
    assert abs(u2 - u) < 1e-3 * u, (u, u2)
    free = _relax_steps(pos, nodes, fext, fix, 0.0, steps=n)[0]
    assert np.abs(free).max() > 2 * u, np.abs(free).max()


def test_control_barely_moves_the_answer_of_a_load_the_mode_does_not_see():
    """Uniform end shear (consistent nodal loads, orthogonal to the mode): the tip deflection with
    the control is within 0.05 % of the deflection without it (both converged)."""
    from dec3d.kernels.feblock import FACES, quad8_traction_loads

    pos, nodes = beam_mesh(10, 1, 1, 10.0, 1.0, 1.0)
    fext = np.zeros_like(pos)
    quad8_traction_loads(pos, nodes[[9]][:, FACES[5]], np.array([[0.0, 0.0, -100.0]]), fext)
    fix = np.zeros_like(pos, bool)
    fix[pos[:, 0] < 1e-9] = True
    p = np.flatnonzero(np.all(abs(pos - [10, 1, 1]) < 1e-9, axis=1))[0]
    u0 = -_relax_steps(pos, nodes, fext, fix, 0.0, tol=1e-8)[0][p, 2]
    u1 = -_relax_steps(pos, nodes, fext, fix, HOURGLASS, tol=1e-8)[0][p, 2]
    assert abs(u1 - u0) < 5e-4 * u0, (u0, u1)


# ----------------------------------------------------------------------------- the seed deck as written
SEED = SHARED / "seeds" / "003_6efdf905be92f7f6.txt"


def fem_beam_deck() -> str:
    """fem_beam.dat as printed in the FE-block text: from its title line to the next section."""
    text = SEED.read_text(encoding="utf-8")
    start = text.index("\nfem_beam.dat\n") + len("\nfem_beam.dat\n")
    return text[start:text.index("\nExample: Tunnel Liner", start)]


@pytest.mark.skipif(not SEED.is_file(), reason=f"FE-block seed text not found at {SEED} (set DEC3D_SHARED)")
def test_seed_fem_beam_runs_unmodified_and_prints_an_error_below_one_percent(tmp_path):
    from dec3d.session import Session

    deck = fem_beam_deck()
    assert "feblock generate 1 1 1\n" in deck and "[solution]" in deck      # as written: default 2x2x2
    out = io.StringIO()
    s = Session(out_dir=tmp_path, stdout=out)
    s.command(deck)
    text = out.getvalue()
    assert "model solve: converged" in text
    line = [ln for ln in text.splitlines() if ln.startswith("Error: ")]
    assert len(line) == 1 and line[0].endswith("%"), text[-500:]
    err = float(line[0][len("Error: "):-1])
    assert 0 <= err < 1.0, line
    # the FISH figure is the model's: the tip node's deflection against 0.4 m
    v = s.model.vertices
    tip = np.flatnonzero(np.all(abs(v["pos"] - [10, 1, 1]) < 1e-9, axis=1))[0]
    assert abs(100 * abs(-v["disp"][tip, 2] - 0.4) / 0.4 - err) < 1e-9



@pytest.mark.parametrize("nq", [2, 3])
def test_f2_patch_distorted_element_under_uniform_stress_through_its_boundary_nodes(nq):
    """F2 of the issue, driven by forces: one distorted 20-node element (mid-edge nodes moved,
    faces not planar) loaded at its nodes (all on its boundary) by the forces of a uniform stress
    sigma0 (twin: sum_g w det J B^T sigma0, the rule of the element), held 3-2-1 against rigid
    motion only, solved statically with the stiffness the kernel applies (2x2x2 with the hourglass
    control, which makes the single element solvable; 3x3x3 as it is): every Gauss point carries
    sigma0 to 1e-8 relative, and the hourglass stresses stay zero."""
    x = distorted(11, amp=0.12)
    s0 = np.array([3e5, -1e5, 2e5, 4e4, -6e4, 5e4])              # xx yy zz xy xz yz
    # B rows are xx yy zz 2xy 2xz 2yz (engineering shear): B^T sigma with sigma xx yy zz xy xz yz
    f = np.zeros(60)
    for p, w in zip(*twin_rule(nq)):
        B, dj = b_matrix(x, p)
        f += w * dj * B.T @ s0
    pos, nodes, rows = one(x)
    Ke = np.zeros((60, 60))
    for j in range(60):
        v = np.zeros((20, 3))
        v.flat[j] = 1.0
        fk = np.zeros((20, 3))
        feb_step(pos, v, nodes, rows, np.array([K]), np.array([G]), 1.0, np.zeros((1, 27, 6)), np.zeros((1, 6)),
                 fk, nq, HOURGLASS)
        Ke[:, j] = -fk.ravel()
    held = [0, 1, 2, 3 * 1 + 1, 3 * 1 + 2, 3 * 3 + 2]            # node 1 xyz, node 2 yz, node 4 z
    free = np.setdiff1d(np.arange(60), held)
    u = np.zeros(60)
    u[free] = np.linalg.solve(Ke[np.ix_(free, free)], f[free])
    gs, st = np.zeros((1, 27, 6)), np.zeros((1, 6))
    feb_step(pos, u.reshape(20, 3), nodes, rows, np.array([K]), np.array([G]), 1.0, gs, st, np.zeros((20, 3)), nq,
             HOURGLASS)
    assert np.abs(gs[0, :nq ** 3] - s0).max() < 1e-8 * np.abs(s0).max()
    if nq == 2:
        assert np.abs(gs[0, 8:14]).max() < 1e-8 * np.abs(s0).max()


# ----------------------------------------------------------------------------- which elements get it
def test_exposed_elements_are_rows_one_element_across_in_two_directions():
    """Counted on the reduced stiffness of free regular meshes (spurious modes = zero modes - 6):
    1x1x1 6, 2x1x1 3, 4x1x1 5, 2x2x1 0, 3x3x1 0, 2x2x2 0; exposed_elements marks every element
    of the first three and none of the others."""
    from test_feblock_beams import _global_stiffness

    from dec3d.model.feblocks import exposed_elements

    for shape, spurious in (((1, 1, 1), 6), ((2, 1, 1), 3), ((4, 1, 1), 5), ((2, 2, 1), 0), ((3, 3, 1), 0),
                            ((2, 2, 2), 0), ((1, 3, 2), 0)):
        pos, nodes = beam_mesh(*shape, *(float(n) for n in shape))
        w = np.linalg.eigvalsh(_global_stiffness(pos, nodes, K, G, 2))
        assert (w < 1e-9 * w.max()).sum() - 6 == spurious, shape
        mask = exposed_elements(nodes)
        assert mask.all() if spurious else not mask.any(), shape


def test_generate_sets_the_control_where_the_mesh_needs_it_and_change_overrides(session):
    from dec3d.errors import Dec3dError

    session.command("model configure feblock\nblock create brick 0 10 0 1 0 1\nblock create brick 0 1 3 4 0 1\n"
                    "block create brick 0 1 6 7 0 1\n"
                    "feblock generate 1 1 1 range id 1\nfeblock generate 0.5 0.5 1 range id 2\n"
                    "feblock generate 1 1 1 integration 3 range id 3")
    es = session.model.store("feblocks")
    h = es["hourglass"][: es.n]
    blk = session.model.blocks["id"][es["block"][: es.n]]
    assert (h[blk == 1] == HOURGLASS).all() and len(h[blk == 1]) == 10
    assert (h[blk == 2] == 0).all() and len(h[blk == 2]) == 4          # 2 x 2 x 1: held by its neighbours
    assert (h[blk == 3] == 0).all()                                       # 3x3x3: no spurious mode
    assert session.output.getvalue().count("one element thick") == 1
    es["gstress"][: es.n, 8:14] = 1.0
    session.command("feblock change hourglass 0.05 range position-x 0 5 position-y 0 1")
    assert np.allclose(es["hourglass"][: es.n][blk == 1], [0.05] * 5 + [HOURGLASS] * 5)
    session.command("feblock change hourglass 0 range position-y 6 7")
    assert (es["gstress"][: es.n][blk == 3, 8:14] == 1.0).all()          # 3x3x3 rows 8-13 are Gauss points
    session.command("feblock change hourglass 0 range position-y 0 1")
    assert (es["hourglass"][: es.n][blk == 1] == 0).all() and (es["gstress"][: es.n][blk == 1, 8:14] == 0).all()
    before = es["hourglass"][: es.n].copy()
    for bad in ("feblock change hourglass -0.1", "feblock change hourglass 1.5"):
        with pytest.raises(Dec3dError, match="hourglass"):
            session.command(bad)
    assert np.array_equal(es["hourglass"][: es.n], before)


def test_block_groups_select_their_fe_elements(session):
    """`feblock change … range group` matches an element's own groups or its block's (as zones do):
    the tunnel-liner deck sets its liner by the group of the prism blocks."""
    session.command("model configure feblock\nblock create brick 0 2 0 1 0 1 group 'liner'\n"
                    "block create brick 0 1 3 4 0 1\nfeblock generate 1 1 1\n"
                    "feblock change cmodel elastic young 30e9 poisson 0.2 density 2400 range group 'liner'")
    es = session.model.store("feblocks")
    blk = session.model.blocks["id"][es["block"][: es.n]]
    assert (es["cmodel"][: es.n][blk == 1] != 0).all() and (es["cmodel"][: es.n][blk == 2] == 0).all()
    assert "selected no FE element" not in session.output.getvalue()
