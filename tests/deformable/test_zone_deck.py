"""The zone commands together in one deck: zoning, in-situ stress, lists, histories, VTK, save and restore."""
import meshio
import numpy as np


DECK = """model new
block create brick 0 2 0 1 0 1
block zone generate edgelength 0.5
block insitu stress -1e6 -1e6 -2e6 0 0 0 gradient-z 0 0 2e4 0 0 0
block zone initialize stress-xy 5e4 range position-x 1 2
block zone history name 'szz' stress-zz position 1.2 0.5 0.5
block history name 'dz' displacement-z position 2 1 1
block zone list information
block vtk 'zones'
model save 'state'
"""


def test_zone_deck_end_to_end(session, tmp_path):
    (tmp_path / "z.dat").write_text(DECK)
    session.call(tmp_path / "z.dat")
    m = session.model
    zs = m.store("zones")
    c = m.vertices["pos"][zs["gp"][:, :4]].mean(axis=1)
    np.testing.assert_allclose(zs["stress"][:, 2], -2e6 + 2e4 * c[:, 2], rtol=1e-14)
    np.testing.assert_array_equal(zs["stress"][:, 3], np.where(c[:, 0] >= 1 - m.tolerance, 5e4, 0.0))
    r = session.results
    assert r["zones"] == zs.n
    assert abs(r["zone_volume"] - 2.0) < 1e-12
    assert r["zone_volume_min"] > 0 and r["zone_dihedral_min"] > 5.0
    mesh = meshio.read(tmp_path / "zones_0000.vtu")
    assert [c.type for c in mesh.cells] == ["tetra"] and len(mesh.cells[0].data) == zs.n
    np.testing.assert_array_equal(mesh.cell_data["stress"][0][:, 2], zs["stress"][:, 2])
    kinds = [h.spec["kind"] for h in m.history_set.items]
    assert kinds == ["zone", "gridpoint"]
    stress = zs["stress"].copy()
    session.command("block zone initialize stress 0 0 0 0 0 0")
    session.command(f"model restore '{tmp_path / 'state'}'")
    np.testing.assert_array_equal(session.model.store("zones")["stress"], stress)
    assert [h.spec for h in session.model.history_set.items] == [h.spec for h in m.history_set.items]
