"""Zones, gridpoints of zoned blocks and cable structures through the Python API, against the stores."""
import numpy as np
import pytest

import dec3d.itasca as it
from it_fixture import fresh_it  # noqa: F401  (autouse: no model bound, a fresh working folder)

ZONED = """
model new
block create brick 0 1 0 1 0 1
block zone generate edgelength 0.5
block zone cmodel assign elastic
block zone property young 1e9 poisson 0.25 density 2000
model gravity 0 0 -10
"""

HANG = """model new
block create brick -0.5 0.5 -0.5 0.5 -1 0
block property density 2000
model gravity 0 0 -10
structure cable create by-line 0 0 -0.9 0 0 2 segments 29
structure cable property young 200e9 cross-sectional-area 1e-4 grout-stiffness 1e8 grout-cohesion 1e9
structure node fix velocity range id 30
"""


def test_zones_and_zonearray_read_the_zone_store():
    it.command(ZONED)
    ids, gp = it.zonearray.ids(), it.gridpointarray.pos()
    z0 = gp[:, 2].copy()
    it.cycle(50)                          # views taken before cycling stay valid and show the new state
    # (small strain: the gridpoints keep their positions; the displacement is the motion)
    np.testing.assert_array_equal(gp[:, 2], z0)
    assert ids.shape == it.zonearray.ids().shape and it.gridpointarray.disp()[:, 2].min() < 0
    zs = it.current().session.model.stores["zones"]
    assert it.block.zone.count() == zs.n > 0
    za = it.zonearray
    assert za.ids().shape == (zs.n,) and za.vol().shape == (zs.n,) and not za.vol().flags.writeable
    assert za.vol().sum() == pytest.approx(1.0, rel=1e-12)            # the zones fill the block
    assert it.block.zonearray is za
    st = za.stress()
    assert st.shape == (zs.n, 3, 3) and np.array_equal(st, st.transpose(0, 2, 1))
    pos = za.pos()
    for k, z in enumerate(it.block.zone.list()):
        assert z.id() == zs["id"][k] and z.vol() == zs["vol" if "vol" in zs else "volume"][k]
        np.testing.assert_array_equal(z.stress(), st[k])
        np.testing.assert_array_equal(z.pos(), pos[k])
        assert z.block().id() == 1 and z.model() == "elastic"
        assert len(z.gridpoints()) == zs["nnode"][k]
    b = it.block.find(1)
    assert len(b.zones()) == zs.n
    g = next(it.block.gridpoint.list())
    assert g.zoned()
    np.testing.assert_array_equal(g.force_unbal(), it.current().session.model.vertices["force"][g.id() - 1])
    assert it.gridpointarray.zoned().all()
    with pytest.raises(ValueError, match="no zone with id 100000"):
        it.block.zone.Zone(it.current(), 100000).pos()
    assert it.block.zone.find(100000) is None


def test_cables_read_their_stores():
    it.command(HANG)
    it.cycle(300)
    segs = it.current().session.model.stores["cable_segments"]
    cables = list(it.structure.cable.list())
    assert it.structure.cable.count() == len(cables) == 29
    for c, fa in zip(cables, segs["fa"]):
        assert c.force_axial() == fa
    n = it.structure.node.find(30)
    np.testing.assert_array_equal(n.vel(), [0, 0, 0])
    assert it.structure.node.find(99) is None
    with pytest.raises(ValueError, match="no cable element with id 99"):
        it.structure.Cable(it.current(), 99).force_axial()
    # the top element (it holds the block's 20 kN) breaks at its strain limit and is read as ruptured
    assert not it.structure.cable.find(29).ruptured()
    it.command("structure cable property tensile-failure-strain 1e-9 range id 29")
    it.cycle(1)
    top = it.structure.cable.find(29)
    assert top.ruptured() and top.state() & 32 and top.force_axial() == 0.0


CANTILEVER = """model new
block create brick 20 21 0 1 0 1
block property density 1000
block fix
structure beam create by-line 0 0 0 4 0 0 segments 8 id 1
structure beam property young 200e9 poisson 0.25 cross-sectional-area 1e-2 moi-y 2e-5 moi-z 5e-5 moi-polar 7e-5
structure node fix velocity rotation range id 1
structure node apply force-z -5000 range id 9
model solve ratio 1e-7
"""


def test_beams_through_the_structure_module():
    """A cantilever L = 4 m under P = 5 kN at its tip: the tip node sags P L³ / 3 E I, the fixed end puts
    the moment P L on the first element; read through it.structure.node and it.structure.beam."""
    it.command(CANTILEVER)
    assert it.structure.beam.count() == 8 and it.structure.node.count() == 9
    tip = it.structure.node.find(9)
    assert -tip.disp()[2] == pytest.approx(5000.0 * 4.0 ** 3 / (3 * 200e9 * 2e-5), rel=1e-3)
    first = it.structure.beam.find(1)
    assert abs(first.moment(1)[1]) == pytest.approx(5000.0 * 4.0, rel=1e-3)
    assert first.force_axial() == pytest.approx(0.0, abs=1e-3) and first.id() == 1
    assert it.structure.beam.find(99) is None and it.structure.dowel.count() == 0
