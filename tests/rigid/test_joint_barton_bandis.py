"""Joint model `barton-bandis` (issue 27): the kernel against a slow twin written from Barton's
and Bandis' equations (kernel docstring), closed forms on one sub-contact, and bad input refused
where it is written."""
import math

import numpy as np
import pytest
from joint_binding import assert_refused_at_binding

from dec3d.commands.values import ValueRangeError
from dec3d.kernels.joints import barton_bandis as bb
from dec3d.physics.jmodels import JOINT_MODELS

NAME = "barton-bandis"
LAW = bb.law.py_func
HOOK = bb.stiffness.py_func
FAILED = 1          # the shared state bit "failed" (written out: the twin shares nothing with the kernel)


def _row(P):
    return JOINT_MODELS[NAME].row(P)[None, :]


# ---- the slow twin --------------------------------------------------------------------------

def twin_normal(P, v):
    """Bandis: σn = kni v/(1 − v/vm) up to v = 0.99 vm, then the tangent line there; kn = dσn/dv."""
    kni, vm = P["stiffness-normal"], P["closure-maximum"]
    if v <= 0:
        return 0.0, kni
    if v <= 0.99 * vm:
        return kni * v / (1 - v / vm), kni / (1 - v / vm) ** 2
    s99 = kni * 0.99 * vm / 0.01
    k99 = kni / 0.01 ** 2
    return s99 + k99 * (v - 0.99 * vm), k99


def twin_peak_deg(P, sn):
    """Barton: φr + JRC log10(JCS/σn), the log term ≥ 0, at most 70° but never below φr."""
    if sn <= 0:
        return max(70.0, P["friction-residual"])
    a = P["friction-residual"] + P["jrc"] * max(math.log10(P["jcs"] / sn), 0.0)
    return max(min(a, 70.0), P["friction-residual"])


def twin_step(P, failed, area, dun, dus, un, udil, fs):
    un = un + dun
    sn, _ = twin_normal(P, -(un - udil))
    if sn <= 0 or area <= 0:
        return 0.0, np.zeros(3), un, failed
    fs = np.asarray(fs, float) - P["stiffness-shear"] * area * np.asarray(dus, float)
    fn = sn * area
    limit = fn * math.tan(math.radians(P["friction-residual"] if failed else twin_peak_deg(P, sn)))
    m = np.linalg.norm(fs)
    if m > limit:
        if not failed:
            failed = True
            limit = fn * math.tan(math.radians(P["friction-residual"]))
        fs = fs * limit / m
    return fn, fs, un, failed


def _kstep(p, h, area, dun, dus, un, fs, state):
    o = LAW(p, 0, h, 0, area, dun, dus[0], dus[1], dus[2], un, 0.0, fs[0], fs[1], fs[2], 0.0, 0.0, 0.0, state)
    return o[0], np.array(o[1:4]), o[4], o[9]


def _props(rng):
    return {"stiffness-normal": 10 ** rng.uniform(8, 10), "stiffness-shear": 10 ** rng.uniform(8, 10),
            "jrc": rng.uniform(0, 20), "jcs": 10 ** rng.uniform(6, 8), "friction-residual": rng.uniform(10, 40),
            "closure-maximum": 10 ** rng.uniform(-4, -3)}


def test_kernel_matches_the_twin_on_random_paths():
    """Random paths (closing up to past 0.99 vm, opening, shear forth and back and sideways):
    forces, failure and history agree with the twin to 1e-9 (relative)."""
    rng = np.random.default_rng(6)
    for trial in range(60):
        P = _props(rng)
        p = _row(P)
        h = np.zeros((1, 8))
        area = rng.uniform(0.1, 2.0)
        vm = P["closure-maximum"]
        un_k = un_t = -rng.uniform(-0.05, 1.02) * vm       # from open to past 0.99 vm
        fs_k = np.zeros(3)
        fs_t = np.zeros(3)
        st, failed = 0, False
        step = vm * 10 ** rng.uniform(-3, -1.5)
        direction = rng.normal(size=3)
        for i in range(200):
            if rng.random() < 0.05:
                direction = -direction
            if rng.random() < 0.05:
                direction = rng.normal(size=3)
            dus = direction / np.linalg.norm(direction) * step * rng.uniform(0, 3)
            dun = rng.normal(0, step) if rng.random() < 0.9 else rng.normal(0, 0.2 * vm)
            fn_k, fs_k, un_k, st = _kstep(p, h, area, dun, dus, un_k, fs_k, st)
            fn_t, fs_t, un_t, failed = twin_step(P, failed, area, dun, dus, un_t, 0.0, fs_t)
            assert fn_k == pytest.approx(fn_t, rel=1e-9, abs=1e-9), (trial, i)
            assert np.allclose(fs_k, fs_t, rtol=1e-9, atol=1e-9 * max(fn_t, 1.0)), (trial, i)
            assert bool(st & FAILED) == failed and un_k == un_t
            kn, ks = HOOK(p, 0, h, 0)
            assert kn == pytest.approx(twin_normal(P, max(-un_t, 0.0))[1], rel=1e-9) and ks == P["stiffness-shear"]


P0 = {"stiffness-normal": 1e9, "stiffness-shear": 1e9, "jrc": 10.0, "jcs": 1e8, "friction-residual": 30.0,
      "closure-maximum": 1e-3}


def test_closure_follows_the_hyperbola_and_its_tangent_past_the_cap():
    p = _row(P0)
    h = np.zeros((1, 8))
    for frac in (0.1, 0.5, 0.9, 0.99):
        v = frac * 1e-3
        fn, fs, un, st = _kstep(p, h, 1.0, -v, np.zeros(3), 0.0, np.zeros(3), 0)
        assert fn == pytest.approx(1e9 * v / (1 - frac), rel=1e-12)
        assert HOOK(p, 0, h, 0)[0] == pytest.approx(1e9 / (1 - frac) ** 2, rel=1e-12)
    # past 0.99 vm: linear with kn = 1e4 kni, finite, even beyond vm itself
    fn, fs, un, st = _kstep(p, h, 1.0, -1.5e-3, np.zeros(3), 0.0, np.zeros(3), 0)
    assert fn == pytest.approx(1e9 * 0.99e-3 / 0.01 + 1e13 * (1.5e-3 - 0.99e-3), rel=1e-12)
    assert HOOK(p, 0, h, 0) == (pytest.approx(1e13), 1e9)
    fn, fs, un, st = _kstep(p, h, 1.0, 2e-3, np.zeros(3), -1.5e-3, np.zeros(3), 0)     # open
    assert fn == 0.0 and not fs.any() and HOOK(p, 0, h, 0)[0] == 1e9


@pytest.mark.parametrize("sn", [1e5, 1e6, 5e6])
def test_peak_then_residual_under_constant_normal_stress(sn):
    """Shear at constant σn in steps of 1 µm: the largest shear stress is the peak
    σn tan(φr + JRC log10(JCS/σn)) within one step's increment ks Δu, it falls to σn tan φr at
    the step that fails, and stays there."""
    p = _row(P0)
    h = np.zeros((1, 8))
    v = sn / (1e9 + sn / 1e-3)                  # σn = kni v / (1 − v/vm) solved for v
    fn, fs, un, st = _kstep(p, h, 1.0, -v, np.zeros(3), 0.0, np.zeros(3), 0)
    assert fn == pytest.approx(sn, rel=1e-12)
    peak = sn * math.tan(math.radians(min(30 + 10 * math.log10(1e8 / sn), 70)))
    taus, states = [], []
    for i in range(int(peak / 1e3) + 500):
        fn, fs, un, st = _kstep(p, h, 1.0, 0.0, np.array([1e-6, 0, 0]), un, fs, st)
        taus.append(-fs[0])
        states.append(st)
    taus = np.array(taus)
    assert peak - 1e3 <= taus.max() <= peak
    assert taus[-1] == pytest.approx(sn * math.tan(math.radians(30)), rel=1e-12)
    k = int(np.argmax(taus))
    assert states[k] & FAILED == 0 and states[k + 1] & FAILED and taus[k + 1] == taus[-1]
    assert h[0, bb.H_PHI] == 30.0


def test_low_stress_cap_and_stress_above_jcs():
    p = _row(P0)
    h = np.zeros((1, 8))
    # σn = 100 Pa: 30 + 10 log10(1e6) = 90° → capped at 70°
    fn, fs, un, st = _kstep(p, h, 1.0, -1e-7, np.zeros(3), 0.0, np.zeros(3), 0)
    assert h[0, bb.H_PHI] == 70.0
    # σn above JCS (v = 0.999 vm): the roughness term is 0, φp = φr
    p2 = _row({**P0, "jcs": 1e6})
    fn, fs, un, st = _kstep(p2, h, 1.0, -0.9e-3, np.zeros(3), 0.0, np.zeros(3), 0)
    assert fn > 1e6 and h[0, bb.H_PHI] == 30.0


BASE = "block create brick 0 1 0 1 0 1\nblock contact jmodel assign barton-bandis\n"


@pytest.mark.parametrize("line, message, column", [
    ("block contact property jrc -1", "`jrc` must be in [0, 20], got -1", 28),
    ("block contact property jcs -1e6", "`jcs` must be > 0, got -1e+06", 28),
    ("block contact property stiffness-shear -5", "`stiffness-shear` must be in [0, 1e+20], got -5", 40),
    ("block contact property friction-residual 95", "`friction-residual` must be in [0, 90], got 95", 42),
    ("block contact property closure-maximum -1e-3", "`closure-maximum` must be > 0, got -0.001", 40),
])
def test_bad_properties_are_refused_at_binding(session, tmp_path, line, message, column):
    assert_refused_at_binding(session, tmp_path, BASE + line, message, column)


@pytest.mark.parametrize("line", ["block contact property jcs 0", "block contact property closure-maximum 0"])
def test_zero_jcs_and_maximum_closure_are_refused_at_binding(session, tmp_path, line):
    deck = tmp_path / "deck.dat"
    deck.write_text(BASE + line + "\n")
    with pytest.raises(ValueRangeError):
        session.call(deck)


def test_residual_friction_90_is_refused_at_binding(session, tmp_path):
    deck = tmp_path / "deck.dat"
    deck.write_text(BASE + "block contact property friction-residual 90\n")
    with pytest.raises(ValueRangeError):
        session.call(deck)


def test_residual_friction_90_never_slips():
    """The kernel given φr = 90 (refused by the command, but a row may hold it) never slips: σn tan 90°."""
    p = _row({**P0, "friction-residual": 90.0})
    h = np.zeros((1, 8))
    fn, fs, un, st = _kstep(p, h, 1.0, -5e-4, np.array([1e-2, 0, 0]), 0.0, np.zeros(3), 0)
    assert fn == pytest.approx(1e6) and fs[0] == pytest.approx(-1e7) and st & FAILED == 0


def test_missing_required_properties_stop_the_cycle(session):
    session.command("block create brick 0 1 0 1 0 1\nblock create brick 0 1 0 1 1 2\nblock property density 2000\n"
                    "block contact jmodel assign barton-bandis\n"
                    "block contact property stiffness-normal 1e9 stiffness-shear 1e9 jrc 10 friction-residual 30 "
                    "closure-maximum 1e-3\n")
    with pytest.raises(Exception) as e:
        session.command("model cycle 1")
    assert "needs property 'jcs'" in str(e.value)


#: J5's closure part without its hand-set time step: 5 MN put at once on a 1 m cube (2000 kg) over a
#: fixed block; kni = 1 GPa/m, vm = 1 mm. Before the model declared its largest stiffness the automatic
#: step (from kni, 1.4 ms) let the block jump 7 cm in the first step and the run stopped unstable at step 2
SUDDEN = """model new
block create brick -1.5 2.5 -1 2 -1 0
block create brick 0 1 0 1 0 1
block property density 2000
model gravity 0 0 0
block contact jmodel assign barton-bandis
block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 jrc 10 jcs 1e8 friction-residual 30 closure-maximum 1e-3
block fix range id 1
block fix rotation range id 2
block apply force-z -5000000 range id 2
block apply velocity-x 0 velocity-y 0 range id 2
model solve ratio 1e-7
"""


def test_largest_stiffness_is_the_hyperbolas_tangent_at_its_cap():
    """stiffness_bound: kn = kni / (1 − 0.99)² (10⁴ kni; kni without vm), ks as given (twin: the formula)."""
    rows = np.array([[1e9, 4e8, 10, 1e8, 30, 1e-3], [2e9, 5e8, 10, 1e8, 30, 0.0]])
    kn, ks = bb.stiffness_bound(rows, 0)
    assert kn == pytest.approx(1e9 / 0.01 ** 2, rel=1e-12) and ks == 4e8
    assert bb.stiffness_bound(rows, 1) == (2e9, 5e8)


def test_a_load_put_at_once_runs_stable_with_the_automatic_step(session):
    """The time step and the masses follow the largest stiffness the law reaches (stiffness_bound),
    so the sudden load closes the joint to the hyperbola's closure, v = σn vm / (kni vm + σn), without a
    hand-set step."""
    from dec3d.physics.jmodels import contact_stiffness
    from dec3d.physics.rigid import engine

    session.command(SUDDEN)
    e = engine(session.model)
    kn, _ = contact_stiffness(e.contacts, e.subcontacts)
    assert kn.max() == pytest.approx(1e13)
    uz = float(session.model.blocks["disp"][1, 2])
    sn = 5e6
    assert uz == pytest.approx(-sn * 1e-3 / (1e9 * 1e-3 + sn), rel=1e-3)
