"""Joint model `softening-mohr` (3DEC's Softening-Healing Mohr-Coulomb, issue 27): the kernel against a
slow twin written from the page's linear-softening formula on random states, single-sub-contact
closed forms (peak, linear fall over D_c, residual, healing, the dissipated energy of a cycle), and bad
property values refused where they are written.

Page: https://docs.itascacg.com/itasca900/3dec/docproject/source/theory/softhealmc/softhealmc.html"""
import math

import numpy as np
import pytest

from dec3d.commands.values import ValueRangeError
from dec3d.errors import Dec3dError
from dec3d.kernels.joints import softening_mohr as K
from dec3d.physics.jmodels import JOINT_MODELS

M = JOINT_MODELS["softening-mohr"]
FAILED, SLIP, TENSION = 1, 2, 4
BASE = {"stiffness-normal": 1e9, "stiffness-shear": 1e9, "friction": 35, "friction-residual": 25,
        "cohesion": 2e5, "cohesion-residual": 0.0, "tension": 1e5, "dc": 1e-3}


def twin(props, slip, area, dun, dus, un, udil, fs, us, state):
    """Softening-healing Mohr-Coulomb from the page, plain Python. Returns (fn, fs, un, udil, us,
    state, slip): S_F = S_peak − (S_peak − S_res) u/D_c below D_c, S_res beyond; the slip of a
    step is the trial's excess over S_F in displacement, (|Fˢ| − S_F)/(ks A); not slipping: healed."""
    g = props.get
    kn, ks = g("stiffness-normal"), g("stiffness-shear")
    t = lambda deg: math.tan(math.radians(deg))
    heal = g("healing", 1.0) != 0.0
    un = un + dun
    us = np.asarray(us, float) + dus
    fs = np.asarray(fs, float) - ks * area * np.asarray(dus, float)
    fn = -kn * area * (un - udil)
    failed = bool(state & FAILED)
    state &= ~(SLIP | TENSION)
    if fn < -(g("tension-residual", 0.0) if failed else g("tension", 0.0)) * area:
        return 0.0, np.zeros(3), un, udil, us, state | FAILED | TENSION, 0.0 if heal else slip
    peak = g("cohesion", 0.0) * area + fn * t(g("friction"))
    res = g("cohesion-residual", 0.0) * area + fn * t(g("friction-residual", g("friction")))
    sf = res if slip >= g("dc") else peak - (peak - res) * slip / g("dc")
    sf = max(sf, 0.0)
    mag = float(np.linalg.norm(fs))
    if mag <= sf:
        return fn, fs, un, udil, us, state, 0.0 if heal else slip
    if ks * area > 0:
        slip = slip + (mag - sf) / (ks * area)
    fs = fs * (sf / mag)
    state |= SLIP | FAILED
    d = float(np.linalg.norm(dus))
    psi, z = g("dilation", 0.0), g("dilation-zero", 0.0)
    if psi and d > 0 and (z <= 0 or np.linalg.norm(us) <= z):
        dd = (1.0 if np.dot(dus, us) >= 0 else -1.0) * d * t(psi)
        udil += dd
        fn += kn * area * dd
    return fn, fs, un, udil, us, state, slip


def _kernel(row, slip, area, dun, dus, un, udil, fs, us, state, law=K.law.py_func):
    h = np.zeros((1, 8))
    h[0, 0] = slip
    out = law(row, 0, h, 0, area, dun, *dus, un, udil, *fs, *us, state)
    return out[0], np.array(out[1:4]), out[4], out[5], np.array(out[6:9]), out[9], h[0, 0]


def _random_case(rng):
    props = dict(BASE)
    props["friction"] = float(rng.uniform(5, 60))
    props["friction-residual"] = float(rng.uniform(0, props["friction"]))
    props["cohesion"] = float(rng.choice([0.0, rng.uniform(0, 1e6)]))
    props["cohesion-residual"] = float(rng.choice([0.0, rng.uniform(0, 2e5)]))
    props["tension"] = float(rng.uniform(0, 5e5))
    props["tension-residual"] = float(rng.choice([0.0, rng.uniform(0, 1e5)]))
    props["dc"] = float(rng.uniform(1e-4, 5e-3))
    props["healing"] = float(rng.choice([0.0, 1.0]))
    if rng.random() < 0.4:
        props["dilation"] = float(rng.uniform(0, 15))
        props["dilation-zero"] = float(rng.choice([0.0, rng.uniform(1e-4, 1e-2)]))
    area = float(rng.choice([0.0, rng.uniform(0.01, 2.0)]))
    slip = float(rng.choice([0.0, rng.uniform(0, 2 * props["dc"])]))
    un = float(rng.uniform(-5e-3, 5e-4))
    dun = float(rng.normal(0, 2e-5))
    dus = rng.normal(0, 5e-4, 3)
    fs = rng.normal(0, 1e6, 3) * area
    us = rng.normal(0, 3e-3, 3)
    udil = float(rng.uniform(0, 2e-4))
    state = int(rng.choice([0, FAILED, FAILED | SLIP, SLIP]))
    return props, slip, area, dun, dus, un, udil, fs, us, state


def test_kernel_matches_the_twin_on_random_states():
    """4000 random states (elastic and healing, slipping before and beyond D_c, with and without
    healing, tension, dilation, reversal): forces to 1e-9 relative, slip to 1e-15 m, same state."""
    rng = np.random.default_rng(27)
    seen = set()
    for _ in range(4000):
        props, slip, area, dun, dus, un, udil, fs, us, state = _random_case(rng)
        want = twin(props, slip, area, dun, dus, un, udil, fs, us, state)
        got = _kernel(M.row(props)[None, :], slip, area, dun, dus, un, udil, fs, us, state)
        scale = 1e-9 * (1.0 + abs(want[0]) + float(np.linalg.norm(want[1])))
        assert abs(got[0] - want[0]) <= scale
        np.testing.assert_allclose(got[1], want[1], rtol=0, atol=scale)
        assert got[2] == pytest.approx(want[2], abs=1e-15)
        assert got[3] == pytest.approx(want[3], rel=1e-12, abs=1e-18)
        np.testing.assert_allclose(got[4], want[4], rtol=0, atol=1e-15)
        assert got[5] == want[5]
        assert got[6] == pytest.approx(want[6], rel=1e-9, abs=1e-15)
        seen.add((want[5], want[6] > 0))
    assert {(0, False), (FAILED | SLIP, True), (FAILED | TENSION, False)} <= seen


def test_compiled_law_matches_the_python_law():
    rng = np.random.default_rng(4)
    for _ in range(200):
        case = _random_case(rng)
        row = M.row(case[0])[None, :]
        a = _kernel(row, *case[1:])
        b = _kernel(row, *case[1:], law=K.law)
        assert a[0] == pytest.approx(b[0], rel=1e-14, abs=1e-9) and a[5] == b[5]
        assert a[6] == pytest.approx(b[6], rel=1e-14, abs=1e-18)
        np.testing.assert_allclose(a[1], b[1], rtol=1e-14, atol=1e-9)


def _shear_path(row, sn, path, area=1.0):
    """A sub-contact held at σn and moved along x by the increments `path`: (u_x, τ, slip) per step."""
    un = -sn / row[0, 0]
    fs, us = np.zeros(3), np.zeros(3)
    udil, state, slip = 0.0, 0, 0.0
    ux, out = 0.0, []
    for d in path:
        fn, fs, un, udil, us, state, slip = _kernel(row, slip, area, 0.0, np.array([d, 0, 0]), un, udil, fs, us,
                                                    state)
        ux += d
        out.append((ux, -fs[0] / area, slip))
    return np.array(out)


def test_linear_fall_from_peak_to_residual_over_dc():
    """σn 1 MPa: peak c + σ tan 35° = 0.9002 MPa, residual σ tan 25° = 0.4663 MPa; at slip u < D_c the
    stress is the linear interpolation (the page's linear formula), then the residual for good."""
    sn = 1e6
    peak = 2e5 + sn * math.tan(math.radians(35))
    res = sn * math.tan(math.radians(25))
    h = _shear_path(M.row(BASE)[None, :], sn, [1e-6] * 3000)
    assert peak - 1e3 < h[:, 1].max() <= peak          # one step's elastic increment ks Δu = 1e3 Pa
    sliding = (h[:, 2] > 0) & (h[:, 2] < 1e-3)
    assert sliding.sum() > 100
    # the stress of a step is S_F at the slip before it: compare with the slip of the previous row
    prev = np.r_[0.0, h[:-1, 2]]
    want = peak - (peak - res) * prev / 1e-3
    np.testing.assert_allclose(h[sliding, 1], want[sliding], rtol=1e-12)
    assert h[-1, 1] == pytest.approx(res, rel=1e-12) and h[-1, 2] > 1e-3


def test_healing_on_reversal_restores_the_peak():
    """Forward past D_c, then back: the unloading step stops the slip, the strength heals (slip 0) and
    the reverse peak is the full peak again; with healing 0 the reverse limit is the residual."""
    sn = 1e6
    peak = 2e5 + sn * math.tan(math.radians(35))
    res = sn * math.tan(math.radians(25))
    path = [1e-6] * 2500 + [-1e-6] * 5000
    h = _shear_path(M.row(BASE)[None, :], sn, path)
    back = h[2500:]
    assert back[0, 2] == 0.0                             # healed at the first elastic step
    assert -peak <= back[:, 1].min() < -peak + 1e3
    h0 = _shear_path(M.row({**BASE, "healing": 0})[None, :], sn, path)
    assert h0[2500:, 1].min() == pytest.approx(-res, rel=1e-12)
    assert h0[-1, 2] > h0[2499, 2]                      # the slip kept growing


def test_dissipated_energy_of_a_cycle_is_the_models_integral():
    """0 → +3 mm → −3 mm → 0: each leg starts healed and slips P (its slip at the leg's end); the work
    ∮τ du less the elastic energy left at the end equals Σ [∫₀^min(P, D_c) S_F du + S_res (P − D_c)⁺],
    S_F = S_peak − (S_peak − S_res) u/D_c, to within the step discretisation (0.1 %)."""
    sn, dc = 1e6, 1e-3
    peak = 2e5 + sn * math.tan(math.radians(35))
    res = sn * math.tan(math.radians(25))
    d = 1e-6
    path = np.array([d] * 3000 + [-d] * 6000 + [d] * 3000)
    h = _shear_path(M.row(BASE)[None, :], sn, path)
    tau = np.r_[0.0, h[:, 1]]
    work = float(np.sum(0.5 * (tau[:-1] + tau[1:]) * path))
    legs = [h[2999, 2], h[8999, 2], h[-1, 2]]
    assert min(legs) > dc                                 # each leg reaches the residual

    def leg(p):
        q = min(p, dc)
        return peak * q - (peak - res) * q * q / (2 * dc) + res * max(p - dc, 0.0)

    want = sum(leg(p) for p in legs)
    stored = h[-1, 1] ** 2 / (2 * 1e9)                   # τ²/(2 ks) per m² left in the shear spring
    assert work - stored == pytest.approx(want, rel=1e-3)


def test_open_joint_carries_nothing_and_tension_does_not_heal():
    row = M.row(BASE)[None, :]
    out = _kernel(row, 5e-4, 1.0, 2e-4, np.zeros(3), 0.0, 0.0, np.zeros(3), np.zeros(3), 0)
    assert out[0] == 0.0 and out[5] == FAILED | TENSION and out[6] == 0.0
    # closed again: not slipping, so healed, but the tension stays at its residual (0)
    out = _kernel(row, 0.0, 1.0, 1e-5, np.zeros(3), 0.0, 0.0, np.zeros(3), np.zeros(3), FAILED)
    assert out[0] == 0.0 and out[5] & TENSION


def test_zero_area_and_zero_stiffness_are_finite():
    row = M.row({**BASE, "stiffness-shear": 0.0})[None, :]
    out = _kernel(row, 2e-4, 0.0, -1e-3, np.array([1e-3, 0, 0]), 0.0, 0.0, np.zeros(3), np.zeros(3), 0)
    assert all(np.isfinite(np.atleast_1d(x)).all() for x in out[:5]) and np.isfinite(out[6])


BAD_BASE = "block create brick 0 1 0 1 0 1\nblock contact jmodel assign softening-mohr\n"


def _col(line):
    return len("block contact property ") + len(line.split()[3]) + 2


@pytest.mark.parametrize("line, message", [
    ("block contact property friction 95", "`friction` must be in [0, 90], got 95"),
    ("block contact property friction-residual 90.5", "`friction-residual` must be in [0, 90], got 90.5"),
    ("block contact property stiffness-normal -1", "`stiffness-normal` must be in [0, 1e+20], got -1"),
    ("block contact property cohesion -1e5", "`cohesion` must be ≥ 0, got -100000"),
    ("block contact property tension-residual -1", "`tension-residual` must be ≥ 0, got -1"),
    # (says "≥ 0" until the command layer passes lo_open: see test_zero_dc_is_refused_where_written)
    ("block contact property dc -1e-3", "`dc` must be > 0, got -0.001"),
    ("block contact property healing 2", "`healing` must be in [0, 1], got 2"),
])
def test_bad_values_are_refused_where_written(session, tmp_path, line, message):
    deck = tmp_path / "deck.dat"
    deck.write_text(BAD_BASE + line + "\n")
    with pytest.raises(ValueRangeError) as e:
        session.call(deck)
    assert e.value.message == message
    assert (e.value.location.file, e.value.location.line, e.value.location.column) == (str(deck), 3, _col(line))


def test_zero_dc_is_refused_where_written(session, tmp_path):
    deck = tmp_path / "deck.dat"
    deck.write_text(BAD_BASE + "block contact property dc 0\n")
    with pytest.raises(ValueRangeError) as e:
        session.call(deck)
    assert e.value.location.line == 3 and e.value.location.column == _col("block contact property dc 0")


def test_unset_dc_stops_the_cycle_naming_the_property(session, tmp_path):
    deck = tmp_path / "deck.dat"
    deck.write_text("block create brick 0 1 0 1 0 1\nblock create brick 0 1 0 1 1 2\nblock property density 2000\n"
                    "block contact jmodel assign softening-mohr\n"
                    "block contact property stiffness-normal 1e9 stiffness-shear 1e9 friction 30\n"
                    "block fix range position-z 0 0.5\nmodel cycle 2\n")
    with pytest.raises(Dec3dError, match="joint model 'softening-mohr' needs property 'dc'"):
        session.call(deck)


def test_slip_history_in_a_deck_is_the_plastic_displacement_and_reads_from_fish(session, tmp_path):
    """The J3 shear box at 1 MN stopped mid-softening (0.75 mm past the peak displacement): every
    sub-contact's history `slip` is its plastic displacement u − τ/ks, the stress is the linear
    interpolation at that slip (to one step's lag), and FISH reads it by name."""
    deck = tmp_path / "shear.dat"
    deck.write_text("""model new
block create brick -1.5 2.5 -1 2 -1 0
block create brick 0 1 0 1 0 1
block property density 2000
model gravity 0 0 0
block contact jmodel assign softening-mohr
block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 friction 35 friction-residual 25 cohesion 2e5 tension 1e5 dc 1e-3
block fix range id 1
block fix rotation range id 2
block mechanical timestep 2.5e-4
block apply force-z -1e6 range id 2
block apply velocity-x 0 velocity-y 0 range id 2
model solve ratio 1e-7
block apply velocity-x 0.01 range id 2
model cycle 480
fish define slips
  global smin = 1.0
  global smax = 0.0
  loop foreach local sc block.subcontact.list
    local v = block.subcontact.prop(sc, 'slip')
    smin = math.min(smin, v)
    smax = math.max(smax, v)
  endloop
end
[slips]
""")
    session.call(deck)
    from dec3d.physics.rigid import engine

    e = engine(session.model)
    ss = e.subcontacts
    ux = 480 * 2.5e-6
    tau = -ss["fs"][:, 0] / ss["area"]
    slip = ss["hist"][:, 0]
    np.testing.assert_allclose(slip, ux - tau / 1e9, rtol=0, atol=1e-9)
    assert 0.2e-3 < slip.min() and slip.max() < 1e-3
    peak = 2e5 + 1e6 * math.tan(math.radians(35))
    res = 1e6 * math.tan(math.radians(25))
    np.testing.assert_allclose(tau, peak - (peak - res) * slip / 1e-3, rtol=0, atol=2e3)
    smin, smax = session.variables["smin"], session.variables["smax"]
    assert smin == pytest.approx(slip.min()) and smax == pytest.approx(slip.max())


def test_reduce_hook_divides_the_strengths_and_keeps_dc():
    rows = np.vstack([M.row({**BASE, "dilation": 30, "tension-residual": 1e4}), M.row({"friction": 30, "dc": 2e-3})])
    before = rows.copy()
    M.reduce(rows, 2.0, False)
    for col in (K.P_TANF, K.P_COH, K.P_COH_RES, K.P_TEN, K.P_TEN_RES):
        np.testing.assert_allclose(rows[:, col], before[:, col] / 2.0)
    assert rows[0, K.P_TANF_RES] == pytest.approx(math.tan(math.radians(25)) / 2) and np.isnan(rows[1, K.P_TANF_RES])
    np.testing.assert_array_equal(rows[:, K.P_DC], before[:, K.P_DC])
    assert rows[0, K.P_TANDIL] == pytest.approx(math.tan(math.radians(35)) / 2)      # capped at the reduced φ
    M.reduce(before, 2.0, True)
    assert before[1, K.P_TANDIL] == pytest.approx(math.tan(math.radians(30)) / 2)


def test_factor_of_safety_of_a_block_at_rest_is_its_peak(session):
    """The incline of the factor-of-safety tests with softening-mohr, c 2 kPa softening to 0 over
    dc = 1 m: σn = 17.32 kPa, FS = (c + σn tan 40°)/(σn tan 30°) = 1.6533. (A short dc would lower it:
    the corners, less loaded than the middle under the tilt's moment, slip first and soften.)"""
    sn = 2000 * 10.0 * math.cos(math.radians(30))
    want = (2e3 + sn * math.tan(math.radians(40))) / (sn * math.tan(math.radians(30)))
    session.run_items(session.load_text("""model new
block create brick -1 8 -1 5 -1 0
block create brick 0 4 0 4 0 1
block property density 2000
model gravity 5.0 0 -8.660254037844386
block contact jmodel assign softening-mohr
block contact material-table default property stiffness-normal 1e8 stiffness-shear 1e8 friction 40 cohesion 2e3 dc 1
block fix range position-z -1 0
model solve ratio 1e-6
model factor-of-safety bracket 1.5 1.8 resolution 0.01 cycles 3000
"""))
    fs = session.results["fos"]
    assert abs(fs - want) / want < 0.01 and session.results["fos.unstable"] > want * 0.998
