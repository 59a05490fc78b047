"""Flow on a network of knots and pipes (dec3d.kernels.jointflow, dec3d.physics.jointflow): the cubic law
through one joint, parallel joints, a channel network against a nodal analysis written here, pressure
diffusion along a joint against the 1-D solution, the explicit kernel against a twin."""
import math

import numpy as np
import pytest
from scipy.special import erfc

from dec3d.kernels.jointflow import flow_steps, stable_dt
from dec3d.physics.jointflow import conductance, hydraulic_aperture, steady

MU = 1e-3           # Pa s
KW = 2e9            # Pa


def _chain(n, length, a, w):
    """A joint of length L cut into n pipes: knots 0..n along it."""
    dx = length / n
    pa = np.arange(n)
    pb = np.arange(1, n + 1)
    c = conductance(np.full(n, a), w, np.full(n, dx), MU)
    vol = np.full(n + 1, a * w * dx)
    vol[[0, -1]] *= 0.5
    return pa, pb, c, vol


def test_one_joint_between_two_reservoirs_follows_the_cubic_law():
    """q = a³ w ΔP / (12 μ L), steady (direct solve) and by the explicit steps run to steady state."""
    a, w, length, dp = 1e-4, 2.0, 10.0, 1e5
    want = a ** 3 * w * dp / (12 * MU * length)
    pa, pb, c, vol = _chain(20, length, a, w)
    fixed = np.zeros(21, bool)
    fixed[[0, -1]] = True
    pf = np.zeros(21)
    pf[0] = dp
    p, q = steady(21, pa, pb, c, fixed, pf)
    assert q == pytest.approx(np.full(20, want), rel=1e-10)
    assert p == pytest.approx(dp * (1 - np.arange(21) / 20), abs=1e-6)
    pt = pf.copy()
    flow = np.zeros(20)
    dt = stable_dt(pa, pb, c, vol, KW, fixed)
    steps = int(5 * (length ** 2 / (KW * a ** 2 / (12 * MU))) / dt)      # five diffusion times
    flow_steps(steps, dt, pa, pb, c, vol, KW, fixed, np.zeros(21), pt, flow)
    assert flow[-1] == pytest.approx(want, rel=0.01)


def test_two_parallel_joints_and_a_channel_network_against_a_nodal_analysis():
    """Two joints of apertures 1e-4 and 2e-4 m between the same reservoirs carry (a1³ + a2³) w ΔP / (12 μ L);
    a 3 × 3 network of channels (4 × 4 knots, left column at 1e5 Pa, right at 0, random apertures) against
    Kirchhoff's equations solved densely here."""
    length, w, dp = 5.0, 1.0, 1e5
    pa, pb = np.array([0, 0]), np.array([1, 1])
    c = conductance(np.array([1e-4, 2e-4]), w, length, MU)
    p, q = steady(2, pa, pb, c, np.array([True, True]), np.array([dp, 0.0]))
    assert q.sum() == pytest.approx((1e-12 + 8e-12) * w * dp / (12 * MU * length), rel=1e-12)
    rng = np.random.default_rng(7)
    idx = np.arange(16).reshape(4, 4)           # idx[row, col]
    pa = np.concatenate((idx[:, :-1].ravel(), idx[:-1, :].ravel()))
    pb = np.concatenate((idx[:, 1:].ravel(), idx[1:, :].ravel()))
    a = rng.uniform(5e-5, 3e-4, len(pa))
    c = conductance(a, 1.0, 1.0, MU)
    fixed = np.zeros(16, bool)
    fixed[idx[:, 0]] = True
    fixed[idx[:, -1]] = True
    pf = np.zeros(16)
    pf[idx[:, 0]] = dp
    p, q = steady(16, pa, pb, c, fixed, pf)
    # the twin: nodal analysis, one equation per knot
    m = np.zeros((16, 16))
    rhs = np.zeros(16)
    for k in range(len(pa)):
        i, j, g = pa[k], pb[k], a[k] ** 3 / (12 * MU)
        m[i, i] += g
        m[j, j] += g
        m[i, j] -= g
        m[j, i] -= g
    for i in range(16):
        if fixed[i]:
            m[i] = 0.0
            m[i, i] = 1.0
            rhs[i] = pf[i]
    want = np.linalg.solve(m, rhs)
    assert p == pytest.approx(want, rel=1e-10, abs=1e-6)
    inflow = sum(q[k] for k in range(len(pa)) if fixed[pa[k]] and pf[pa[k]] == dp)
    outflow = sum(q[k] for k in range(len(pa)) if fixed[pb[k]] and pf[pb[k]] == 0.0)
    assert inflow == pytest.approx(outflow, rel=1e-10)


def test_pressure_diffusion_along_a_joint_follows_erfc():
    """A step p0 at one end of a long joint: p = p0 erfc(x / (2 √(D t))), D = K_w a² / (12 μ)."""
    a, w, length, n, p0 = 1e-4, 1.0, 20.0, 400, 1e5
    pa, pb, c, vol = _chain(n, length, a, w)
    fixed = np.zeros(n + 1, bool)
    fixed[[0, -1]] = True
    p = np.zeros(n + 1)
    p[0] = p0
    d = KW * a ** 2 / (12 * MU)
    t = 4.0 / d                                  # √(D t) = 2 m
    dt = stable_dt(pa, pb, c, vol, KW, fixed)
    steps = int(math.ceil(t / dt))
    used = flow_steps(steps, t / steps, pa, pb, c, vol, KW, fixed, np.zeros(n + 1), p, np.zeros(n))
    assert used == pytest.approx(t / steps)
    x = np.arange(n + 1) * length / n
    assert np.abs(p - p0 * erfc(x / (2 * math.sqrt(d * t)))).max() < 0.03 * p0


def _steps_twin(nsteps, dt, pa, pb, c, vol, kw, fixed, q_in, p):
    p = p.copy()
    for _ in range(nsteps):
        q = c * (p[pa] - p[pb])
        net = q_in.copy()
        np.add.at(net, pa, -q)
        np.add.at(net, pb, q)
        p = np.where(fixed, p, p + kw * dt / vol * net)
    return p


def test_flow_steps_against_twin_and_a_step_too_large_is_reduced():
    rng = np.random.default_rng(2)
    nk, npipe = 30, 60
    pa = rng.integers(0, nk, npipe)
    pb = (pa + rng.integers(1, nk, npipe)) % nk
    c = rng.uniform(1e-12, 1e-10, npipe)
    vol = rng.uniform(1e-4, 1e-3, nk)
    fixed = rng.random(nk) < 0.2
    q_in = np.where(fixed, 0.0, rng.uniform(-1e-6, 1e-6, nk))
    p = rng.uniform(0, 1e5, nk)
    dt = stable_dt(pa, pb, c, vol, KW, fixed)
    s = np.zeros(nk)
    np.add.at(s, pa, c)
    np.add.at(s, pb, c)
    assert dt == pytest.approx((0.5 * vol / (KW * s))[~fixed & (s > 0)].min())
    got = p.copy()
    flow_steps(25, 0.9 * dt, pa, pb, c, vol, KW, fixed, q_in, got, np.zeros(npipe))
    assert got == pytest.approx(_steps_twin(25, 0.9 * dt, pa, pb, c, vol, KW, fixed, q_in, p), rel=1e-12, abs=1e-9)
    big = p.copy()
    used = flow_steps(2000, 1e6, pa, pb, c, vol, KW, fixed, q_in, big, np.zeros(npipe))
    assert used == dt and np.all(np.isfinite(big))


def test_aperture_and_bad_input():
    assert hydraulic_aperture([-1e-3, 0.0, 5e-4, 1.0], 1e-4, 2e-5, 3e-4).tolist() == pytest.approx(
        [2e-5, 1e-4, 3e-4, 3e-4])
    with pytest.raises(ValueError, match="viscosity"):
        conductance(1e-4, 1.0, 1.0, 0.0)
    with pytest.raises(ValueError, match="aperture is negative"):
        conductance(-1e-4, 1.0, 1.0, MU)
    with pytest.raises(ValueError, match="aperture-minimum"):
        hydraulic_aperture(0.0, 1e-4, 3e-4, 2e-4)
    with pytest.raises(ValueError, match="no pressure boundary"):
        steady(3, [0, 1], [1, 2], [1.0, 1.0], [False, False, False], [0, 0, 0])
    with pytest.raises(ValueError, match="no pressure boundary"):
        steady(4, [0, 2], [1, 3], [1.0, 1.0], [True, False, False, False], [1.0, 0, 0, 0])
