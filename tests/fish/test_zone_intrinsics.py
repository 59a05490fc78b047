"""FISH zone intrinsics on a brick zoned by hand (tests/zoning_fixture.py): five tetrahedra of a
2 x 1 x 1 m brick; volumes sum to 2 m³ (corner tets 1/6 of the box each, central 1/3), zone
centroids are corner means computed here from the gridpoint positions, stresses read back."""
import numpy as np
import pytest

from dec3d.errors import ExpressionError
from tests.zoning_fixture import zone_brick


def test_zone_reads(session):
    session.command("block create brick 0 2 0 1 0 1")
    m = session.model
    zone_brick(m, 0)
    zs = m.store("zones")
    zs["stress"][:, 0] = np.arange(1, zs.n + 1) * -1e6
    session.command("fish define tot\n local s = 0.0\n loop foreach z block.zone.list\n"
                    "  s = s + block.zone.vol(z)\n endloop\n tot = s\nend\n[v = tot]\n"
                    "[n = block.zone.num]\n[zx = block.zone.pos.x(2)]\n[sxx = block.zone.stress.xx(3)]\n"
                    "[b = block.zone.block(1)]\n[g = block.zone.gp(2, 4)]\n[f = block.zone.find(99)]")
    v = session.variables
    assert v["n"] == 5
    assert v["v"] == pytest.approx(2.0, rel=1e-12)
    r2 = int(np.nonzero(zs["id"] == 2)[0][0])
    assert v["zx"] == pytest.approx(m.vertices["pos"][zs["gp"][r2][:4]].mean(axis=0)[0], rel=1e-12)
    r3 = int(np.nonzero(zs["id"] == 3)[0][0])
    assert v["sxx"] == pytest.approx(-1e6 * (r3 + 1), rel=1e-12)
    assert v["b"] == 1 and v["f"] == 0
    assert v["g"] == int(zs["gp"][r2, 3]) + 1


def test_missing_zone_is_a_clear_error(session):
    session.command("block create brick 0 1 0 1 0 1")
    with pytest.raises(ExpressionError) as e:
        session.command("[s = block.zone.vol(7)]")
    assert "`block.zone.vol`: there is no zone with id 7" in e.value.message


def test_zone_ids_out_of_row_order_still_find_their_zone(session):
    session.command("block create brick 0 2 0 1 0 1")
    m = session.model
    zone_brick(m, 0)
    zs = m.store("zones")
    zs["id"][:] = zs["id"][::-1].copy()            # row 0 now holds zone n, row n-1 zone 1
    zs["volume"][:] = np.arange(1, zs.n + 1)      # the row number + 1, to see which row is read
    session.command("[v1 = block.zone.vol(1)]\n[vn = block.zone.vol(5)]")
    assert session.variables["v1"] == 5.0 and session.variables["vn"] == 1.0


def test_zone_state_reads_the_plastic_state_of_a_yielding_specimen(tmp_path):
    """The Mohr-Coulomb specimen pulled to its tension cut-off (tests/deformable/test_zone_mohr_cycle.py):
    every zone is tension-now (bit 2) while pulled, and only tension-past (8) once unloaded; FISH reads the
    same bits the zones store holds."""
    from tests.deformable.test_zone_mohr_cycle import _session, _specimen

    s = _session(tmp_path, _specimen(0.0, 2e-7, tension=5e5))
    walk = ("[st = list.sequence(0)]\nfish define states\n loop foreach z block.zone.list\n"
            "  st = list.append(st, block.zone.state(z))\n endloop\nend\n@states")
    s.command("model cycle 3000\n" + walk)
    zs = s.model.store("zones")
    assert s.variables["st"] == [int(x) for x in zs["state"]]
    assert all(x & 2 for x in s.variables["st"])
    s.command("block gridpoint apply velocity-z -2e-7 range position-z 1\nmodel cycle 50\n" + walk)
    assert s.variables["st"] == [8] * zs.n
    with pytest.raises(ExpressionError) as e:
        s.command("[q = block.zone.state(99)]")
    assert "`block.zone.state`: there is no zone with id 99" in e.value.message
