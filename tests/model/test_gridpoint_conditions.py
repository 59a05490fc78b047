"""`block gridpoint apply` / `apply-remove` set the gridpoint condition fields of zoned blocks only."""
import numpy as np
import pytest

from tests.zoning_fixture import zone_brick


def _zoned(session):
    session.command("block create brick 0 1 0 1 0 1")
    session.command("block create brick 3 4 0 1 0 1")
    zone_brick(session.model, 0)
    return session.model


def test_velocity_and_force_on_range(session):
    m = _zoned(session)
    session.command("block gridpoint apply velocity-z -1e-3 range position-z 0")
    v = m.vertices
    hit = v["zoned"] & np.isclose(v["pos"][:, 2], 0.0)
    assert hit.sum() == 4
    assert np.all(v["apply_fix"][hit] == 4) and np.all(v["apply_fix"][~hit] == 0)
    np.testing.assert_array_equal(v["vapp"][hit, 2], -1e-3)
    session.command("block gridpoint apply force 1 2 3 range position-z 1")
    top = v["zoned"] & np.isclose(v["pos"][:, 2], 1.0)
    np.testing.assert_array_equal(v["fapp"][top], np.tile([1.0, 2.0, 3.0], (4, 1)))
    assert np.all(v["fapp"][~top] == 0.0)
    session.command("block gridpoint apply-remove velocity")
    assert np.all(v["apply_fix"] == 0) and np.all(v["vapp"] == 0.0)
    np.testing.assert_array_equal(v["fapp"][top, 2], 3.0)
    session.command("block gridpoint apply-remove")
    assert np.all(v["fapp"] == 0.0)


def test_range_on_rigid_block_only_warns(session):
    m = _zoned(session)
    session.command("block gridpoint apply velocity 0 0 0 range position-x 4")
    assert "vertices of rigid blocks, which are not gridpoints" in session.output.getvalue()
    assert np.all(m.vertices["apply_fix"] == 0)


def test_no_condition_is_an_error(session):
    from dec3d.errors import Dec3dError
    _zoned(session)
    with pytest.raises(Dec3dError, match="needs velocity"):
        session.command("block gridpoint apply range position-z 0")


def test_initialize_displacement_and_velocity(session):
    m = _zoned(session)
    v = m.vertices
    v["disp"][:] = 0.25
    pos0 = v["pos"].copy()
    session.command("block gridpoint initialize displacement 0 0 0")
    assert np.all(v["disp"][v["zoned"]] == 0.0) and np.all(v["disp"][~v["zoned"]] == 0.25)
    np.testing.assert_array_equal(v["pos"], pos0)
    session.command("block gridpoint initialize velocity-y 0.5 range position-y 1")
    hit = v["zoned"] & np.isclose(v["pos"][:, 1], 1.0)
    np.testing.assert_array_equal(v["velocity"][hit, 1], 0.5)
    assert np.all(v["velocity"][~hit] == 0.0)
