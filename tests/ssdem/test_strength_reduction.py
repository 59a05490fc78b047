"""`--strength-reduction`: c' and tan(phi') divided by F until the static DEM fails.

Published references:
  * Griffiths & Lane (1999), Geotechnique 49(3), example 1 (2H:1V, H = 10 m,
    c'/(gamma H) = 0.05, phi' = 20 deg, no foundation layer): FE strength reduction
    FS = 1.40 (Bishop & Morgenstern's charts 1.38).
  * ACADS EX1(a) (Giam & Donald 1989): referee FS 1.00.
Tolerance 0.04: the FE value and the limit-equilibrium values of these slopes differ by
0.02-0.03 among themselves; a rigid-block mechanism on one circle sits among them.
"""
import json
from pathlib import Path

import numpy as np
import pytest

from dec3d.ssdem import reduction, solve
from dec3d.ssdem.analysis import run_problem, summary_numbers
from dec3d.ssdem.cli import main
from dec3d.ssdem.readers import read

DATA = Path(__file__).parent / "data"


def holds_by_hand(prob, factor):
    """Independent of reduction.py: divide the strengths in place of a copy, run the full
    load history (no early stop) and look at every step."""
    itf = prob.interfaces
    saved = itf.c_p, itf.c_r, itf.tan_p, itf.tan_r
    try:
        itf.c_p, itf.c_r = saved[0] / factor, saved[1] / factor
        itf.tan_p, itf.tan_r = saved[2] / factor, saved[3] / factor
        st = solve.run(prob)
    finally:
        itf.c_p, itf.c_r, itf.tan_p, itf.tan_r = saved
    return all(r.converged for r in st.steps) and st.removed.sum() == 0


@pytest.mark.parametrize("name, published", [("griffiths_lane_ex1.toml", 1.40), ("acads_1a.toml", 1.00)])
def test_reduction_factor_against_the_published_value(name, published):
    prob = read(DATA / name)
    an = run_problem(prob, strength_reduction=True)
    r = an.reduction
    assert r["fs"] == pytest.approx(published, abs=0.04)
    # the property that defines it: the slope holds at F - 0.005 and fails at F
    assert r["fails_at"] == r["fs"] and r["holds_at"] == pytest.approx(r["fs"] - 0.005)
    assert holds_by_hand(prob, r["fs"] - 0.005)
    assert not holds_by_hand(prob, r["fs"])
    assert summary_numbers(an)["fs_reduction"] == r["fs"]


SMALL = """
title = "small"
[profile]
points = [[0.0, 0.0], [10.0, 0.0], [30.0, 10.0], [45.0, 10.0]]
[[layer]]
c = 10.0
phi = 20.0
gamma = 20.0
kn = 3.5e5
ks = 1.0e5
tension_cutoff = false
[surface]
type = "circle"
centre = [12.0, 24.0]
radius = 24.0
[mesh]
slices = 8
rows = 1
[analysis]
steps = 4
{extra}
"""


def test_cli_flag_and_toml_option_report_the_second_fs(tmp_path, capsys):
    f = tmp_path / "small.toml"
    f.write_text(SMALL.format(extra=""))
    assert main([str(f), "--out", str(tmp_path / "a"), "--strength-reduction"]) == 0
    text = capsys.readouterr().out
    rec = json.loads((tmp_path / "a" / "result.json").read_text())
    fs = rec["strength_reduction"]["fs"]
    assert rec["summary"]["fs_reduction"] == fs
    assert f"FS (strength reduction of c' and tan phi' until the static DEM fails): {fs:.3f}" in text
    assert f"{fs:.3f}" in (tmp_path / "a" / "summary.txt").read_text()
    # the same from the input file; without either there is no second FS
    f.write_text(SMALL.format(extra="strength_reduction = true"))
    assert main([str(f), "--out", str(tmp_path / "b"), "--quiet"]) == 0
    assert json.loads((tmp_path / "b" / "result.json").read_text())["strength_reduction"]["fs"] == fs
    f.write_text(SMALL.format(extra=""))
    assert main([str(f), "--out", str(tmp_path / "c"), "--quiet"]) == 0
    rec = json.loads((tmp_path / "c" / "result.json").read_text())
    assert rec["strength_reduction"] is None and "fs_reduction" not in rec["summary"]


def test_bracket_grows_down_and_up_from_the_guess():
    from dec3d.ssdem.readers.toml_input import read_toml
    prob = read_toml(Path("small.toml"), text=SMALL.format(extra=""))
    up = reduction.search(prob, guess=1.2)
    down = reduction.search(prob, guess=1.8)
    assert up["fs"] == down["fs"]
    assert up["trials"][0] == (1.2, True) and down["trials"][0] == (1.8, False)
    assert all(np.isclose(f * 200, round(f * 200)) for f, _ in up["trials"] + down["trials"])


def test_a_slope_that_fails_at_full_strength_gets_its_fs_from_the_limit_state(tmp_path):
    """c' = 2 kPa: the small slope cannot hold its weight (Bishop on the circle 0.961), so the
    secant iteration at full strength has no equilibrium to settle on and Eq. 2.6 no converged
    state.  The analysis brackets the strength factor F (c', tan phi' / F) at which it stops
    holding and evaluates Eq. 2.6 with the full strengths on the converged state at the
    largest F that holds.  Checked here by hand: the bracket with an independent run of the
    load history, Eq. 2.6 from that run's stresses (perfectly plastic: tau_f = c' + sigma' tan phi')."""
    from dec3d.ssdem.readers.toml_input import read_toml
    prob = read_toml(Path("small.toml"), text=SMALL.format(extra="").replace("c = 10.0", "c = 2.0"))
    an = run_problem(prob, compare_bishop=True)
    q = summary_numbers(an)
    assert an.limit["full_strength"] == "unstable blocks at step 4"   # a mechanism at F = 1
    st = an.limit["state"]
    lo, hi = st["factor"], st["fails_at"]
    assert hi == pytest.approx(lo + 0.005) and hi <= 1.0
    assert holds_by_hand(prob, lo) and not holds_by_hand(prob, hi)
    # Eq. 2.6 by hand on the state at F = lo, full strengths
    itf = prob.interfaces
    saved = itf.c_p, itf.c_r, itf.tan_p, itf.tan_r
    try:
        itf.c_p, itf.c_r, itf.tan_p, itf.tan_r = (v / lo for v in saved)
        run = solve.run(prob)
    finally:
        itf.c_p, itf.c_r, itf.tan_p, itf.tan_r = saved
    on = itf.on_surface
    sig = -run.kn * run.rel[:, 0]
    tau = run.ks * run.rel[:, 1]
    tau_f = np.maximum(saved[0] + sig * saved[2], 0.0)
    by_hand = np.sum((tau_f * itf.length)[on]) / np.sum((np.abs(tau) * itf.length)[on])
    assert q["fs_dem"] == pytest.approx(by_hand, rel=1e-9)
    # every spring held within its reduced strength (to the tolerance: the trial stress of
    # the last solve overshoots it by less than tol), so the full strengths give at least F
    assert q["fs_dem"] >= lo * (1 - prob.settings.tol)
    # both limit factors on one circle: within 1 % of Bishop's
    assert q["fs_dem"] == pytest.approx(q["fs_bishop"], rel=0.01)
    assert q["limit_holds_at"] == lo and q["limit_fails_at"] == hi
    assert q["fs_dem_full_strength"] == an.safety.fs_global
    from dec3d.ssdem.report import summary_text
    text = summary_text(an)
    assert "the slope does not hold at full strength: " in text
    assert f"holds (converged in every step) at F = {lo:.3f} and not at F = {hi:.3f}" in text
    assert f"Eq. 2.6) at the limit state: {q['fs_dem']:.3f}" in text


def test_a_slope_that_holds_has_no_limit_search():
    from dec3d.ssdem.readers.toml_input import read_toml
    prob = read_toml(Path("small.toml"), text=SMALL.format(extra=""))
    an = run_problem(prob)
    assert an.limit is None and an.reduction is None
    assert summary_numbers(an)["fs_dem"] == an.safety.fs_global


@pytest.mark.parametrize("factor", [0.9, 0.96])
def test_over_relaxed_secant_update_reaches_the_plain_fixed_point_sooner(monkeypatch, factor):
    """solve._Relaxation takes the springs a plain secant update softened further along the
    same geometric sequence, and undoes it when it went past a spring's law: the state it
    converges to is the plain iteration's (to the tolerance 1e-3), in fewer iterations.  The
    small slope with c' = 2 kPa near its limit (it stops holding at F ~ 0.97)."""
    from dec3d.ssdem.readers.toml_input import read_toml
    prob = reduction.reduced(read_toml(Path("small.toml"), text=SMALL.format(extra="").replace("c = 10.0", "c = 2.0")),
                             factor)
    runs = {}
    for omega in (1.0, solve.OMEGA_MAX):
        monkeypatch.setattr(solve, "OMEGA_MAX", omega)
        runs[omega] = solve.run(prob)
    plain, fast = runs[1.0], runs[solve.OMEGA_MAX]
    assert reduction.verdict(prob, plain) == "" and reduction.verdict(prob, fast) == ""
    np.testing.assert_allclose(fast.u, plain.u, rtol=0, atol=2e-3 * np.abs(plain.u).max())
    np.testing.assert_allclose(fast.ks, plain.ks, rtol=5e-3)
    assert sum(r.iterations for r in fast.steps) < 0.8 * sum(r.iterations for r in plain.steps)
