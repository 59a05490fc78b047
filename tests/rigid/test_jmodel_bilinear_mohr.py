"""Joint model `bilinear-mohr` (3DEC's Bilinear Mohr-Coulomb, issue 27): the kernel against a slow
twin written from the page's formulas on random states, single-sub-contact closed forms on both
sides of the threshold, and bad property values refused where they are written.

Page: https://docs.itascacg.com/itasca900/3dec/docproject/source/theory/bilinear/bilinearmc.html"""
import math

import numpy as np
import pytest

from dec3d.commands.values import ValueRangeError
from dec3d.kernels.joints import bilinear_mohr as K
from dec3d.physics.jmodels import JOINT_MODELS

M = JOINT_MODELS["bilinear-mohr"]
FAILED, SLIP, TENSION = 1, 2, 4
BASE = {"stiffness-normal": 1e9, "stiffness-shear": 5e8, "friction": 40, "friction-2": 20, "cohesion": 1e5,
        "cohesion-2": 6e5, "tension": 2e5}


def _row(**kw):
    v = dict(BASE)
    v.update({k.replace("_", "-"): x for k, x in kw.items()})
    return M.row(v)[None, :]


def twin(props, area, dun, dus, un, udil, fs, us, state):
    """Bilinear Mohr-Coulomb from the page, in plain Python: stresses, envelopes by name."""
    g = props.get
    kn, ks = g("stiffness-normal"), g("stiffness-shear")
    t = lambda deg: math.tan(math.radians(deg))
    phi1, phi2 = g("friction"), g("friction-2", 0.0)
    phi1r = g("friction-residual", phi1)
    phi2r = g("f2-residual", phi2)
    c1, c2, c1r, c2r = g("cohesion", 0.0), g("cohesion-2", 0.0), g("cohesion-residual", 0.0), g("c2-residual", 0.0)
    psi1 = g("dilation", 0.0)
    psi2 = g("dilation-2", psi1)

    def cross(given, ca, pa, cb, pb):
        if given is not None:
            return given
        return math.inf if t(pb) == t(pa) else (ca - cb) / (t(pb) - t(pa))

    snc = cross(g("nstress"), c1, phi1, c2, phi2)
    snr = cross(g("nstress-residual"), c1r, phi1r, c2r, phi2r)
    un = un + dun
    us = np.asarray(us, float) + dus
    fs = np.asarray(fs, float) - ks * area * np.asarray(dus, float)
    fn = -kn * area * (un - udil)
    failed = bool(state & FAILED)
    state &= ~(SLIP | TENSION)
    tens = g("tension-residual", 0.0) if failed else g("tension", 0.0)
    if fn < -tens * area:
        return 0.0, np.zeros(3), un, udil, us, state | FAILED | TENSION
    sn = fn / area if area > 0 else 0.0

    def strength(residual):
        if residual:
            c, phi = (c1r, phi1r) if sn < snr else (c2r, phi2r)
        else:
            c, phi = (c1, phi1) if sn < snc else (c2, phi2)
        return max(c * area + fn * t(phi), 0.0)

    lim = strength(failed)
    mag = float(np.linalg.norm(fs))
    if mag > lim:
        if not failed:
            state |= FAILED
            lim = strength(True)
        fs = fs * (lim / mag)
        state |= SLIP
        psi = psi2 if sn >= snr else psi1
        d = float(np.linalg.norm(dus))
        z = g("dilation-zero", 0.0)
        if psi and d > 0 and (z <= 0 or np.linalg.norm(us) <= z):
            dd = (1.0 if np.dot(dus, us) >= 0 else -1.0) * d * t(psi)
            udil += dd
            fn += kn * area * dd
    return fn, fs, un, udil, us, state


def _kernel(row, area, dun, dus, un, udil, fs, us, state, law=K.law.py_func):
    h = np.zeros((1, 8))
    out = law(row, 0, h, 0, area, dun, *dus, un, udil, *fs, *us, state)
    return out[0], np.array(out[1:4]), out[4], out[5], np.array(out[6:9]), out[9]


def _random_case(rng):
    props = dict(BASE)
    props["friction"] = float(rng.uniform(5, 60))
    props["friction-2"] = float(rng.uniform(0, 60))
    props["cohesion"] = float(rng.choice([0.0, rng.uniform(0, 1e6)]))
    props["cohesion-2"] = float(rng.uniform(0, 2e6))
    props["tension"] = float(rng.uniform(0, 5e5))
    if rng.random() < 0.5:
        props["friction-residual"] = float(rng.uniform(0, 40))
        props["f2-residual"] = float(rng.uniform(0, 40))
        props["cohesion-residual"] = float(rng.uniform(0, 3e5))
        props["c2-residual"] = float(rng.uniform(0, 3e5))
        props["tension-residual"] = float(rng.uniform(0, 1e5))
    if rng.random() < 0.3:
        props["nstress"] = float(rng.uniform(0, 3e6))
    if rng.random() < 0.3:
        props["nstress-residual"] = float(rng.uniform(0, 3e6))
    if rng.random() < 0.6:
        props["dilation"] = float(rng.uniform(0, 20))
        if rng.random() < 0.5:
            props["dilation-2"] = float(rng.uniform(0, 20))
        props["dilation-zero"] = float(rng.choice([0.0, rng.uniform(1e-4, 1e-2)]))
    area = float(rng.choice([0.0, rng.uniform(0.01, 2.0)]))
    un = float(rng.uniform(-5e-3, 5e-4))          # mostly closed (σn up to ~5 MPa), sometimes open
    dun = float(rng.normal(0, 2e-5))
    dus = rng.normal(0, 5e-4, 3)
    fs = rng.normal(0, 1e6, 3) * area
    us = rng.normal(0, 3e-3, 3)
    udil = float(rng.uniform(0, 2e-4))
    state = int(rng.choice([0, FAILED, FAILED | SLIP, SLIP]))
    return props, area, dun, dus, un, udil, fs, us, state


def test_kernel_matches_the_twin_on_random_states():
    """4000 random states (elastic, slipping on either envelope, peak and residual, tension,
    dilation on either side of the residual threshold, reversal): same forces to 1e-9 relative,
    same displacements and state bits."""
    rng = np.random.default_rng(27)
    seen = set()
    for _ in range(4000):
        props, area, dun, dus, un, udil, fs, us, state = _random_case(rng)
        want = twin(props, area, dun, dus, un, udil, fs, us, state)
        got = _kernel(M.row(props)[None, :], area, dun, dus, un, udil, fs, us, state)
        scale = 1e-9 * (1.0 + abs(want[0]) + float(np.linalg.norm(want[1])))
        assert abs(got[0] - want[0]) <= scale
        np.testing.assert_allclose(got[1], want[1], rtol=0, atol=scale)
        assert got[2] == pytest.approx(want[2], abs=1e-15)
        assert got[3] == pytest.approx(want[3], rel=1e-12, abs=1e-18)
        np.testing.assert_allclose(got[4], want[4], rtol=0, atol=1e-15)
        assert got[5] == want[5]
        seen.add(want[5])
    assert {0, FAILED | SLIP, FAILED | TENSION} <= seen


def test_compiled_law_matches_the_python_law():
    rng = np.random.default_rng(3)
    for _ in range(200):
        props, area, dun, dus, un, udil, fs, us, state = _random_case(rng)
        row = M.row(props)[None, :]
        a = _kernel(row, area, dun, dus, un, udil, fs, us, state)
        b = _kernel(row, area, dun, dus, un, udil, fs, us, state, law=K.law)
        assert a[0] == pytest.approx(b[0], rel=1e-14, abs=1e-9) and a[5] == b[5]
        np.testing.assert_allclose(a[1], b[1], rtol=1e-14, atol=1e-9)


def _slide(row, sn, area=1.0, steps=400, dus=2e-5):
    """A sub-contact pressed to σn (a fixed closure) and sheared in x in `steps` increments:
    the shear force of every step."""
    un = -sn / row[0, 0]
    fs = np.zeros(3)
    us = np.zeros(3)
    udil, state = 0.0, 0
    out = []
    for _ in range(steps):
        fn, fs, un, udil, us, state = _kernel(row, area, 0.0, np.array([dus, 0, 0]), un, udil, fs, us, state)
        out.append((fn / area, -fs[0] / area, state))
    return out


def _peak_within_a_step(hist, peak, step=1e4):
    """The largest shear stress held is the closed-form peak less at most one step's elastic
    increment (ks Δu = 5e8 · 2e-5 = 1e4 Pa): the step that crosses it fails."""
    held = max(f for _, f, _ in hist)
    assert peak - step < held <= peak * (1 + 1e-12)


def test_peak_and_residual_on_both_sides_of_the_automatic_threshold():
    """φ₁ 40°, c₁ 0.1 MPa; φ₂ 20°, c₂ 0.6 MPa: σᶜ = 0.5 MPa / (tan 40° − tan 20°) = 1.0523 MPa.
    Peak c + σ tan φ of the envelope on its side; after failure the residual (c 0, φ the peak φ of
    the residual side, whose threshold is 0/0-free: residual envelopes through the origin,
    tan φ₁ ≠ tan φ₂ → σᶜʳ = 0: envelope 2 at every compression)."""
    snc = 0.5e6 / (math.tan(math.radians(40)) - math.tan(math.radians(20)))
    assert snc == pytest.approx(1.052345e6, rel=1e-6)
    row = _row()
    for sn, c, phi in ((0.5e6, 1e5, 40), (3e6, 6e5, 20)):
        hist = _slide(row, sn)
        _peak_within_a_step(hist, c + sn * math.tan(math.radians(phi)))
        assert hist[-1][1] == pytest.approx(sn * math.tan(math.radians(20)), rel=1e-12)
        assert hist[-1][0] == pytest.approx(sn, rel=1e-12)


def test_given_thresholds_and_residual_envelopes():
    """nstress 2 MPa overrides the intersection: at 1.5 MPa envelope 1 still holds (c₁ + σ tan 40°);
    residual envelopes 1: (0.05 MPa, 30°), 2: (0.3 MPa, 15°) with nstress-residual 1 MPa."""
    row = _row(nstress=2e6, friction_residual=30, f2_residual=15, cohesion_residual=5e4, c2_residual=3e5,
               nstress_residual=1e6)
    for sn, peak, res in ((1.5e6, 1e5 + 1.5e6 * math.tan(math.radians(40)), 3e5 + 1.5e6 * math.tan(math.radians(15))),
                          (0.5e6, 1e5 + 0.5e6 * math.tan(math.radians(40)), 5e4 + 0.5e6 * math.tan(math.radians(30)))):
        hist = _slide(row, sn, steps=600)
        _peak_within_a_step(hist, peak, 1e4)
        assert hist[-1][1] == pytest.approx(res, rel=1e-12)


def test_tension_cut_off_then_residual_tension():
    row = _row(tension_residual=5e4)
    kn = row[0, 0]
    # pulled to 0.15 MPa < T = 0.2 MPa: holds
    fn, *_ = _kernel(row, 2.0, 1.5e-4, np.zeros(3), 0.0, 0.0, np.zeros(3), np.zeros(3), 0)
    assert fn == pytest.approx(-0.15e6 * 2.0)
    # to 0.25 MPa: fails, carries nothing, failed for good
    out = _kernel(row, 2.0, 2.5e-4, np.zeros(3), 0.0, 0.0, np.zeros(3), np.zeros(3), 0)
    assert out[0] == 0.0 and out[5] == FAILED | TENSION
    # failed: 0.1 MPa of tension is now beyond the residual 0.05 MPa
    out = _kernel(row, 2.0, 1e5 / kn, np.zeros(3), 0.0, 0.0, np.zeros(3), np.zeros(3), FAILED)
    assert out[0] == 0.0
    out = _kernel(row, 2.0, 4e4 / kn, np.zeros(3), 0.0, 0.0, np.zeros(3), np.zeros(3), FAILED)
    assert out[0] == pytest.approx(-4e4 * 2.0)


def test_dilation_switches_at_the_residual_threshold():
    """ψ₁ 10° below σᶜʳ, ψ₂ 2° above (σᶜʳ = 1 MPa given): Δu_dil = |Δuˢ| tan ψ while slipping."""
    row = _row(dilation=10, dilation_2=2, nstress_residual=1e6)
    for sn, psi in ((0.5e6, 10), (2e6, 2)):
        kn = row[0, 0]
        fs = np.array([-1e7, 0, 0])                    # far beyond any limit: slipping at once
        out = _kernel(row, 1.0, 0.0, np.array([1e-4, 0, 0]), -sn / kn, 0.0, fs, np.array([1e-3, 0, 0]), FAILED)
        assert out[3] == pytest.approx(1e-4 * math.tan(math.radians(psi)), rel=1e-12)
    # dilation-2 unset: ψ₁ on both sides
    row = _row(dilation=10, nstress_residual=1e6)
    out = _kernel(row, 1.0, 0.0, np.array([1e-4, 0, 0]), -2e6 / 1e9, 0.0, np.array([-1e7, 0, 0]),
                  np.array([1e-3, 0, 0]), FAILED)
    assert out[3] == pytest.approx(1e-4 * math.tan(math.radians(10)), rel=1e-12)


def test_parallel_envelopes_and_zero_area_are_finite():
    row = _row(friction_2=40)                          # parallel: envelope 1 everywhere
    hist = _slide(row, 3e6)
    _peak_within_a_step(hist, 1e5 + 3e6 * math.tan(math.radians(40)))
    out = _kernel(_row(), 0.0, -1e-3, np.array([1e-3, 0, 0]), 0.0, 0.0, np.zeros(3), np.zeros(3), 0)
    assert all(np.isfinite(x).all() for x in (out[0], out[1], out[3]))


def test_unset_residual_friction_and_thresholds_show_their_fallbacks():
    row = M.row({"friction": 35, "friction-2": 25})
    assert M.value(row, "friction-residual") == pytest.approx(35)
    assert M.value(row, "f2-residual") == pytest.approx(25)
    assert math.isnan(row[K.P_NSTRESS]) and math.isnan(row[K.P_NSTRESS_RES])


BAD_BASE = "block create brick 0 1 0 1 0 1\nblock contact jmodel assign bilinear-mohr\n"


@pytest.mark.parametrize("line, message, column", [
    ("block contact property friction-2 95", "`friction-2` must be in [0, 90], got 95", 35),
    ("block contact property f2-residual 91", "`f2-residual` must be in [0, 90], got 91", 36),
    ("block contact property dilation-2 90", "`dilation-2` must be in [0, 90), got 90", 35),
    ("block contact property stiffness-shear -1e9", "`stiffness-shear` must be in [0, 1e+20], got -1e+09", 40),
    ("block contact property cohesion-2 -5", "`cohesion-2` must be ≥ 0, got -5", 35),
    ("block contact property c2-residual -1", "`c2-residual` must be ≥ 0, got -1", 36),
    ("block contact property nstress -1e6", "`nstress` must be ≥ 0, got -1e+06", 32),
])
def test_bad_values_are_refused_where_written(session, tmp_path, line, message, column):
    deck = tmp_path / "deck.dat"
    deck.write_text(BAD_BASE + line + "\n")
    with pytest.raises(ValueRangeError) as e:
        session.call(deck)
    assert e.value.message == message
    assert (e.value.location.file, e.value.location.line, e.value.location.column) == (str(deck), 3, column)


def test_reduce_hook_divides_every_strength_and_limits_dilation():
    """`model factor-of-safety` (the host's reduce): c, tan φ, T of both envelopes, peak and residual,
    over F; an unset residual friction and ψ₂ keep following; thresholds kept; ψ ≤ the reduced φ."""
    rows = _row(friction_residual=30, cohesion_residual=5e4, dilation=30, nstress=2e6)
    rows = np.vstack([rows, _row(dilation=5)])
    before = rows.copy()
    M.reduce(rows, 2.0, False)
    for col in (K.P_TANF, K.P_TANF2, K.P_COH, K.P_COH2, K.P_COH_RES, K.P_COH2_RES, K.P_TEN, K.P_TEN_RES):
        np.testing.assert_allclose(rows[:, col], before[:, col] / 2.0)
    assert rows[0, K.P_TANF_RES] == pytest.approx(math.tan(math.radians(30)) / 2)
    assert np.isnan(rows[1, K.P_TANF_RES]) and np.isnan(rows[:, K.P_TANF2_RES]).all()
    assert rows[0, K.P_NSTRESS] == 2e6 and np.isnan(rows[1, K.P_NSTRESS])
    # ψ 30° > the reduced φ₁ (tan 40°/2 = 0.42): capped; ψ₂ (unset: ψ₁) capped at the reduced tan 20°
    assert rows[0, K.P_TANDIL] == pytest.approx(math.tan(math.radians(40)) / 2)
    assert rows[0, K.P_TANDIL2] == pytest.approx(math.tan(math.radians(20)) / 2)
    assert rows[1, K.P_TANDIL] == pytest.approx(math.tan(math.radians(5)))
    rows = before.copy()
    M.reduce(rows, 2.0, True)
    assert rows[1, K.P_TANDIL2] == pytest.approx(math.tan(math.radians(20)) / 2)


def test_factor_of_safety_of_a_block_on_the_second_envelope(session):
    """A 4 x 4 x 1 m block on a plane dipping 30° (gravity tilted): σn = ρ g cos 30° · 1 m = 17.3 kPa,
    above σᶜ = 1 kPa/(tan 60° − tan 40°) = 1.12 kPa, so envelope 2 (c₂ 1 kPa, φ₂ 40°) holds:
    FS = (c₂ + σn tan 40°)/(σn tan 30°) = 1.5533 (envelope 1, φ 60° and c 0, would give 3.0). The residual
    envelope 2 is the peak one (c2-residual 1 kPa): the block's corners, less loaded than its middle
    (the tilt's moment), slip first, and a residual without c₂ would bring the factor down to 1.4534."""
    from dec3d.physics.rigid import engine

    g = 10.0
    sn = 2000 * g * math.cos(math.radians(30))
    want = (1e3 + sn * math.tan(math.radians(40))) / (sn * math.tan(math.radians(30)))
    session.run_items(session.load_text(f"""model new
block create brick -1 8 -1 5 -1 0
block create brick 0 4 0 4 0 1
block property density 2000
model gravity {g * math.sin(math.radians(30))} 0 {-g * math.cos(math.radians(30))}
block contact jmodel assign bilinear-mohr
block contact material-table default property stiffness-normal 1e8 stiffness-shear 1e8 friction 60 friction-2 40 cohesion-2 1e3 c2-residual 1e3
block fix range position-z -1 0
model solve ratio 1e-6
model factor-of-safety bracket 1.4 1.7 resolution 0.01 cycles 3000
"""))
    fs = session.results["fos"]
    assert abs(fs - want) / want < 0.01 and session.results["fos.unstable"] > want * 0.998
    assert engine(session.model).contacts["jmodel"].tolist() == [K.CODE]
