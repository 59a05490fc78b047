"""The object API against the model's stores: every getter reads what the store holds, every setter
writes what a cycle then moves with, and bad input is a clear Python exception."""
import numpy as np
import pytest

import dec3d.itasca as it
from it_fixture import fresh_it  # noqa: F401  (autouse: no model bound, a fresh working folder)

TWO = """
model new
block create brick 0 1 0 1 0 1 group 'base'
block create brick 0 1 0 1 1 2 group 'top'
block property density 2000
block contact jmodel assign mohr
block contact property stiffness-normal 1e9 stiffness-shear 1e9 friction 30
model gravity 0 0 -10
block fix range group 'base'
"""


def _store():
    return it.current().session.model


def test_block_getters_read_the_store():
    it.command(TWO)
    it.cycle(20)
    b = _store().blocks
    assert it.block.count() == b.n == 2 and it.block.maxid() == 2
    for blk, r in zip(it.block.list(), range(b.n)):
        assert blk.id() == b["id"][r]
        np.testing.assert_array_equal(blk.pos(), b["centroid"][r])
        np.testing.assert_array_equal(blk.vel(), b["velocity"][r])
        np.testing.assert_array_equal(blk.rvel(), b["spin"][r])
        np.testing.assert_array_equal(blk.disp(), b["disp"][r])
        assert blk.vol() == b["volume"][r] and blk.mass() == b["mass"][r] and blk.density() == 2000
        assert len(blk.faces()) == 6 and len(blk.gridpoints()) == 8
    top = it.block.find(2)
    assert top.group() == "top" and top.in_group("TOP") and not top.in_group("base")
    assert top.groups() == {"Default": "top"}
    assert it.block.find(1).fix() and not top.fix()
    assert it.block.near((0.4, 0.5, 1.9)) == top
    np.testing.assert_allclose(top.mass(), 2000.0, rtol=1e-12)
    # faces and gridpoints: the store's rows
    f = top.faces()[0]
    r = f.id() - 1
    np.testing.assert_array_equal(f.pos(), _store().faces["centroid"][r])
    assert f.block() == top and f.area() == pytest.approx(1.0)
    g = top.gridpoints()[0]
    np.testing.assert_array_equal(g.pos(), _store().vertices["pos"][g.id() - 1])
    assert g.block() == top
    np.testing.assert_allclose(it.gridpointarray.pos()[g.id() - 1], g.pos())
    np.testing.assert_allclose(it.gridpointarray.vel()[g.id() - 1], g.vel())
    np.testing.assert_allclose(it.gridpointarray.disp()[g.id() - 1], g.disp())


def test_contact_and_subcontact_getters_sum_the_subcontact_store():
    it.command(TWO)
    it.cycle(200)
    (c,) = it.block.contact.list()
    assert c.id() == (1, 2) and c.end1().id() == 1 and c.end2().id() == 2
    assert it.block.contact.find(2, 1) == c and it.block.contact.find(1, 1) is None
    st = _store()
    ss = st.stores["subcontacts"]
    subs = c.subcontacts()
    assert len(subs) == ss.n > 0
    assert c.force_norm() == pytest.approx(ss["fn"].sum(), rel=1e-15)
    np.testing.assert_allclose(c.force_shear(), ss["fs"].sum(axis=0))
    assert c.area() == pytest.approx(ss["area"].sum(), rel=1e-15) and c.area() > 0
    np.testing.assert_allclose(c.normal(), [0, 0, 1])
    # the top block's weight rests on the contact (20000 N) after the run settles
    assert c.force_norm() == pytest.approx(20000.0, rel=1e-3)
    for k, s in enumerate(subs):
        assert s.force_norm() == ss["fn"][k] and s.area() == ss["area"][k]
        np.testing.assert_array_equal(s.pos(), ss["pos"][k])
        np.testing.assert_array_equal(s.disp_shear(), ss["us"][k])
        assert s.contact() == c
    assert it.block.subcontact.count() == ss.n
    # out-of-balance loads: the settled top block is in balance; the fixed base needs the reaction of both
    # weights (20 kN each); Python reads what FISH reads
    base, top = it.block.find(1), it.block.find(2)
    assert abs(top.force_unbal()).max() < 20000.0 * 1e-3
    assert base.force_unbal()[2] == pytest.approx(-40000.0, rel=1e-3)
    it.command("[fu = block.force.unbal.z(1)]\n[mu = block.moment.x(1)]")
    assert it.fish.get("fu") == base.force_unbal()[2] and it.fish.get("mu") == base.moment_unbal()[0]


def test_setters_then_cycle():
    it.command("""
model new
block create brick 0 1 0 1 0 1
block property density 1000
block mechanical damping local 0
""")
    b = it.block.find(1)
    b.set_vel((0.5, 0, 0))
    it.cycle(10)
    t = it.mech_age()
    assert t > 0
    np.testing.assert_allclose(b.disp(), [0.5 * t, 0, 0], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(b.pos(), [0.5 + 0.5 * t, 0.5, 0.5], rtol=1e-12)
    # an applied force accelerates the free block: v = F/m t
    b.set_vel((0, 0, 0))
    b.set_force_app((0, 0, 300.0))
    t0 = it.mech_age()
    it.cycle(10)
    np.testing.assert_allclose(b.vel()[2], 300.0 / 1000.0 * (it.mech_age() - t0), rtol=1e-9)
    b.set_density(2500)
    assert b.mass() == pytest.approx(2500.0)
    b.set_group("g1", "slotA")
    assert b.group("slotA") == "g1" and b.in_group("g1") and b.group() == ""
    # fixed, the block stays where it is under its applied force; freed, the force moves it again
    b.set_vel((0, 0, 0))
    b.set_fix(True)
    p0 = b.pos()
    it.cycle(5)
    assert b.fix() and (b.fixity() & 0b111111) == 0b111111
    np.testing.assert_array_equal(b.pos(), p0)
    b.set_fix(False)
    assert not b.fix()
    it.cycle(5)
    assert b.pos()[2] > p0[2]


def test_bad_input_is_a_clear_python_exception():
    it.command(TWO)
    assert it.block.find(99) is None
    with pytest.raises(TypeError, match="block id"):
        it.block.find("1")
    b = it.block.find(2)
    with pytest.raises(ValueError, match="no group slot 'nope'"):
        b.group("nope")
    with pytest.raises(ValueError, match="shape"):
        b.set_vel((1, 2))
    with pytest.raises(ValueError, match="finite"):
        b.set_vel((1, np.nan, 0))
    with pytest.raises(ValueError, match="density"):
        b.set_density(-1)
    it.command("block delete range id 2")
    with pytest.raises(ValueError, match="block 2 does not exist any more"):
        b.pos()
    with pytest.raises(ValueError, match="no zone"):
        it.block.zone.Zone(it.current(), 5).vol()
    with pytest.raises(ValueError, match="no gridpoint"):
        it.block.gridpoint.Gridpoint(it.current(), 10_000).pos()
    with pytest.raises(it.ItascaError, match=r"test_objects.py:\d+:27: error: unknown command"):
        it.command("block frobnicate 1")
    with pytest.raises(TypeError, match="string"):
        it.command(3)
    with pytest.raises(ValueError, match="whole number"):
        it.cycle(-1)


def test_contact_that_is_gone_is_an_error():
    it.command(TWO)
    (c,) = it.block.contact.list()
    it.command("block delete range id 2")
    with pytest.raises(ValueError, match="gone"):
        c.force_norm()


def test_fish_get_set_round_trip():
    it.command(TWO)
    it.fish.set("load", 2.5)
    it.fish.set("dir", np.array([0.0, 0.0, 1.0]))
    it.command("""
fish define twice
    twice = load * 2
end
[result = twice]
[up = block.pos.z(2) + vector.z(dir)]
""")
    assert it.fish.get("result") == 5.0 and it.fish.get("twice") == 5.0
    assert it.fish.get("up") == pytest.approx(2.5)
    np.testing.assert_array_equal(it.fish.get("dir"), [0, 0, 1])
    it.command("fish define scaled(a, v)\n    scaled = a * vector.z(v)\nend")
    assert it.fish.call_function("scaled", 3, np.array([0, 0, 2.0])) == 6.0
    with pytest.raises(KeyError, match="no FISH function 'nope'"):
        it.fish.call_function("nope")
    with pytest.raises(it.ItascaError, match="FISH function 'scaled' failed"):
        it.fish.call_function("scaled", "text", (0, 0, 1))
    with pytest.raises(KeyError, match="no FISH variable 'nothing'"):
        it.fish.get("nothing")
    with pytest.raises(ValueError, match="finite"):
        it.fish.set("x", float("inf"))
    with pytest.raises(ValueError, match="function"):
        it.fish.set("twice", 1)


def test_globals():
    it.command("python-reset-state false")
    it.set_gravity((0, 0, -9.81))
    np.testing.assert_array_equal(it.gravity(), [0, 0, -9.81])
    assert it.current().session.model.settings.gravity == (0.0, 0.0, -9.81)
    with pytest.raises(ValueError, match="finite"):
        it.set_gravity((0, 0, np.nan))
    assert it.deterministic() and it.dim() == 3 and it.threads() >= 1
    assert it.timestep() == 0.0 and it.mech_age() == 0.0
