"""Engine state in the model: save/restore mid-run, contact ranges, groups and resets,
damping modes, density scaling, joined blocks."""
import numpy as np
import pytest

from dec3d.physics.rigid import engine
from test_engine import DECK

SPRING = DECK          # the block on a joint spring of test_engine.py

STACK3 = """model new
block create brick 0 1 0 1 -1 0
block create brick 0 1 0 1 0 1
block create brick 0 1 0 1 1 2
block property density 2000
model gravity 0 0 -10
block contact jmodel assign mohr
block contact property stiffness-normal 1e8 stiffness-shear 1e8 friction 30
block fix range position-z -1 0
"""


def _run(session, text):
    session.run_items(session.load_text(text))
    return engine(session.model)


def _disp(session, z):
    b = session.model.blocks
    r = int(np.argmin(np.abs(b["centroid"][:, 2] - z)))
    return float(b["disp"][r, 2])


def test_save_restore_mid_run_continues_bit_identically(session, tmp_path):
    """Contacts, sub-contact forces and engine settings travel in the save file: a run saved
    half-way and restored ends exactly where an uninterrupted run ends."""
    deck = STACK3 + "block mechanical damping none\nblock initialize velocity-x 0.01 range position-z 1 2\n"
    _run(session, deck + "model cycle 300\n")
    whole = session.model.blocks["centroid"].copy()
    _run(session, deck + f"model cycle 150\nmodel save '{tmp_path / 'half.d3s'}'\n")
    half_sc = engine(session.model).subcontacts["fs"].copy()
    assert np.abs(half_sc).max() > 0
    _run(session, f"model new\nmodel restore '{tmp_path / 'half.d3s'}'\n")
    e = engine(session.model)
    assert np.array_equal(e.subcontacts["fs"], half_sc)
    assert session.model.step == 150
    _run(session, "model cycle 150\n")
    assert np.array_equal(session.model.blocks["centroid"], whole)


def test_contact_property_range_selects_contacts_by_position(session):
    """Joint 1 (z = 0) stiff, joint 2 (z = 1) soft: closures follow each joint's kn."""
    _run(session, STACK3 + "block contact property stiffness-normal 4e8 range position-z -0.01 0.01\n"
                           "model solve ratio 1e-8\n")
    e = engine(session.model)
    c = e.contacts
    kn = c["prop"][:, 0]
    z = c["pos"][:, 2]
    assert kn[np.abs(z) < 0.01].tolist() == [4e8] and kn[np.abs(z - 1) < 0.01].tolist() == [1e8]
    w = 2000 * 10.0          # weight of one cube [N]
    # joint 1 carries 2 w at kn 4e8, joint 2 carries w at kn 1e8 (area 1 m²)
    assert _disp(session, 0.5) == pytest.approx(-2 * w / 4e8, rel=2e-3)
    assert _disp(session, 1.5) - _disp(session, 0.5) == pytest.approx(-w / 1e8, rel=2e-3)


def test_contact_group_then_range_group(session):
    _run(session, STACK3 + "block contact group 'top' range position-z 0.99 1.01\n"
                           "block contact property friction 10 range group 'top'\n")
    e = engine(session.model)
    c = e.contacts
    names = [session.model.groups.name(g) if g >= 0 else None for g in c["group"][:, 0]]
    top = np.array([n == "top" for n in names])
    assert top.sum() == 1 and abs(c["pos"][top][0, 2] - 1.0) < 1e-6
    assert np.degrees(np.arctan(c["prop"][top, 2]))[0] == pytest.approx(10.0)
    assert np.degrees(np.arctan(c["prop"][~top, 2]))[0] == pytest.approx(30.0)


def test_group_intersection_selects_contacts_between_two_block_groups(session):
    _run(session, STACK3 + "block group 'base' range position-z -1 0\nblock group 'mid' range position-z 0 1\n"
                           "block contact property cohesion 5e4 range group-intersection 'base' 'mid'\n")
    c = engine(session.model).contacts
    coh = c["prop"][:, 3]
    assert sorted(coh.tolist()) == [0.0, 5e4] and abs(c["pos"][coh > 0][0, 2]) < 1e-6


def test_contact_reset_displacement_keeps_forces(session):
    _run(session, STACK3 + "block apply force-x 5e3 range position-z 1 2\nmodel cycle 200\n")
    ss = engine(session.model).subcontacts
    fn = ss["fn"].copy()
    assert np.abs(ss["us"]).max() > 0
    _run(session, "block contact reset displacement\n")
    assert np.abs(ss["us"]).max() == 0 and np.array_equal(ss["fn"], fn)


def test_property_of_a_model_without_it_is_an_error(session):
    from dec3d.errors import Dec3dError

    with pytest.raises(Dec3dError, match="no property 'friction'"):
        _run(session, SPRING + "block contact property friction 30\n")


@pytest.mark.parametrize("damping", ["local", "combined", "global"])
def test_every_static_damping_settles_at_mg_over_k(session, damping):
    _run(session, SPRING + f"block mechanical damping {damping}\nmodel solve ratio 1e-6\n")
    assert _disp(session, 0.5) == pytest.approx(-2.000e-3, rel=2e-3)


def test_density_scaling_settles_blocks_of_very_different_mass(session):
    """A 0.1 m cube on a 1 m cube on the base: the damped run with density scaling reaches
    the static closures w/kn of each joint."""
    deck = """model new
block create brick 0 1 0 1 -1 0
block create brick 0 1 0 1 0 1
block create brick 0.4 0.5 0.4 0.5 1 1.1
block property density 2000
model gravity 0 0 -10
block contact jmodel assign elastic
block contact property stiffness-normal 1e8 stiffness-shear 1e8
block fix range position-z -1 0
model solve ratio 1e-7
"""
    e = _run(session, deck)
    assert e.mass_scaling()
    w_small, w_big = 2000 * 10 * 1e-3, 2000 * 10.0
    assert _disp(session, 0.5) == pytest.approx(-(w_big + w_small) / 1e8, rel=3e-3)
    assert _disp(session, 1.05) - _disp(session, 0.5) == pytest.approx(-w_small / (1e8 * 0.01), rel=3e-3)


def test_joined_blocks_move_as_one_and_rest_on_their_base(session):
    _run(session, STACK3 + "block join range position-z 0 2\nmodel solve ratio 1e-7\n")
    b = session.model.blocks
    lo, hi = _disp(session, 0.5), _disp(session, 1.5)
    assert lo == pytest.approx(hi, abs=1e-12)                     # rigidly together
    assert lo == pytest.approx(-2 * 2000 * 10 / 1e8, rel=3e-3)   # on the base joint only
    assert np.abs(b["spin"]).max() < 1e-9


def test_cycle_timing_prints_the_phase_breakdown(session):
    _run(session, SPRING + "model cycle 50 timing\n")
    text = session.output.getvalue()
    assert "50 steps" in text
    for phase in ("detection", "neighbour search", "sub-contacts", "cycle kernel", "histories"):
        assert phase in text


def test_block_vtk_interval_writes_snapshots_while_cycling(session, tmp_path):
    import pyvista as pv

    _run(session, SPRING + f"block vtk filename '{tmp_path / 'snap'}' interval 20\nmodel cycle 100\n")
    files = sorted(tmp_path.glob("snap_[0-9]*.vtu"))             # (the joints files are snap_joints_*)
    assert len(files) == 6                                      # step 0, then 20, 40, 60, 80, 100
    assert len(sorted(tmp_path.glob("snap_joints_*.vtu"))) == 6
    pvd = (tmp_path / "snap.pvd").read_text()
    assert pvd.count("<DataSet") == 12 and pvd.count('part="1"') == 6          # blocks (part 0) and joints
    last = pv.read(files[-1])
    assert np.isclose(last.points[:, 2].max(), 1.0 + session.model.blocks["disp"][1, 2], atol=1e-12)


def test_fast_block_gets_its_contact_before_it_meets_the_base(session):
    """Default settings (Δt 2.8 ms: 1.3 cm of fall per step against a 5 mm CTOL): the
    dropped cube has its contact before touching, so the bounce returns to the release
    height (R4 with the defaults)."""
    deck = """model new
block create brick 0 1 0 1 -1 0
block create brick 0 1 0 1 1 2
block property density 2000
model gravity 0 0 -10
block contact jmodel assign elastic
block contact material-table default property stiffness-normal 10e6 stiffness-shear 10e6
block fix range position-z -1 0
block mechanical damping none
block history name 'uz' displacement-z position 0.5 0.5 1.5
history interval 1
model solve time 1.6
"""
    _run(session, deck)
    from dec3d.physics.history import histories

    h = histories(session.model).find("uz")
    t, uz = np.array(h.times), np.array(h.values)
    assert uz[t < 0.4].min() < -0.7 and uz[t > 0.6].max() == pytest.approx(0.0, abs=0.02)


def test_tall_block_topples_about_its_edge_without_sliding(session):
    """R1 toppling case: b/h = 0.4 < tan 30°, φ = 40° > 30°: the block turns about its
    downhill edge, which neither slides nor sinks into the base."""
    deck = """model new
block create brick -5 40 -5 15 -2 0
block create brick 0 10 0 10 0 25
block property density 2000
block contact jmodel assign mohr
block contact material-table default property stiffness-normal 10e6 stiffness-shear 10e6 friction 40
block fix range position-z -2 0
model gravity 0 0 -10
model solve ratio 1e-6
model gravity [10.0 * math.sin(30.0 * math.pi / 180.0)] 0 [-10.0 * math.cos(30.0 * math.pi / 180.0)]
block mechanical damping none
"""
    _run(session, deck)
    m = session.model
    v, b = m.vertices, m.blocks
    r = int(np.flatnonzero(b["id"] == 2)[0])
    rows = np.arange(b["vert_start"][r], b["vert_start"][r] + b["vert_count"][r])
    pivot = rows[(np.abs(v["pos"][rows, 0] - 10) < 0.01) & (np.abs(v["pos"][rows, 2]) < 0.1)]
    assert len(pivot) == 2
    top = rows[(np.abs(v["pos"][rows, 0]) < 0.01) & (v["pos"][rows, 2] > 24)]
    p0, t0 = v["pos"][pivot].copy(), v["pos"][top].copy()
    # 2.4 s of model time (600 steps of 4 ms when the fixed base still bounded the step; the step
    # follows the moving block only now, physics.rigid.RigidEngine.timestep)
    _run(session, "model solve time 2.4\n")
    assert b["spin"][r, 1] > 0.1                                   # turning towards +x
    edge = np.linalg.norm(v["pos"][pivot] - p0, axis=1).max()
    assert np.linalg.norm(v["pos"][top] - t0, axis=1).min() > 10 * edge   # the edge stays put:
    assert edge < 0.2                                              # elastic bounce of a 1e7 Pa/m joint only
    assert v["pos"][rows, 2].min() > -0.25                         # a 1 % point area sank it 1.8 m
    assert b["disp"][r, 2] > 0.1                                   # the centroid rises as it pivots


def test_kinetic_energy_history_of_a_free_fall(session, tmp_path):
    """½ m v² of a cube falling freely, undamped: after n steps the velocity is n g Δt."""
    deck = """model new
block create brick 0 1 0 1 10 11
block property density 2000
model gravity 0 0 -10
block mechanical damping none
model history name 'ke' mechanical kinetic-energy
history interval 10
model cycle 100
"""
    e = _run(session, deck)
    from dec3d.physics.history import histories

    h = histories(session.model).find("ke")
    v = 10.0 * np.array(h.steps) * e.dt
    assert np.allclose(h.values, 0.5 * 2000.0 * v ** 2, rtol=1e-9)
