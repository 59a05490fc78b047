"""`block face apply stress` on zoned blocks: forces t·A/3 to the gridpoints, loads add, removal exact."""
import numpy as np
import pytest

from tests.zoning_fixture import zone_brick


def _zoned(session):
    session.command("block create brick 0 1 0 1 0 1")
    zone_brick(session.model, 0)
    return session.model


def test_normal_stress_on_unit_face_gives_sigma_times_area(session):
    m = _zoned(session)
    session.command("block face apply stress-normal -2e6 range position-z 1")
    f = m.vertices["fface"]
    np.testing.assert_allclose(f.sum(axis=0), [0.0, 0.0, -2e6], atol=1e-6)
    top = np.isclose(m.vertices["pos"][:, 2], 1.0)
    assert np.all(f[~top] == 0.0)
    # adds to the existing load, as 3DEC does
    session.command("block face apply stress-normal -1e6 range position-z 1")
    np.testing.assert_allclose(f.sum(axis=0), [0.0, 0.0, -3e6], atol=1e-6)
    session.command("block face apply-remove")
    assert np.all(m.vertices["fface"] == 0.0)


def test_full_tensor_on_side_face(session):
    m = _zoned(session)
    s = np.array([1.0, 2.0, 3.0, 4.0, 5.0, 6.0]) * 1e5
    session.command("block face apply stress " + " ".join(repr(float(x)) for x in s) + " range position-x 0")
    sig = np.array([[s[0], s[3], s[4]], [s[3], s[1], s[5]], [s[4], s[5], s[2]]])
    expect = sig @ np.array([-1.0, 0.0, 0.0]) * 1.0          # outward normal of x = 0 times area 1
    np.testing.assert_allclose(m.vertices["fface"].sum(axis=0), expect, rtol=1e-12)
    session.command("block face apply-remove stress range position-z 1")      # other faces: nothing changes
    np.testing.assert_allclose(m.vertices["fface"].sum(axis=0), expect, rtol=1e-12)
    session.command("block face apply-remove range position-x 0")
    assert np.all(m.vertices["fface"] == 0.0)


def test_rigid_faces_take_no_stress_and_warn(session):
    session.command("block create brick 0 1 0 1 0 1")
    session.command("block face apply stress-normal -1e6 range position-z 1")
    assert "selected no boundary face of a zoned block" in session.output.getvalue()
    assert np.all(session.model.vertices["fface"] == 0.0)


def test_no_stress_given_is_an_error(session):
    from dec3d.errors import Dec3dError
    _zoned(session)
    with pytest.raises(Dec3dError, match="needs stress"):
        session.command("block face apply range position-z 1")
