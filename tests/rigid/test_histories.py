"""Histories: sampling interval, CSV against the engine state, PNG written, results figures."""
import csv
import math

import numpy as np
import pytest

from dec3d.physics.history import figures, histories
from dec3d.physics.rigid import engine

from test_engine import DECK as _BLOCK_ON_SPRING

DECK = _BLOCK_ON_SPRING + "block mechanical damping none\n"   # the same block, undamped


def _run(session, extra):
    session.run_items(session.load_text(DECK + extra))
    return engine(session.model)


def test_sampled_every_interval_steps(session):
    _run(session, "block history displacement-z block-id 2\nmodel history mechanical time-total\nmodel cycle 95\n")
    hs = histories(session.model)
    assert [h.id for h in hs.items] == [1, 2] and hs.interval == 10
    assert hs.items[0].steps == list(range(10, 100, 10))
    _run(session, "history interval 3\nblock history velocity block-id 2\nmodel cycle 9\n")
    h = histories(session.model).items[-1]
    assert h.steps == [3, 6, 9]


def test_csv_matches_engine_state_and_png_written(session, tmp_path):
    e = _run(session, "block history name 'uz' displacement-z position 0.4 0.6 0.7\n"
                      "block history name 'v' velocity-z block-id 2\n"
                      "model history name 't' mechanical time-total\nhistory interval 5\nmodel cycle 50\n"
                      "history export 1 2 3 file 'out/h.csv'\n")
    b = session.model.blocks
    rows = list(csv.reader(open(tmp_path / "out" / "h.csv")))
    assert rows[0][:2] == ["step", "time"] and rows[0][2].startswith("uz (block 2 displacement-z")
    assert len(rows) == 1 + 10
    last = rows[-1]
    assert int(last[0]) == e.step == 50
    assert float(last[1]) == e.time == float(last[4])
    assert float(last[2]) == b["disp"][1, 2] and float(last[3]) == b["velocity"][1, 2]
    for name in ("uz", "v", "t"):
        png = tmp_path / "out" / f"h_{name}.png"
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert session.results["uz.final"] == b["disp"][1, 2]
    assert session.results["t.max"] == pytest.approx(e.time)


def test_export_vs_and_errors(session, tmp_path):
    from dec3d.errors import Dec3dError

    _run(session, "block history displacement-z block-id 2\nmodel history mechanical time-total\nmodel cycle 20\n"
                  "history export 1 vs 2 file 'vs.csv'\n")
    rows = list(csv.reader(open(tmp_path / "vs.csv")))
    assert "time-total" in rows[0][2] and "displacement-z" in rows[0][3]
    with pytest.raises(Dec3dError, match="no history 7"):
        _run(session, "history export 7 file 'x.csv'\n")
    with pytest.raises(Dec3dError, match="either"):
        _run(session, "block history velocity\n")


def test_figures_of_a_synthetic_sine():
    t = np.arange(0, 2.0, 1e-3)
    v = 3.0 + 0.5 * np.sin(2 * math.pi * 7.3 * t + 0.3)
    f = figures(t, v)
    assert f["frequency"] == pytest.approx(7.3, rel=2e-3)
    assert f["final"] == v[-1] and f["min"] == v.min() and f["max"] == v.max()
    assert figures([0.0, 1.0], [1.0, 1.0])["frequency"] == 0.0


def test_undamped_block_frequency(session):
    _run(session, "block history name 'z' displacement-z block-id 2\nhistory interval 1\nmodel cycle 400\n"
                  "history export 1 file 'z.csv'\n")
    f0 = math.sqrt(10e6 / 2000) / (2 * math.pi)
    assert session.results["z.frequency"] == pytest.approx(f0, rel=0.01)


def test_rvelocity_position_and_contact_histories(session):
    _run(session, "block history name 'pz' position-z block-id 2\nblock history name 'wz' rvelocity-z block-id 2\n"
                  "block contact history name 'fn' force-normal position 0.5 0.5 0\n"
                  "block contact history name 'un' displacement-normal position 0.5 0.5 0\n"
                  "block contact history name 'fs' force-shear position 0.5 0.5 0\n"
                  "block initialize rvelocity-z 0.25 range id 2\nhistory interval 1\nmodel cycle 30\n"
                  "history export 'pz' 'wz' 'fn' 'un' 'fs' file 'c.csv'\n")
    b = session.model.blocks
    sc = session.model.store("subcontacts")
    n = len(sc)
    assert session.results["pz.final"] == b["centroid"][1, 2]
    assert session.results["wz.final"] == b["spin"][1, 2]
    assert session.results["fn.final"] == pytest.approx(sc["fn"][:n].sum(), rel=1e-12)
    assert session.results["fn.max"] > 0
    assert session.results["un.final"] == pytest.approx(sc["un"][:n].mean(), rel=1e-12)
    assert session.results["fs.final"] == pytest.approx(np.linalg.norm(sc["fs"][:n].sum(axis=0)), rel=1e-12)


def test_contact_history_before_any_contact_is_nan_then_follows_the_pair(session):
    session.run_items(session.load_text(
        "model new\nblock create brick 0 1 0 1 0 1\nblock create brick 0 1 0 1 2 3\nblock property density 1000\n"
        "block contact history name 'f' force-normal position 0.5 0.5 1.5\nhistory interval 1\nmodel cycle 3\n"
        "history export 'f' file 'f.csv'\n"))
    assert math.isnan(session.results["f.final"])


def test_angular_momentum_and_shape_error_of_a_spinning_brick(session):
    session.run_items(session.load_text(
        "model new\nblock create brick -0.5 0.5 -1 1 -1.5 1.5\nblock property density 1000\nmodel gravity 0 0 0\n"
        "block mechanical damping none\nblock mechanical timestep 1e-3\nblock initialize rvelocity-x 1 rvelocity-y 1 rvelocity-z 1\n"
        "block history name 'L' angular-momentum block-id 1\nblock history name 'Lz' angular-momentum-z block-id 1\n"
        "block history name 's' shape-error block-id 1\nhistory interval 1\nmodel cycle 1\n"
        "history export 'L' 'Lz' 's' file 'l.csv'\n"))
    # L = diag(6500, 5000, 2500) (1, 1, 1) after one step: the brick has turned by 1.7 mrad
    assert session.results["L.final"] == pytest.approx(math.sqrt(6500**2 + 5000**2 + 2500**2), rel=1e-6)
    assert session.results["Lz.final"] == pytest.approx(2500, rel=5e-3)
    assert session.results["s.final"] < 1e-12


def test_best_rotation_recovers_a_rotation():
    from dec3d.physics.history import best_rotation

    rng = np.random.default_rng(3)
    a = rng.normal(size=(8, 3))
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    q *= np.sign(np.linalg.det(q))
    assert np.allclose(best_rotation(a, a @ q.T), q, atol=1e-12)


SPIN = ("model new\nblock create brick 0 1 0 2 0 0.5\nblock create brick 3 4 0 1 0 1\nblock property density 2000\n"
        "block mechanical damping none\nblock mechanical timestep 1e-3\n")


def test_rotation_of_a_spinning_block_follows_omega_t_past_half_a_turn(session):
    """A free spin ω = 2 rad/s about z for 2500 steps of 1 ms: the Cayley update turns the block by
    2 atan(ω Δt / 2) per step, 5.0000 rad in all (past π, where the short rotation vector flips)."""
    session.run_items(session.load_text(
        SPIN + "block initialize rvelocity-z 2 range id 1\nblock history name 'r' rotation block-id 1\n"
        "block history name 'rz' rotation-z block-id 1\nblock history name 'rx' rotation-x block-id 1\n"
        "block history name 'r2' rotation block-id 2\nhistory interval 10\nmodel cycle 2500\n"
        "history export 'r' 'rz' 'rx' 'r2' file 'r.csv'\n"))
    per_step = 2 * math.atan(2 * 1e-3 / 2)
    hs = histories(session.model)
    rz = hs.find("rz")
    np.testing.assert_allclose(rz.values, np.array(rz.steps) * per_step, rtol=1e-9)
    assert session.results["r.final"] == pytest.approx(2500 * per_step, rel=1e-9)
    assert session.results["r.final"] == pytest.approx(5.0, rel=1e-6)         # ω t
    assert abs(session.results["rx.max"]) < 1e-9 and abs(session.results["rx.min"]) < 1e-9
    assert session.results["r2.max"] == 0.0                                   # the other block never moved


def test_point_fixed_to_a_translating_and_spinning_block(session):
    """Block 1 moves at v = (1, 0, 0.5) m/s and spins at 2 rad/s about z; a point fixed to it at its top corner
    (1, 2, 0.5) and an inner point (0.25, 0.5, 0.25) follow c(t) + Rz(θ)(p₀ − c₀)."""
    session.run_items(session.load_text(
        SPIN + "block initialize velocity-x 1 velocity-z 0.5 rvelocity-z 2 range id 1\n"
        "block history name 'px' position-x material-point 1 2 0.5\nblock history name 'py' position-y block-id 1 material-point 1 2 0.5\n"
        "block history name 'ux' displacement-x block-id 1 material-point 0.25 0.5 0.25\n"
        "block history name 'uz' displacement-z block-id 1 material-point 0.25 0.5 0.25\n"
        "block history name 'vy' velocity-y block-id 1 material-point 0.25 0.5 0.25\n"
        "block history name 'v' velocity block-id 1 material-point 0.25 0.5 0.25\n"
        "history interval 50\nmodel cycle 1000\n"
        "history export 'px' 'py' 'ux' 'uz' 'vy' 'v' file 'p.csv'\n"))
    t, th = 1.0, 1000 * 2 * math.atan(1e-3)
    c0, c = np.array([0.5, 1.0, 0.25]), np.array([0.5 + t, 1.0, 0.25 + 0.5 * t])
    rz = np.array([[math.cos(th), -math.sin(th), 0], [math.sin(th), math.cos(th), 0], [0, 0, 1]])
    corner = c + rz @ (np.array([1, 2, 0.5]) - c0)
    inner0 = np.array([0.25, 0.5, 0.25])
    inner = c + rz @ (inner0 - c0)
    r = session.results
    assert r["px.final"] == pytest.approx(corner[0], abs=1e-12) and r["py.final"] == pytest.approx(corner[1], abs=1e-12)
    # the corner is a vertex: the history is exactly where that vertex is
    v = session.model.vertices
    assert np.linalg.norm(v["pos"] - [r["px.final"], r["py.final"], corner[2]], axis=1).min() < 1e-12
    assert r["ux.final"] == pytest.approx((inner - inner0)[0], abs=1e-12)
    assert r["uz.final"] == pytest.approx(0.5 * t, rel=1e-12)
    vel = np.array([1.0, 0.0, 0.5]) + np.cross([0, 0, 2.0], inner - c)
    assert r["vy.final"] == pytest.approx(vel[1], rel=1e-9)
    assert r["v.final"] == pytest.approx(np.linalg.norm(vel), rel=1e-9)


def test_point_and_rotation_errors(session):
    from dec3d.errors import Dec3dError

    with pytest.raises(Dec3dError, match="not both"):
        session.run_items(session.load_text(SPIN + "block history position-x block-id 1 position 0 0 0\n"))
    with pytest.raises(Dec3dError, match="material-point"):         # rvelocity is of the block, not of a point
        session.run_items(session.load_text(SPIN + "block history rvelocity-z block-id 1 material-point 0 0 0\n"))
    with pytest.raises(Dec3dError, match=r"`block-id <i>` \(or `material-point"):
        session.run_items(session.load_text(SPIN + "block history displacement-x\n"))


def test_rotation_and_material_point_histories_continue_after_save_and_restore(tmp_path):
    """Spin past π (rotation unwrapping) and a point fixed to a moving block: 1500 steps, save, restore,
    1500 more give the same CSV as 3000 steps in one go — the unwrapping state and the point's place in
    the block's frame travel in the save file."""
    import io

    from dec3d.session import Session

    hist = ("block initialize velocity-x 1 rvelocity-z 2 range id 1\n"
            "block history name 'rz' rotation-z block-id 1\n"
            "block history name 'px' position-x block-id 1 material-point 1 2 0.5\nhistory interval 100\n")
    a = Session(out_dir=tmp_path / "a", stdout=io.StringIO())
    a.run_items(a.load_text(SPIN + hist + "model cycle 3000\nhistory export 'rz' 'px' file 'h.csv'\n"))
    b = Session(out_dir=tmp_path / "b", stdout=io.StringIO())
    b.run_items(b.load_text(SPIN + hist + "model cycle 1500\nmodel save 'half'\n"))
    c = Session(out_dir=tmp_path / "b", stdout=io.StringIO())
    c.run_items(c.load_text("model restore 'half'\nmodel cycle 1500\nhistory export 'rz' 'px' file 'h.csv'\n"))
    ha, hc = (tmp_path / "a" / "h.csv").read_text(), (tmp_path / "b" / "h.csv").read_text()
    assert ha == hc and len(ha.splitlines()) == 1 + 30
    assert a.results["rz.final"] == pytest.approx(3000 * 2 * math.atan(1e-3), rel=1e-9)   # 6 rad: past π
