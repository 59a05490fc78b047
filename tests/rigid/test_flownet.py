"""The flow network built from the contacts (dec3d.physics.flowgeom, dec3d.physics.flownet) and its kernels
(dec3d.kernels.jointflow: zone_update, network_steps, sub_pressures) against slow twins written here from the
formulas; the geometry against the cubic law on triangulated planes; knots of two planes merged."""
import math

import numpy as np
import pytest

from dec3d.kernels.jointflow import network_steps, stable_dt, sub_pressures, zone_update
from dec3d.physics.flowgeom import build_geometry
from dec3d.physics.jointflow import steady

MU = 1e-3


def _rect_contact(x0, x1, y0, y1, z=0.0):
    """One contact in the plane z: four corner sub-contacts, each twice (both blocks' vertices)."""
    c = np.array([[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]], float)
    return np.concatenate([c, c[::-1]])


def _network(contacts, normals, size, tol=1e-9):
    pos = np.concatenate(contacts)
    counts = np.array([len(c) for c in contacts])
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    return build_geometry(starts, counts, np.asarray(normals, float), pos, size, tol), pos


def _twin_zone_update(g, un, a0, amin, amax, mu, npipe, nk):
    """Plain loops over the zones: a_t = clamp(a0 + Σ w un), c_p = Σ a³/(12 μ) cot/2 (≥ 0), V_i = Σ a A / 3."""
    zap = np.zeros(len(g["zk"]))
    c = np.zeros(npipe)
    vol = np.zeros(nk)
    for t in range(len(g["zk"])):
        ct = g["zcontact"][t]
        u = sum(g["zw"][t, j] * un[g["zsub"][t, j]] for j in range(3))
        a = min(max(a0[ct] + u, amin[ct]), amax[ct])
        zap[t] = a
        for j in range(3):
            if g["zpipe"][t, j] >= 0:
                c[g["zpipe"][t, j]] += a ** 3 / (12 * mu) * g["zcot"][t, j]
            vol[g["zk"][t, j]] += a * g["zarea"][t] / 3
    return zap, np.maximum(c, 0.0), vol


def _update(g, un, a0, amin, amax):
    nk, npipe = len(g["pos"]), len(g["pa"])
    zap, c, vol = np.zeros(len(g["zk"])), np.zeros(npipe), np.zeros(nk)
    zone_update(g["zsub"], g["zw"], g["zcontact"], un, a0, amin, amax, g["zk"], g["zarea"], g["zcot"], g["zpipe"],
                MU, zap, c, vol)
    return zap, c, vol


def test_a_refined_joint_carries_the_cubic_law_and_its_volume():
    """A 10 × 2 m joint cut into flow zones of 0.5 m: steady flow between its ends is a³ w ΔP / (12 μ L) to
    round-off (the cotangent weights are exact for a linear pressure), the knots' volumes sum to a·A."""
    g, pos = _network([_rect_contact(0, 10, 0, 2)], [[0, 0, 1]], 0.5)
    nk = len(g["pos"])
    assert nk == 21 * 5
    un = np.zeros(len(pos))
    a = np.array([1e-4])
    zap, c, vol = _update(g, un, a, np.array([0.0]), np.array([1.0]))
    assert vol.sum() == pytest.approx(1e-4 * 20, rel=1e-12)
    x = g["pos"][:, 0]
    fixed = (x < 1e-9) | (x > 10 - 1e-9)
    p, q = steady(nk, g["pa"], g["pb"], c, fixed, np.where(x < 1e-9, 1e5, 0.0))
    assert p == pytest.approx(1e5 * (1 - x / 10), abs=1e-6)
    inflow = sum(q[k] if fixed[g["pa"][k]] and x[g["pa"][k]] < 1e-9 else -q[k] if fixed[g["pb"][k]] and
                 x[g["pb"][k]] < 1e-9 else 0.0 for k in range(len(q)))
    assert inflow == pytest.approx(1e-12 * 2 * 1e5 / (12 * MU * 10), rel=1e-10)


def test_knots_of_two_planes_at_one_place_are_one_knot_and_flow_passes():
    """Two joints meeting at a line (a horizontal one and a vertical one sharing the edge x = 5): the knots
    on the edge are shared, so a pressure held at the far end of each joint drives flow from one to the
    other, in series: q = ΔP / (L1/(T1 w) + L2/(T2 w))."""
    h = _rect_contact(0, 5, 0, 1, 0.0)
    v = np.array([[5, 0, 0], [5, 1, 0], [5, 1, 3], [5, 0, 3]], float)
    g, pos = _network([h, v], [[0, 0, 1], [1, 0, 0]], 0.0)
    assert len(g["pos"]) == 6
    a0 = np.array([1e-4, 2e-4])
    zap, c, vol = _update(g, np.zeros(len(pos)), a0, np.zeros(2), np.ones(2))
    kp = g["pos"]
    left = kp[:, 0] < 1e-9
    top = kp[:, 2] > 3 - 1e-9
    fixed = left | top
    p, q = steady(len(kp), g["pa"], g["pb"], c, fixed, np.where(left, 1e5, 0.0))
    t1, t2 = 1e-12 / (12 * MU), 8e-12 / (12 * MU)
    want = 1e5 / (5 / t1 + 3 / t2)
    net = np.zeros(len(kp))
    np.add.at(net, g["pa"], q)
    np.add.at(net, g["pb"], -q)
    assert net[left].sum() == pytest.approx(want, rel=1e-10)
    assert net[top].sum() == pytest.approx(-want, rel=1e-10)


def test_the_build_is_deterministic_and_sub_contacts_read_their_knot():
    contacts = [_rect_contact(0, 4, 0, 3), _rect_contact(4, 7, 0, 3)]
    g1, pos = _network(contacts, [[0, 0, 1], [0, 0, 1]], 0.7)
    g2, _ = _network(contacts, [[0, 0, 1], [0, 0, 1]], 0.7)
    for k in g1:
        assert np.array_equal(g1[k], g2[k])
    assert np.allclose(g1["pos"][g1["sknot"]], pos)
    # the shared edge x = 4 is split at the same points on both contacts: one set of knots
    on = np.abs(g1["pos"][:, 0] - 4) < 1e-9
    assert on.sum() == math.ceil(3 / 0.7) + 1


def test_zone_update_against_its_twin():
    rng = np.random.default_rng(3)
    contacts = [_rect_contact(0, 3, 0, 2), _rect_contact(0, 3, 0, 2, 1.0) + rng.uniform(0, 0.01, (8, 3)) * [1, 1, 0]]
    g, pos = _network(contacts, [[0, 0, 1], [0, 0, 1]], 0.6)
    un = rng.uniform(-2e-4, 3e-4, len(pos))
    a0, amin, amax = np.array([1e-4, 2e-4]), np.array([3e-5, 5e-5]), np.array([2.5e-4, 4e-4])
    zap, c, vol = _update(g, un, a0, amin, amax)
    tz, tc, tv = _twin_zone_update(g, un, a0, amin, amax, MU, len(g["pa"]), len(g["pos"]))
    assert zap == pytest.approx(tz, rel=1e-13)
    assert c == pytest.approx(tc, rel=1e-12, abs=1e-30)
    assert vol == pytest.approx(tv, rel=1e-13)
    assert (zap >= 3e-5).all() and (zap <= 4e-4).all()


def _twin_steps(nsteps, dt, pa, pb, c, dg, vol, kw, fixed, q_in, p):
    p = p.copy()
    for _ in range(nsteps):
        q = c * (p[pa] - p[pb] + dg)
        net = q_in.copy()
        for k in range(len(q)):
            net[pa[k]] -= q[k]
            net[pb[k]] += q[k]
        p = np.where(fixed | (vol <= 0), p, p + kw * dt / np.where(vol > 0, vol, 1.0) * net)
    return p, q


def test_network_steps_against_its_twin_with_gravity_and_a_step_too_large_is_reduced():
    rng = np.random.default_rng(5)
    nk, npipe = 25, 50
    pa = rng.integers(0, nk, npipe)
    pb = (pa + rng.integers(1, nk, npipe)) % nk
    c = rng.uniform(1e-12, 1e-10, npipe)
    dg = rng.uniform(-1e4, 1e4, npipe)
    vol = rng.uniform(1e-4, 1e-3, nk)
    vol[3] = 0.0                      # a knot without volume keeps its pressure
    fixed = rng.random(nk) < 0.2
    q_in = np.where(fixed, 0.0, rng.uniform(-1e-6, 1e-6, nk))
    p0 = rng.uniform(0, 1e5, nk)
    dt = stable_dt(pa, pb, c, vol, 2e9, fixed)
    got = p0.copy()
    flow = np.zeros(npipe)
    network_steps(30, 0.8 * dt, pa, pb, c, dg, vol, 2e9, fixed, q_in, got, flow)
    want, wq = _twin_steps(30, 0.8 * dt, pa, pb, c, dg, vol, 2e9, fixed, q_in, p0)
    assert got == pytest.approx(want, rel=1e-12, abs=1e-9)
    assert flow == pytest.approx(wq, rel=1e-9)          # (the last step's pipe flows)
    assert got[3] == p0[3]
    big = p0.copy()
    used = network_steps(500, 1e9, pa, pb, c, dg, vol, 2e9, fixed, q_in, big, flow)
    assert used == dt and np.all(np.isfinite(big))


def test_a_column_of_water_at_rest_does_not_flow():
    """A vertical joint 4 m high, hydrostatic p = ρ g (4 − z): the gravity term cancels the pressure
    difference in every pipe."""
    v = np.array([[0, 0, 0], [2, 0, 0], [2, 0, 4], [0, 0, 4]], float)
    g, pos = _network([v], [[0, 1, 0]], 0.5)
    zap, c, vol = _update(g, np.zeros(len(pos)), np.array([1e-4]), np.zeros(1), np.ones(1))
    x = g["pos"]
    dg = -1000.0 * ((x[g["pa"]] - x[g["pb"]]) @ np.array([0, 0, -9.81]))
    p = 1000 * 9.81 * (4 - x[:, 2])
    flow = np.zeros(len(c))
    p1 = p.copy()
    network_steps(10, 1.0, g["pa"], g["pb"], c, dg, vol, 2e9, np.zeros(len(p), bool), np.zeros(len(p)), p1, flow)
    assert np.abs(flow).max() < 1e-12 * np.abs(c * (p[g["pa"]] - p[g["pb"]])).max()
    assert p1 == pytest.approx(p, abs=1e-6)


def test_sub_pressures_against_its_twin():
    """pp from the sub-contact's knot; the force: each zone's A (mean corner pressure) handed out by its
    centroid's weights, shared among the sub-contacts at one place, plus the applied pressure × A′."""
    g, pos = _network([_rect_contact(0, 4, 0, 2), _rect_contact(4, 6, 0, 2)], [[0, 0, 1], [0, 0, 1]], 0.5)
    rng = np.random.default_rng(9)
    ns, nk = len(pos), len(g["pos"])
    sknot = g["sknot"].copy()
    sknot[3] = -1                       # (a sub-contact without a knot keeps its pressure)
    scontact = np.repeat([0, 1], 8)
    p = rng.uniform(0, 1e5, nk)
    app = np.array([100.0, 250.0])
    parea = rng.uniform(0.1, 1.0, ns)
    pp0 = rng.uniform(0, 10, ns)
    count = np.bincount(g["srep"], minlength=ns).astype(float)
    pp, ppf = pp0.copy(), np.zeros(ns)
    sub_pressures(sknot, g["srep"], count, scontact, p, app, parea, g["zk"], g["zsub"], g["zw"], g["zarea"], pp, ppf)
    force = np.zeros(ns)
    for t in range(len(g["zk"])):
        f = g["zarea"][t] * np.mean(p[g["zk"][t]])
        for j in range(3):
            force[g["zsub"][t, j]] += f * g["zw"][t, j]
    for s in range(ns):
        if sknot[s] >= 0:
            same = [r for r in range(ns) if g["srep"][r] == g["srep"][s]]
            assert pp[s] == pytest.approx(p[sknot[s]] + app[scontact[s]], rel=1e-15)
            assert ppf[s] == pytest.approx(force[g["srep"][s]] / len(same) + app[scontact[s]] * parea[s], rel=1e-12)
        else:
            assert pp[s] == pp0[s] and ppf[s] == pytest.approx(pp0[s] * parea[s], rel=1e-15)


def test_the_zone_forces_keep_the_resultant_and_moment_of_a_linear_pressure():
    """A pressure linear over a 4 × 2 contact cut into 0.5 m zones: the sub-contact forces sum to ∫p dA and
    their moment about the origin is ∫x p dA (both exact: the zones' forces are exact, their centroid
    moments exact for a linear p to O(h²)… here checked at 1e-3)."""
    g, pos = _network([_rect_contact(0, 4, 0, 2)], [[0, 0, 1]], 0.5)
    ns = len(pos)
    p = 1e5 - 2e4 * g["pos"][:, 0]
    count = np.bincount(g["srep"], minlength=ns).astype(float)
    pp, ppf = np.zeros(ns), np.zeros(ns)
    sub_pressures(g["sknot"], g["srep"], count, np.zeros(ns, np.int64), p, np.zeros(1), np.zeros(ns), g["zk"],
                  g["zsub"], g["zw"], g["zarea"], pp, ppf)
    assert ppf.sum() == pytest.approx(2 * (1e5 * 4 - 1e4 * 16), rel=1e-12)
    assert (ppf * pos[:, 0]).sum() == pytest.approx(2 * (0.5e5 * 16 - 2e4 * 64 / 3), rel=1e-2)
