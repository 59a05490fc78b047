"""The arrays added for readers of the VTK files (issue 31, item 2), read back with meshio and checked
against the stores: plastic state as categories, zone stress averaged to the gridpoints (against a plain
loop over the zones), group names and plastic labels as text, stress component names."""
import numpy as np

DECK = """model new
block create brick 0 1 0 1 0 2 group 'rock'
block group 'upper' range position-z 1 2
block zone generate edgelength 0.5
block zone cmodel assign mohr-coulomb
block zone property bulk 1e8 shear 6e7 density 2000 cohesion 1e3 friction 30 tension 1e2
block gridpoint apply velocity 0 0 0 range position-z 0
model gravity 0 0 -9.81
model cycle 300
block vtk 'z'"""


def _twin_gridpoint_stress(zs, nvert):
    """Σ V σ / Σ V over the zones that use each point, zone by zone (all nodes of each zone)."""
    num = [np.zeros(6) for _ in range(nvert)]
    den = [0.0] * nvert
    for z in range(zs.n):
        for k in range(int(zs["nnode"][z])):
            g = int(zs["gp"][z, k])
            num[g] = num[g] + abs(zs["volume"][z]) * zs["stress"][z]
            den[g] += abs(zs["volume"][z])
    return np.array([num[g] / den[g] if den[g] > 0 else np.zeros(6) for g in range(nvert)])


def test_zone_arrays_round_trip(session, tmp_path):
    import meshio

    from dec3d.io.vtk import PLASTIC_LABELS, read_text_array

    for line in DECK.splitlines():
        session.command(line)
    m = meshio.read(tmp_path / "z_0000.vtu")
    zs = session.model.store("zones")
    zid = np.concatenate(m.cell_data["zone_id"])
    row = {int(i): r for r, i in enumerate(zs["id"])}
    rows = np.array([row[int(i)] for i in zid])
    state = zs["state"][rows]
    assert len(np.unique(state)) >= 3                      # the deck yields zones in several ways
    for bit, key in ((1, "shear_now"), (2, "tension_now"), (4, "shear_past"), (8, "tension_past")):
        got = np.concatenate(m.cell_data[key])
        assert got.dtype == np.uint8
        np.testing.assert_array_equal(got, (state & bit) != 0)
    labels = read_text_array(m.field_data["plastic_labels"])
    assert labels == list(PLASTIC_LABELS) and labels[0] == "none" and labels[5] == "shear-n shear-p"
    code = np.concatenate(m.cell_data["plastic_label"])
    np.testing.assert_array_equal(code, state & 15)
    np.testing.assert_array_equal(np.concatenate(m.cell_data["plastic_state"]), state)   # kept as it was
    # stress at the gridpoints, VTK order XX YY ZZ XY YZ XZ
    twin = _twin_gridpoint_stress(zs, session.model.vertices.n)[:, [0, 1, 2, 3, 5, 4]]
    np.testing.assert_allclose(m.point_data["stress_gp"], twin, rtol=1e-12, atol=1e-9 * np.abs(twin).max())
    assert np.abs(twin[:, 2]).max() > 1e3                   # gravity loaded them
    assert read_text_array(m.field_data["group_names"]) == list(session.model.groups.names)
    assert "upper" in read_text_array(m.field_data["group_names"])
    text = (tmp_path / "z_0000.vtu").read_text()
    assert 'Name="stress" NumberOfComponents="6" ComponentName0="XX" ComponentName1="YY" ComponentName2="ZZ" ' \
           'ComponentName3="XY" ComponentName4="YZ" ComponentName5="XZ"' in text
    # PyVista reads the same
    import pyvista as pv
    g = pv.read(tmp_path / "z_0000.vtu")
    np.testing.assert_array_equal(g.cell_data["plastic_label"], code)
