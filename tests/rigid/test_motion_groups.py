"""rigid_motion_groups (joined blocks, full inertia, damping modes), group_properties and
inertial_masses: against the slow twin in tests/reference/rigid_ref.py and against physics."""
import math

import numpy as np
import pytest

from dec3d.kernels.bundles import NSERVO, Bodies, Damping, Groups, Servo, new_servo, servo_values
from dec3d.kernels.motion import block_timestep, rigid_motion_groups
from dec3d.physics.bodies import group_properties, inertial_masses
from reference.rigid_ref import cayley_matrix, motion_groups_ref

# The adaptive servo's bounds as motion.py's docstring states the rule (times 1/Δt): α_v starts at
# 0.02/Δt when the servo starts at 0, never falls below 1e-4/Δt, and is capped where D₁ = 1 − α_vΔt/2
# reaches 1/2 (so the cap is 2·(1 − 1/2) = 1/Δt, derived here, not copied).
SERVO_RULE = dict(start=0.02, floor=1e-4, cap=2.0 * (1.0 - 0.5))

# The twin keeps the damping state as one flat array: the servo's fields (``bundles.Servo``, in
# order), then 6 previous unbalanced forces/moments per group; the kernel gets a ``Damping`` bundle
# of views into it (``Model.step``), so both update the same layout.
S_ALPHA, S_WINDOW, S_HIST = (Servo._fields.index(k) for k in ("alpha", "window", "hist"))


def flat_servo(ng):
    return np.concatenate([servo_values(new_servo()), np.zeros(6 * ng)])


SIGNS = np.array([[i, j, k] for k in (-0.5, 0.5) for j in (-0.5, 0.5) for i in (-0.5, 0.5)])


def _rand_rot(rng):
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


class Model:
    """Boxes (8 vertices each) with their masses and inertia, grouped by ``groups`` (lists of rows)."""

    def __init__(self, boxes, groups, rho=1.0):
        nb = len(boxes)
        self.mass = np.empty(nb)
        self.centroid = np.empty((nb, 3))
        self.inertia = np.empty((nb, 3, 3))
        self.iapprox = np.empty(nb)
        vp = []
        for b, (c, dims, R) in enumerate(boxes):
            dims = np.asarray(dims, float)
            m = rho * dims.prod()
            self.mass[b] = m
            self.centroid[b] = c
            d2 = dims ** 2
            self.inertia[b] = R @ np.diag(m / 12 * np.array([d2[1] + d2[2], d2[0] + d2[2], d2[0] + d2[1]])) @ R.T
            self.iapprox[b] = m * d2.sum() / 12 * 2 / 3
            vp.append(np.asarray(c) + (SIGNS * dims) @ R.T)
        self.vpos = np.vstack(vp)
        self.vstart = np.arange(nb, dtype=np.int64) * 8
        self.vcount = np.full(nb, 8, np.int64)
        self.gstart = np.cumsum([0] + [len(g) for g in groups]).astype(np.int64)
        self.gmember = np.concatenate([np.asarray(g, np.int64) for g in groups])
        (self.gmass, self.gcentroid, self.ginertia, self.gprin, self.gaxes,
         self.giscalar) = group_properties(self.gstart, self.gmember, self.mass, self.centroid,
                                           self.inertia, self.iapprox)
        self.gimass = self.gmass.copy()
        z = lambda: np.zeros((nb, 3))
        self.fixity = np.zeros(nb, np.uint8)
        self.force, self.moment, self.fapp, self.mapp = z(), z(), z(), z()
        self.vel, self.spin, self.disp = z(), z(), z()
        self.servo = flat_servo(len(groups))
        self.out = np.zeros(4)

    def copy(self):
        m = Model.__new__(Model)
        for k, v in self.__dict__.items():
            setattr(m, k, v.copy() if isinstance(v, np.ndarray) else v)
        return m

    def step(self, dt, gravity, mode, alpha, full, vmax=1e6, fn=rigid_motion_groups, **kw):
        if fn is rigid_motion_groups:
            s = self.servo
            damping = Damping(int(mode), float(alpha), Servo(*(s[i:i + 1] for i in range(NSERVO))),
                              s[NSERVO:].reshape(-1, 6))
            groups = Groups(self.gstart, self.gmember, self.gmass, self.gimass, self.giscalar, self.gprin,
                            self.gaxes, self.gcentroid)
            bodies = Bodies(self.mass, self.fixity, self.force, self.moment, self.fapp, self.mapp, self.vel,
                            self.spin, self.centroid, self.disp, self.vstart, self.vcount, self.vpos)
            return fn(dt, np.asarray(gravity, float), full, damping, groups, bodies, vmax, self.out)
        return fn(dt, np.asarray(gravity, float), mode, alpha, self.servo, full, self.gstart, self.gmember,
                  self.gmass, self.gimass, self.giscalar, self.gprin, self.gaxes, self.gcentroid,
                  self.mass, self.fixity, self.force, self.moment, self.fapp, self.mapp, self.vel,
                  self.spin, self.centroid, self.disp, self.vstart, self.vcount, self.vpos, vmax, self.out, **kw)


def _random_model(rng):
    """Single boxes and joined pairs / triples (boxes touching face to face, turned together)."""
    boxes, groups, nb = [], [], 0
    for g in range(7):
        R = _rand_rot(rng)
        base = rng.normal(size=3) * 5
        k = [1, 1, 2, 3, 1, 2, 1][g]
        dims = rng.uniform(0.5, 2.0, size=3)
        mem = []
        for j in range(k):
            boxes.append((base + R @ np.array([j * dims[0], 0, 0]), dims * [1, rng.uniform(0.7, 1), 1], R))
            mem.append(nb)
            nb += 1
        groups.append(mem)
    m = Model(boxes, groups, rho=rng.uniform(1000, 3000))
    m.vel[:] = rng.normal(size=m.vel.shape) * 0.1
    m.spin[:] = rng.normal(size=m.spin.shape) * 0.3
    for g in range(len(groups)):  # members of a group move rigidly with the leader
        mem = groups[g]
        for b in mem[1:]:
            m.spin[b] = m.spin[mem[0]]
    m.fixity[:] = rng.choice([0, 0, 0, 1, 4, 8, 40, 63], size=nb).astype(np.uint8)
    return m


@pytest.mark.parametrize("mode", [0, 1, 2, 3, 4])
@pytest.mark.parametrize("full", [False, True])
@pytest.mark.parametrize("seed", range(3))
def test_kernel_matches_twin(mode, full, seed):
    rng = np.random.default_rng(1000 * seed + 10 * mode + full)
    a = _random_model(rng)
    a.servo[S_ALPHA] = (0.0, 1e6, 3.0)[seed]   # the start rule, the cap (1/Δt = 1000), inside
    a.servo[S_WINDOW] = 3           # a short adaptive window so that the servo acts within the test
    if mode == 3 and seed == 2:
        a.gimass *= 1.7       # mass-scaled groups
        a.giscalar *= 1.7
    b = a.copy()
    grav = np.array([0.3, -0.2, -9.81])
    for step in range(12):
        f = rng.normal(size=a.force.shape) * 1e4
        mo = rng.normal(size=a.moment.shape) * 1e4
        for m in (a, b):
            m.force[:] = f
            m.moment[:] = mo
            m.fapp[:] = 100.0
            m.mapp[:, 1] = -50.0
        ra = a.step(1e-3, grav, mode, 0.8, full)
        rb = b.step(1e-3, grav, mode, 0.8, full, fn=motion_groups_ref, rule=SERVO_RULE)
        assert ra == rb == -1
        for k in ("vel", "spin", "centroid", "disp", "vpos", "gaxes", "gcentroid", "servo", "out",
                  "force", "moment"):
            x, y = getattr(a, k), getattr(b, k)
            np.testing.assert_allclose(x, y, rtol=1e-12, atol=1e-12 * (1 + np.abs(y).max()), err_msg=k)


def test_twin_blow_up_index_matches():
    rng = np.random.default_rng(5)
    a = _random_model(rng)
    a.vel[a.gmember[a.gstart[3]]] = 1e9
    b = a.copy()
    assert a.step(1e-3, np.zeros(3), 1, 0.8, False) == b.step(1e-3, np.zeros(3), 1, 0.8, False,
                                                               fn=motion_groups_ref) == 3


# ------------------------------------------------------------------------------------------------
# (3) the one-block-per-row kernel against the same twin, every block a group of one
# ------------------------------------------------------------------------------------------------

# ------------------------------------------------------------------------------------------------
# (1) torque-free asymmetric brick
# ------------------------------------------------------------------------------------------------

def _brick_inertia_from_vertices(v, m):
    """World inertia tensor of a box of mass m from its 8 vertices (edges 0-1, 0-2, 0-4)."""
    e = [v[1] - v[0], v[2] - v[0], v[4] - v[0]]
    lens = [np.linalg.norm(x) for x in e]
    J = np.zeros((3, 3))
    for k in range(3):
        u = e[k] / lens[k]
        o = [lens[j] ** 2 for j in range(3) if j != k]
        J += m / 12 * (o[0] + o[1]) * np.outer(u, u)
    return J


def test_torque_free_brick_full_inertia_conserves_L_energy_and_shape():
    R0 = cayley_matrix([0.1, 0.2, -0.3])
    m = Model([(np.array([1.0, 2.0, 3.0]), (1.0, 2.0, 3.0), R0)], [[0]], rho=1.0)
    m.spin[0] = R0 @ np.array([1.0, 0.5, 0.3]) * 2.0      # not along a principal axis
    dt = 2e-3
    d0 = np.linalg.norm(m.vpos[:, None] - m.vpos[None], axis=2)

    def ang_mom():
        w = m.spin[0]
        a = w * dt / 2
        P = cayley_matrix(a / (1 + math.sqrt(1 + a @ a)))
        J = _brick_inertia_from_vertices(m.vpos, m.mass[0])
        return P.T @ J @ w

    L0 = ang_mom()
    E0 = 0.5 * m.spin[0] @ L0
    wmin = np.inf
    for n in range(10000):
        assert m.step(dt, np.zeros(3), 0, 0.0, True) == -1
        if n % 500 == 0 or n == 9999:
            L = ang_mom()
            assert np.linalg.norm(L - L0) <= 1e-9 * np.linalg.norm(L0)
            assert abs(0.5 * m.spin[0] @ L - E0) <= 1e-3 * E0
        wmin = min(wmin, abs(m.spin[0] @ L0) / np.linalg.norm(L0))
    d = np.linalg.norm(m.vpos[:, None] - m.vpos[None], axis=2)
    np.testing.assert_allclose(d, d0, atol=1e-9)
    # the principal axes turned with the vertices
    np.testing.assert_allclose(m.gaxes[0] @ np.diag(m.gprin[0]) @ m.gaxes[0].T,
                               _brick_inertia_from_vertices(m.vpos, m.mass[0]), atol=1e-9)
    # and the body really precessed: ω is not a constant vector
    assert np.linalg.norm(m.spin[0] - R0 @ np.array([1.0, 0.5, 0.3]) * 2.0) > 0.1
    np.testing.assert_allclose(m.centroid[0], [1, 2, 3], atol=1e-12)


def test_torque_free_brick_scalar_inertia_keeps_omega():
    R0 = cayley_matrix([0.1, 0.2, -0.3])
    m = Model([(np.zeros(3), (1.0, 2.0, 3.0), R0)], [[0]])
    w0 = np.array([0.7, -1.1, 0.4])
    m.spin[0] = w0
    for _ in range(2000):
        m.step(1e-3, np.zeros(3), 0, 0.0, False)
    assert np.array_equal(m.spin[0], w0)


# ------------------------------------------------------------------------------------------------
# (2) joined pairs
# ------------------------------------------------------------------------------------------------

def _pair(full_rot=np.eye(3)):
    return Model([(full_rot @ np.array([0.0, 0, 0]), (1, 1, 1), full_rot),
                  (full_rot @ np.array([1.0, 0, 0]), (1, 1, 1), full_rot)], [[0, 1]], rho=1.0)


def test_group_properties_of_a_pair_is_a_2x1x1_box():
    R = cayley_matrix([0.3, -0.2, 0.5])
    m = _pair(R)
    assert m.gmass[0] == pytest.approx(2.0)
    np.testing.assert_allclose(m.gcentroid[0], R @ [0.5, 0, 0], atol=1e-15)
    ref = R @ np.diag(2 / 12 * np.array([2.0, 5.0, 5.0])) @ R.T
    np.testing.assert_allclose(m.ginertia[0], ref, atol=1e-14)
    np.testing.assert_allclose(m.gprin[0], [4 / 12, 10 / 12, 10 / 12], atol=1e-14)
    np.testing.assert_allclose(m.gaxes[0] @ np.diag(m.gprin[0]) @ m.gaxes[0].T, ref, atol=1e-14)
    assert np.linalg.det(m.gaxes[0]) == pytest.approx(1.0)
    assert m.giscalar[0] == pytest.approx(m.iapprox.sum() + 2 * 0.25)


@pytest.mark.parametrize("full", [False, True])
def test_joined_pair_free_falls_with_g(full):
    m = _pair(cayley_matrix([0.2, 0.1, 0.0]))
    g = np.array([0.0, 0.0, -9.81])
    dt = 1e-3
    c0 = m.centroid.copy()
    for n in range(1, 1001):
        m.step(dt, g, 0, 0.0, full)
    np.testing.assert_allclose(m.vel, [[0, 0, -9.81]] * 2, rtol=1e-12)
    np.testing.assert_allclose(m.spin, 0.0, atol=0)
    # central differences: z = −g dt² n(n+1)/2 after n steps from rest
    np.testing.assert_allclose(m.centroid - c0, [[0, 0, -9.81 * dt * dt * 1000 * 1001 / 2]] * 2, rtol=1e-12)
    assert m.out[0] == pytest.approx(2 * 9.81)


@pytest.mark.parametrize("full", [False, True])
def test_joined_pair_pushed_off_centre_spins_about_composite_centroid(full):
    m = _pair()
    dt = 1e-4
    Fy = 12.0
    m.fapp[1] = [0.0, Fy, 0.0]             # on the right cube: arm 0.5 from the composite centroid
    Iz = m.giscalar[0] if not full else m.gprin[0][2]
    m.step(dt, np.zeros(3), 0, 0.0, full)
    wz = 0.5 * Fy * dt / Iz
    assert m.spin[0, 2] == pytest.approx(wz, rel=1e-9)
    np.testing.assert_allclose(m.spin[0], m.spin[1], atol=0)
    V = Fy * dt / 2.0
    np.testing.assert_allclose(m.vel[0], [0, V - 0.5 * wz, 0], rtol=1e-6, atol=1e-9)   # new arm turned by ωΔt
    np.testing.assert_allclose(m.vel[1], [0, V + 0.5 * wz, 0], rtol=1e-6, atol=1e-9)
    # keep pushing: the composite centroid moves with V, the members keep their distance
    for _ in range(3000):
        m.fapp[1] = [0.0, Fy, 0.0]
        m.step(dt, np.zeros(3), 0, 0.0, full)
    C = m.mass @ m.centroid / m.mass.sum()
    np.testing.assert_allclose(C, m.gcentroid[0], atol=1e-12)
    assert np.linalg.norm(m.centroid[1] - m.centroid[0]) == pytest.approx(1.0, abs=1e-12)
    assert m.gcentroid[0, 1] == pytest.approx(0.5 * Fy / 2.0 * (3001 * dt) ** 2, rel=1e-3)


# ------------------------------------------------------------------------------------------------
# (4) adaptive global damping, (5) combined damping
# ------------------------------------------------------------------------------------------------

def test_adaptive_global_damping_brings_a_spring_mass_to_rest():
    m = Model([(np.zeros(3), (1, 1, 1), np.eye(3))], [[0]], rho=1000.0)
    k = 1e6
    dt = block_timestep(m.mass[0], k, 0.1)
    g = np.array([0.0, 0.0, -9.81])
    zeq = -m.mass[0] * 9.81 / k
    alphas = []
    for n in range(4000):
        m.force[0, 2] = -k * m.centroid[0, 2]
        m.step(dt, g, 3, 0.0, False)
        alphas.append(m.servo[S_ALPHA])
    alphas = np.array(alphas)
    assert np.all(alphas > 0) and np.all(alphas <= 1.0 / dt)
    assert abs(m.centroid[0, 2] - zeq) < 1e-6 * abs(zeq)
    assert abs(m.vel[0, 2]) < 1e-6 * abs(zeq) * math.sqrt(k / m.mass[0])
    w = math.sqrt(k / m.mass[0])
    # the servo settles near α = ω/π (R = πα/(2ω) = 0.5 for one oscillator)
    assert 0.2 * w / math.pi < np.median(alphas[500:1500]) < 5 * w / math.pi
    assert np.isfinite(m.servo).all()


def test_adaptive_damping_recovers_when_a_settled_model_is_loaded_again():
    m = Model([(np.zeros(3), (1, 1, 1), np.eye(3))], [[0]], rho=1000.0)
    k = 1e6
    dt = block_timestep(m.mass[0], k, 0.1)
    for phase, load in ((0, 0.0), (1, 5e3)):
        m.fapp[0, 0] = load
        for n in range(4000):
            m.force[0, 0] = -k * m.centroid[0, 0]
            m.step(dt, np.zeros(3), 3, 0.0, False)
        assert abs(m.centroid[0, 0] - load / k) <= 1e-6 * 5e3 / k
        assert 0 < m.servo[S_ALPHA] <= 1.0 / dt


@pytest.mark.parametrize("v,f,fprev", [(0.2, 50.0, 40.0), (0.2, 50.0, 60.0), (-0.2, 50.0, 60.0),
                                       (-0.2, -50.0, -40.0), (0.0, 50.0, 60.0), (0.2, -30.0, -30.0)])
def test_combined_damping_one_step_against_eq83(v, f, fprev):
    m = Model([(np.zeros(3), (1, 1, 1), np.eye(3))], [[0]], rho=10.0)
    m.vel[0, 0] = v
    m.spin[0, 1] = -v
    m.force[0, 0] = f
    m.moment[0, 1] = f
    m.servo[S_HIST] = 1.0
    m.servo[NSERVO + 0] = fprev
    m.servo[NSERVO + 4] = fprev
    alpha, dt = 0.7, 1e-3
    m.step(dt, np.zeros(3), 2, alpha, False)
    sg = lambda x: float(np.sign(x))
    fd = alpha * abs(f) * (sg(v) - sg(f - fprev)) / 2       # Eq. 83, as a force subtracted from F
    assert m.vel[0, 0] == pytest.approx(v + (f - fd) / m.gimass[0] * dt, rel=1e-14)
    md = alpha * abs(f) * (sg(-v) - sg(f - fprev)) / 2
    assert m.spin[0, 1] == pytest.approx(-v + (f - md) / m.giscalar[0] * dt, rel=1e-14)
    assert m.servo[NSERVO + 0] == f and m.servo[NSERVO + 4] == f


def test_combined_damping_first_step_is_half_local():
    m = Model([(np.zeros(3), (1, 1, 1), np.eye(3))], [[0]], rho=10.0)
    m.vel[0, 0] = 0.3
    m.force[0, 0] = 40.0
    m.step(1e-3, np.zeros(3), 2, 0.8, False)
    assert m.vel[0, 0] == pytest.approx(0.3 + (40 - 0.4 * 40) / 10 * 1e-3, rel=1e-14)


def test_combined_damping_needs_its_servo_tail():
    m = Model([(np.zeros(3), (1, 1, 1), np.eye(3))], [[0]])
    m.servo = np.zeros(NSERVO)
    with pytest.raises(ValueError):
        m.step(1e-3, np.zeros(3), 2, 0.8, False)


def test_combined_damping_damps_oscillation_with_uniform_drift():
    """Eq. 83's purpose: an oscillator riding on a steady velocity is still damped."""
    res = {}
    for mode in (1, 2):
        m = Model([(np.zeros(3), (1, 1, 1), np.eye(3))], [[0]], rho=1000.0)
        k = 1e6
        dt = block_timestep(m.mass[0], k, 0.1)
        v0 = 0.05
        m.vel[0, 0] = v0 + 0.01          # drift + an oscillation around the moving anchor
        for n in range(3000):
            m.force[0, 0] = -k * (m.centroid[0, 0] - v0 * dt * (n + 0.5) + v0 * dt * 0.5)
            m.step(dt, np.zeros(3), mode, 0.8, False)
        res[mode] = abs(m.vel[0, 0] - v0)
    assert res[2] < 1e-2 * 0.01
    assert res[2] < res[1]


# ------------------------------------------------------------------------------------------------
# (6) density scaling
# ------------------------------------------------------------------------------------------------

def test_inertial_masses_meet_eq87():
    mass = np.array([1.0, 50.0, 2000.0, 7.0])
    isc = np.array([0.2, 9.0, 700.0, 1.0])
    kb = np.array([1e8, 1e8, 1e6, 0.0])
    dt, frac = 2e-4, 0.1
    im, iis = inertial_masses(mass, isc, kb, dt, frac)
    assert np.all(im >= mass)
    for i in range(3):
        assert block_timestep(im[i], kb[i], frac) >= dt * (1 - 1e-15)
    assert block_timestep(im[0], kb[0], frac) == pytest.approx(dt, rel=1e-15)   # scaled: exactly dt
    assert im[2] == mass[2] and im[3] == mass[3]                                  # stable already / free
    np.testing.assert_allclose(iis / isc, im / mass, rtol=1e-15)
    assert im[0] == pytest.approx(1e8 * (dt / 0.2) ** 2, rel=1e-15)
