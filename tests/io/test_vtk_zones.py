"""VTK output of zoned blocks: tetra and quadratic-tetra cells with stress measures and gridpoint motion,
read back by pyvista and meshio with the values written; rigid blocks stay polyhedra."""
import meshio
import numpy as np
import pytest
import pyvista as pv

from dec3d.geometry.polyhedron import brick, tetrahedron
from dec3d.io.vtk import VtkSeries, write_vtu
from dec3d.model.blocks import add_blocks
from dec3d.model.model import Model
from tests.deformable.zone_fixtures import zone_tet10
from tests.zoning_fixture import zone_brick

# ParaView's symmetric tensor order XX YY ZZ XY YZ XZ, from the store's xx yy zz xy xz yz
_VTK = [0, 1, 2, 3, 5, 4]


def _zoned(rigid=True):
    m = Model()
    shapes = [brick(0, 1, 0, 1, 0, 1), tetrahedron((3, 0, 0), (4, 0, 0), (3, 1, 0), (3, 0, 1))]
    if rigid:
        shapes.append(brick(5, 6, 0, 1, 0, 2))
    add_blocks(m, shapes, density=2500.0)
    zone_brick(m, int(np.flatnonzero(m.blocks["id"] == 1)[0]))
    zone_tet10(m, int(np.flatnonzero(m.blocks["id"] == 2)[0]))
    zs = m.store("zones")
    rng = np.random.default_rng(11)
    zs["stress"][:] = rng.normal(size=(zs.n, 6)) * 1e6
    v = m.vertices
    gp = np.flatnonzero(v["zoned"])
    v["disp"][gp] = rng.normal(size=(gp.size, 3)) * 1e-3
    v["velocity"][gp] = rng.normal(size=(gp.size, 3))
    if rigid:
        m.blocks["velocity"][np.flatnonzero(m.blocks["id"] == 3)[0]] = [0.0, 0.0, -1.0]
    return m


def _expected(m):
    """Zone rows in the order written (4-node zones, then 10-node ones) and the measures, worked out here."""
    zs = m.store("zones")
    rows = np.concatenate([np.flatnonzero(zs["nnode"] == 4), np.flatnonzero(zs["nnode"] == 10)])
    s = zs["stress"][rows]
    full = np.array([[[a[0], a[3], a[4]], [a[3], a[1], a[5]], [a[4], a[5], a[2]]] for a in s])
    ev = np.sort(np.linalg.eigvals(full).real, axis=1)
    vm = np.sqrt(((ev[:, 0] - ev[:, 1]) ** 2 + (ev[:, 1] - ev[:, 2]) ** 2 + (ev[:, 2] - ev[:, 0]) ** 2) / 2)
    return rows, s, ev, vm


def test_zones_read_back_with_pyvista(tmp_path):
    m = _zoned()
    zs = m.store("zones")
    grid = pv.read(write_vtu(m, tmp_path / "all.vtu"))
    rows, s, ev, vm = _expected(m)
    assert grid.n_cells == 1 + zs.n and grid.n_points == m.vertices.n
    np.testing.assert_array_equal(grid.celltypes, [42] + [10] * 5 + [24])
    np.testing.assert_array_equal(grid.cell_data["zone_id"], np.concatenate([[0], zs["id"][rows]]))
    np.testing.assert_array_equal(grid.cell_data["overlay"], -1)
    np.testing.assert_array_equal(grid.cell_data["block_id"], [3, 1, 1, 1, 1, 1, 2])
    np.testing.assert_array_equal(grid.cell_data["stress"][1:], s[:, _VTK])
    np.testing.assert_array_equal(grid.cell_data["stress"][0], 0.0)
    np.testing.assert_allclose(grid.cell_data["mean_stress"][1:], s[:, :3].mean(axis=1), rtol=1e-12)
    np.testing.assert_allclose(grid.cell_data["principal_stress"][1:], ev, rtol=1e-9, atol=1e-6)
    np.testing.assert_allclose(grid.cell_data["von_mises"][1:], vm, rtol=1e-9)
    # VTK's own cell volumes: the polyhedron's and every zone's (a straight-edged 10-node zone too)
    sizes = grid.compute_cell_sizes(length=False, area=False)["Volume"]
    np.testing.assert_allclose(sizes, np.concatenate([[2.0], zs["volume"][rows]]), rtol=1e-12)
    assert (zs["volume"] > 0).all()
    # point data: gridpoints their own motion; rigid vertices their block's
    v = m.vertices
    gp = v["zoned"]
    np.testing.assert_array_equal(grid.point_data["displacement"][gp], v["disp"][gp])
    np.testing.assert_array_equal(grid.point_data["velocity"][gp], v["velocity"][gp])
    np.testing.assert_array_equal(grid.point_data["velocity"][~gp], np.tile([0, 0, -1.0], ((~gp).sum(), 1)))
    # the tensor as ParaView sees it: component names of a 6-component array, and the xz value
    assert grid.cell_data["stress"].shape == (1 + zs.n, 6)
    k = int(rows[0])
    assert grid.cell_data["stress"][1, 5] == zs["stress"][k, 4]


def test_series_of_a_mixed_model_reads_with_meshio_and_pyvista(tmp_path):
    m = _zoned()
    series = VtkSeries(tmp_path / "run")
    series.write(m, 0.0)
    m.store("zones")["stress"][:, 0] += 1.0
    series.write(m, 0.5)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.pvd", "run_0000.vtu", "run_0001.vtu",
                                                          "run_zones_0000.vtu", "run_zones_0001.vtu"]
    rows, s, ev, vm = _expected(m)
    z = meshio.read(tmp_path / "run_zones_0001.vtu")
    assert [(c.type, len(c.data)) for c in z.cells] == [("tetra", 5), ("tetra10", 1)]
    zs = m.store("zones")
    np.testing.assert_array_equal(z.cells[0].data, zs["gp"][rows[:5], :4])
    np.testing.assert_array_equal(z.cells[1].data, zs["gp"][rows[5:], :10])
    np.testing.assert_array_equal(np.concatenate(z.cell_data["stress"]), s[:, _VTK])
    np.testing.assert_allclose(np.concatenate(z.cell_data["von_mises"]), vm, rtol=1e-9)
    np.testing.assert_array_equal(np.concatenate(z.cell_data["zone_id"]), zs["id"][rows])
    gp = m.vertices["zoned"]
    np.testing.assert_array_equal(z.point_data["displacement"][gp], m.vertices["disp"][gp])
    b = meshio.read(tmp_path / "run_0001.vtu")
    assert [c.type for c in b.cells] == ["polyhedron8"] and "stress" not in b.cell_data
    np.testing.assert_array_equal(np.concatenate(b.cell_data["block_id"]), [3])
    reader = pv.get_reader(tmp_path / "run.pvd")
    assert list(reader.time_values) == [0.0, 0.5]
    reader.set_active_time_value(0.5)
    data = reader.read()
    assert data.n_blocks == 2
    assert data[0].n_cells == 1 and data[1].n_cells == zs.n
    np.testing.assert_array_equal(data[1].cell_data["stress"], s[:, _VTK])


def test_all_zoned_model_is_one_file_meshio_reads(tmp_path):
    m = _zoned(rigid=False)
    series = VtkSeries(tmp_path / "z")
    vtu = series.write(m, 0.0)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["z.pvd", "z_0000.vtu"]
    mesh = meshio.read(vtu)
    assert [c.type for c in mesh.cells] == ["tetra", "tetra10"]
    rows, s, ev, vm = _expected(m)
    np.testing.assert_allclose(np.concatenate(mesh.cell_data["principal_stress"]), ev, rtol=1e-9, atol=1e-6)
    np.testing.assert_array_equal(mesh.points, m.vertices["pos"])


def test_overlay_of_mixed_hexahedral_zones(tmp_path):
    m = Model()
    add_blocks(m, [brick(0, 1, 0, 1, 0, 1)], density=2000.0)
    zone_brick(m, 0, mixed=True)
    grid = pv.read(write_vtu(m, tmp_path / "hex.vtu"))
    assert grid.n_cells == 10
    np.testing.assert_array_equal(grid.cell_data["overlay"], [0] * 5 + [1] * 5)
    sizes = grid.compute_cell_sizes(length=False, area=False)["Volume"]
    for k in (0, 1):                               # each set fills the cube once
        assert sizes[grid.cell_data["overlay"] == k].sum() == pytest.approx(1.0, rel=1e-14)


def test_rigid_only_output_is_unchanged_by_an_empty_zones_store(tmp_path):
    from dec3d.model.zones import zone_stores
    m = Model()
    add_blocks(m, [brick(0, 1, 0, 1, 0, 1)], density=2000.0)
    a = open(write_vtu(m, tmp_path / "a.vtu"), "rb").read()
    zone_stores(m)
    b = open(write_vtu(m, tmp_path / "b.vtu"), "rb").read()
    assert a == b and b"zone_id" not in b


@pytest.mark.parametrize("cells", ["blocks", "zones"])
def test_write_vtu_cells_selector(tmp_path, cells):
    m = _zoned()
    grid = pv.read(write_vtu(m, tmp_path / f"{cells}.vtu", cells=cells))
    assert grid.n_cells == (1 if cells == "blocks" else m.store("zones").n)
