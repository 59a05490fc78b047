"""FISH block intrinsics read the current model: a 2 x 1 x 1 m brick of density 1000 kg/m³
has volume 2 m³, mass 2000 kg and its centroid at (1, 0.5, 0.5)."""
import pytest

from dec3d.errors import ExpressionError


def test_block_list_and_properties(session):
    session.command("block create brick 0 2 0 1 0 1\nblock create brick 0 1 0 1 1 2\n"
                    "block property density 1000\nblock group 'top' range position-z 1.5\n"
                    "block fix range position-z 1.5")
    session.command("fish define report\n loop foreach b block.list\n"
                    "  io.out(string.build('%1 %2 %3 %4', block.id(b), block.pos(b), block.group(b), block.fix(b)))\n"
                    " endloop\n report = list.size(block.list)\nend\n[n = report]\n"
                    "[io.out(block.pos.z(block.find(2)))]\n[io.out(block.find(99))]\n"
                    "[v1 = block.vol(1)]\n[m1 = block.mass(1)]\n[m2 = block.mass(2)]")
    out = session.output.getvalue().splitlines()
    assert out[0] == "1 (1.0,0.5,0.5)  false"
    assert out[1] == "2 (0.5,0.5,1.5) top true"
    assert out[2:] == ["1.5", "0"]
    v = session.variables
    assert v["n"] == 2
    assert v["v1"] == pytest.approx(2.0, rel=1e-12) and v["m1"] == pytest.approx(2000.0, rel=1e-12)
    assert v["m2"] == pytest.approx(1000.0, rel=1e-12)
    session.command("[vz = block.vel.z(1)]\n[dx = block.disp(1)->x]")
    assert session.variables["vz"] == 0.0 and session.variables["dx"] == 0.0


def test_missing_block_is_a_clear_error(session):
    with pytest.raises(ExpressionError) as e:
        session.command("[m = block.mass(7)]")
    assert "`block.mass`: there is no block with id 7" in e.value.message and e.value.location.column == 6


def test_block_walk_and_velocity_writes(session):
    """A lone block with no gravity keeps the velocity FISH gives it: after n steps it has moved v n dt."""
    session.command("block create brick 0 1 0 1 0 1\nblock create brick 5 6 0 1 0 1\nblock create brick 9 10 0 1 0 1\n"
                    "block property density 1000\nblock delete range id 2\n"
                    "fish define walk\n  local b = block.head\n  local out = list.sequence(0)\n"
                    "  loop while b # 0\n    out = list.append(out, b)\n    b = block.next(b)\n  endloop\n"
                    "  walk = out\nend\n[w = walk]\n"
                    "[block.vel(1) = vector(0.1, 0.0, 0.0)]\n[block.vel.z(3) = -0.2]\n"
                    "[block.force.app.y(3) = 0.0]\nmodel cycle 10\n"
                    "[dt = mech.timestep]\n[dx = block.disp.x(1)]\n[dz = block.disp.z(3)]\n[vx = block.vel.x(1)]")
    v = session.variables
    assert v["w"] == [1, 3]
    assert v["dt"] > 0 and v["vx"] == 0.1
    assert v["dx"] == pytest.approx(0.1 * 10 * v["dt"], rel=1e-9)
    assert v["dz"] == pytest.approx(-0.2 * 10 * v["dt"], rel=1e-9)


def test_block_writes_refuse_bad_values(session):
    session.command("block create brick 0 1 0 1 0 1")
    for text, msg in [("[block.vel(1) = 3]", "`block.vel` is set to a vector of finite numbers, not a integer"),
                      ("[block.vel.x(1) = 'a']", "`block.vel.x` is set to a finite number"),
                      ("[block.vel.x(4) = 1.0]", "there is no block with id 4"),
                      ("[q = mech.solve('bogus')]", "'bogus' is not one of ratio"),
                      ("[q = mech.solve('ratio-')]", "'ratio-' is ambiguous")]:
        with pytest.raises(ExpressionError) as e:
            session.command(text)
        assert msg in e.value.message, text
    assert tuple(session.model.blocks["velocity"][0]) == (0.0, 0.0, 0.0)


def test_mech_solve_is_the_measure_model_solve_uses(session):
    session.command("block create brick 0 1 0 1 0 1\nblock create brick 0 1 0 1 1 2\nblock property density 1000\n"
                    "block contact jmodel assign elastic\nblock contact property stiffness-normal 1e9 stiffness-shear 1e9\n"
                    "model gravity 0 0 -10\nblock fix range position-z 0 1\nhistory interval 1\n"
                    "model history name 'r' mechanical ratio-local\nmodel history name 'u' mechanical unbalanced-max\n"
                    "model cycle 50\n[r = mech.solve('ratio-local')]\n[u = mech.solve('unbal')]")
    hs = session.model.history_set
    assert session.variables["r"] == hs.find("r").values[-1] > 0
    assert session.variables["u"] == hs.find("u").values[-1] > 0


def test_unbalanced_force_right_after_block_delete(session):
    """`block delete` moves block rows; block.force.unbal reads the contacts detected again for the
    blocks that are left (it used to index the old rows: a Python IndexError). Three stacked 1 m
    cubes (2000 kg each, g = 10), the top one deleted after 20 steps: the middle block's unbalanced
    force is its weight less what its contact with the base carries, and the lone contact left is
    the base-middle one."""
    session.command("block create brick 0 1 0 1 0 1\nblock create brick 0 1 0 1 1 2\nblock create brick 0 1 0 1 2 3\n"
                    "block property density 2000\n"
                    "block contact property stiffness-normal 1e9 stiffness-shear 1e9\n"
                    "block fix range position-z 0 1\nmodel gravity 0 0 -10\nmodel cycle 20\n"
                    "block delete range position-z 2 3")
    session.command("[fz = block.force.unbal.z(block.find(2))]\n[nc = list.size(block.contact.list)]")
    m = session.model
    ss = m.store("subcontacts")
    v = session.variables
    assert v["nc"] == 1
    assert v["fz"] == pytest.approx(ss["fn"][: ss.n].sum() - 20000.0, rel=1e-9, abs=1e-6)


def test_block_near_is_the_nearest_centroid(session):
    """Centroids (1, 0.5, 0.5) and (0.5, 0.5, 1.5): (0.2, 0.5, 1.8) is nearer the second; the point
    (0.75, 0.5, 1.0) is 0.25² + 0.5² from both, a tie the lower id takes; no block gives 0."""
    session.command("[e = block.near(0, 0, 0)]")
    assert session.variables["e"] == 0
    session.command("block create brick 0 2 0 1 0 1\nblock create brick 0 1 0 1 1 2\n"
                    "[a = block.near(0.2, 0.5, 1.8)]\n[b = block.near(vector(1.9, 0.1, 0.1))]\n"
                    "[t = block.near(0.75, 0.5, 1.0)]")
    v = session.variables
    assert (v["a"], v["b"], v["t"]) == (2, 1, 1)
    for text in ("[q = block.near(1, 2)]", "[q = block.near('a', 0, 0)]"):
        with pytest.raises(ExpressionError) as e:
            session.command(text)
        assert "`block.near` takes a vector or three finite numbers x, y, z" in e.value.message


def test_clock_and_gravity_intrinsics(session):
    """time.kernel (processor ms) and time.clock (wall hundredths of a second) grow while FISH works;
    global.gravity reads `model gravity`."""
    session.command("model gravity 1 -2 -9.5\n[g = global.gravity]\n[gz = global.gravity.z]\n"
                    "[k0 = time.kernel]\n[c0 = time.clock]\n"
                    "fish define busy\n local s = 0\n loop local i (1, 300000)\n  s = s + i\n endloop\n busy = s\nend\n"
                    "[s = busy]\n[k1 = time.kernel]\n[c1 = time.clock]")
    v = session.variables
    assert tuple(v["g"]) == (1.0, -2.0, -9.5) and v["gz"] == -9.5
    assert v["s"] == 300000 * 300001 // 2
    assert v["k1"] > v["k0"] and type(v["c1"]) is int and v["c1"] >= v["c0"] >= 0
