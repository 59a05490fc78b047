"""20-node bricks (kernels/feblock*.py) in explicit relaxation loops: a uniaxial bar and the
FE-block text's cantilever (003_*, "Verification: Cantilever Beam") against beam theory and
CalculiX, the reduced rule's zero-energy mode, the parallel step bit for bit, and the FE bench.
"""
import numpy as np
import pytest
from feblock_twin import beam_mesh

from dec3d.kernels.feblock import FACES, feb_step, feb_stiffness, quad8_traction_loads


# ----------------------------------------------------------------------------- explicit relaxation loops
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

