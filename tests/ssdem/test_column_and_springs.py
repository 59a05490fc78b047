"""A block column under self-weight, and the spring laws on two-block tests."""
import numpy as np
import pytest

from dec3d.ssdem import safety, solve, springs
from dec3d.ssdem.build import from_polygons


def box(x0, y0, w=1.0, h=1.0):
    return np.array([[x0, y0], [x0 + w, y0], [x0 + w, y0 + h], [x0, y0 + h]])


def test_column_interfaces_carry_the_weight_above():
    """Six 2 m x 1.5 m blocks on a fixed base, gamma = 20 kN/m^3: joint k carries the blocks above it."""
    n, w, h, gamma = 6, 2.0, 1.5, 20e3
    polys = [box(0, -h, w, h)] + [box(0, k * h, w, h) for k in range(n)]
    prob = from_polygons(polys, [True] + [False] * n, kn=1e8, ks=4e7, c=1e9, phi=30, gamma=gamma, n_steps=3)
    st = solve.run(prob)
    s = safety.evaluate(prob, st)
    itf = prob.interfaces
    order = np.argsort(itf.mid[:, 1])
    weight = gamma * w * h
    expected = weight * np.arange(n, 0, -1)                # joint at the bottom of block k carries n - k blocks
    np.testing.assert_allclose(s.sigma_n[order] * itf.length[order], expected, rtol=1e-10)
    assert np.abs(s.tau).max() < 1e-6 * weight
    # closure of each joint = load / (k_n L); the top block settles by the sum
    np.testing.assert_allclose(-st.u[-1, 1], np.sum(expected / (1e8 * w)), rtol=1e-10)


def two_block(T=0.0, N=0.0, up=0.0, **props):
    """Block B (free) on block A (fixed), unit squares; loads on B's centroid, in N per m."""
    return from_polygons([box(0, -1), box(0, 0)], [True, False], force=[[0, 0, 0], [T, -N + up, 0]], **props)


def test_tension_cut_off():
    """Pull B up: below the tensile strength it hangs on the normal spring, above it cracks and falls away."""
    p = two_block(up=4e3, kn=1e6, ks=1e6, c=20e3, phi=30, tensile=5e3, cutoff=True, n_steps=2)
    st = solve.run(p)
    assert not st.cracked.any() and not st.removed.any()
    assert st.u[1, 1] == pytest.approx(4e3 / 1e6, rel=1e-9)
    p = two_block(up=6e3, kn=1e6, ks=1e6, c=20e3, phi=30, tensile=5e3, cutoff=True, n_steps=2)
    st = solve.run(p)
    assert st.cracked.all() and st.kn[0] == 0 and st.ks[0] == 0
    assert st.removed[1] and st.removed_step[1] == 2          # 3 kPa at step 1 holds, 6 kPa at step 2 does not
    # a cohesionless interface has no cut-off (thesis 3.2.1 A): the normal spring stays
    p = two_block(up=6e3, kn=1e6, ks=1e6, c=0.0, phi=30, tensile=0.0, cutoff=False, n_steps=2)
    st = solve.run(p)
    assert not st.cracked.any() and st.u[1, 1] == pytest.approx(6e-3, rel=1e-9)


def test_peak_strength_and_interface_fs_before_yield():
    """N = 50 kN, T = 20 kN on 1 m: tau_p = 10 + 50 tan 30 kPa; FS = tau_p / 20 kPa."""
    p = two_block(T=20e3, N=50e3, kn=1e7, ks=1e6, c=10e3, phi=30, n_steps=4)
    st = solve.run(p)
    s = safety.evaluate(p, st)
    tau_p = 10e3 + 50e3 * np.tan(np.radians(30))
    assert s.tau_mob[0] == pytest.approx(20e3, rel=1e-9) and s.sigma_n[0] == pytest.approx(50e3, rel=1e-9)
    assert s.fs[0] == pytest.approx(tau_p / 20e3, rel=1e-9)
    assert st.ks[0] == 1e6 and s.yield_pct[0] == 0.0


def test_force_beyond_peak_strength_makes_the_block_unstable():
    """Statically determinate: shear beyond tau_p has no equilibrium; B leaves at the first such step.

    At load step k of 5, tau = 10 k kPa and tau_p = 10 + 10 k tan 30 kPa: step 2 holds
    (20 < 21.55), step 3 does not (30 > 27.32).  Only the tangent-matrix test sees it: the
    secant spring just softens and the block slides further every iteration.
    """
    p = two_block(T=50e3, N=50e3, kn=1e7, ks=1e6, c=10e3, phi=30, n_steps=5)
    st = solve.run(p)
    assert st.removed[1] and st.removed_step[1] == 3
    assert [r.n_unstable for r in st.steps] == [0, 0, 1, 1, 1]
    assert st.steps[2].iterations <= 2 * 10


def test_secant_softening_matches_the_spring_law():
    """B sheared between a softening joint (below) and a stiff elastic one (above).

    phi = 0, c_p = 10 kPa, c_r = 2 kPa, k_s1 = 1000 kPa/m: delta_peak = 0.01 m, delta_res = 0.05 m;
    the top joint (k_s2 = 400 kPa/m) keeps the softening branch stable under force control:
    T = tau_1(d) + 400 d with tau_1(d) = 12 - 200 d on the branch, so T = 16 kN gives d = 0.02 m,
    tau_1 = 8 kPa, secant k_s1 = 400 kPa/m.  Huge k_n suppresses the block's rotation.
    """
    polys = [box(0, -1), box(0, 0), box(0, 1)]
    p = from_polygons(polys, [True, False, True], force=[[0, 0, 0], [16e3, 0, 0], [0, 0, 0]],
                      kn=1e9, ks=1e6, c=10e3, c_res=2e3, phi=0.0, delta_res=0.05, n_steps=10, tol=1e-10)
    itf = p.interfaces
    top = itf.mid[:, 1] > 0.5
    itf.ks[top], itf.c_p[top], itf.c_r[top] = 4e5, 1e12, 1e12
    st = solve.run(p)
    s = safety.evaluate(p, st)
    bottom = ~top
    assert st.u[1, 0] == pytest.approx(0.02, rel=1e-6)
    assert abs(st.u[1, 2]) < 1e-9
    assert s.tau_mob[bottom][0] == pytest.approx(8e3, rel=1e-6)
    assert st.ks[bottom][0] == pytest.approx(4e5, rel=1e-6)
    assert s.tau_avail[bottom][0] == pytest.approx(8e3, rel=1e-6)       # interpolated strength at d
    assert s.yield_pct[bottom][0] == pytest.approx(60.0, rel=1e-6)
    assert s.fs[bottom][0] == pytest.approx(1.0, rel=1e-6)
    assert st.steps[-1].converged


def test_law_pieces_and_no_stiffening_on_unloading():
    ks0, tp, tr, dres = np.full(4, 1e3), np.full(4, 10.0), np.full(4, 2.0), np.full(4, 0.05)
    d = np.array([0.005, 0.02, 0.05, 0.2])
    ks, tau = springs.secant_ks(d, tp, tr, ks0, dres)
    np.testing.assert_allclose(tau, [10.0, 8.0, 2.0, 2.0])               # peak, interpolated, residual
    np.testing.assert_allclose(ks, [1e3, 400.0, 40.0, 10.0])
    # unloading (smaller slip) would give a larger secant value: the old stiffness is kept
    z = np.zeros(4)
    kn, ks2, _, _, plastic = springs.update(np.full(4, 1e4), ks, np.zeros(4, bool), ks0, d / 4, z, z,
                                   np.full(4, 10.0), z, np.full(4, 2.0), z, dres, z, np.zeros(4, bool))
    np.testing.assert_array_equal(ks2, ks)
    assert not plastic.any()


def test_convergence_measure_is_the_overshoot_of_the_strength():
    """The secant iteration stops when no spring's trial stress exceeds its strength by more
    than `tol` (as a fraction): (k_old - k_new)/k_old = 1 - tau_f/tau_trial, whatever the
    spring has already lost.  Two springs, k_s0 = 1e5 kPa/m: one intact overshooting by
    0.05 %, one softened to 1e2 (0.1 % of k_s0) whose trial stress is 1 % over its strength.
    Measured against k_s0 the second would count as a change of 1e-5 and pass any tolerance."""
    delta = np.array([1e-4, 0.5])                 # slips of the last solve, m
    ks_old = np.array([1e5, 1e2])
    tau_trial = ks_old * delta                   # 10 kPa and 50 kPa
    tau_f = tau_trial / np.array([1.0005, 1.01])  # strengths at those slips
    ks_new = tau_f / delta                       # the secant of the law
    change = solve.stiffness_change(ks_old, ks_new, np.array([True, True]))
    assert change == pytest.approx(1 - 1 / 1.01, rel=1e-12)
    # an inactive (removed) interface and a spring with no stiffness left do not count
    assert solve.stiffness_change(ks_old, ks_new, np.array([True, False])) == pytest.approx(1 - 1 / 1.0005)
    assert solve.stiffness_change(np.array([0.0]), np.array([0.0]), np.array([True])) == 0.0


def test_blocks_freed_by_a_tension_crack_get_no_limit_search():
    """A removal after a tension crack is the thesis's own outcome; dividing the strength
    does not close the crack, so no strength-factor bracket is searched (analysis.run_problem)."""
    from dec3d.ssdem.analysis import run_problem
    p = two_block(up=6e3, kn=1e6, ks=1e6, c=20e3, phi=30, tensile=5e3, cutoff=True, n_steps=2)
    an = run_problem(p)
    assert an.state.removed[1] and an.state.cracked.all()
    assert an.limit is None
