"""VTK snapshots read back with pyvista."""
import math

import numpy as np
import pytest
import pyvista as pv

from dec3d.geometry.cutting import cut_joint_set
from dec3d.geometry.polyhedron import brick, tetrahedron
from dec3d.io.vtk import VtkSeries, write_vtu
from dec3d.model.blocks import add_blocks, group_blocks, hide_blocks
from dec3d.model.model import Model


@pytest.fixture
def model():
    m = Model()
    add_blocks(m, [brick(0, 2, 0, 2, 0, 2), tetrahedron((3, 0, 0), (4, 0, 0), (3, 1, 0), (3, 0, 1))],
               density=2500.0, group="rock")
    cut_joint_set(m, math.radians(60), math.radians(30), spacing=0.7)
    group_blocks(m, m.blocks["centroid"][:, 2] > 1, "top", slot="level")
    hide_blocks(m, m.blocks["id"] == 2)
    m.blocks["velocity"][:, 2] = -1.0
    return m


def test_vtu_reads_back_with_cells_and_data(model, tmp_path):
    path = write_vtu(model, tmp_path / "blocks.vtu")
    grid = pv.read(path)
    b = model.blocks
    assert grid.n_cells == b.n and grid.n_points == model.vertices.n
    assert (grid.celltypes == 42).all()
    order = np.argsort(b["vert_count"], kind="stable")      # cells go by vertex count, then row
    np.testing.assert_array_equal(grid.cell_data["block_id"], b["id"][order])
    np.testing.assert_array_equal(grid.cell_data["density"], b["density"][order])
    np.testing.assert_array_equal(grid.cell_data["volume"], b["volume"][order])
    np.testing.assert_array_equal(grid.cell_data["hidden"], b["hidden"][order].astype(np.uint8))
    np.testing.assert_array_equal(grid.cell_data["group:Default"], b["group"][order, 0])
    np.testing.assert_array_equal(grid.cell_data["group:level"], b["group"][order, 1])
    assert {k: int(grid.field_data[k][0]) for k in grid.field_data.keys()
            if k.startswith("group_code:")} == {"group_code:rock": 0, "group_code:top": 1}
    from dec3d.io.vtk import read_text_array
    assert read_text_array(grid.field_data["group_names"]) == ["rock", "top"]      # line i: the name of code i
    np.testing.assert_array_equal(grid.point_data["displacement"], 0.0)     # nothing has moved
    np.testing.assert_array_equal(grid.point_data["velocity"], np.tile([0, 0, -1.0], (model.vertices.n, 1)))
    # VTK computes the same polyhedron volumes from the faces written
    sizes = grid.compute_cell_sizes(length=False, area=False)["Volume"]
    np.testing.assert_allclose(sizes, b["volume"][order], rtol=1e-12)


def test_vtu_is_deterministic(model, tmp_path):
    a = write_vtu(model, tmp_path / "a.vtu")
    b = write_vtu(model, tmp_path / "b.vtu")
    assert open(a, "rb").read() == open(b, "rb").read()


def test_pvd_series(model, tmp_path):
    series = VtkSeries(tmp_path / "out" / "run")
    series.write(model, 0.0)
    model.vertices["pos"][:, 2] += 0.5
    series.write(model, 0.25)
    reader = pv.get_reader(series.pvd_path)
    assert list(reader.time_values) == [0.0, 0.25]
    reader.set_active_time_value(0.25)
    mesh = reader.read()[0]
    assert mesh.n_cells == model.blocks.n
    assert mesh.bounds[5] == pytest.approx(2.5)


def test_empty_model_writes_a_valid_file(tmp_path):
    grid = pv.read(write_vtu(Model(), tmp_path / "empty.vtu"))
    assert grid.n_cells == 0
