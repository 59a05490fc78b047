"""No-tension interfaces ([analysis] interfaces = "no-tension", dec3d/ssdem/contact.py).

Checks: the contact matrix against a field of discrete springs that cannot pull (a slow
twin written from the definition), and a rigid block on a level and on an inclined base
under an eccentric load against the closed form of a footing on tensionless springs:
contact length a = L for e <= L/6, a = 3 (L/2 - e) beyond, edge stress 2 N / a, and no
equilibrium once the resultant leaves the interface (e > L/2).
"""
import math

import numpy as np
import pytest

from dec3d.ssdem import contact, reduction, safety, solve
from dec3d.ssdem.build import from_polygons
from dec3d.ssdem.readers.errors import SsdemInputError
from dec3d.ssdem.readers.toml_input import read_toml


def spring_field(rel, L, kn, ks, n=20000):
    """Twin: (N, T, M) on b at the midpoint from n springs along the interface, each
    pushing only when its gap g(s) = dn - dw s is closed (g < 0); midpoint rule."""
    dn, ds, dw = rel
    N = T = M = 0.0
    h = L / n
    for i in range(n):
        s = -L / 2 + (i + 0.5) * h
        g = dn - dw * s
        if g < 0:
            p = -kn * g * h                 # push on b along +n
            N += p
            M += -s * p                     # (s t) x (p n) = -s p
            T += -ks * ds * h
    return np.array([N, T, M])


@pytest.mark.parametrize("rel", [
    (-1e-3, 2e-4, 0.0),          # closed, no rotation: whole length
    (-1e-3, -1e-4, 4e-4),        # closed throughout (|dw| L/2 < |dn|)
    (-1e-3, 1e-4, 3e-3),         # partly open on the s < dn/dw side
    (2e-4, 1e-4, -2e-3),         # opening at the midpoint, closed for s < -0.1
    (1e-3, 1e-4, 1e-4),          # open throughout
])
def test_contact_forces_match_a_field_of_springs_that_cannot_pull(rel):
    L, kn, ks = 1.3, 2e7, 8e6
    r = np.array([rel])
    s1, s2 = contact.zone(r, np.array([L]), np.array([True]))
    got = contact.forces(r, np.array([kn]), np.array([ks]), s1, s2)[0]
    want = spring_field(rel, L, kn, ks)
    scale = kn * L * 1e-3
    np.testing.assert_allclose(got, want, atol=1e-6 * scale, rtol=1e-6)


def test_whole_contact_is_the_linear_interface():
    L, kn, ks = 0.7, 3e6, 1e6
    s1, s2 = contact.zone(np.array([[5e-3, 0.0, 1.0]]), np.array([L]), np.array([False]))
    K = contact.local_matrix(np.array([kn]), np.array([ks]), s1, s2)[0]
    np.testing.assert_allclose(K, np.diag([kn * L, ks * L, kn * L ** 3 / 12]), rtol=1e-14)


def box(x0, y0, w, h):
    return np.array([[x0, y0], [x0 + w, y0], [x0 + w, y0 + h], [x0, y0 + h]], float)


def rotate(p, beta):
    c, s = math.cos(beta), math.sin(beta)
    return p @ np.array([[c, s], [-s, c]])


def block_on_base(beta_deg, moment, L=2.0, h=1.0, gamma=20e3, **kw):
    """A free L x h block on a fixed block, both turned by beta; self-weight plus `moment`
    at the block's centroid; cohesion high enough that nothing slides."""
    beta = math.radians(beta_deg)
    polys = [rotate(box(0, -1, L, 1), beta), rotate(box(0, 0, L, h), beta)]
    return from_polygons(polys, [True, False], kn=1e8, ks=4e7, c=1e9, phi=30, gamma=gamma,
                         force=[[0, 0, 0], [0, 0, moment]], n_steps=1, tol=1e-9, max_iter=500,
                         interfaces="no-tension", **kw)


@pytest.mark.parametrize("beta_deg", [0.0, 20.0])
@pytest.mark.parametrize("e_over_L", [0.1, 0.3, 0.45, 0.499])
def test_eccentric_block_contact_length_and_edge_stress(beta_deg, e_over_L):
    L, h, gamma = 2.0, 1.0, 20e3
    W = gamma * L * h
    beta = math.radians(beta_deg)
    N = W * math.cos(beta)
    # moment about the interface midpoint P of the weight at the centroid C = P + (h/2) n
    n = np.array([-math.sin(beta), math.cos(beta)])
    arm = 0.5 * h * n
    m_weight = arm[0] * (-W)
    moment = e_over_L * L * N - m_weight                  # total moment about P = N e
    prob = block_on_base(beta_deg, moment, L, h, gamma)
    st = solve.run(prob)
    assert reduction.verdict(prob, st) == ""
    itf = prob.interfaces
    assert itf.m == 1
    a = float(st.s2[0] - st.s1[0])
    e = e_over_L * L
    a_closed = L if e <= L / 6 else 3 * (L / 2 - e)
    assert a == pytest.approx(a_closed, rel=1e-6)
    # a counter-clockwise moment presses the block's left edge E = P - (L/2) d down (d: the
    # base direction): the contact reaches E and runs a from it
    d = np.array([math.cos(beta), math.sin(beta)])
    t = np.array([-itf.normal[0, 1], itf.normal[0, 0]])
    s_edge = float(-(L / 2) * d @ t)
    ends = sorted([float(st.s1[0]), float(st.s2[0])], key=lambda v: abs(v - s_edge))
    assert ends[0] == pytest.approx(s_edge, abs=1e-9 * L)
    # edge stress: 2 N / a when partly open, N/L (1 + 6 e / L) when closed
    g_edge = st.rel[0, 0] - st.rel[0, 2] * s_edge
    sigma_edge = -1e8 * g_edge
    want = 2 * N / a_closed if e > L / 6 else N / L * (1 + 6 * e / L)
    assert sigma_edge == pytest.approx(want, rel=1e-6)
    # forces on the interface: N and the shear W sin(beta); Eq. 2.6 uses the contact length
    s = safety.evaluate(prob, st)
    assert s.sigma_n[0] * a == pytest.approx(N, rel=1e-6)
    assert abs(s.tau[0]) * a == pytest.approx(W * math.sin(beta), rel=1e-6, abs=1e-6 * W)


@pytest.mark.parametrize("beta_deg", [0.0, 20.0])
def test_a_resultant_off_the_interface_tips_the_block(beta_deg):
    """The moment capacity of a no-tension interface is N L/2: beyond it the block tips;
    a linear interface (tension allowed) holds the same block."""
    L, h, gamma = 2.0, 1.0, 20e3
    W = gamma * L * h
    beta = math.radians(beta_deg)
    N = W * math.cos(beta)
    m_weight = 0.5 * h * (-math.sin(beta)) * (-W)
    moment = 0.51 * L * N - m_weight
    prob = block_on_base(beta_deg, moment, L, h, gamma)
    st = solve.run(prob)
    assert reduction.verdict(prob, st).startswith("unstable") and st.removed[1]
    prob.settings.interfaces = "linear"
    st = solve.run(prob)
    assert reduction.verdict(prob, st) == ""


def test_a_block_pulled_off_its_base_is_removed():
    """All of its contact opens and stays open: nothing holds the block."""
    prob = from_polygons([box(0, -1, 1, 1), box(0, 0, 1, 1)], [True, False], kn=1e7, ks=1e7, c=1e4,
                         phi=30, force=[[0, 0, 0], [0, 5e3, 0]], n_steps=1, interfaces="no-tension")
    st = solve.run(prob)
    assert st.removed[1] and not st.cracked.any()
    assert st.removed_step[1] == 1


SLOPE = """\
units = "kN-m"
[profile]
points = [[0.0, 0.0], [10.0, 0.0], [20.0, 5.0], [30.0, 5.0]]
[[layer]]
c = 10.0
phi = 25.0
gamma = 18.0
kn = 1.0e5
ks = 4.0e4
tensile_strength = 5.0
[mesh]
size = 1.0
bottom = -4.0
[analysis]
interfaces = "no-tension"
"""


def test_no_tension_with_a_tensile_strength_is_an_error_at_its_line():
    with pytest.raises(SsdemInputError) as exc:
        read_toml("slope.toml", text=SLOPE)
    err = exc.value
    assert err.field == "layer[1].tensile_strength" and "carry no tension" in err.message
    assert err.line == SLOPE.splitlines().index("tensile_strength = 5.0") + 1
    p = read_toml("slope.toml", text=SLOPE.replace("tensile_strength = 5.0\n", ""))
    assert p.settings.interfaces == "no-tension"


def test_contact_damping_ends_a_cycle_and_keeps_the_fixed_point():
    """A contact update that overshoots by -1.5 x its error (the plain iteration runs away
    in an alternating cycle) settles on the same fixed point once damped."""
    L = np.array([1.0])
    fixed = 0.2                                     # s1 of the fixed point; s2 = L/2 throughout
    s1 = np.array([-0.5])
    damp = solve._ContactDamping(1)
    for _ in range(200):
        n1 = fixed - 1.5 * (s1 - fixed)
        s1, _ = damp.step(s1, np.array([0.5]), n1, np.array([0.5]), L, 1e-9)
    assert s1[0] == pytest.approx(fixed, abs=1e-9)
    plain = -0.5
    for _ in range(20):
        plain = fixed - 1.5 * (plain - fixed)
    assert abs(plain - fixed) > 100
