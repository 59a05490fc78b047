"""Save / restore with a zoned (deformable) block: exact round trip, and the zones store's
cross-store indices checked on restore (a corrupt file is a clear error)."""
import numpy as np
import pytest

import dec3d.physics.history  # noqa: F401  (with rigid: registers what save files may name)
import dec3d.physics.rigid  # noqa: F401
from dec3d.geometry.polyhedron import brick
from dec3d.io.state import StateFileError, restore_state, save_state
from dec3d.model.blocks import add_blocks
from dec3d.model.model import Model
from dec3d.model.zones import ZMODEL_ELASTIC
from tests.zoning_fixture import zone_brick


@pytest.fixture
def zoned():
    m = Model()
    add_blocks(m, [brick(0, 1, 0, 1, 0, 1), brick(2, 3, 0, 1, 0, 1)], density=2500.0)
    zone_brick(m, 0, mixed=True)
    zs = m.store("zones")
    zs["cmodel"][:] = ZMODEL_ELASTIC
    zs["stress"][:, 2] = np.arange(zs.n) * -1.5e5
    m.vertices["fface"][:, 2] = 7.0
    return m


def test_zoned_save_restore_save_is_byte_identical(zoned, tmp_path):
    a = save_state(zoned, tmp_path / "a.sav", records=["model new"])
    restored, meta = restore_state(a)
    b = save_state(restored, tmp_path / "b.sav", records=meta["records"])
    assert open(a, "rb").read() == open(b, "rb").read()
    zs, rz = zoned.store("zones"), restored.store("zones")
    assert rz.n == zs.n == 10
    for key in zs.fields:
        np.testing.assert_array_equal(rz[key], zs[key])
    for key in ("link", "fface", "zoned"):
        np.testing.assert_array_equal(restored.vertices[key], zoned.vertices[key])


@pytest.mark.parametrize("corrupt, message", [
    (lambda m: m.store("zones")["gp"].__setitem__((3, 1), m.vertices.n + 4), "zone gridpoint rows point outside"),
    (lambda m: m.store("zones")["gp"].__setitem__((2, 7), 0), "past its node count"),
    (lambda m: m.store("zones")["block"].__setitem__(0, 5), "zone block rows point outside the blocks"),
    (lambda m: m.store("zones")["nnode"].__setitem__(1, 6), "node count other than 4 or 10"),
    (lambda m: m.store("zones")["cmodel"].__setitem__(4, 99), "unknown constitutive model code"),
    (lambda m: m.vertices["link"].__setitem__(0, m.vertices.n), "gridpoint link points outside"),
])
def test_corrupt_zones_are_refused(zoned, tmp_path, corrupt, message):
    corrupt(zoned)
    path = save_state(zoned, tmp_path / "bad.sav")
    with pytest.raises(StateFileError, match=message):
        restore_state(path)
