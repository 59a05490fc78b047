"""Dynamic mode (`model dynamic`), Rayleigh damping (`block mechanical damping rayleigh`) and the time
functions of `block apply … table|fish` and `block gridpoint apply … table|fish` (dec3d.physics.dynamic).
The damping ratio and Newmark's sliding block are measured in verification/DY1_*, DY2_*; the kernel
of the stiffness term against its twin in tests/rigid/test_rayleigh_kernel.py."""
import math

import numpy as np
import pytest

from dec3d.commands.values import ValueRangeError
from dec3d.errors import BindError, CommandError, Dec3dError, NotSupportedError
from dec3d.physics.dynamic import TimeFunctionError, interpolate, rayleigh_coefficients, stiffness_timestep
from dec3d.session import Session

M, K = 2000.0, 1e7                       # the block of R3: 1 m cube, rho 2000, kn A = 1e7 N/m
SPRING = """model new
block create brick 0 1 0 1 -1 0
block create brick 0 1 0 1 0 1
block property density 2000
block contact jmodel assign elastic
block contact material-table default property stiffness-normal 10e6 stiffness-shear 10e6
block fix range position-z -1 0
"""


def _run(session, text):
    session.run_items(session.load_text(text))
    return session


def _out(session):
    return session.output.getvalue()


# ------------------------------------------------------------------ model dynamic

def test_active_list_and_time_total(session):
    s = _run(session, SPRING + "model dynamic list\n")
    assert "dynamic mode        : off" in _out(s)
    m = s.model.settings.mechanical
    _run(s, "model dynamic active\n")                       # bare: on
    assert m["dynamic"] is True
    _run(s, "model dynamic active off\nmodel dynamic active on\nmodel dynamic time-total 2.5\n"
            "[t0 = dynamic.time.total]\nmodel dynamic list\n")
    assert s.variables["t0"] == 2.5 and m["dyn_time"] == 2.5
    text = _out(s)
    assert "dynamic mode        : on" in text and "dynamic time-total  : 2.5\n" in text
    assert "density scaling     : off (real masses)" in text and "full (Euler equations)" in text


def test_dynamic_time_runs_only_in_dynamic_mode(session):
    s = _run(session, SPRING + "model dynamic active on\nmodel history name 'td' dynamic time-total\n"
                               "history interval 1\nmodel cycle 20\n")
    dt = s.model.rigid_engine.dt
    m = s.model.settings.mechanical
    assert m["dyn_time"] == pytest.approx(20 * dt, rel=1e-12)
    h = s.model.history_set.find("td")
    assert h.values[-1] == pytest.approx(20 * dt, rel=1e-12)
    _run(s, "model dynamic active off\nmodel cycle 10\n")
    assert m["dyn_time"] == pytest.approx(20 * dt, rel=1e-12)      # static steps do not count
    assert s.model.time == pytest.approx(20 * dt + 10 * s.model.rigid_engine.dt, rel=1e-12)


def test_dynamic_mode_real_masses_text_timestep_and_no_static_damping(session):
    """Local damping set, dynamic on: Δt is Eq. 87 with the real smallest mass and the largest contact
    stiffness × face area (3DEC theory, frac 0.1), and an oscillation is not damped."""
    s = _run(session, SPRING + "block mechanical damping local 0.8\nmodel dynamic active on\n"
                               "block initialize velocity-z 0.01 range position-z 0 1\n"
                               "block history name 'v' velocity-z position 0.5 0.5 0.5\nhistory interval 1\n"
                               "model cycle 600\n")
    eng = s.model.rigid_engine
    assert not eng.mass_scaling() and eng.full_inertia() and eng.damping() == (0, 0.0)
    assert eng.dt == pytest.approx(0.1 * 2.0 * math.sqrt(M / K), rel=1e-12)
    v = np.array(s.model.history_set.find("v").values)
    # undamped: the last cycles' peak is the first's (no gravity here: oscillation about the start)
    assert v[-100:].max() == pytest.approx(v[:100].max(), rel=2e-3)
    assert "local damping is set and is not applied in dynamic mode" in \
        _run(s, "model dynamic list\n").output.getvalue()


@pytest.mark.parametrize("line, error, words", [
    ("model dynamic time-total -1", ValueRangeError, "time-total"),
    ("model dynamic active maybe", BindError, "unknown keyword `maybe`"),
    ("model dynamic follower on", NotSupportedError, "model dynamic follower"),
    ("model history dynamic energy", BindError, "energy"),
])
def test_model_dynamic_bad_input(session, line, error, words):
    # a line dec3d does not implement binds (the deck runs up to it) and stops the run there
    with pytest.raises(error) as e:
        session.run_items(session.load_text(SPRING + line + "\n"))
    assert e.value.location.line == 8 and words in e.value.format()


# ------------------------------------------------------------------ Rayleigh damping

def test_rayleigh_coefficients_and_forms(session):
    w = 2 * math.pi * 10.0
    for cmd, want in (("rayleigh 0.05 10", (0.05 * w, 0.05 / w)), ("rayleigh 0.05 10 mass", (0.1 * w, 0.0)),
                      ("rayleigh 0.05 10 stiffness", (0.0, 0.1 / w)), ("rayleigh 0 0", (0.0, 0.0)),
                      ("ray 0.02 10 stiff", (0.0, 0.04 / w))):
        _run(session, SPRING + f"block mechanical damping {cmd}\n")
        assert rayleigh_coefficients(session.model) == pytest.approx(want, rel=1e-14)
        assert session.model.settings.mechanical["damping"] == "rayleigh"
    # the damping ratio the coefficients give at ω: (α/ω + βω)/2, least (= ξ) at the set frequency
    a, b = 0.05 * w, 0.05 / w
    xi = [(a / x + b * x) / 2 for x in (0.5 * w, w, 2 * w)]
    assert xi[1] == pytest.approx(0.05) and min(xi) == xi[1]


def test_stiffness_damping_lowers_the_timestep(session):
    assert stiffness_timestep(1e-3, 0.0) == 1e-3
    lam = 0.25
    assert stiffness_timestep(1e-3, lam * 1e-3) == pytest.approx(1e-3 * (math.sqrt(1 + lam ** 2) - lam))
    # a central-difference oscillator ω = 2/Δt₀ with stiffness damping β is stable at the lowered step
    dt0, beta = 1e-3, 5e-4
    w = 2 / dt0
    dt = stiffness_timestep(dt0, beta)
    c = beta * w * w                  # c/m of the mode
    amp = np.array([[1.0, dt], [-w * w * dt, 1.0 - c * dt - w * w * dt * dt]])   # (u, v) with v at half steps
    assert max(abs(np.linalg.eigvals(amp))) <= 1.0 + 1e-12
    _run(session, SPRING + "model dynamic active on\nblock mechanical damping rayleigh 0.05 11.254 stiffness\n"
                           "model cycle 5\n")
    beta = 2 * 0.05 / (2 * math.pi * 11.254)
    assert session.model.rigid_engine.dt == pytest.approx(stiffness_timestep(0.2 * math.sqrt(M / K), beta),
                                                          rel=1e-12)


@pytest.mark.parametrize("line, error, words", [
    ("block mechanical damping rayleigh 0.05", BindError, "two values"),
    ("block mechanical damping rayleigh 1.5 10", ValueRangeError, "fraction of critical damping"),
    ("block mechanical damping rayleigh 0.05 -2", ValueRangeError, "rayleigh frequency"),
    ("block mechanical damping rayleigh 0.05 0", BindError, "needs a frequency > 0"),
    ("block mechanical damping local 0.5 mass", BindError, "belongs to rayleigh"),
])
def test_damping_bad_input(session, line, error, words):
    with pytest.raises(error) as e:
        session.load_text(SPRING + line + "\n")
    assert e.value.location.line == 8 and words in e.value.format()


def test_rayleigh_deferred_values_checked_when_run(session):
    with pytest.raises(Dec3dError) as e:
        _run(session, SPRING + "[xi = 2.0]\nblock mechanical damping rayleigh [xi] 10\n")
    assert "fraction of critical damping" in str(e.value)


# ------------------------------------------------------------------ time functions

PAIR = SPRING.replace("block fix range position-z -1 0\n", "")


def test_table_force_follows_the_table_linearly(session):
    """force-x 1000 × table(t) on the free top block, t the model time (not dynamic): f = m a."""
    s = _run(session, PAIR + "model gravity 0 0 0\nblock fix range id 1\nblock mechanical damping none\n"
                             "table 1 add (0, 0) (1, 2) (100, 2)\nblock apply force-x 500 table 1 range id 2\n"
                             "block apply force-z 7 range id 2\nmodel cycle 40\n")
    b, eng = s.model.blocks, s.model.rigid_engine
    t_last = s.model.time - eng.dt                   # the last step's force was set at its start
    assert b["fapp"][1, 0] == pytest.approx(500 * 2 * t_last, rel=1e-12)
    assert b["fapp"][1, 2] == 7.0                       # the constant part stays as it was
    # velocity = Σ f Δt / m with f = 1000 t at each step's start
    n = 40
    want = sum(1000.0 * k * eng.dt for k in range(n)) * eng.dt / M
    assert b["velocity"][1, 0] == pytest.approx(want, rel=1e-9)
    _run(s, "block apply-remove force-x range id 2\n")
    assert not s.model.settings.mechanical["timefns"] and b["fapp"][1, 0] == 0.0


def test_table_velocity_and_dynamic_time(session):
    """velocity-x 2 × table(t) on a held block, t the dynamic time at each step's middle: the
    displacement is the integral of the table (trapezoidal = exact for a linear table)."""
    s = _run(session, PAIR + "model gravity 0 0 0\nblock fix range id 1\nmodel dynamic active on\n"
                             "model dynamic time-total 0\ntable 'ramp' add (0, 0) (10, 10)\n"
                             "block apply velocity-x 2 table 'ramp' range id 2\nmodel cycle 30\n")
    b, eng = s.model.blocks, s.model.rigid_engine
    t = s.model.settings.mechanical["dyn_time"]
    assert b["velocity"][1, 0] == pytest.approx(2 * (t - eng.dt / 2), rel=1e-12)
    assert b["disp"][1, 0] == pytest.approx(t * t, rel=1e-9)       # ∫ 2τ dτ
    # a constant velocity replaces the time function; the block then keeps that velocity
    _run(s, "block apply velocity-x 0.5 range id 2\nmodel cycle 5\n")
    assert not s.model.settings.mechanical["timefns"] and b["velocity"][1, 0] == 0.5


def test_fish_time_function(session):
    s = _run(session, PAIR + "model gravity 0 0 0\nblock fix range id 1\nblock mechanical damping none\n"
                             "fish define pulse\n  pulse = 0\n  if mech.time < 0.01 then\n    pulse = 1\n"
                             "  end_if\nend\nblock apply force-z 2e4 fish pulse range id 2\nmodel cycle 50\n")
    eng, b = s.model.rigid_engine, s.model.blocks
    n_on = math.ceil(0.01 / eng.dt - 1e-12)                      # steps that started before 0.01 s
    # the contact (elastic, no tension) only touched: the block leaves it with the impulse of the pulse
    assert n_on >= 2 and b["fapp"][1, 2] == 0.0
    assert b["velocity"][1, 2] == pytest.approx(2e4 * n_on * eng.dt / M, rel=1e-9)
    assert s.model.settings.mechanical["timefns"][0]["fish"] == "pulse"


def test_time_function_errors(session, tmp_path):
    with pytest.raises(CommandError) as e:
        _run(session, PAIR + "block apply force-x 1 table 9 range id 2\n")
    assert e.value.location.line == 7 and "there is no table 9" in str(e.value)
    with pytest.raises(CommandError) as e:
        _run(session, PAIR + "table 3 label 'empty'\nblock apply force-x 1 table 3 range id 2\n")
    assert "table 3 has no points" in str(e.value)
    with pytest.raises(BindError) as e:
        session.load_text(PAIR + "block apply force-x 1 table 1 fish f\n")
    assert "not both" in str(e.value)
    # a table deleted after the command: the cycle stops naming the command's file:line and changes nothing
    s = Session(out_dir=tmp_path)
    items = s.load_text(PAIR + "table 1 add (0, 1) (1, 1)\nblock apply force-x 1 table 1 range id 2\n"
                               "table 1 delete\nmodel cycle 5\n")
    with pytest.raises(TimeFunctionError) as e:
        s.run_items(items)
    assert "<input>:8:1: there is no table 1 any more" in str(e.value)
    assert s.model.step == 0 and not s.model.blocks["velocity"].any()


def test_save_restore_keeps_dynamic_state_and_continues_bit_for_bit(tmp_path):
    deck = (PAIR + "model gravity 0 0 -10\nblock fix range id 1\nmodel dynamic active on\n"
            "model dynamic time-total 1.5\nblock mechanical damping rayleigh 0.05 11.254\n"
            "table 1 add (0, 0) (3, 3)\nblock apply force-x 100 table 1 range id 2\n"
            "block initialize velocity-z 0.01 range id 2\n")
    a = Session(out_dir=tmp_path / "a")
    a.run_items(a.load_text(deck + "model cycle 80\n"))
    b = Session(out_dir=tmp_path / "b")
    b.run_items(b.load_text(deck + "model cycle 30\nmodel save 'half'\n"))
    c = Session(out_dir=tmp_path / "b")
    c.run_items(c.load_text("model restore 'half'\n"))
    mc = c.model.settings.mechanical
    assert mc["dynamic"] is True and mc["damping"] == "rayleigh" and mc["rayleigh"] == [0.05, 11.254, "both"]
    assert mc["dyn_time"] == b.model.settings.mechanical["dyn_time"] and len(mc["timefns"]) == 1
    c.run_items(c.load_text("model cycle 50\n"))
    for f in ("centroid", "velocity", "fapp"):
        assert np.array_equal(a.model.blocks[f], c.model.blocks[f]), f
    assert a.model.settings.mechanical["dyn_time"] == mc["dyn_time"]


def test_interpolate_holds_the_ends():
    xs, ys = [0.0, 1.0, 3.0], [0.0, 2.0, -2.0]
    assert [interpolate(xs, ys, x) for x in (-1, 0, 0.5, 1, 2, 3, 9)] == [0, 0, 1, 2, 0, -2, -2]


def test_gridpoint_time_functions(tmp_path):
    """Zoned cube: its base gridpoints driven by velocity-z 0.1 × table(t) (dynamic time), its top by a
    force-x that follows another table; the held gridpoints move by the integral of the table."""
    s = Session(out_dir=tmp_path)
    for line in ("block create brick 0 1 0 1 0 1", "block zone generate edgelength 0.5",
                 "block zone cmodel assign elastic", "block zone property young 1e9 poisson 0.25 density 2500",
                 "model dynamic active on", "model dynamic time-total 0",
                 "table 1 add (0, 0) (1, 1)", "table 2 add (0, 3) (1, 3)",
                 "block gridpoint apply velocity-z 0.1 table 1 range position-z 0",
                 "block gridpoint apply force-x 10 table 2 range position-z 1",
                 "block gridpoint apply force-y 4 range position-z 1",
                 "model cycle 40"):
        s.command(line)
    v, m = s.model.vertices, s.model
    t = m.settings.mechanical["dyn_time"]
    dt = m.rigid_engine.dt
    base = v["zoned"] & (np.abs(v["pos"][:, 2]) < 1e-9)
    top = v["zoned"] & (np.abs(v["pos"][:, 2] - 1) < 1e-9)
    assert base.sum() >= 4 and top.sum() >= 4
    assert np.allclose(v["velocity"][base, 2], 0.1 * (t - dt / 2), rtol=1e-12)
    assert np.allclose(v["disp"][base, 2], 0.05 * t * t, rtol=1e-9)      # ∫ 0.1 τ dτ
    assert np.allclose(v["fapp"][top, 0], 30.0) and np.allclose(v["fapp"][top, 1], 4.0)
    s.command("block gridpoint apply-remove force-x")
    assert np.allclose(v["fapp"][top, 0], 0.0) and len(m.settings.mechanical["timefns"]) == 1
    with pytest.raises(CommandError) as e:
        s.command("block gridpoint apply velocity-x 1 fish nothing range position-z 0")
    assert "no FISH function `nothing`" in str(e.value)
    with pytest.raises(CommandError) as e:
        s.command("block gridpoint apply force-z 1 table 42 range position-z 1")
    assert "there is no table 42" in str(e.value)
    with pytest.raises(BindError) as e:
        s.command("block gridpoint apply force-z 1 table 1 fish f")
    assert "not both" in str(e.value)


def newmark_slip(accel, g_tan_phi, t_end, dt=2e-6):
    """Newmark's rigid-plastic sliding block, integrated step by step (semi-implicit Euler): the block
    follows the base while the base acceleration a_b(t) does not exceed a_y = g tan φ, else it is
    pulled by friction at a_y until its velocity reaches the base's again. Returns the slip ∫(v_b − v_k)."""
    vb = vk = slip = 0.0
    t = 0.0
    while t < t_end:
        ab = accel(t)
        sliding = vb - vk > 0.0 or ab > g_tan_phi
        ak = g_tan_phi if sliding else ab
        vb += ab * dt
        vk = min(vk + ak * dt, vb) if sliding else vk + ak * dt
        slip += (vb - vk) * dt
        t += dt
    return slip


def test_dy2_against_newmark_integration(tmp_path):
    """verification/DY2: the deck's permanent slip against Newmark's equation integrated here (2 %), and
    the closed form of a rectangular pulse against that integration (0.1 %)."""
    from conftest import ROOT

    ay = 10.0 * math.tan(math.radians(30.0))
    a_pulse, t_pulse = 2.0 * ay, 0.2
    d_num = newmark_slip(lambda t: a_pulse if t < t_pulse else 0.0, ay, 0.45)
    v = a_pulse * t_pulse
    d_closed = v * v / (2.0 * ay) * (1.0 - ay / a_pulse)
    assert d_num == pytest.approx(d_closed, rel=1e-3)
    s = Session(out_dir=tmp_path)
    deck = ROOT / "verification" / "DY2_newmark_sliding_block" / "deck.dat"
    s.run_items(s.load_file(deck))
    assert s.variables["slip"] == pytest.approx(d_num, rel=0.02)
    assert s.variables["slip_closed"] == pytest.approx(d_closed, rel=1e-12)


@pytest.mark.parametrize("form", ["mass", "stiffness"])
def test_rayleigh_on_zones_damps_the_first_axial_mode(tmp_path, form):
    """A zoned column (0.5 × 0.5 × 2 m, rollers on its sides, fixed base) vibrating in its first axial
    mode (initial velocity sin(πz/2L)): the logarithmic decrement gives the damping ratio Rayleigh's term
    gives at the measured frequency ω — stiffness: β ω / 2 (damping stresses β D ε̇ in the zones), mass:
    α / (2ω) (viscous gridpoint damping) — within 2 %."""
    from dec3d.verify import damping_ratio

    s = Session(out_dir=tmp_path)
    for line in ("block create brick 0 0.5 0 0.5 0 2", "block zone generate edgelength 0.5",
                 "block zone cmodel assign elastic", "block zone property young 1e9 poisson 0.25 density 2500",
                 "block gridpoint apply velocity-x 0 range position-x 0",
                 "block gridpoint apply velocity-x 0 range position-x 0.5",
                 "block gridpoint apply velocity-y 0 range position-y 0",
                 "block gridpoint apply velocity-y 0 range position-y 0.5",
                 "block gridpoint apply velocity-z 0 range position-z 0", "model dynamic active on",
                 f"block mechanical damping rayleigh 0.05 86.6 {form}"):
        s.command(line)
    v = s.model.vertices
    z = v["pos"][:, 2]
    v["velocity"][:, 2] = np.where(v["zoned"] & (z > 1e-9), 0.01 * np.sin(math.pi * z / 4.0), 0.0)
    for line in ("block history name 'vt' velocity-z position 0.25 0.25 2", "history interval 1",
                 "model solve time 0.12"):
        s.command(line)
    h = s.model.history_set.find("vt")
    t, vel = np.array(h.times), np.array(h.values)
    sg = np.sign(vel)
    zc = np.flatnonzero(sg[1:] * sg[:-1] < 0)
    w = 2 * math.pi * (len(zc) - 1) / 2 / (t[zc[-1]] - t[zc[0]])
    # 1-D estimate of the first mode of a constrained column: c / 4L, c = √((K + 4G/3)/ρ) (86.6 Hz)
    assert w / (2 * math.pi) == pytest.approx(86.6, rel=0.03)
    alpha, beta = rayleigh_coefficients(s.model)
    want = beta * w / 2 if form == "stiffness" else alpha / (2 * w)
    assert damping_ratio(vel) == pytest.approx(want, rel=0.02)
