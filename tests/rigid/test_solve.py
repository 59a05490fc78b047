"""`model solve`: Itasca's equilibrium measures checked against a slow computation from their
definitions, the end-of-solve report, the step cap, "not converged", the zero-stiffness warning."""
import math
import re

import numpy as np
import pytest

from dec3d.commands import model_solve
from dec3d.physics.rigid import engine

BASE = """model new
block create brick 0 1 0 1 -1 0
block create brick 0 1 0 1 0 1
block create brick 0.2 1.2 0 1 1 2
block create brick 0 1 0 1 2 2.5
block create brick 0 1 0 1 2.5 3
block property density 2000
model gravity 0 0 -10
block contact jmodel assign mohr
block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 friction 30
block fix range position-z -1 0
"""


def _run(session, text):
    session.run_items(session.load_text(text))
    return engine(session.model)


def _slow_criteria(m, e):
    """The definitions (Itasca, "Reaching Equilibrium" / `zone ratio`), one body and one sub-contact
    at a time: a body is a block or a group of joined blocks; unbalanced force |ΣF| of contact
    forces, weight and applied force with the held components left out; applied magnitude Σ|F|
    of the same forces one by one; bodies held in x, y and z take no part."""
    b, cs, ss = m.blocks, e.contacts, e.subcontacts
    g = [float(x) for x in m.settings.gravity]
    nb = b.n
    force = [[0.0, 0.0, 0.0] for _ in range(nb)]
    mag = [0.0] * nb
    for s in range(ss.n):
        c = int(ss["contact"][s])
        n = cs["normal"][c]
        f = [float(ss["fn"][s]) * float(n[i]) + float(ss["fs"][s][i]) for i in range(3)]   # on B, −f on A
        size = math.sqrt(sum(x * x for x in f))
        a_, b_ = int(cs["a"][c]), int(cs["b"][c])
        for i in range(3):
            force[b_][i] += f[i]
            force[a_][i] -= f[i]
        mag[a_] += size
        mag[b_] += size
    bodies = {}
    for r in range(nb):
        if b["hidden"][r]:
            continue
        lead = int(b["leader"][r]) if b["leader"][r] >= 0 else r
        bodies.setdefault(lead, []).append(r)
    un, ap = [], []
    for lead, rows in bodies.items():
        held = int(b["fixity"][lead]) | int(b["apply_fix"][lead])
        if held & 7 == 7:
            continue
        tot = [0.0, 0.0, 0.0]
        A = 0.0
        for r in rows:
            w = [float(b["mass"][r]) * g[i] for i in range(3)]
            fa = [float(b["fapp"][r][i]) for i in range(3)]
            for i in range(3):
                tot[i] += force[r][i] + w[i] + fa[i]
            A += mag[r] + math.sqrt(sum(x * x for x in w)) + math.sqrt(sum(x * x for x in fa))
        tot = [0.0 if (held >> i) & 1 else tot[i] for i in range(3)]
        un.append(math.sqrt(sum(x * x for x in tot)))
        ap.append(A)
    mean_un, mean_ap = sum(un) / len(un), sum(ap) / len(ap)
    return {"ratio": mean_un / mean_ap, "ratio-average": mean_un / mean_ap,
            "ratio-local": 0.1 * max(u / a for u, a in zip(un, ap) if a > 0),
            "ratio-maximum": 0.1 * max(un) / mean_ap, "unbalanced-maximum": max(un)}


def test_criteria_match_the_definitions_on_a_moving_stack(session):
    """Mid-run (far from equilibrium), with an applied force, a block held in x only and two
    joined blocks, so that every rule of the definitions matters. ``_slow_criteria`` is also the
    slow twin of the kernel ``kernels/balance.body_balance`` behind ``criteria()``."""
    e = _run(session, BASE + "block apply force 300 -200 50 range position-z 1 2\n"
                             "block fix velocity-x range position-z 1 2\n"
                             "block join range position-z 2 3\nmodel cycle 37\n")
    m = session.model
    assert e.subcontacts.n > 0 and np.abs(e.subcontacts["fn"]).max() > 0
    want = _slow_criteria(m, e)
    got = e.criteria()
    assert got.keys() == want.keys()
    for k in want:
        assert got[k] == pytest.approx(want[k], rel=1e-12, abs=1e-300), k
    assert 1e-6 < got["ratio"] < 1.0          # not a trivial state


def test_free_fall_has_ratio_one_and_unbalanced_force_mg(session):
    e = _run(session, "model new\nblock create brick 0 1 0 1 0 1\nblock property density 1000\n"
                      "model gravity 0 0 -10\nmodel cycle 3\n")
    c = e.criteria()
    assert c["unbalanced-maximum"] == pytest.approx(1000 * 10, rel=1e-14)
    assert c["ratio"] == pytest.approx(1.0, rel=1e-14)
    assert c["ratio-local"] == pytest.approx(0.1, rel=1e-14)
    assert c["ratio-maximum"] == pytest.approx(0.1, rel=1e-14)


@pytest.mark.parametrize("key", ["ratio", "ratio-average", "ratio-local", "ratio-maximum", "unbalanced-maximum"])
def test_each_limit_stops_the_solve_when_met_and_not_before(session, key):
    limit = 1.0 if key == "unbalanced-maximum" else 1e-6
    e = _run(session, BASE + f"model history name 'h' mechanical {key}\nhistory interval 10\n"
                             f"model solve {key} {limit}\n")
    text = session.output.getvalue()
    assert e.criteria()[key] <= limit
    h = session.model.history_set.find("h")
    # the history samples the same measure; every earlier check (each 10 steps) was above the limit
    assert h.values[-1] == e.criteria()[key]
    assert all(v > limit for v in h.values[:-1])
    assert re.search(rf"model solve: converged: {key} [0-9.e+-]+ ≤ {limit:g}; \d+ steps", text), text


def test_end_of_solve_report(session):
    e = _run(session, BASE + "model solve ratio 1e-5\n")
    lines = session.output.getvalue().strip().splitlines()
    m = session.model
    c = e.criteria()
    assert lines[-2] == (f"model solve: converged: ratio {c['ratio']:.4g} ≤ 1e-05; {m.step} steps (to step {m.step}), "
                         f"model time {m.time:.6g} (total {m.time:.6g})")      # no unit unless declared
    assert lines[-1] == (f"  ratio {c['ratio']:.4g}, ratio-average {c['ratio-average']:.4g}, "
                         f"ratio-local {c['ratio-local']:.4g}, ratio-maximum {c['ratio-maximum']:.4g}, "
                         f"unbalanced-maximum {c['unbalanced-maximum']:.4g}")
    assert session.warnings == []


def test_default_cap_says_not_converged_and_warns_at_the_end_of_the_run(session, monkeypatch):
    monkeypatch.setattr(model_solve, "SOLVE_CYCLE_CAP", 40)
    _run(session, "model new\nblock create brick 0 1 0 1 0 1\nblock property density 1000\nmodel gravity 0 0 -10\n"
                  "model solve\n")
    lines = session.output.getvalue().strip().splitlines()
    assert session.model.step == 40
    assert lines[-2].startswith("model solve: not converged (ratio ≤ 1e-05 not met): stopped by the step limit "
                                "(40 steps, dec3d’s default cap); 40 steps (to step 40)")
    assert session.warnings == ["<input>:5: model solve did not converge (ratio ≤ 1e-05): stopped by the step "
                                "limit (40 steps, dec3d’s default cap) at step 40; " + lines[-1].strip()]


def test_time_limit_with_a_ratio_says_not_converged(session):
    e = _run(session, BASE + "model solve ratio 1e-30 time 0.002\n")
    assert e.time == pytest.approx(0.002, abs=e.dt)
    assert "not converged (ratio ≤ 1e-30 not met): stopped by the time limit (0.002 s)" in session.output.getvalue()


def test_time_only_solve_is_not_a_convergence_claim(session):
    _run(session, BASE + "model solve time 0.002\n")
    text = session.output.getvalue()
    assert "model solve: stopped by the time limit (0.002 s)" in text and "converged" not in text
    assert session.warnings == []


def test_unconverged_solve_in_dec3d_run_warns_at_the_end_and_exits_0(tmp_path, capsys):
    from dec3d.cli import main

    deck = tmp_path / "d.dat"
    deck.write_text(BASE + "model solve ratio 1e-30 cycles 30\nmodel cycle 5\n")
    rc = main(["run", str(deck), "-q"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 0
    assert err[-1].startswith(f"warning: {deck}:12: model solve did not converge (ratio ≤ 1e-30): stopped by the "
                              "step limit (30 steps) at step 30; ratio ")


def test_zero_stiffness_warning_before_cycling(session):
    deck = BASE.replace("block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 "
                        "friction 30\n", "")
    _run(session, deck + "model cycle 1\n")
    first = session.output.getvalue().splitlines()[0]
    assert first == ("warning: 4 of 4 contacts have zero normal or shear stiffness (the first between blocks 1 and 2): "
                     "blocks will sink into each other or slide freely; set stiffness-normal and stiffness-shear with "
                     "`block contact property` or `block contact material-table default property`")


def test_no_stiffness_warning_when_stiffness_is_set(session):
    _run(session, BASE + "model cycle 1\nmodel solve cycles 5\n")
    assert "warning" not in session.output.getvalue()


def test_cap_holds_for_a_time_limit_joined_by_and(session, monkeypatch):
    """`time t and` cannot end a solve whose ratio is never met: the cap ends it."""
    monkeypatch.setattr(model_solve, "SOLVE_CYCLE_CAP", 40)
    _run(session, "model new\nblock create brick 0 1 0 1 0 1\nblock property density 1000\nmodel gravity 0 0 -10\n"
                  "model solve ratio 1e-3 time 1e-6 and\n")
    assert session.model.step == 40
    assert "not converged (ratio ≤ 0.001 not met): stopped by the step limit (40 steps, dec3d’s default cap)" \
        in session.output.getvalue()
