"""Pore pressure in the joints (dec3d.physics.water, `block water`, `block contact apply pore-pressure`): effective
stress in the cycle, the water table, FISH, save/restore,
bad input (the kernels against their twins: test_water_kernels.py)."""
import numpy as np
import pytest

from dec3d.errors import Dec3dError
from dec3d.physics.rigid import engine

STACK = """model new
block create brick 0 1 0 1 -1 0
block create brick 0 1 0 1 0 1
block property density 2000
model gravity 0 0 -10
block fix range position-z -1 0
block contact jmodel assign mohr
block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 friction 30
"""


def _run(session, text):
    session.run_items(session.load_text(text))
    return engine(session.model)


# ---------------------------------------------------------------- the cycle

def test_effective_normal_force_and_total_balance(session):
    """A cube on a fixed base with p = 5 kPa on the joint: the joint law keeps (σn − p) A, the unbalanced
    force counts the water (the solve converges), and p = σn makes the normal force zero."""
    e = _run(session, STACK + "block contact apply pore-pressure 5000\nmodel solve ratio 1e-8\n")
    ss = e.subcontacts
    assert ss["fn"].sum() == pytest.approx(20000 - 5000, rel=1e-6)
    assert ss["ppf"].sum() == pytest.approx(5000, rel=1e-12)
    assert np.all(ss["pp"] == 5000)
    e = _run(session, "block contact apply pore-pressure 15000\nmodel cycle 400\n")
    assert abs(e.subcontacts["fn"].sum()) < 1e-3 * 20000


def test_water_table_pressure_and_gravity_given_later(session):
    """`block water` before `model gravity`: the pressures come when gravity is known (before the next
    cycle); `block water clear` takes them away."""
    text = STACK.replace("model gravity 0 0 -10\n", "") + "block water density 1000\nblock water plane normal 0 0 1 origin 0 0 2\n"
    e = _run(session, text)
    assert np.all(e.subcontacts["pp"] == 0.0)           # no gravity yet
    e = _run(session, "model gravity 0 0 -10\nmodel cycle 1\n")
    assert e.subcontacts["pp"] == pytest.approx(np.full(e.subcontacts.n, 1000 * 10 * 2.0))
    e = _run(session, "model solve ratio 1e-8\n")
    assert e.subcontacts["fn"].sum() == pytest.approx(20000 - 20000, abs=1e-3)  # W = 20 kN, U = 20 kN: floating
    e = _run(session, "block water clear\nmodel cycle 1\n")
    assert np.all(e.subcontacts["pp"] == 0.0) and np.all(e.subcontacts["ppf"] == 0.0)


def test_fish_reads_the_pressures(session):
    _run(session, STACK + "block contact apply pore-pressure 3000\nmodel cycle 10\n"
                          "[c = block.contact.find(1, 2)]\n[pc = block.contact.pp(c)]\n"
                          "[sl = block.contact.subcontactlist(c)]\n[ps = block.subcontact.pp(sl(1))]\n")
    assert session.variables["pc"] == pytest.approx(3000)
    assert session.variables["ps"] == pytest.approx(3000)


def test_save_restore_keeps_the_pressures_and_continues_bit_identically(session, tmp_path):
    deck = STACK + "block contact apply pore-pressure 19000\nblock mechanical damping none\n"
    _run(session, deck + "model cycle 300\n")
    whole = session.model.blocks["centroid"].copy()
    _run(session, deck + f"model cycle 150\nmodel save '{tmp_path / 'half.d3s'}'\n")
    _run(session, f"model new\nmodel restore '{tmp_path / 'half.d3s'}'\n")
    assert np.all(engine(session.model).subcontacts["pp"] == 19000)
    _run(session, "model cycle 150\n")
    assert np.array_equal(session.model.blocks["centroid"], whole)


# ---------------------------------------------------------------- bad input

@pytest.mark.parametrize("line, message", [
    ("block water\n", "needs one of density, plane, clear, list"),
    ("block water plane normal 0 0 1\n", "needs `normal nx ny nz` and `origin x y z`"),
    ("block water normal 0 0 1 origin 0 0 0\n", "belongs to `block water plane`"),
    ("block water plane normal 0 0 0 origin 0 0 0\n", "normal is the zero vector"),
    ("block water density -1\n", "density"),
    ("block contact apply\n", "needs `pore-pressure <p>`"),
    ("block contact apply pore-pressure 1e5 range position-z 5 6\n", "no contact in range"),
])
def test_bad_input_is_refused_with_its_place(session, line, message):
    with pytest.raises(Dec3dError) as err:
        _run(session, STACK + line)
    assert message in str(err.value)
    text = err.value.format()
    assert ":9:" in text                        # the line of the command in the deck
    assert engine(session.model).subcontacts["pp"].sum() == 0.0


def test_no_contacts_refused(session):
    with pytest.raises(Dec3dError, match="no contacts"):
        _run(session, "model new\nblock create brick 0 1 0 1 0 1\nblock contact apply pore-pressure 1\n")


def test_dam_example_factors_of_safety(tmp_path):
    """examples/water/dam_foundation.dat: sliding FS (W − U) tan 45° / P by hand: 2.0741 without drainage
    (U = ½ γw H B), 2.6667 with a third of the uplift; the strength reduction brackets each to 0.01."""
    from conftest import ROOT
    from dec3d.session import run_deck

    s = run_deck(ROOT / "examples" / "water" / "dam_foundation.dat", out_dir=tmp_path)
    assert s.results["fos.1"] == pytest.approx((1.2e6 - 360e3) / 405e3, abs=0.01)
    assert s.results["fos.2"] == pytest.approx((1.2e6 - 120e3) / 405e3, abs=0.01)


D7 = """model new
block create brick 0 1 0 1 0 1
block create brick 0 1 0 1 1 2
block property density 2000
block zone generate edgelength 0.5 range position-z 0 1
block zone cmodel assign elastic
block zone property young 1e9 poisson 0.25 density 2000
model gravity 0 0 -10
block contact jmodel assign elastic
block contact material-table default property stiffness-normal 1e10 stiffness-shear 1e10
block gridpoint apply velocity-z 0 range position-z 0
block gridpoint apply velocity-x 0 range position-x 0
block gridpoint apply velocity-x 0 range position-x 1
block gridpoint apply velocity-y 0 range position-y 0
block gridpoint apply velocity-y 0 range position-y 1
"""


def test_a_zoned_side_takes_the_water_on_its_gridpoints(session):
    """A rigid cube on a zoned one (D7, the mixed-contact path): with p = 8 kPa in the joint the joint keeps
    W − p A (the water carries the rest) and taking the pressure away gives the dry joint force back."""
    e = _run(session, D7 + "block contact apply pore-pressure 8000\nmodel solve ratio 1e-7\n")
    assert e.subcontacts["fn"].sum() == pytest.approx(20000 - 8000, rel=1e-4)
    assert e.subcontacts["ppf"].sum() == pytest.approx(8000, rel=1e-12)
    e = _run(session, "block contact apply pore-pressure -8000\nmodel solve ratio 1e-7\n")
    assert e.subcontacts["fn"].sum() == pytest.approx(20000, rel=1e-4)


def test_a_pressure_that_is_not_finite_is_refused(session):
    with pytest.raises(Dec3dError, match="not finite"):
        _run(session, STACK + "block water density 1e300\nblock water plane normal 0 0 1 origin 0 0 1e12\n")


def test_contact_history_of_the_pore_pressure(session):
    _run(session, STACK + "block contact history name 'pw' pore-pressure position 0.5 0.5 0\nhistory interval 1\n"
                          "model cycle 2\nblock contact apply pore-pressure 4000\nmodel cycle 2\n")
    h = [x for x in session.model.history_set.items if x.name == "pw"][0]
    assert h.values[0] == 0.0 and h.values[-1] == pytest.approx(4000.0)


def test_insitu_pore_pressure_with_a_gradient(session):
    """`block insitu pore-pressure p0 gradient g`: p0 + g·x on the joints (here at z = 0 and x, y in 0..1)."""
    e = _run(session, STACK + "block insitu pore-pressure 1000 gradient 200 0 -5000\n")
    ss = e.subcontacts
    assert ss["pp"] == pytest.approx(1000 + 200 * ss["pos"][:, 0])
    e = _run(session, "model solve ratio 1e-8\n")
    assert e.subcontacts["fn"].sum() == pytest.approx(20000 - 1100, rel=1e-5)   # mean pressure 1100 Pa on 1 m²
    with pytest.raises(Dec3dError, match="goes with `pore-pressure`"):
        _run(session, STACK + "block insitu gradient 0 0 1\n")
