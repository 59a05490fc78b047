"""Save / restore of a model with zones of every kind (4-node, mixed hexahedral, 10-node) beside a rigid
block: every field of the zones store, every gridpoint field and the faces' source round trip exactly;
zone and gridpoint histories come back and go on sampling the same values; bad history entries refused."""
from types import SimpleNamespace

import numpy as np
import pytest

from dec3d.geometry.polyhedron import brick, tetrahedron
from dec3d.io.state import StateFileError, restore_state, save_state
from dec3d.model.blocks import add_blocks
from dec3d.model.model import Model
from dec3d.model.zones import NZPROP, ZMODEL_ELASTIC
from dec3d.physics.history import histories
from tests.deformable.zone_fixtures import zone_tet10
from tests.zoning_fixture import zone_brick


def _model():
    m = Model()
    add_blocks(m, [brick(0, 1, 0, 1, 0, 1), brick(2, 3, 0, 1, 0, 1),
                   tetrahedron((5, 0, 0), (6, 0, 0), (5, 1, 0), (5, 0, 1)), brick(8, 9, 0, 1, 0, 1)], density=2500.0)
    zone_brick(m, int(np.flatnonzero(m.blocks["id"] == 1)[0]))
    zone_brick(m, int(np.flatnonzero(m.blocks["id"] == 2)[0]), mixed=True)
    zone_tet10(m, int(np.flatnonzero(m.blocks["id"] == 3)[0]))
    rng = np.random.default_rng(5)
    zs, v = m.store("zones"), m.vertices
    zs["stress"][:] = rng.normal(size=(zs.n, 6)) * 1e6
    zs["gstress"][:] = rng.normal(size=(zs.n, 4, 6)) * 1e6
    zs["cmodel"][:] = ZMODEL_ELASTIC
    zs["prop"][:] = rng.uniform(1, 2, size=(zs.n, NZPROP)) * 1e9
    zs["state"][:] = rng.integers(0, 8, size=zs.n)
    zs["hist"][:] = rng.normal(size=zs["hist"].shape)           # the zone models' history
    gp = np.flatnonzero(v["zoned"])
    for key, shape in (("imass", ()), ("fapp", (3,)), ("fface", (3,)), ("vapp", (3,)), ("disp", (3,)),
                       ("velocity", (3,)), ("force", (3,)), ("mass", ())):
        v[key][gp] = rng.normal(size=(gp.size,) + shape)
    v["apply_fix"][gp] = rng.integers(0, 8, size=gp.size)
    v["link"][gp[1]] = gp[0]
    return m


def test_every_zone_and_gridpoint_field_round_trips(tmp_path):
    m = _model()
    hs = histories(m)
    zs = m.store("zones")
    hs.add_zone("stress-xz", int(zs["id"][7]), "sz")
    hs.add_gridpoint("velocity-y", 2, 3, "gv")
    hs(SimpleNamespace(step=10, time=0.1))
    a = save_state(m, tmp_path / "a.sav")
    r, _ = restore_state(a)
    for name in ("zones", "vertices", "faces"):
        s0, s1 = m.store(name), r.store(name)
        assert s1.n == s0.n and set(s1.fields) == set(s0.fields)
        for key in s0.fields:
            np.testing.assert_array_equal(s1[key], s0[key], err_msg=f"{name}.{key}")
    assert r.store("zones")["nnode"].tolist().count(10) == 1 and (r.store("zones")["hex"] >= 0).sum() == 10
    assert (r.faces["source"] >= 0).sum() == (m.faces["source"] >= 0).sum() > 0
    rh = r.history_set
    assert [(h.name, h.spec) for h in rh.items] == [(h.name, h.spec) for h in hs.items]
    assert [h.values for h in rh.items] == [h.values for h in hs.items]
    for model in (m, r):                           # both go on alike
        model.store("zones")["stress"][7, 4] = 42.0
        model.vertices["velocity"][model.blocks["vert_start"][1] + 3, 1] = -0.25
        model.history_set(SimpleNamespace(step=20, time=0.2))
    assert rh.find("sz").values == hs.find("sz").values and rh.find("sz").values[-1] == 42.0
    assert rh.find("gv").values[-1] == hs.find("gv").values[-1] == -0.25
    b = save_state(r, tmp_path / "b.sav")
    m2, _ = restore_state(b)
    np.testing.assert_array_equal(m2.store("zones")["gstress"], m.store("zones")["gstress"])


@pytest.mark.parametrize("spoil, message", [
    (lambda h: h.spec.__setitem__("local", -1), "gridpoint index -1"),
    (lambda h: h.spec.__setitem__("local", 500), "block 2 has no gridpoint 501"),
    (lambda h: h.spec.__setitem__("block_id", 99), "block 99 has no gridpoint"),
])
def test_bad_gridpoint_history_is_refused(tmp_path, spoil, message):
    m = _model()
    h = histories(m).add_gridpoint("displacement", 2, 1, "g")
    spoil(h)
    path = save_state(m, tmp_path / "bad.sav")
    with pytest.raises(StateFileError, match=message):
        restore_state(path)


def test_bad_zone_history_is_refused(tmp_path):
    m = _model()
    h = histories(m).add_zone("stress-xx", 1, "z")
    h.spec["zone_id"] = 0
    path = save_state(m, tmp_path / "bad.sav")
    with pytest.raises(StateFileError, match="zone id 0"):
        restore_state(path)
