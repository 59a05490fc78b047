"""Density scaling by body (`block mechanical mass-scale body`): the row-sum kernel against its
dense twin on a real stack (random cases: test_bodyscale_kernel.py), the stability bound it
promises (largest natural frequency of the scaled system), and the steps a cube stack needs to
reach its static answer."""
import numpy as np
import pytest
import scipy.linalg

from dec3d.errors import Dec3dError
from dec3d.kernels.bodyscale import body_row_sums
from dec3d.kernels.joints import P_KN, P_KS
from dec3d.physics.eigen import assemble
from dec3d.physics.rigid import engine, mech
from dec3d.physics.steps import _Run
from reference.bodyscale_ref import row_sums_ref


def _kernel(*args):
    ng = len(args[1])
    rt, rr = np.zeros(ng), np.zeros(ng)
    body_row_sums(*args, rt, rr)
    return rt, rr


def _stack(n, extra=""):
    lines = ["model new", f"block create brick 0 {n} 0 {n} -1 0"]
    lines += [f"block create brick {i} {i + 1} {j} {j + 1} {k} {k + 1}"
              for i in range(n) for j in range(n) for k in range(n)]
    lines += ["block property density 2600", "block fix range position-z -1 0", "model gravity 0 0 -9.81",
              "block mechanical damping local 0.8", "block contact jmodel assign mohr",
              "block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 "
              "friction 34.38 cohesion 0 tension 0"]
    return "\n".join(lines) + "\n" + extra


def _run(session, text):
    session.run_items(session.load_text(text))
    return engine(session.model)


def test_row_sums_of_a_real_stack_match_the_twin(session):
    e = _run(session, _stack(2, "block mechanical mass-scale body\nmodel cycle 12\n"))
    b, cs, ss = session.model.blocks, e.contacts, e.subcontacts
    gstart, gmember = e._groups()
    gid = np.full(b.n, -1, np.int64)
    gid[gmember] = np.repeat(np.arange(len(gstart) - 1), np.diff(gstart))
    args = (gid, b["centroid"][gmember], np.sqrt(b["inertia_approx"][gmember] / b["mass"][gmember]),
            b["fixity"][gmember].astype(np.int64), cs["a"], cs["b"], cs["normal"],
            np.ascontiguousarray(cs["prop"][:, P_KN]), np.ascontiguousarray(cs["prop"][:, P_KS]),
            ss["contact"], ss["pos"], ss["area"])
    rt, rr = _kernel(*args)
    rt0, rr0 = row_sums_ref(*args)
    np.testing.assert_allclose(rt, rt0, rtol=1e-12)
    np.testing.assert_allclose(rr, rr0, rtol=1e-12)


@pytest.mark.parametrize("safety", [0.5, 0.8])
def test_scaled_masses_bound_the_largest_frequency(session, safety):
    """The promise of the scaling: with the inertial masses and scalar inertias it gives, the
    largest natural frequency of the 3 × 3 × 3 stack (all sub-contacts as springs, scalar inertia
    as the motion kernel uses it) satisfies ω_max Δt ≤ 2 × safety — and the bound is not loose by
    more than a factor 2 (it is what buys the larger step)."""
    e = _run(session, _stack(3, f"block mechanical mass-scale body safety {safety}\nmodel cycle 12\n"))
    run = _Run(e, 1, None)
    K, _, free, leaders, _ = assemble(session.model, tol=1.0)
    assert np.array_equal(run.gmember[run.gstart[:-1]], leaders)
    m = np.stack([run.gimass] * 3 + [run.gisc] * 3, 1).ravel()
    idx = np.flatnonzero(free)
    w2 = scipy.linalg.eigh(K[idx][:, idx].toarray(), np.diag(m[idx]), eigvals_only=True)
    wdt = np.sqrt(w2.max()) * run.dt
    assert 2 * safety * 0.5 < wdt <= 2 * safety * (1 + 1e-9)
    # the median body keeps its real mass (the time scale stays physical)
    assert np.min(np.abs(run.gimass / run.gmass - 1.0)) < 1e-9


def _steps_to_static(session, extra, cap=5000):
    """Steps until the base reaction is within 0.1 % of the weight and every block slower than
    1e-5 m/s (the bench's time-to-equilibrium test, bench/rigid_bench.py), checked per batch."""
    e = _run(session, _stack(4, extra))
    b = session.model.blocks
    free = b["fixity"] == 0
    weight = float(b["mass"][free].sum()) * 9.81

    def state(_=None):
        cs, ss = e.contacts, e.subcontacts
        rows = ((cs["a"] == 0) | (cs["b"] == 0))[ss["contact"]]
        react = abs(float(np.sum(ss["fn"][rows] * cs["normal"][ss["contact"][rows], 2])))
        vmax = float(np.linalg.norm(b["velocity"][free], axis=1).max())
        return abs(react - weight) / weight, vmax

    def done(_):
        err, vmax = state()
        return err <= 1e-3 and vmax < 1e-5

    e.cycle(cap, stop=done)
    return session.model.step, state()


def test_stack_reaches_its_static_answer_in_few_steps(session):
    """4 × 4 × 4 cube stack (the bench scene at n = 4, local damping 0.8). Measured on this code:
    130 steps with `mass-scale body` (safety 0.7) against 820 with Eq. (87) scaling (`mass-scale on`). Caps:
    250 steps, and at most a third of the Eq. (87) steps; both runs end at the static answer. The default
    (no mass-scale command) scales by body with the masses only raised: as few steps."""
    steps_body, (err, vmax) = _steps_to_static(session, "block mechanical mass-scale body\n")
    assert err <= 1e-3 and vmax < 1e-5
    assert steps_body <= 250
    steps_eq87, (err87, vmax87) = _steps_to_static(session, "block mechanical mass-scale on\n")
    assert err87 <= 1e-3 and vmax87 < 1e-5
    assert 3 * steps_body <= steps_eq87
    steps_default, (err0, vmax0) = _steps_to_static(session, "")
    assert err0 <= 1e-3 and vmax0 < 1e-5
    assert steps_default <= 250 and 3 * steps_default <= steps_eq87


def test_mass_scale_body_settings_and_bad_input(session):
    _run(session, "block mechanical mass-scale body safety 0.7\n")
    m = mech(session.model)
    assert (m["scaling"], m["safety"], m["mass_scale"]) == ("body", 0.7, "on")
    with pytest.raises(Dec3dError, match="`safety` goes with `mass-scale body`"):
        _run(session, "block mechanical mass-scale on safety 0.5\n")
    assert m["scaling"] == "body"                       # the refused command changed nothing
    for bad in ("0", "1", "1.5", "-0.2"):
        with pytest.raises(Dec3dError, match="safety"):
            _run(session, f"block mechanical mass-scale body safety {bad}\n")
    _run(session, "block mechanical mass-scale automatic\n")
    assert (m["scaling"], m["mass_scale"]) == ("auto", "auto")
    assert engine(session.model).scaling() == "raised"    # the default of static runs with local damping
    _run(session, "model dynamic list\n")
    assert "density scaling     : on (by body, masses only raised)" in session.output.getvalue()
    _run(session, "block mechanical damping global\n")
    assert engine(session.model).scaling() == "eq87"
    _run(session, "block mechanical damping local\n")
    _run(session, "block mechanical mass-scale on\n")
    assert (m["scaling"], m["mass_scale"], engine(session.model).scaling()) == ("eq87", "on", "eq87")
    _run(session, "block mechanical mass-scale automatic safety 0.6\nblock mechanical mass-scale timestep 1e-4\n")
    # a time step alone asks for the partial scaling of 3DEC (masses only raised): Eq. (87)
    assert (m["scaling"], m["mass_scale"], m["safety"], engine(session.model).scaling()) == ("auto", "on", 0.6,
                                                                                            "eq87")


def test_saved_scaling_settings_round_trip_and_bad_values_are_refused(session, tmp_path):
    from dec3d.io.state import _settings_problem

    _run(session, _stack(2, "block mechanical mass-scale body safety 0.6\nmodel cycle 20\n"
                            f"model save '{tmp_path / 'a.sav'}'\n"))
    dt = engine(session.model).dt
    _run(session, f"model new\nmodel restore '{tmp_path / 'a.sav'}'\n")
    m = mech(session.model)
    assert (m["scaling"], m["safety"]) == ("body", 0.6)
    _run(session, "model cycle 10\n")
    assert engine(session.model).dt == pytest.approx(dt, rel=1e-6)
    assert "`scaling` is 'fast', not one of eq87, body, raised, auto" in _settings_problem({"mechanical": {"scaling": "fast"}})
    assert "`safety` has the value 1.0" in _settings_problem({"mechanical": {"safety": 1.0}})
    assert _settings_problem({"mechanical": {"scaling": "body", "safety": 0.5}}) is None


JOINED = """model new
block create brick 0 1 0 1 -1 0
block create brick 0 1 0 1 0 1
block create brick 0 1 0 1 1 2
block create brick 0 1 0 1 2 3
block create brick 5 6 0 1 10 11
block property density 2000
model gravity 0 0 -10
block fix range position-z -1 0
block contact jmodel assign mohr
block contact material-table default property stiffness-normal 1e8 stiffness-shear 1e8 friction 30
block join range position-z 1 3
"""


def test_joined_group_and_a_free_block_under_body_scaling(session):
    """Two joined cubes on a cube on the base, and a cube falling far away (no contact): the free
    cube keeps its real mass and inertia, the joined pair is one body (its row sums over both
    members' contacts), and the column settles to its static answer: every contact carries the
    weight above it."""
    e = _run(session, JOINED + "block mechanical mass-scale body\nmodel cycle 10\n")
    run = _Run(e, 1, None)
    b = session.model.blocks
    lone = int(np.flatnonzero(b["centroid"][:, 0] > 4)[0])
    g = int(np.flatnonzero(run.gmember[run.gstart[:-1]] == lone)[0])
    assert run.gimass[g] == run.gmass[g] and run.gisc[g] == run.giscalar[g]
    assert len(run.gstart) - 1 == b.n - 1                # the joined pair is one group
    _run(session, "block initialize velocity-z 0 range position-x 4 7\nblock fix range position-x 4 7\n"
                  "model solve ratio 1e-7 cycles 5000\n")
    assert "converged: ratio" in session.output.getvalue()
    cs, ss = e.contacts, e.subcontacts
    w = 2000 * 10.0
    z = b["centroid"][:, 2]
    lower, base = int(np.argmin(np.abs(z - 0.5))), int(np.argmin(np.abs(z + 0.5)))
    upper = int(np.argmin(np.abs(z - 1.5)))
    for pair, carried in (((base, lower), 3 * w), ((lower, upper), 2 * w)):
        c = int(np.flatnonzero((cs["a"] == pair[0]) & (cs["b"] == pair[1]))[0])
        assert float(ss["fn"][ss["contact"] == c].sum()) == pytest.approx(carried, rel=1e-4)


def test_body_scaling_at_a_given_timestep(session):
    """`mass-scale body timestep Δt`: the run uses that step, and every body's inertial mass is
    its translation row sum × (Δt / 2s)²."""
    e = _run(session, _stack(2, "block mechanical mass-scale body safety 0.5\n"
                                "block mechanical mass-scale timestep 2e-3\nmodel cycle 10\n"))
    run = _Run(e, 1, None)
    assert run.dt == 2e-3
    b, cs, ss = session.model.blocks, e.contacts, e.subcontacts
    gid = np.full(b.n, -1, np.int64)
    gid[run.gmember] = np.repeat(np.arange(len(run.gstart) - 1), np.diff(run.gstart))
    rt, rr = row_sums_ref(gid, run.gcen, np.sqrt(run.giscalar / run.gmass),
                          (b["fixity"] | b["apply_fix"])[run.gmember[run.gstart[:-1]]].astype(np.int64),
                          cs["a"], cs["b"], cs["normal"], cs["prop"][:, P_KN], cs["prop"][:, P_KS],
                          ss["contact"], ss["pos"], ss["area"])
    free = rt > 0
    assert free.sum() == 8
    # (the run takes back the masses of the last detection, worked out from the geometry of that
    # step; the blocks have moved about 1e-6 of their size since)
    np.testing.assert_allclose(run.gimass[free], rt[free] * (2e-3 / 1.0) ** 2, rtol=1e-5)
    np.testing.assert_allclose(run.gisc[free], rr[free] * (2e-3 / 1.0) ** 2, rtol=1e-5)


def test_default_static_scaling_raises_masses_only(session):
    """The default of a static run (no mass-scale command, local damping): by body with the masses
    only raised, m_i = max(m, R_t (Δt / 2s)²) and I_i = max(I, R_r (Δt / 2s)²), s = 0.5; the top
    cubes (fewer contacts, R_t below the median) keep their real masses, the others are raised."""
    e = _run(session, _stack(2, "model cycle 10\n"))
    assert e.scaling() == "raised"
    run = _Run(e, 1, None)
    b, cs, ss = session.model.blocks, e.contacts, e.subcontacts
    gid = np.full(b.n, -1, np.int64)
    gid[run.gmember] = np.repeat(np.arange(len(run.gstart) - 1), np.diff(run.gstart))
    rt, rr = row_sums_ref(gid, run.gcen, np.sqrt(run.giscalar / run.gmass),
                          (b["fixity"] | b["apply_fix"])[run.gmember[run.gstart[:-1]]].astype(np.int64),
                          cs["a"], cs["b"], cs["normal"], cs["prop"][:, P_KN], cs["prop"][:, P_KS],
                          ss["contact"], ss["pos"], ss["area"])
    f = (run.dt / 1.0) ** 2
    free = rt > 0
    assert free.sum() == 8
    # (masses of the last detection: the blocks have moved about 1e-6 of their size since)
    np.testing.assert_allclose(run.gimass[free], np.maximum(run.gmass, rt * f)[free], rtol=1e-5)
    np.testing.assert_allclose(run.gisc[free], np.maximum(run.giscalar, rr * f)[free], rtol=1e-5)
    assert (run.gimass >= run.gmass).all() and (run.gisc >= run.giscalar).all()
    assert (run.gimass[free] == run.gmass[free]).any() and (run.gimass[free] > 1.01 * run.gmass[free]).any()


# a 10 × 10 × 5 m block on a 40° incline (gravity tilted), friction 45°: it must stay put
_INCLINE = ("model new\nblock create brick -5 40 -5 15 -2 0\nblock create brick 0 10 0 10 0 5\n"
            "block property density 2000\nmodel gravity 6.4279 0 -7.6604\nblock contact jmodel assign mohr\n"
            "block contact material-table default property stiffness-normal 10e6 stiffness-shear 10e6 friction 45\n"
            "block fix range position-z -2 0\n")


def test_full_inertia_bound_uses_the_smallest_principal_moment(session):
    """With Euler's equations (damping none: full inertia) the body turns with its principal moments
    × m_i/m; the flat block's smallest moment is 0.46 of the scalar inertia, so the ratio must come
    from it or ω_max Δt exceeds 2 × safety (it was 2.1 at safety 0.8 and the block fell through)."""
    e = _run(session, _INCLINE + "block mechanical mass-scale body safety 0.8\nblock mechanical damping none\n"
                                 "model cycle 3\n")
    run = _Run(e, 1, None)
    K, _, free, leaders, _ = assemble(session.model, tol=1.0)
    assert list(leaders) == [0, 1] and not free[:6].any()          # the fixed base's rows are out
    g = 0 if run.gmember[run.gstart[0]] == 1 else 1
    r = run.gimass[g] / run.gmass[g]
    mass = 2000.0 * 500.0
    prin = mass * np.array([10 ** 2 + 5 ** 2, 10 ** 2 + 5 ** 2, 10 ** 2 + 10 ** 2]) / 12.0   # axis-aligned box
    m = np.concatenate([[1.0] * 6, [mass * r] * 3, prin * r])
    idx = np.flatnonzero(free)
    w2 = scipy.linalg.eigh(K[idx][:, idx].toarray(), np.diag(m[idx]), eigvals_only=True)
    assert np.sqrt(w2.max()) * run.dt <= 1.6 * (1 + 1e-9)



@pytest.mark.parametrize("safety", ["", " safety 0.5"])
def test_body_scaling_with_global_damping_holds_a_block_friction_holds(session, safety):
    """A 10 × 10 × 5 m block set down on a 40° slope (gravity tilted), φ = 45°: friction holds
    it. With `mass-scale body` and `damping global` the adaptive servo used to start at 0.02/Δt;
    the block rang at ω Δt ≈ 1 for some 300 steps and slid 65 mm downhill (15 mm at s = 0.5)
    and 27 mm sideways before it held. It now starts at the servo's aim for ω = 2s/Δt and the
    block stays within what its contact's elastic shear takes (0.1 mm)."""
    g = 9.81
    tilt = np.radians(40.0)
    eng = _run(session, "\n".join([
        "model new", "block create brick -20 30 -10 20 -2 0", "block create brick 0 10 0 10 0 5",
        "block property density 2600", "block fix range position-z -2 0",
        f"model gravity {g * np.sin(tilt)} 0 {-g * np.cos(tilt)}", "block contact jmodel assign mohr",
        "block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 friction 45 "
        "cohesion 0 tension 0",
        "block mechanical mass-scale body" + safety, "block mechanical damping global", ""]))
    b = session.model.blocks
    row = int(np.flatnonzero(b["fixity"] == 0)[0])
    c0 = b["centroid"][row].copy()
    _run(session, "model cycle 2000\n")
    d = b["centroid"][row] - c0
    # elastic shear under the block's weight: τ A / (ks A) = ρ g h sin 40° / ks ≈ 8e-5 m
    assert abs(d[0]) < 5e-4 and abs(d[1]) < 1e-4
    assert float(np.linalg.norm(b["velocity"][row])) < 1e-6
    assert eng.scaling() == "body"
