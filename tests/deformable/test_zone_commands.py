"""`block zone initialize`, `block insitu`, `block zone list`, `block gridpoint list`: values set on the
zones store and sub-contacts, tables printed, and bad input refused with file:line (nothing changed)."""
import numpy as np
import pytest

from dec3d.errors import Dec3dError, NotSupportedError
from tests.deformable.zone_fixtures import zone_tet10
from tests.zoning_fixture import zone_brick

# the Gauss points of a 4-point tetrahedron rule, as barycentric weights (a on one corner, b on the others):
# a = (5 + 3√5) / 20, b = (5 − √5) / 20
_A, _B = (5 + 3 * 5 ** 0.5) / 20, (5 - 5 ** 0.5) / 20


def _model(session, tet10=False):
    session.command("block create brick 0 1 0 1 0 1")
    session.command("block create brick 3 4 0 1 0 2")
    zone_brick(session.model, 0)
    if tet10:
        session.command("block create tetrahedron 6 0 0 7 0 0 6 1 0 6 0 1")
        m = session.model
        zone_tet10(m, int(np.flatnonzero(m.blocks["id"] == 3)[0]))
    return session.model


def _centroids(m):
    zs = m.store("zones")
    return m.vertices["pos"][zs["gp"][:, :4]].mean(axis=1)


def test_initialize_full_tensor_and_components(session):
    m = _model(session)
    zs = m.store("zones")
    session.command("block zone initialize stress -1e6 -2e6 -3e6 1e5 2e5 3e5")
    np.testing.assert_array_equal(zs["stress"], np.tile([-1e6, -2e6, -3e6, 1e5, 2e5, 3e5], (zs.n, 1)))
    session.command("block zone initialize stress-yy 5 stress-yz -7")
    np.testing.assert_array_equal(zs["stress"][:, [1, 5]], np.tile([5.0, -7.0], (zs.n, 1)))
    np.testing.assert_array_equal(zs["stress"][:, 0], -1e6)        # untouched components stay


def test_initialize_gradient_origin_add_multiply_and_range(session):
    m = _model(session)
    zs = m.store("zones")
    c = _centroids(m)
    session.command("block zone initialize stress-zz -1e6 gradient 10 20 1e4 origin 0 0 2")
    expect = -1e6 + 10 * c[:, 0] + 20 * c[:, 1] + 1e4 * (c[:, 2] - 2)
    np.testing.assert_allclose(zs["stress"][:, 2], expect, rtol=1e-15)
    session.command("block zone initialize stress-zz 2 multiply range position-z 0.5 1")
    upper = c[:, 2] >= 0.5
    assert upper.any() and (~upper).any()
    np.testing.assert_allclose(zs["stress"][:, 2], np.where(upper, 2 * expect, expect), rtol=1e-15)
    session.command("block zone initialize stress-xy 3 add\nblock zone initialize stress-xy 4 add")
    np.testing.assert_array_equal(zs["stress"][:, 3], 7.0)


def test_initialize_ten_node_zone_takes_gauss_point_values(session):
    m = _model(session, tet10=True)
    zs = m.store("zones")
    r = int(np.flatnonzero(zs["nnode"] == 10)[0])
    session.command("block zone initialize stress-xx 100 gradient 1 2 3")
    p = m.vertices["pos"][zs["gp"][r, :4]]
    w = np.full((4, 4), _B) + np.eye(4) * (_A - _B)
    gauss = w @ p
    np.testing.assert_allclose(zs["gstress"][r, :, 0], 100 + gauss @ [1, 2, 3], rtol=1e-14)
    np.testing.assert_allclose(zs["stress"][r, 0], 100 + p.mean(axis=0) @ [1, 2, 3], rtol=1e-14)
    assert (zs["gstress"][zs["nnode"] == 4] == 0).all()


def test_zone_range_by_block_group(session):
    m = _model(session)
    session.command("block create brick 0 1 0 1 1 2")
    zone_brick(m, int(np.flatnonzero(m.blocks["id"] == 3)[0]))
    session.command("block group 'top' range position-z 1.5")
    session.command("block zone initialize stress-xx -9 range group 'top'")
    zs = m.store("zones")
    top = m.blocks["id"][zs["block"]] == 3
    assert top.sum() == 5
    np.testing.assert_array_equal(zs["stress"][:, 0], np.where(top, -9.0, 0.0))


@pytest.mark.parametrize("line, message", [
    ("block zone initialize", "needs stress"),
    ("block zone initialize stress 1 2 3 0 0 0 stress-xx 4", "not both"),
    ("block zone initialize stress-xx 1 stress-yy 2 gradient 0 0 1", "exactly one stress component"),
    ("block zone initialize stress 1 2 3 0 0 0 gradient 0 0 1", "exactly one stress component"),
    ("block zone initialize stress-xx 1 origin 0 0 1", "give `gradient` too"),
    ("block zone initialize stress-xx 1 add multiply", "`add` or `multiply`"),
    ("block zone initialize stress-xx 1 gradient 1 0 0 multiply", "cannot be combined"),
    ("block zone initialize stress-xx 1 2", "unexpected value `2`"),
    ("block zone initialize stress-xx [1/0]", "value of `stress-xx`: division by zero"),
])
def test_initialize_bad_input(session, line, message):
    m = _model(session)
    with pytest.raises(Dec3dError, match=message) as e:
        session.command("\n" + line)
    assert e.value.location is not None and e.value.location.line == 2
    assert (m.store("zones")["stress"] == 0).all()


def test_initialize_not_finite_changes_nothing(session):
    m = _model(session)
    with pytest.raises(Dec3dError, match="would not be finite"):
        session.command("block zone initialize stress-xx 1 gradient 1e308 0 0 origin -1e10 0 0")
    assert (m.store("zones")["stress"] == 0).all()


def test_initialize_vary_is_not_supported(session):
    _model(session)
    with pytest.raises(NotSupportedError, match="vary"):
        session.command("block zone initialize stress-xx 1 vary 0 0 1")


def test_initialize_selecting_nothing_warns(session):
    _model(session)
    session.command("block zone initialize stress-xx 1 range position-x 50 60")
    assert "warning" in session.output.getvalue() and "selected no zone" in session.output.getvalue()


# ------------------------------------------------------------------------------------------- insitu
def _contact_model(session):
    session.command("block create brick 0 1 0 1 0 1\nblock create brick 0 1 0 1 1 2")
    session.command("block contact jmodel assign mohr")
    session.command("block contact property stiffness-normal 1e9 stiffness-shear 2e9 friction 30 "
                    "cohesion 1e9 tension 1e9")
    session.command("block property density 1000\nblock fix\nmodel cycle 1")
    return session.model


def test_insitu_sets_subcontact_forces_that_the_joint_law_keeps(session):
    m = _contact_model(session)
    cs, ss = m.store("contacts"), m.store("subcontacts")
    assert cs.n == 1 and ss.n > 0
    np.testing.assert_allclose(cs["normal"][0], [0, 0, 1], atol=1e-15)
    session.command("block insitu stress -1e6 -2e6 -3e6 1e5 2e5 3e5")
    area = ss["area"]
    assert abs(area.sum() - 1.0) < 1e-12
    # plane z = 1, n = +z: traction σ·n = (σxz, σyz, σzz); force on the upper block −A σ·n
    np.testing.assert_allclose(ss["fn"], 3e6 * area, rtol=1e-14)
    np.testing.assert_allclose(ss["fs"], -area[:, None] * np.array([2e5, 3e5, 0.0]), rtol=1e-14, atol=1e-9)
    np.testing.assert_allclose(ss["un"], -3e6 / 1e9, rtol=1e-14)
    fn0, fs0 = ss["fn"].copy(), ss["fs"].copy()
    session.command("model cycle 5")          # blocks fixed: the joint law keeps what insitu set
    np.testing.assert_allclose(ss["fn"], fn0, rtol=1e-12)
    np.testing.assert_allclose(ss["fs"], fs0, rtol=1e-12)


def test_insitu_gradient_at_subcontact_points_and_zones(session):
    m = _contact_model(session)
    ss = m.store("subcontacts")
    session.command("block create brick 5 6 0 1 0 1")
    zone_brick(m, int(np.flatnonzero(m.blocks["id"] == 3)[0]))
    session.command("block insitu stress 0 0 -1e6 0 0 0 gradient-x 0 0 1e3 0 0 0 gradient-z 0 0 2e4 0 0 0")
    szz = -1e6 + 1e3 * ss["pos"][:, 0] + 2e4 * ss["pos"][:, 2]
    np.testing.assert_allclose(ss["fn"], -szz * ss["area"], rtol=1e-13)
    np.testing.assert_allclose(ss["fs"], 0.0, atol=1e-9)
    zs = m.store("zones")
    c = _centroids(m)
    np.testing.assert_allclose(zs["stress"][:, 2], -1e6 + 1e3 * c[:, 0] + 2e4 * c[:, 2], rtol=1e-14)
    np.testing.assert_array_equal(zs["stress"][:, [0, 1, 3, 4, 5]], 0.0)


def test_insitu_range_selects_contacts_and_zones(session):
    m = _contact_model(session)
    session.command("block create brick 5 6 0 1 0 1")
    zone_brick(m, int(np.flatnonzero(m.blocks["id"] == 3)[0]))
    session.command("block insitu stress -1 -1 -1 0 0 0 range position-x 4 7")
    assert (m.store("subcontacts")["fn"] == 0).all()           # the contact at x = 0.5 is outside
    np.testing.assert_array_equal(m.store("zones")["stress"][:, :3], -1.0)


def test_insitu_range_that_contacts_lack_sets_zones_and_says_so(session):
    m = _contact_model(session)
    session.command("block create brick 5 6 0 1 0 1")
    zone_brick(m, int(np.flatnonzero(m.blocks["id"] == 3)[0]))
    zid = int(m.store("zones")["id"][2])
    session.command(f"block insitu stress -1 -1 -1 0 0 0 range id {zid}")
    zs = m.store("zones")
    np.testing.assert_array_equal(zs["stress"][:, 0], np.where(zs["id"] == zid, -1.0, 0.0))
    assert (m.store("subcontacts")["fn"] == 0).all()
    assert "the range does not select contacts (contacts have no id)" in session.output.getvalue()


@pytest.mark.parametrize("line, message, exc", [
    ("block insitu", "needs stress", Dec3dError),
    ("block insitu stress 1 2 3", "expected 6 numbers, got 3", Dec3dError),
    ("block insitu stress 1 2 3 0 0 0 gradient-z 1 2", "expected 6 numbers, got 2", Dec3dError),
    ("block insitu stress 1 2 3 0 0 0 nodisplacements", "nodisplacements", NotSupportedError),
])
def test_insitu_bad_input(session, line, message, exc):
    m = _model(session)
    with pytest.raises(exc, match=message) as e:
        session.command("\n" + line)
    assert e.value.location.line == 2
    assert (m.store("zones")["stress"] == 0).all()


def test_insitu_with_nothing_selected_warns(session):
    session.command("block create brick 0 1 0 1 0 1")
    session.command("block insitu stress -1 -1 -1 0 0 0")
    assert "selected no zone and no sub-contact" in session.output.getvalue()


# ------------------------------------------------------------------------------------------- lists
def test_zone_list_table(session):
    m = _model(session)
    session.command("block zone initialize stress -1e6 -2e6 -3e6 4 5 6")
    session.output.truncate(0)
    session.output.seek(0)
    session.command("block zone list range position-z 0.6 1")
    lines = session.output.getvalue().splitlines()
    zs = m.store("zones")
    c = _centroids(m)
    pick = np.flatnonzero(c[:, 2] >= 0.6)
    assert lines[0].split()[:6] == ["id", "block", "x", "y", "z", "volume"]
    assert len(lines) == 1 + pick.size
    for line, r in zip(lines[1:], pick):
        f = line.split()
        assert int(f[0]) == zs["id"][r] and int(f[1]) == 1
        np.testing.assert_allclose([float(x) for x in f[2:5]], c[r], rtol=1e-4)
        assert float(f[5]) == pytest.approx(zs["volume"][r], rel=1e-4)
        np.testing.assert_allclose([float(x) for x in f[6:12]], [-1e6, -2e6, -3e6, 4, 5, 6], rtol=1e-4)


def test_zone_list_information(session):
    _model(session)
    session.command("block zone list information")
    r = session.results
    # five tetrahedra of the unit cube: edges 1 and √2, corner tetrahedra have 54.74° dihedral angles
    # (arctan √2), the smallest volume is 1/6
    assert r["zones"] == 5 and r["gridpoints"] == 8
    assert r["zone_edge_min"] == pytest.approx(1.0, rel=1e-14)
    assert r["zone_edge_max"] == pytest.approx(2 ** 0.5, rel=1e-14)
    assert r["zone_dihedral_min"] == pytest.approx(np.degrees(np.arctan(2 ** 0.5)), rel=1e-12)
    assert r["zone_volume_min"] == pytest.approx(1 / 6, rel=1e-14)
    assert r["zone_volume"] == pytest.approx(1.0, rel=1e-14)
    assert "smallest dihedral angle 54.74 degrees" in session.output.getvalue()


def test_zone_list_without_zones(session):
    session.command("block create brick 0 1 0 1 0 1\nblock zone list information")
    assert session.results["zones"] == 0
    assert "zones 0 (of 0), gridpoints 0" in session.output.getvalue()


def test_gridpoint_list(session):
    m = _model(session)
    v = m.vertices
    session.command("block gridpoint apply velocity-z 0 range position-z 0")
    session.command("block gridpoint apply force 0 0 -5 range position 1 1 1")
    gp = np.flatnonzero(v["zoned"])
    v["disp"][gp] = np.arange(gp.size * 3).reshape(-1, 3) * 1e-3
    v["velocity"][gp, 0] = 0.5
    session.output.truncate(0)
    session.output.seek(0)
    session.command("block gridpoint list")
    lines = session.output.getvalue().splitlines()
    assert len(lines) == 1 + 8
    for line, r in zip(lines[1:], gp):
        f = line.split()
        assert int(f[0]) == r + 1 and int(f[1]) == 1
        nums = np.array([float(x) for x in f[2:11]])
        np.testing.assert_allclose(nums, np.concatenate([v["pos"][r], v["disp"][r], v["velocity"][r]]),
                                   rtol=1e-4, atol=1e-12)
        cond = " ".join(f[11:])
        assert ("vz=0" in cond) == (v["pos"][r, 2] == 0.0)
        assert ("fz=-5" in cond) == bool((v["pos"][r] == 1.0).all())


def test_gridpoint_list_of_rigid_range_warns(session):
    _model(session)
    session.command("block gridpoint list range position-x 3.5 4")
    assert "selected no gridpoint" in session.output.getvalue()
