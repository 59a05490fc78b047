"""FISH gridpoint intrinsics (block.gp.*) on a model of two bricks: block 1 (0..2 x 0..1 x 0..1 m) zoned
by hand into five tetrahedra (tests/zoning_fixture.py), block 2 a rigid unit cube at x 3..4. Values are
put into the stores here and read back through FISH; rigid-vertex motion is worked out by hand."""
import numpy as np
import pytest

from dec3d.errors import ExpressionError
from tests.zoning_fixture import zone_brick


@pytest.fixture
def model(session):
    session.command("block create brick 0 2 0 1 0 1\nblock create brick 3 4 0 1 0 1")
    m = session.model
    zone_brick(m, 0)
    return m


def _row_at(m, xyz):
    d = np.linalg.norm(m.vertices["pos"] - np.array(xyz, float), axis=1)
    r = int(np.argmin(d))
    assert d[r] == 0.0
    return r


def test_zone_gp_is_a_gridpoint_usable_with_block_gp(session, model):
    m = model
    session.command("fish define check\n  local worst = 0.0\n  loop foreach local z block.zone.list\n"
                    "    local c = vector(0, 0, 0)\n    loop local i (1, 4)\n"
                    "      c = c + block.gp.pos(block.zone.gp(z, i))\n    endloop\n"
                    "    worst = math.max(worst, math.mag(c / 4.0 - block.zone.pos(z)))\n  endloop\n"
                    "  check = worst\nend\n[w = check]\n[n = block.gp.num]\n[nl = list.size(block.gp.list)]\n"
                    "[g = block.zone.gp(1, 1)]\n[hb = block.gp.block(g)]\n[zz = block.gp.zoned(g)]\n"
                    "[f0 = block.gp.find(0)]\n[fn = block.gp.find(n)]")
    v = session.variables
    assert v["w"] == pytest.approx(0.0, abs=1e-12)          # the zone's corners average to its centroid
    assert v["n"] == v["nl"] == m.vertices.n
    assert v["hb"] == 1 and v["zz"] is True
    assert v["f0"] == 0 and v["fn"] == v["n"]


def test_zoned_gridpoints_read_their_own_fields(session, model):
    m = model
    vs = m.vertices
    r = _row_at(m, (2, 1, 1))
    vs["disp"][r] = (1e-3, -2e-3, 3e-3)
    vs["velocity"][r] = (0.5, 0.0, -0.25)
    vs["force"][r] = (10.0, 20.0, -30.0)
    g = r + 1
    session.command(f"[p = block.gp.pos({g})]\n[dz = block.gp.disp.z({g})]\n[d = block.gp.disp({g})]\n"
                    f"[vx = block.gp.vel.x({g})]\n[fy = block.gp.force.y({g})]\n[f = block.gp.force({g})]")
    v = session.variables
    assert tuple(v["p"]) == (2.0, 1.0, 1.0)
    assert v["dz"] == 3e-3 and tuple(v["d"]) == (1e-3, -2e-3, 3e-3)
    assert v["vx"] == 0.5 and v["fy"] == 20.0 and tuple(v["f"]) == (10.0, 20.0, -30.0)


def test_rigid_vertices_read_their_blocks_motion(session, model):
    m = model
    b, vs = m.blocks, m.vertices
    k = int(np.nonzero(b["id"] == 2)[0][0])
    b["velocity"][k] = (1.0, 0.0, 0.0)
    b["spin"][k] = (0.0, 0.0, 2.0)                  # about z through the centroid (3.5, 0.5, 0.5)
    r = _row_at(m, (4, 1, 0))
    vs["pos"][r] = (4.1, 1.0, 0.0)                 # moved 0.1 m along x since it was made
    g = r + 1
    session.command(f"[v = block.gp.vel({g})]\n[d = block.gp.disp({g})]\n[hb = block.gp.hostblock({g})]\n"
                    f"[zz = block.gp.zoned({g})]")
    v = session.variables
    # v + w x (x - c) = (1, 0, 0) + (0, 0, 2) x (0.6, 0.5, -0.5) = (1 - 2*0.5, 2*0.6, 0) = (0, 1.2, 0)
    assert tuple(v["v"]) == pytest.approx((0.0, 1.2, 0.0), abs=1e-12)
    assert tuple(v["d"]) == pytest.approx((0.1, 0.0, 0.0), abs=1e-12)
    assert v["hb"] == 2 and v["zz"] is False


def test_gp_near(session, model):
    m = model
    session.command("[a = block.gp.near(1.9, 0.1, 0.05)]\n[b = block.gp.near(vector(3.9, 0.9, 1.2))]")
    v = session.variables
    assert tuple(m.vertices["pos"][v["a"] - 1]) == (2.0, 0.0, 0.0)
    assert tuple(m.vertices["pos"][v["b"] - 1]) == (4.0, 1.0, 1.0)


def test_gp_bad_input(session, model):
    m = model
    rigid = _row_at(m, (3, 0, 0)) + 1
    cases = [("[q = block.gp.pos(0)]", "`block.gp.pos`: there is no gridpoint 0"),
             ("[q = block.gp.disp.x('a')]", "`block.gp.disp.x` takes a gridpoint"),
             (f"[q = block.gp.force({rigid})]", f"gridpoint {rigid} is a vertex of a rigid block"),
             ("[q = block.gp.near(1, 2)]", "`block.gp.near` takes a vector or three numbers"),
             (f"[q = block.gp.pos({m.vertices.n + 1})]", f"there is no gridpoint {m.vertices.n + 1}")]
    for text, msg in cases:
        with pytest.raises(ExpressionError) as e:
            session.command(text)
        assert msg in e.value.message, text
        assert e.value.location.line == 1 and e.value.location.column == 6


def test_empty_model_has_no_gridpoints(session):
    session.command("[n = block.gp.num]\n[l = list.size(block.gp.list)]\n[g = block.gp.near(0, 0, 0)]")
    assert (session.variables["n"], session.variables["l"], session.variables["g"]) == (0, 0, 0)


def test_gplist_walk_visits_each_gridpoint_of_a_block_once(session, model):
    m = model
    # block.gp.next from the first entry of block.gplist, 0 after the last
    session.command("fish define walk(b)\n  local n = 0\n  local l = block.gplist(b)\n  local g = l(1)\n  loop while g # 0\n"
                    "    n = n + 1\n    if block.gp.block(g) # b then\n      n = -1000\n    endif\n"
                    "    g = block.gp.next(g)\n  endloop\n  walk = n\nend\n[n1 = walk(1)]\n[n2 = walk(2)]")
    k1, k2 = (int(np.nonzero(m.blocks["id"] == i)[0][0]) for i in (1, 2))
    assert session.variables["n1"] == int(m.blocks["vert_count"][k1]) > 0
    assert session.variables["n2"] == int(m.blocks["vert_count"][k2]) == 8
    # `loop foreach` over the list (as the public decks write it): each gridpoint once, all of block 2
    session.command("fish define each(b)\n  local s = 0\n  local n = 0\n  loop foreach g block.gplist(b)\n"
                    "    n = n + 1\n    if block.gp.block(g) = b then\n      s = s + 1\n    endif\n"
                    "  endloop\n  each = n * 1000 + s\nend\n[e2 = each(2)]")
    assert session.variables["e2"] == 8 * 1000 + 8
    with pytest.raises(ExpressionError) as e:
        session.command("[q = block.gplist(9)]")
    assert "`block.gplist`: there is no block with id 9" in e.value.message
