"""Flow in the joints through the commands (`model configure fluid`, `block fluid …`, `flowplane property`,
`flowknot apply …`): the network follows the contacts, bad input refused with its place, save/restore
continues bit for bit, outputs (VTK, FISH, histories). Numbers against closed forms: verification/W4–W6."""
import numpy as np
import pytest

from dec3d.errors import Dec3dError
from dec3d.physics.rigid import engine

JOINT = """model new
model configure fluid
block create brick 0 10 0 2 -1 0
block create brick 0 10 0 2 0 1
block property density 2000
block fix
block contact jmodel assign mohr
block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 friction 30
flowplane property aperture-initial 1e-4 aperture-minimum 1e-5 aperture-maximum 1e-3
"""


def _run(session, text):
    session.run_items(session.load_text(text))
    return engine(session.model)


def test_steady_flow_reaches_the_sub_contacts_and_transient_tends_to_it(session):
    """Steady: the sub-contacts take the knots' linear pressure; the explicit steps in the cycle run to the
    same state (five diffusion times)."""
    e = _run(session, JOINT + "flowknot apply pore-pressure 1e5 range position-x 0\n"
                              "flowknot apply pore-pressure 0 range position-x 10\nblock fluid solve-steady\n")
    ss = e.subcontacts
    assert ss["pp"] == pytest.approx(1e5 * (1 - ss["pos"][:, 0] / 10), abs=1e-6)
    assert ss["ppf"].sum() == pytest.approx(0.5e5 * 20, rel=1e-9)
    steady = session.model.store("flowknots")["pp"].copy()
    d = 2e9 * 1e-8 / 12e-3
    _run(session, f"flowknot initialize pore-pressure 0\nblock mechanical timestep {5 * 100 / d / 50}\nmodel cycle 50\n")
    assert session.model.store("flowknots")["pp"] == pytest.approx(steady, abs=0.01 * 1e5)


def test_the_network_follows_the_contacts_and_keeps_its_conditions(session):
    """A third block makes a second joint: the network is built again at the next cycle, the knots of the
    first joint keep their pressure boundaries."""
    e = _run(session, JOINT + "block fluid zone-size 2.5\nflowknot apply pore-pressure 1e5 range position-x 0\n"
                              "model cycle 1\n")
    kn = session.model.store("flowknots")
    n0, fixed0 = kn.n, int(kn["fixed"].sum())
    assert n0 == 5 * 2 and fixed0 == 2
    _run(session, "block create brick 0 10 0 2 1 2\nblock property density 2000\nblock fix\nmodel cycle 1\n")
    assert kn.n == 2 * 5 * 2 and int(kn["fixed"].sum()) == 2     # (z = 0 keeps its two; the new joint's are free)
    assert len(session.model.store("flowsubs")["knot"]) == e.subcontacts.n


@pytest.mark.parametrize("line, message", [
    ("block fluid property viscosity 0\n", "viscosity"),
    ("block fluid property bulk -1\n", "bulk"),
    ("flowplane property aperture-initial -1e-4\n", "aperture-initial"),
    ("flowplane property aperture-minimum 2e-3 aperture-maximum 1e-3\n", "aperture-minimum 0.002 is above"),
    ("flowknot apply pore-pressure 1e5 range position-x 50\n", "holds no flow knot"),
    ("flowknot apply gradient 5 discharge 1\n", "goes with `pore-pressure`"),
    ("flowknot apply\n", "needs one of pore-pressure"),
    ("block fluid solve-steady\n", "no flow knot has a pressure boundary"),
])
def test_bad_input_is_refused_with_its_place(session, line, message):
    with pytest.raises(Dec3dError) as err:
        _run(session, JOINT + line)
    assert message in str(err.value)
    assert ":10:" in err.value.format()          # the line of the command in the deck


def test_fluid_commands_need_configure(session):
    with pytest.raises(Dec3dError, match="needs `model configure fluid` first"):
        _run(session, JOINT.replace("model configure fluid\n", ""))


def test_save_restore_continues_bit_identically(session, tmp_path):
    deck = JOINT + ("block fluid zone-size 2\nflowknot apply pore-pressure 1e5 range position-x 0\n"
                    "block mechanical timestep 1e-3\n")
    _run(session, deck + "model cycle 20\n")
    whole = session.model.store("flowknots")["pp"].copy()
    _run(session, deck + f"model cycle 10\nmodel save '{tmp_path / 'half.d3s'}'\n")
    _run(session, f"model new\nmodel restore '{tmp_path / 'half.d3s'}'\nmodel cycle 10\n")
    assert np.array_equal(session.model.store("flowknots")["pp"], whole)
    assert not np.all(whole == whole[0])


def test_fish_and_vtk_and_fluid_off(session, tmp_path):
    _run(session, JOINT + "flowknot apply pore-pressure 1e5 range position-x 0\n"
                          "flowknot apply pore-pressure 0 range position-x 10\nblock fluid solve-steady\n"
                          "[c = block.contact.find(1, 2)]\n[fp = block.contact.flow.pp(c)]\n"
                          "[fa = block.contact.flow.aperture(c)]\n[fr = block.contact.flow.rate(c)]\n"
                          "[nk = flowknot.num]\n[v = flowknot.volume(1)]\n")
    v = session.variables
    assert v["fp"] == pytest.approx(5e4, rel=1e-9)
    assert v["fa"] == pytest.approx(1e-4, rel=1e-9)
    assert v["fr"] == pytest.approx(1e-12 / 12e-3 * 1e5 / 10, rel=1e-9)       # m²/s: q / w
    # (a third of each triangle at its corners: the two triangles of the rectangle meet at two of the four)
    assert v["nk"] == 4 and min(abs(v["v"] / (1e-4 * 10 / 3) - k) for k in (1, 2)) < 1e-9
    from dec3d.io.contactvtk import contact_point_data

    _pts, data = contact_point_data(session.model)
    assert "flow_rate" in data and data["flow_pressure"] == pytest.approx(np.full(len(_pts), 5e4))
    e = _run(session, "model fluid active off\n")
    assert np.all(e.subcontacts["pp"] == 0.0)


def test_histories_of_pressure_and_discharge_and_their_save(session, tmp_path):
    """A pressure step at x = 0: the pressure at mid-joint rises towards the steady 5e4 Pa and the inflow
    falls towards the cubic law's; both histories survive a save and restore."""
    d = 2e9 * 1e-8 / 12e-3
    _run(session, JOINT + "block fluid zone-size 1\nflowknot apply pore-pressure 1e5 range position-x 0\n"
                          "flowknot apply pore-pressure 0 range position-x 10\n"
                          f"block mechanical timestep {4 * 100 / d / 40}\nhistory interval 1\n"
                          "flowknot history name 'pm' pore-pressure position 5 1 0\n"
                          "flowknot history name 'qin' discharge position 0 1 0\nmodel cycle 40\n"
                          f"model save '{tmp_path / 'h.d3s'}'\nmodel new\nmodel restore '{tmp_path / 'h.d3s'}'\n")
    from dec3d.physics.history import histories

    hs = histories(session.model)
    pm, qin = hs.find("pm"), hs.find("qin")
    assert len(pm.values) == 40 and pm.values[0] < pm.values[-1]
    assert pm.values[-1] == pytest.approx(5e4, rel=0.02)
    # the knot at (0, 1, 0) supplies its share of q = a³ w ΔP / (12 μ L): the middle one of the edge's three
    assert qin.values[-1] == pytest.approx(0.5 * 1e-12 * 2 * 1e5 / (12e-3 * 10), rel=0.02)
    assert qin.values[0] > qin.values[-1]


def test_dam_example_with_uplift_from_flow(tmp_path):
    """examples/water/dam_foundation_flow.dat: the uplift from the steady flow in the base joint, 360 kN
    undrained and 120 kN with a drain at x = 2 held at 7.5 kPa (the pressure inside the contact reaches the
    dam through the flow zones' forces); FS (W − U) tan 45° / P = 2.0741 and 2.6667 to the bracket's 0.01."""
    from conftest import ROOT
    from dec3d.session import run_deck

    s = run_deck(ROOT / "examples" / "water" / "dam_foundation_flow.dat", out_dir=tmp_path)
    assert s.variables["uplift_drained"] == pytest.approx(120e3, rel=1e-9)
    assert s.results["fos.1"] == pytest.approx((1.2e6 - 360e3) / 405e3, abs=0.01)
    assert s.results["fos.2"] == pytest.approx((1.2e6 - 120e3) / 405e3, abs=0.01)


def test_a_zone_size_far_too_small_is_refused(session):
    with pytest.raises(Dec3dError, match="larger `block fluid zone-size`"):
        _run(session, JOINT + "block fluid zone-size 1e-4\nflowknot apply pore-pressure 1 range position-x 0\n")


def test_a_vertical_joint_open_at_its_top_holds_water_at_rest(session):
    """A vertical joint 4 m high held at p = 0 at its top: the steady state is hydrostatic, ρ g (4 − z), once
    gravity is given (the pipes' gravity term follows `model gravity` given after the network was built)."""
    deck = """model new
model configure fluid
block create brick 0 1 0 1 0 4
block create brick 1 2 0 1 0 4
block property density 2000
block fix
block contact jmodel assign mohr
block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 friction 30
block fluid zone-size 1
flowplane property aperture-initial 1e-4 aperture-minimum 1e-5 aperture-maximum 1e-3
flowknot apply pore-pressure 0 range position-z 4
block fluid solve-steady
"""
    _run(session, deck)
    kn = session.model.store("flowknots")
    assert np.all(kn["pp"] == 0.0)
    _run(session, "model gravity 0 0 -10\nblock fluid solve-steady\n")
    assert kn["pp"] == pytest.approx(1000 * 10 * (4 - kn["pos"][:, 2]), abs=1e-6)


def test_a_zoned_block_takes_the_flow_pressure_on_its_gridpoints(session):
    """A zoned cube on a fixed rigid base: the sub-contacts at its face gridpoints are the knots (3 × 3); the
    pressure held on one edge fills the joint and the joint law keeps (σn − p) A."""
    _run(session, """model new
model configure fluid
block create brick 0 1 0 1 0 1
block create brick 0 1 0 1 1 2
block property density 2000
block zone generate edgelength 0.5 range position-z 1 2
block zone cmodel assign elastic
block zone property young 1e9 poisson 0.25 density 2000
model gravity 0 0 -10
block fix range position-z 0 1
block contact jmodel assign elastic
block contact material-table default property stiffness-normal 1e10 stiffness-shear 1e10
flowplane property aperture-initial 1e-4 aperture-minimum 1e-5 aperture-maximum 1e-3
flowknot apply pore-pressure 5000 range position-x 0
model cycle 200
[pfar = flowknot.pp(flowknot.near(1, 1, 1))]
[fn = block.contact.force.norm(block.contact.find(1, 2))]
""")
    assert session.model.store("flowknots").n == 9
    assert session.variables["pfar"] == pytest.approx(5000, rel=1e-6)
    assert session.variables["fn"] == pytest.approx(20000 - 5000, rel=1e-3)


def test_an_inflow_at_one_end_raises_the_pressure_by_the_cubic_law(session):
    """1e-6 m³/s put in at x = 0 (half at each of its two knots), the far end held at 0: steady
    p(0) = Q 12 μ L / (a³ w) = 6e4 Pa; `flowknot apply-remove` takes the inflow away again."""
    _run(session, JOINT + "flowknot apply discharge 0.5e-6 range position-x 0\n"
                          "flowknot apply pore-pressure 0 range position-x 10\nblock fluid solve-steady\n"
                          "[p0 = flowknot.pp(flowknot.near(0, 0, 0))]\n[q0 = flowknot.discharge(flowknot.near(0, 0, 0))]\n"
                          "flowknot apply-remove range position-x 0\nblock fluid solve-steady\n"
                          "[p1 = flowknot.pp(flowknot.near(0, 0, 0))]\n")
    v = session.variables
    assert v["p0"] == pytest.approx(1e-6 * 12e-3 * 10 / (1e-12 * 2), rel=1e-9)
    assert v["q0"] == pytest.approx(0.5e-6, rel=1e-12)
    assert v["p1"] == pytest.approx(0.0, abs=1e-6)


def test_fluid_list_prints_the_network_and_its_stable_step(session):
    _run(session, JOINT + "flowknot apply pore-pressure 0 range position-x 10\nblock fluid list\n")
    text = session.output.getvalue()
    # 0.5 V / (K_w Σc) at the free knot of x = 0 off the diagonal: V = a (wL/2)/3, Σc = T (w/(2L) + L/(2w))
    t = 1e-12 / 12e-3
    want = 0.5 * (1e-4 * 10 / 3) / (2e9 * t * (0.1 + 2.5))
    assert f"4 knots, 5 pipes, stable flow step {want:.4g} s" in text
