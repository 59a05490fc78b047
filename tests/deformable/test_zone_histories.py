"""`block zone history stress-..` and `block history displacement|velocity|position ..` on gridpoints of
zoned blocks: the right zone / gridpoint is picked, followed after vertex rows move, bad input refused."""
from types import SimpleNamespace

import numpy as np
import pytest

from dec3d.errors import Dec3dError
from tests.zoning_fixture import zone_brick


def _model(session):
    session.command("block create brick 0 1 0 1 0 1\nblock create brick 3 4 0 1 0 1")
    zone_brick(session.model, 0)
    return session.model


def _sample(m, step=10):
    hs = m.history_set
    hs(SimpleNamespace(step=step, time=step * 1e-3))
    return {h.name: h.values[-1] for h in hs.items}


def test_zone_history_picks_the_zone_containing_the_point(session):
    m = _model(session)
    zs = m.store("zones")
    cen = m.vertices["pos"][zs["gp"][:, :4]].mean(axis=1)
    for r in range(zs.n):
        zs["stress"][r, 4] = 100.0 * (r + 1)
        x, y, z = (float(t) for t in cen[r])
        session.command(f"block zone history name 'z{r}' stress-xz position {x!r} {y!r} {z!r}")
    got = _sample(m)
    for r in range(zs.n):
        assert got[f"z{r}"] == 100.0 * (r + 1)
        assert m.history_set.find(f"z{r}").spec["zone_id"] == zs["id"][r]


def test_zone_history_outside_takes_nearest_centroid_and_follows_stress(session):
    m = _model(session)
    zs = m.store("zones")
    cen = m.vertices["pos"][zs["gp"][:, :4]].mean(axis=1)
    far = np.array([-5.0, 0.2, 0.3])
    near = int(np.argmin(np.linalg.norm(cen - far, axis=1)))
    session.command("block zone history name 's' stress-yy position -5 0.2 0.3")
    session.command(f"block zone history name 'byid' stress-zz zone-id {int(zs['id'][2])}")
    zs["stress"][near, 1] = -7.0
    zs["stress"][2, 2] = 3.5
    assert _sample(m) == {"s": -7.0, "byid": 3.5}
    # another block zoned: vertex rows move, zone ids stay
    zone_brick(m, int(np.flatnonzero(m.blocks["id"] == 2)[0]))
    zs["stress"][near, 1] = -8.0
    assert _sample(m, 20)["s"] == -8.0


def test_block_history_on_a_zoned_block_follows_the_nearest_gridpoint(session):
    m = _model(session)
    v = m.vertices
    session.command("block history name 'dz' displacement-z position 1.1 1.05 0.9")
    session.command("block history name 'v' velocity position 0 0 0.2")
    session.command("block history name 'rigid' velocity-x position 3.5 0.5 0.5")
    corner = int(np.flatnonzero(v["zoned"] & (np.abs(v["pos"] - [1, 1, 1]).sum(axis=1) == 0))[0])
    origin = int(np.flatnonzero(v["zoned"] & (np.abs(v["pos"]).sum(axis=1) == 0))[0])
    v["disp"][corner, 2] = -2e-3
    v["velocity"][origin] = [3.0, 0.0, 4.0]
    m.blocks["velocity"][np.flatnonzero(m.blocks["id"] == 2)[0], 0] = 0.25
    assert _sample(m) == {"dz": -2e-3, "v": 5.0, "rigid": 0.25}
    assert m.history_set.find("dz").spec["kind"] == "gridpoint"
    # the rigid block is zoned afterwards: the zoned block's rows move; the history keeps its gridpoint
    zone_brick(m, int(np.flatnonzero(m.blocks["id"] == 2)[0]))
    corner = int(np.flatnonzero(v["zoned"] & (np.abs(v["pos"] - [1, 1, 1]).sum(axis=1) == 0))[0])
    v["disp"][corner, 2] = -3e-3
    assert _sample(m, 20)["dz"] == -3e-3


def test_block_history_gridpointid(session):
    m = _model(session)
    v = m.vertices
    row = int(np.flatnonzero(v["zoned"])[3])
    v["velocity"][row, 1] = -0.5
    session.command(f"block history name 'g' velocity-y gridpointid {row + 1}")
    assert _sample(m) == {"g": -0.5}


@pytest.mark.parametrize("line, message", [
    ("block zone history stress-xx", "either `position <x y z>` or `zone-id <i>`"),
    ("block zone history stress-xx position 0 0 0 zone-id 1", "either `position <x y z>` or `zone-id <i>`"),
    ("block zone history stress-xx zone-id 99", "there is no zone 99"),
    ("block history velocity-x gridpointid 999", "there is no gridpoint 999"),
    ("block history rotation gridpointid 1", "not a gridpoint quantity"),
    ("block history velocity-x gridpointid 1 position 0 0 0", "names the gridpoint alone"),
])
def test_bad_input(session, line, message):
    m = _model(session)
    with pytest.raises(Dec3dError, match=message) as e:
        session.command("\n" + line)
    assert e.value.location.line == 2
    assert not getattr(m, "history_set", None) or not m.history_set.items


def test_gridpointid_of_a_rigid_vertex_is_refused(session):
    m = _model(session)
    rigid = int(np.flatnonzero(~m.vertices["zoned"])[0])
    with pytest.raises(Dec3dError, match=f"there is no gridpoint {rigid + 1}"):
        session.command(f"block history displacement gridpointid {rigid + 1}")


def test_zone_history_without_zones(session):
    session.command("block create brick 0 1 0 1 0 1")
    with pytest.raises(Dec3dError, match="there are no zones"):
        session.command("block zone history stress-xx position 0 0 0")


def test_model_histories_of_the_solve_measures_exist(session):
    session.command("model history name 'ub' mechanical unbalanced-maximum\nmodel history name 'r' mechanical ratio")
    assert [h.spec["quantity"] for h in session.model.history_set.items] == ["unbalanced-maximum", "ratio"]
