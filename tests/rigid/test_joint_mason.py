"""Joint model ``mason`` (MASON): the kernel against its slow twin (tests/rigid/mason_twin.py) on
random paths, and the joint-level tests MASON's documentation describes (tension, shear,
compression): peak strengths, the fracture energies G_I, G_II, G_c recovered by integrating the
force–displacement curve (3 %), energy dissipated per loading cycle against the model's own
dissipation integral (2 %), bad input refused at binding with its deck location."""
import math

import numpy as np
import pytest
from mason_twin import MasonTwin

from dec3d.errors import Dec3dError
from dec3d.kernels.joints import mason as kernel
from dec3d.physics.jmodels import ALIASES, JOINT_MODELS
from dec3d.session import Session

MODEL = JOINT_MODELS["mason"]
HI = {n: i for i, n in enumerate(MODEL.hist_names)}


class Joint:
    """One sub-contact of area A driven through the compiled kernel law."""

    def __init__(self, props, area=1.0):
        self.p = MODEL.row(props)[None, :]
        self.h = np.zeros((1, 8))
        self.area = area
        self.un = self.udil = 0.0
        self.fs = np.zeros(3)
        self.us = np.zeros(3)
        self.fn = 0.0
        self.state = 0

    def step(self, dun, dus=(0.0, 0.0, 0.0)):
        out = kernel.law(self.p, 0, self.h, 0, self.area, dun, dus[0], dus[1], dus[2], self.un, self.udil,
                         self.fs[0], self.fs[1], self.fs[2], self.us[0], self.us[1], self.us[2], self.state)
        self.fn = out[0]
        self.fs = np.array(out[1:4])
        self.un, self.udil = out[4], out[5]
        self.us = np.array(out[6:9])
        self.state = out[9]
        return self

    def hist(self, name):
        return self.h[0, HI[name]]


BASE = {"stiffness-normal": 1e10, "stiffness-shear": 5e9, "tension": 0.2e6, "cohesion": 0.3e6, "friction": 35.0,
        "g_i": 20.0, "g_ii": 100.0, "compression": 5e6, "g_c": 5000.0, "peak_ratio": 2.0}


# ---------------------------------------------------------------- twin comparison

def _random_props(rng):
    kn = 10 ** rng.uniform(9, 11)
    ft = rng.uniform(0, 0.5e6)
    coh = rng.uniform(0, 0.6e6)
    fc = rng.choice([0.0, rng.uniform(2e6, 20e6)])
    props = {"stiffness-normal": kn, "stiffness-shear": kn * rng.uniform(0.2, 1.0),
             "stiffness-initial": kn * rng.choice([1.0, rng.uniform(1.0, 3.0)]),
             "tension": ft, "cohesion": coh, "friction": rng.uniform(20, 45),
             "friction-residual": rng.uniform(15, 45), "cohesion-residual": coh * rng.choice([0.0, 0.2]),
             "tension-residual": ft * rng.choice([0.0, 0.1]),
             "g_i": rng.uniform(5, 50), "g_ii": rng.uniform(20, 500), "compression": fc,
             "g_c": rng.uniform(1e3, 2e4), "peak_ratio": rng.uniform(1.0, 4.0), "comp-residual": fc * 0.2,
             "cn": rng.choice([0.0, rng.uniform(-1e6, 1e6)]), "cnn": rng.uniform(0.5, 1.5),
             "css": rng.uniform(1.0, 9.0), "dilation": rng.choice([0.0, rng.uniform(0, 20)]),
             "dilation-zero": rng.choice([0.0, rng.uniform(0.5e6, 5e6)]), "delta": rng.uniform(0, 500)}
    return props


def _random_path(rng, props, n):
    """Normal and shear increments at the scale of each surface's elastic limit: opening past the
    tensile peak, closing into the cap, slipping both ways, with reversals."""
    kn, ks = props["stiffness-normal"], props["stiffness-shear"]
    un_scale = max(props["tension"], 1e4) / kn
    cap_scale = max(props["compression"], 1e6) / props["stiffness-initial"]
    us_scale = max(props["cohesion"], 1e4) / ks
    mode = rng.integers(0, 4, size=n // 25 + 1).repeat(25)[:n]
    dun = np.where(mode == 0, rng.normal(0.3, 1.0, n) * un_scale,
                   np.where(mode == 1, -rng.normal(0.3, 1.0, n) * cap_scale * 0.3, rng.normal(0, 0.2, n) * un_scale))
    dus = rng.normal(0, 1.0, (n, 3)) * us_scale * np.where(mode >= 2, 0.5, 0.05)[:, None]
    dus[:, 2] = 0.0
    return dun, dus


@pytest.mark.parametrize("seed", range(12))
def test_kernel_matches_its_twin_on_random_paths(seed):
    rng = np.random.default_rng(seed)
    props = _random_props(rng)
    j = Joint(props, area=rng.uniform(0.01, 2.0))
    t = MasonTwin(props)
    dun, dus = _random_path(rng, props, 400)
    fs, us, un, udil = np.zeros(3), np.zeros(3), 0.0, 0.0
    seen = set()
    for k in range(len(dun)):
        j.step(dun[k], dus[k])
        fn, fs, un, udil, us, flags = t.step(j.area, dun[k], dus[k], un, udil, fs, us)
        seen |= flags
        scale_f = max(abs(fn), 1e-3 * props["stiffness-normal"] * j.area * 1e-6, 1.0)
        assert j.fn == pytest.approx(fn, rel=1e-9, abs=1e-9 * scale_f), k
        assert np.allclose(j.fs, fs, rtol=1e-9, atol=1e-9 * max(np.abs(fs).max(), scale_f)), k
        assert j.un == pytest.approx(un, rel=1e-12, abs=1e-18) and j.udil == pytest.approx(udil, rel=1e-9, abs=1e-18)
        for name, v in t.hist.items():
            assert j.hist(name) == pytest.approx(v, rel=1e-9, abs=1e-15), (k, name)
        kn, ks = kernel.stiffness(j.p, 0, j.h, 0)
        kn_twin = props["stiffness-normal"] * (1 - t.hist["dt"]) if t.hist["open"] else props["stiffness-initial"]
        assert kn == pytest.approx(kn_twin, rel=1e-9, abs=1e-12 * props["stiffness-normal"])
        assert ks == props["stiffness-shear"]
    assert seen & {"slip", "failed"}


def test_random_paths_visit_every_regime():
    """The twin comparison above is only as good as its paths: over its seeds the joints crack in
    tension, slip, and yield on the cap."""
    regimes = set()
    for seed in range(12):
        rng = np.random.default_rng(seed)
        props = _random_props(rng)
        t = MasonTwin(props)
        dun, dus = _random_path(rng, props, 400)
        fs, us, un, udil = np.zeros(3), np.zeros(3), 0.0, 0.0
        for k in range(len(dun)):
            fn, fs, un, udil, us, flags = t.step(1.0, dun[k], dus[k], un, udil, fs, us)
            regimes |= flags
        if t.hist["u_pc"] > 0:
            regimes.add("cap")
    assert regimes >= {"tension", "slip", "cap"}


# ---------------------------------------------------------------- joint-level tests

def _post_peak_area(x, y, base):
    """∫ (y − base) dx from the peak of y on (trapezoid)."""
    i = int(np.argmax(y))
    return float(np.trapezoid(y[i:] - base, x[i:])), i


def test_tension_peak_and_G_I():
    """Direct tension: linear to ft at ft/kn, then the post-peak area of the stress–opening curve
    above the residual is G_I (3 %); the secant unloading goes back to the origin."""
    props = dict(BASE, **{"tension-residual": 0.02e6})
    j = Joint(props, area=0.5)
    ft, kn, gI = props["tension"], props["stiffness-normal"], props["g_i"]
    du = ft / kn / 100
    w, s = [0.0], [0.0]
    while w[-1] < ft / kn + 14 * gI / (ft - 0.02e6):
        j.step(du)
        w.append(j.un)
        s.append(-j.fn / j.area)
    w, s = np.array(w), np.array(s)
    assert s.max() == pytest.approx(ft, rel=1e-3)
    assert w[np.argmax(s)] == pytest.approx(ft / kn, rel=0.02)
    area, _ = _post_peak_area(w, s, 0.02e6)
    assert area == pytest.approx(gI, rel=0.03)
    # unloading along the secant: half the opening, half the stress, and none at closure
    t_end, w_end = s[-1], w[-1]
    j.step(-w_end / 2)
    assert -j.fn / j.area == pytest.approx(t_end / 2, rel=1e-9)
    assert j.hist("dt") == pytest.approx(1 - t_end / (kn * w_end), rel=1e-9)


def test_shear_peak_residual_and_G_II():
    """Direct shear at a held normal stress σ: peak c + σ tan φ, residual c_r + σ tan φ_r; the
    area of (τ − τ_res) over the plastic slip (u − τ/ks) is G_II (friction not softening, 3 %)."""
    props = dict(BASE, **{"cohesion-residual": 0.0})
    sig = 0.5e6
    j = Joint(props, area=1.0)
    j.step(-sig / props["stiffness-normal"])
    assert j.fn == pytest.approx(sig)
    ks, c, gII = props["stiffness-shear"], props["cohesion"], props["g_ii"]
    tanf = math.tan(math.radians(props["friction"]))
    du = c / ks / 50
    u, t = [0.0], [0.0]
    while u[-1] < 20 * gII / c:
        j.step(0.0, (du, 0.0, 0.0))
        u.append(j.us[0])
        t.append(-j.fs[0])
    u, t = np.array(u), np.array(t)
    assert t.max() == pytest.approx(c + sig * tanf, rel=2e-3)
    assert t[-1] == pytest.approx(sig * tanf, rel=1e-3)
    area, _ = _post_peak_area(u - t / ks, t, sig * tanf)
    assert area == pytest.approx(gII, rel=0.03)
    assert j.hist("kappa_s") == pytest.approx(u[-1] - t[-1] / ks, rel=1e-6)


def test_shear_with_friction_softening_dissipates_the_coupled_energy():
    """With φ_r < φ, friction softens with cohesion (L&R): the area above the residual is
    G_II (1 + σ (tan φ − tan φ_r)/(c − c_r)) (3 %)."""
    props = dict(BASE, **{"friction-residual": 30.0})
    sig = 0.4e6
    j = Joint(props)
    j.step(-sig / props["stiffness-normal"])
    ks, c, gII = props["stiffness-shear"], props["cohesion"], props["g_ii"]
    tf, tr = math.tan(math.radians(35)), math.tan(math.radians(30))
    du = c / ks / 50
    u, t = [0.0], [0.0]
    while u[-1] < 20 * gII / c:
        j.step(0.0, (0.0, du, 0.0))
        u.append(j.us[1])
        t.append(-j.fs[1])
    u, t = np.array(u), np.array(t)
    area, _ = _post_peak_area(u - t / ks, t, sig * tr)
    assert area == pytest.approx(gII * (1 + sig * (tf - tr) / c), rel=0.03)


def test_dilatancy_decays_with_slip_and_confinement_and_not_when_open():
    """L&R Eq. 12: Δu_dil = Δκs tan ψ₀ (1 − σ/σ_ψ0) e^(−δ κs). Without a confinement limit the uplift
    after a slip κ is tan ψ₀ (1 − e^(−δκ))/δ (1 %); at σ ≥ σ_ψ0 there is none; an open joint slides
    without dilating."""
    props = dict(BASE, **{"dilation": 10.0, "delta": 2000.0, "cohesion": 0.0, "tension": 0.0})
    j = Joint(props)
    j.step(-0.2e6 / props["stiffness-normal"])
    for _ in range(2000):
        j.step(0.0, (2e-6, 0.0, 0.0))
    k = j.hist("kappa_s")
    assert k > 3e-3
    assert j.udil == pytest.approx(math.tan(math.radians(10)) * (1 - math.exp(-2000 * k)) / 2000, rel=0.01)
    confined = Joint(dict(props, **{"dilation-zero": 0.1e6}))
    confined.step(-0.2e6 / props["stiffness-normal"])
    for _ in range(200):
        confined.step(0.0, (2e-6, 0.0, 0.0))
    assert confined.hist("kappa_s") > 0 and confined.udil == 0.0
    opened = Joint(props)
    opened.step(1e-5)
    for _ in range(200):
        opened.step(0.0, (2e-6, 0.0, 0.0))
    assert opened.udil == 0.0 and opened.fn == 0.0 and not opened.fs.any()


def test_compression_cap_hardening_peak_and_G_c():
    """Pure compression (Cnn = 1, Cn = 0): elastic to σe = 2fc/(n+1), then hardening to fc at the
    closure n σe/kn0, then the post-peak area above fc_r is G_c (3 %); unloading at kn0 leaves the
    plastic closure."""
    props = dict(BASE, **{"comp-residual": 1e6, "stiffness-initial": 2e10})
    j = Joint(props, area=0.25)
    fc, n, kn0, gc = props["compression"], props["peak_ratio"], props["stiffness-initial"], props["g_c"]
    se = 2 * fc / (n + 1)
    dp = n * se / kn0
    dd = dp / 200
    d, s = [0.0], [0.0]
    while d[-1] < dp + 12 * gc / (fc - 1e6):
        j.step(-dd)
        d.append(-j.un)
        s.append(j.fn / j.area)
    d, s = np.array(d), np.array(s)
    elastic = d < se / kn0 * 0.999
    assert np.allclose(s[elastic], kn0 * d[elastic], rtol=1e-9)
    assert s.max() == pytest.approx(fc, rel=1e-4)
    assert d[np.argmax(s)] == pytest.approx(dp, rel=0.01)
    area, _ = _post_peak_area(d, s, 1e6)
    assert area == pytest.approx(gc, rel=0.03)
    upc = j.hist("u_pc")
    assert upc == pytest.approx(d[-1] - s[-1] / kn0, rel=1e-9)
    j.step(s[-1] / kn0 / 2)                       # unload half way at kn0
    assert j.fn / j.area == pytest.approx(s[-1] / 2, rel=1e-6)
    assert j.hist("dc") == pytest.approx(1 - s[-1] / fc, rel=1e-6)


def test_cap_with_shear_lowers_the_compressive_limit():
    """On the ellipse Cnn σ² + Css τ² + Cn σ = σ̄c² at a shear stress held below the Coulomb limit."""
    props = dict(BASE, **{"css": 9.0, "cn": 0.5e6, "cnn": 1.2, "cohesion": 2e6, "peak_ratio": 1.0})
    j = Joint(props)
    tau = 1.0e6
    j.step(0.0, (-tau / props["stiffness-shear"], 0, 0))
    assert j.fs[0] == pytest.approx(tau)
    fc = props["compression"]
    smax = 0.0
    for _ in range(400):
        j.step(-fc / props["stiffness-normal"] / 100)
        smax = max(smax, j.fn)
    # n = 1: σ̄c = fc at the elastic limit and softening after: the highest σ is the ellipse's at σ̄c = fc
    expect = (-0.5e6 + math.sqrt(0.5e6 ** 2 + 4 * 1.2 * (fc ** 2 - 9.0 * tau ** 2))) / (2 * 1.2)
    assert smax == pytest.approx(expect, rel=2e-3)


def _loop_work(x, f):
    return float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(x)))


def test_cyclic_shear_dissipation_per_cycle_matches_the_model_integral():
    """Three full shear cycles at a held normal stress: per cycle ∮ τ du equals the plastic work
    Σ τ Δκs the model accumulates (2 %), cycle after cycle as the strength softens."""
    props = dict(BASE, **{"g_ii": 50.0})
    sig = 0.3e6
    j = Joint(props)
    j.step(-sig / props["stiffness-normal"])
    ks, c = props["stiffness-shear"], props["cohesion"]
    amp = 40 * c / ks
    nseg = 400
    path = np.concatenate([np.linspace(0, amp, nseg), np.linspace(amp, -amp, 2 * nseg)[1:],
                           np.linspace(-amp, 0, nseg)[1:]])
    for cycle in range(3):
        u, t, plastic = [j.us[0]], [-j.fs[0]], 0.0
        for k in range(1, len(path)):
            kap = j.hist("kappa_s")
            j.step(0.0, (path[k] - path[k - 1], 0.0, 0.0))
            plastic += abs(j.fs[0]) * (j.hist("kappa_s") - kap)
            u.append(j.us[0])
            t.append(-j.fs[0])
        work = _loop_work(np.array(u), np.array(t))
        assert plastic > 0 and work == pytest.approx(plastic, rel=0.02), cycle


def test_cyclic_tension_compression_dissipation_matches_the_model_integral():
    """Open past the tensile peak, close into the cap past its peak, reopen: each cycle's work
    minus the change of stored energy equals the model's dissipation Σ ½ kn e² Δdt + σ Δu_pc (2 %),
    for cycles of growing amplitude (a cycle within the last one's bounds dissipates nothing)."""
    props = dict(BASE, **{"compression": 2e6, "g_c": 200.0, "comp-residual": 0.3e6, "g_i": 5.0})
    j = Joint(props)
    kn, kn0 = props["stiffness-normal"], props["stiffness-normal"]
    a_t = 6 * props["tension"] / kn
    a_c = 6 * props["compression"] / kn0
    nseg = 600
    path = np.concatenate([np.linspace(0, a_t, nseg), np.linspace(a_t, -a_c, 2 * nseg)[1:],
                           np.linspace(-a_c, 0, nseg)[1:]])

    def stored():
        e = j.un - j.udil + j.hist("u_pc")
        return 0.5 * kn * (1 - j.hist("dt")) * e * e if e > 0 else 0.5 * kn0 * e * e

    for cycle in range(3):
        grow = 1.0 + 0.5 * cycle                  # each cycle goes further: new damage every time
        un, fn, diss = [j.un], [j.fn], 0.0
        w0 = stored()
        for k in range(1, len(path)):
            dt0, upc0 = j.hist("dt"), j.hist("u_pc")
            j.step(grow * (path[k] - path[k - 1]))
            e = j.un - j.udil + j.hist("u_pc")
            diss += 0.5 * kn * e * e * (j.hist("dt") - dt0) + j.fn * (j.hist("u_pc") - upc0)
            un.append(j.un)
            fn.append(j.fn)
        # the normal force on B is −kn A (uⁿ …): work done on the joint is −∫ fn duⁿ
        work = -_loop_work(np.array(un), np.array(fn))
        assert diss > 0 and work - (stored() - w0) == pytest.approx(diss, rel=0.02), cycle


def test_no_area_no_force_and_history_kept():
    j = Joint(BASE, area=0.0)
    j.step(1e-3, (1e-3, 0, 0))
    assert j.fn == 0 and not j.fs.any() and not j.h.any()


# ---------------------------------------------------------------- commands

DECK = """block create brick 0 1 0 1 0 1
block create brick 0 1 0 1 1 2
block contact jmodel assign {model}
block contact property stiffness-normal 1e10 stiffness-shear 1e10 G_I 10 G_II 50 G_c 1e4 {extra}
"""




@pytest.mark.parametrize("extra,msg", [
    ("G_I 0", "`g_i` must be > 0"),
    ("G_II -5", "`g_ii` must be [>≥] 0"),
    ("G_c 0", "`g_c` must be > 0"),
    ("stiffness-shear -1e9", r"`stiffness-shear` must be in \[0, 1e\+20\]"),
    ("stiffness-initial -1", r"`stiffness-initial` must be in \[0, 1e\+20\]"),
    ("friction 90", r"`friction` must be in \[0, 90\)"),
    ("friction-residual 95", r"`friction-residual` must be in \[0, 90[\])]"),
    ("peak_ratio 0.5", "`peak_ratio` must be ≥ 1"),
    ("Cnn 0", "`cnn` must be > 0"),
])
def test_bad_input_refused_at_binding_with_its_location(tmp_path, extra, msg):
    deck = tmp_path / "bad.dat"
    deck.write_text(DECK.format(model="mason", extra=extra))
    s = Session(out_dir=tmp_path)
    with pytest.raises(Dec3dError, match=msg) as exc:
        s.call(deck)
    loc = exc.value.location
    assert loc is not None and loc.file.endswith("bad.dat") and loc.line == 4
    line = DECK.splitlines()[3].format(extra=extra)
    # the keyword or its value
    assert loc.column in (line.index(extra) + 1, line.index(extra) + len(extra.split()[0]) + 2)


def test_safego_names(tmp_path):
    """mason_v6/v7/v8 (the SAFEGO decks' names, same keywords) are this model; mason_debug2 (four
    undocumented keywords more) is refused with its reason."""
    assert {ALIASES[n] for n in ("mason_v6", "mason_v7", "mason_v8")} == {"mason"}
    deck = tmp_path / "v8.dat"
    deck.write_text(DECK.format(model="mason_v8", extra="tension 1e5 cohesion 1e5 friction 30 compression 5e6 "
                                "comp-residual 1e6 Cn 0 Cnn 1 Css 9 peak_ratio 2 friction-residual 30 "
                                "cohesion-residual 0 stiffness-initial 1e10"))
    s = Session(out_dir=tmp_path)
    s.call(deck)
    cs = s.model.store("contacts")
    assert cs.n and np.all(cs["jmodel"] == kernel.CODE)
    deck = tmp_path / "debug2.dat"
    deck.write_text(DECK.format(model="mason_debug2", extra=""))
    with pytest.raises(Dec3dError, match="nlimit1, nlimit2, mult_base and mult_dc_gain") as exc:
        Session(out_dir=tmp_path).call(deck)
    assert exc.value.location.line == 3


def test_missing_fracture_energy_stops_cycling_naming_it(tmp_path):
    s = Session(out_dir=tmp_path)
    for line in DECK.format(model="mason", extra="").splitlines()[:3]:
        s.command(line)
    s.command("block contact property stiffness-normal 1e10 stiffness-shear 1e10 G_I 10 G_II 50")
    s.command("block property density 2000")
    s.command("block fix range id 1")
    with pytest.raises(Dec3dError, match="needs property 'g_c'"):
        s.command("model cycle 1")


def test_factor_of_safety_reduces_coulomb_and_tension_strengths_only():
    """`model factor-of-safety`: tan φ, c, ft (peak and residual) over F, dilatancy at most the
    reduced friction; the cap, the stiffnesses and the fracture energies unchanged."""
    vals = dict(BASE, **{"friction-residual": 30.0, "cohesion-residual": 0.1e6, "tension-residual": 0.05e6,
                         "dilation": 40.0})
    rows = np.tile(MODEL.row(vals), (2, 1))
    before = rows.copy()
    MODEL.reduce(rows, 2.0, False)
    for name in ("cohesion", "tension", "cohesion-residual", "tension-residual"):
        assert np.allclose([MODEL.value(r, name) for r in rows], vals[name] / 2)
    for name in ("friction", "friction-residual"):
        tan = math.tan(math.radians(vals[name])) / 2
        assert np.allclose([MODEL.value(r, name) for r in rows], math.degrees(math.atan(tan)))
    reduced_friction = math.degrees(math.atan(math.tan(math.radians(35)) / 2))
    assert np.allclose([MODEL.value(r, "dilation") for r in rows], reduced_friction)
    for name in ("stiffness-normal", "stiffness-shear", "compression", "g_i", "g_ii", "g_c", "peak_ratio"):
        col = MODEL.props[name].column
        assert np.array_equal(rows[:, col], before[:, col])


HANGING = """
model new
block create brick 0 1 0 1 1 2
block create brick 0 1 0 1 0 1
block property density 2000
block contact jmodel assign mason_v8
block contact property stiffness-normal 1e9 stiffness-shear 1e9 stiffness-initial 2e9 tension {ft} ...
  cohesion 5e4 friction 30 G_I 1 G_II 10 G_c 1e4 compression 5e6
block fix range position-z 1.5 2
block mechanical timestep 2e-4
model gravity 0 0 -10
model cycle 150
"""


@pytest.mark.parametrize("ft", [5e4, 1e4])
def test_a_hanging_block_holds_or_cracks_off_in_the_engine(tmp_path, ft):
    """A 1 m cube (20 kN) hung from a fixed one by a MASON joint: ft A = 50 kN holds it (elastic,
    undamaged, the stiffness hook answers kn while open); ft A = 10 kN cracks (dt → 1 as the crack
    opens by a few G_I/ft, 4.5 mm of fall in 150 steps), the damage survives save and restore."""
    from dec3d.io.state import restore_state, save_state
    from dec3d.physics.jmodels import stiffness
    from dec3d.physics.rigid import engine

    s = Session(out_dir=tmp_path)
    s.run_items(s.load_text(HANGING.format(ft=ft)))
    e = engine(s.model)
    ss = e.subcontacts
    assert ss.n > 0
    kn, ks = stiffness(e.contacts, ss)
    h = ss["hist"]
    if ft == 5e4:
        assert not h[:, :HI["open"]].any() and (h[:, HI["open"]] == 1).all()
        assert ss["fn"].sum() == pytest.approx(-2e4, rel=0.02)       # hanging: tension carries the weight
        assert np.allclose(kn, 1e9) and np.allclose(ks, 1e9)
        return
    assert (h[:, HI["dt"]] > 0.99).all() and (h[:, HI["kappa_t"]] > 3 * 1.0 / ft).all()
    # the force left: ft A exp(−ft κt/G_I) (no residual)
    assert ss["fn"].sum() == pytest.approx(-ft * np.exp(-ft * h[0, HI["kappa_t"]] / 1.0), rel=0.05)
    assert (kn < 1e7).all()
    path = save_state(s.model, tmp_path / "m.sav")
    restored, _ = restore_state(path)
    np.testing.assert_array_equal(restored.store("subcontacts")["hist"], h)
