"""Joint model `cy` (continuously yielding, issue 27): the kernel against a slow twin written from
the model's equations (kernel docstring: Cundall & Lemos 1990 as 3DEC gives it), closed forms on
one sub-contact, and bad input refused where it is written."""
import math

import numpy as np
import pytest
from joint_binding import assert_refused_at_binding
from scipy.integrate import solve_ivp

from dec3d.kernels.joints import cy
from dec3d.physics.jmodels import JOINT_MODELS

NAME = "cyjm"
LAW = cy.law.py_func
HOOK = cy.stiffness.py_func


def _row(**kw):
    """A property row (1, NPROP) from user values (degrees, Pa, m) through the host's declaration."""
    vals = {k.replace("_", "-"): v for k, v in kw.items()}
    return JOINT_MODELS[NAME].row(vals)[None, :]


# ---- the slow twin: plain Python from the equations, its own state dict ----------------------

def twin_step(P, st, area, dun, dus, un, udil, fs):
    """One step of the continuously yielding joint. P: user properties (degrees); st: the twin's
    own state {up, r, d (previous increment direction), sn}. Returns (fn, fs (3,), un)."""
    an, asf = P["kn-initial"], P["ks-initial"]
    en, es = P["exponent-normal"], P["exponent-shear"]
    phi = math.radians(P["friction"])
    phi0 = math.radians(P.get("friction-initial", P["friction"]))
    R = P["roughness"]
    un = un + dun
    v = -(un - udil)
    # normal: dσ/dv = a σ^e from σ = 0 at v = 0  →  σ^(1-e) = (1 - e) a v
    sn = ((1 - en) * an * v) ** (1 / (1 - en)) if v > 0 else 0.0
    st["sn"] = sn
    if sn <= 0 or area <= 0:
        return 0.0, np.zeros(3), un
    ks = asf * sn ** es
    phim = phi + (phi0 - phi) * math.exp(-st["up"] / R)
    taum = sn * math.tan(phim)
    tau = -np.asarray(fs, float) / area                      # stress acting against the motion
    dus = np.asarray(dus, float)
    m = np.linalg.norm(dus)
    if m > 0:
        d = dus / m
        if np.dot(d, st["d"]) < 0:                           # reversal: restart with F = 1
            st["r"] = np.dot(tau, d) / taum
        F = (1 - np.dot(tau, d) / taum) / max(1 - st["r"], 1e-12)
        F = min(max(F, 0.0), 1.0)
        tau = tau + F * ks * dus
        st["up"] += (1 - F) * m
        st["d"] = d
    n = np.linalg.norm(tau)
    if n > taum:
        tau = tau * taum / n
    return sn * area, -tau * area, un


def _kernel_step(p, h, area, dun, dus, un, udil, fs, state=0):
    out = LAW(p, 0, h, 0, area, dun, dus[0], dus[1], dus[2], un, udil, fs[0], fs[1], fs[2], 0.0, 0.0, 0.0, state)
    return out[0], np.array(out[1:4]), out[4], out[9]


def test_kernel_matches_the_twin_on_random_paths():
    """Many random paths (closing, opening, shearing back and forth, changing direction): force,
    history and normal displacement agree with the twin to 1e-9 (relative)."""
    rng = np.random.default_rng(27)
    for trial in range(60):
        P = {"kn-initial": 10 ** rng.uniform(5, 9), "ks-initial": 10 ** rng.uniform(5, 9),
             "exponent-normal": rng.choice([0.0, rng.uniform(0, 0.8)]),
             "exponent-shear": rng.choice([0.0, rng.uniform(0, 0.8)]),
             "friction-initial": rng.uniform(20, 60), "friction": rng.uniform(5, 20),
             "roughness": 10 ** rng.uniform(-5, -3)}
        p = _row(**{k.replace("-", "_"): v for k, v in P.items()})
        h = np.zeros((1, 8))
        st = {"up": 0.0, "r": 0.0, "d": np.zeros(3), "sn": 0.0}
        area = rng.uniform(0.1, 2.0)
        un = -abs(rng.normal(0, 1e-4))
        fs_k = np.zeros(3)
        fs_t = np.zeros(3)
        un_k = un_t = un
        step = 10 ** rng.uniform(-7, -5)
        direction = rng.normal(size=3)
        for i in range(200):
            if rng.random() < 0.05:
                direction = -direction                         # reversal
            if rng.random() < 0.05:
                direction = rng.normal(size=3)                 # new direction
            dus = direction / np.linalg.norm(direction) * step * rng.uniform(0, 2)
            dun = rng.normal(0, step * 0.3)
            fn_k, fs_k, un_k, _ = _kernel_step(p, h, area, dun, dus, un_k, 0.0, fs_k)
            fn_t, fs_t, un_t = twin_step(P, st, area, dun, dus, un_t, 0.0, fs_t)
            scale = max(fn_t, 1e-30)
            assert fn_k == pytest.approx(fn_t, rel=1e-9, abs=1e-12), (trial, i)
            assert np.allclose(fs_k, fs_t, rtol=1e-9, atol=1e-9 * scale), (trial, i, fs_k, fs_t)
            assert un_k == un_t
            assert h[0, cy.H_UP] == pytest.approx(st["up"], rel=1e-9, abs=1e-18)
            assert h[0, cy.H_SN] == pytest.approx(st["sn"], rel=1e-9, abs=1e-12)


def test_normal_stress_and_tangent_stiffness_follow_the_power_law():
    """σn at closure v is ((1 − e) a v)^(1/(1 − e)) and the hook's kn is a σn^e (both exact)."""
    a, e = 1e6, 0.5
    p = _row(kn_initial=a, ks_initial=2e6, exponent_normal=e, exponent_shear=0.25, friction_initial=30,
             roughness=1e-3)
    h = np.zeros((1, 8))
    for v in (1e-5, 1e-4, 2e-3):
        fn, fs, un, _ = _kernel_step(p, h, 2.0, -v, np.zeros(3), 0.0, 0.0, np.zeros(3))
        sn = (0.5 * a * v) ** 2
        assert fn == pytest.approx(2.0 * sn, rel=1e-12)
        kn, ks = HOOK(p, 0, h, 0)
        assert kn == pytest.approx(a * sn ** e, rel=1e-12) and ks == pytest.approx(2e6 * sn ** 0.25, rel=1e-12)
    # opening: nothing carried, stiffness back to a 0^e = 0
    fn, fs, un, _ = _kernel_step(p, h, 2.0, 1e-3, np.zeros(3), -5e-4, 0.0, np.zeros(3))
    assert fn == 0.0 and not fs.any() and HOOK(p, 0, h, 0) == (0.0, 0.0)


def _shear_ode(sn, ks, phi0, phi, R, u):
    """τ(u) of monotonic shear at constant σn, the law's ODE: dτ/du = ks (1 − τ/τm), duᵖ/du = τ/τm,
    τm(uᵖ) = σn tan(φ + (φ0 − φ) e^(−uᵖ/R)), until τ meets the falling bound τm; after that τ = τm
    with duᵖ = du (the stress is kept at the bound). Returns (τ at the u given, u and τ at the meeting
    = the peak)."""
    def tm(up):
        return sn * np.tan(phi + (phi0 - phi) * np.exp(-up / R))

    def rhs(x, y):
        return [ks * (1 - y[0] / tm(y[1])), y[0] / tm(y[1])]

    def meet(x, y):
        return y[0] - tm(y[1]) * (1 - 1e-12)
    meet.terminal = True
    sol = solve_ivp(rhs, (0, u[-1]), [0.0, 0.0], rtol=1e-11, atol=1e-12, dense_output=True, events=meet,
                    max_step=R / 50)
    um, upm = sol.t[-1], sol.y[1, -1]
    tau = np.where(u < um, sol.sol(np.minimum(u, um))[0], tm(upm + np.maximum(u - um, 0)))
    return tau, um, tm(upm)


def test_monotonic_shear_follows_the_ode_and_ends_at_the_intrinsic_friction():
    """Constant σn, small equal shear steps: τ(u) follows the law's ODE within 0.3 % of the peak
    (peak within 0.2 %), and
    after uᵖ ≫ R the stress is σn tan φ (the intrinsic friction) to 1e-6."""
    sn, ks, R = 1e6, 1e9, 5e-4
    p = _row(kn_initial=1e9, ks_initial=ks, friction_initial=45, friction=30, roughness=R)
    h = np.zeros((1, 8))
    v = sn / 1e9
    fn, fs, un, _ = _kernel_step(p, h, 1.0, -v, np.zeros(3), 0.0, 0.0, np.zeros(3))
    assert fn == pytest.approx(sn)
    du = 1e-6
    taus = []
    for i in range(20000):                                   # 20 mm, 40 R
        fn, fs, un, _ = _kernel_step(p, h, 1.0, 0.0, np.array([du, 0, 0]), un, 0.0, fs)
        taus.append(-fs[0])
    taus = np.array(taus)
    u = du * np.arange(1, 20001)
    ref, upeak, peak = _shear_ode(sn, ks, math.radians(45), math.radians(30), R, u)
    assert taus.max() == pytest.approx(peak, rel=2e-3)
    assert np.abs(taus - ref).max() < 3e-3 * peak
    assert taus[-1] == pytest.approx(sn * math.tan(math.radians(30)), rel=1e-6)
    assert h[0, cy.H_PHIM] == pytest.approx(30.0, rel=1e-6)
    # the peak stays below the initial strength σn tan φ0 (the stress only approaches its bound)
    assert taus.max() < sn * math.tan(math.radians(45))


def test_reversal_unloads_with_the_full_shear_stiffness():
    """After a reversal F = 1: the first reversed step changes τ by ks |Δu| exactly, and then yields."""
    sn, ks = 1e6, 1e9
    p = _row(kn_initial=1e9, ks_initial=ks, friction_initial=40, friction=30, roughness=1e-3)
    h = np.zeros((1, 8))
    fn, fs, un, _ = _kernel_step(p, h, 1.0, -1e-3, np.zeros(3), 0.0, 0.0, np.zeros(3))
    for i in range(2000):
        fn, fs, un, _ = _kernel_step(p, h, 1.0, 0.0, np.array([1e-6, 0, 0]), un, 0.0, fs)
    before = fs[0]
    fn, fs, un, _ = _kernel_step(p, h, 1.0, 0.0, np.array([-1e-6, 0, 0]), un, 0.0, fs)
    assert fs[0] - before == pytest.approx(ks * 1e-6, rel=1e-12)
    assert h[0, cy.H_R] == pytest.approx(before / (sn * math.tan(math.radians(h[0, cy.H_PHIM]))), rel=1e-3) \
        or h[0, cy.H_R] < 0


def test_an_exponent_near_one_stays_finite():
    """e_n = 0.99: σn = (0.01 a_n v)^100 overflows a double at v = 1 mm for a_n = 1e9; the law caps it
    (1e30 Pa) and every output and the hook stay finite."""
    p = _row(kn_initial=1e9, ks_initial=1e9, exponent_normal=0.99, exponent_shear=0.99, friction_initial=30,
             roughness=1e-3)
    h = np.zeros((1, 8))
    out = LAW(p, 0, h, 0, 1.0, -1e-3, 1e-4, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0)
    assert all(math.isfinite(x) for x in out[:9]) and out[0] == 1e30
    assert all(math.isfinite(k) for k in HOOK(p, 0, h, 0))


def test_zero_area_and_zero_friction_are_finite():
    p = _row(kn_initial=1e9, ks_initial=1e9, friction_initial=0, roughness=1e-3)
    h = np.zeros((1, 8))
    out = LAW(p, 0, h, 0, 0.0, -1e-4, 1e-5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0)
    assert all(math.isfinite(x) for x in out[:9]) and out[0] == 0.0
    out = LAW(p, 0, h, 0, 1.0, -1e-4, 1e-5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0)
    assert out[0] == pytest.approx(1e5) and out[1] == 0.0      # no friction: no shear force


BASE = "block create brick 0 1 0 1 0 1\nblock contact jmodel assign cyjm\n"


@pytest.mark.parametrize("line, message, column", [
    ("block contact property kn-initial -1e9", "`kn-initial` must be in [0, 1e+20], got -1e+09", 35),
    ("block contact property exponent-normal 1", "`exponent-normal` must be in [0, 1), got 1", 40),
    ("block contact property exponent-shear -0.1", "`exponent-shear` must be in [0, 1), got -0.1", 39),
    ("block contact property friction-initial 95", "`friction-initial` must be in [0, 90], got 95", 41),
    ("block contact property roughness -1e-3", "`roughness` must be ≥ 0, got -0.001", 34),
])
def test_bad_properties_are_refused_at_binding(session, tmp_path, line, message, column):
    assert_refused_at_binding(session, tmp_path, BASE + line, message, column)


def test_model_answers_to_its_long_name_and_lists_its_history():
    m = JOINT_MODELS["cyjm"]
    assert m.code == 2 and m.hist_names[:3] == ("plastic-shear", "normal-stress", "friction-mobilized")
    from dec3d.physics.jmodels import ALIASES
    assert ALIASES["continuously-yielding"] == ALIASES["cy"] == "cyjm"


def test_strength_reduction_divides_both_friction_tangents():
    """`model factor-of-safety` (the host's reduce): tan φ0 and tan φ divided by F; unset φ stays NaN."""
    m = JOINT_MODELS["cyjm"]
    rows = np.vstack([_row(friction_initial=40, friction=30, roughness=1e-3),
                      _row(friction=30, roughness=1e-3)])
    m.reduce(rows, 1.5, False)
    assert m.value(rows[0], "friction-initial") == pytest.approx(math.degrees(math.atan(math.tan(math.radians(40)) / 1.5)))
    assert m.value(rows[0], "friction") == pytest.approx(
        math.degrees(math.atan(math.tan(math.radians(30)) / 1.5)))
    assert np.isnan(rows[1, cy.P_PHI0]) and m.value(rows[1], "friction-initial") == m.value(rows[1], "friction")


def test_history_in_a_run_reads_back_from_fish_and_survives_save_restore(session, tmp_path):
    """A cube sheared 1 mm under 1 MN on `cy` (the J1 set-up, shorter): every sub-contact's σn history
    is N/A, its plastic shear displacement is positive and below the 1 mm sheared, the mobilised
    friction-initial lies between 30 and 40 degrees; FISH reads them by name, and a saved and restored model
    has the same history."""
    session.command(
        "block create brick -1.5 2.5 -1 2 -1 0\nblock create brick 0 1 0 1 0 1\nblock property density 2000\n"
        "block contact jmodel assign cyjm\n"
        "block contact material-table default property kn-initial 1e6 exponent-normal 0.5 "
        "ks-initial 1e9 friction-initial 40 friction 30 roughness 1e-3\n"
        "block fix range id 1\nblock fix rotation range id 2\nblock mechanical timestep 2.5e-4\n"
        "block apply force-z -1e6 range id 2\nblock apply velocity-x 0 velocity-y 0 range id 2\n"
        "model solve ratio 1e-7\nblock apply velocity-x 0.02 range id 2\nmodel cycle 200\n"
        "fish define hist\n  local cl = block.contact.list\n  local c = cl(1)\n  local sl = block.contact.subcontactlist(c)\n"
        "  global up = block.subcontact.prop(sl(1), 'plastic-shear')\n"
        "  global phim = block.subcontact.prop(sl(1), 'friction-mobilized')\n"
        "  global phi0 = block.subcontact.prop(sl(1), 'friction-initial')\nend\n@hist\n")
    v = session.variables
    assert 0.0 < v["up"] < 1e-3 and 30.0 < v["phim"] < 40.0 and v["phi0"] == pytest.approx(40.0)
    sc = session.model.rigid_engine.subcontacts
    h = sc["hist"][:, :cy.NHIST].copy()
    assert np.allclose(h[:, cy.H_SN], 1e6, rtol=1e-6)
    assert np.allclose(sc["fn"] / sc["area"], 1e6, rtol=1e-6)
    session.command(f"model save '{tmp_path / 'cy.sav'}'\nmodel new\nmodel restore '{tmp_path / 'cy.sav'}'\n")
    from dec3d.physics.rigid import engine
    assert np.array_equal(engine(session.model).subcontacts["hist"][:, :cy.NHIST], h)
