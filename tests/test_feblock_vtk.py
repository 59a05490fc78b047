"""`block vtk` with FE blocks: the elements go to `<stem>_fe_<nnnn>.vtu` as quadratic hexahedra
(VTK 25), part 2 of the .pvd, with nodal displacements and element-averaged Gauss-point
stresses, read back by meshio and pyvista against the model after a solve."""
import io
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from dec3d.session import Session

BEAM = """model new
model configure feblock
block create brick 0 10 0 1 0 1
feblock generate 1 1 1 integration 3
block zone cmodel assign elastic
block zone property density 2000 young 1e6 poisson 0.2
block gridpoint apply velocity 0 0 0 range position-x 0
block gridpoint apply force-z [-100.0/3.0] range position-x 10 position-z 1
model large-strain off
model solve
block vtk 'beam'
"""


@pytest.fixture(scope="module")
def solved(tmp_path_factory):
    out = tmp_path_factory.mktemp("fevtk")
    s = Session(out_dir=out, stdout=io.StringIO())
    s.command(BEAM)
    return s, out


def test_pvd_lists_the_fe_file_as_part_2(solved):
    s, out = solved
    sets = ET.parse(out / "beam.pvd").getroot().findall(".//DataSet")
    assert [(d.get("file"), d.get("part")) for d in sets] == [("beam_0000.vtu", "0"), ("beam_fe_0000.vtu", "2")]


def test_meshio_reads_elements_displacement_and_stress(solved):
    import meshio

    s, out = solved
    m = s.model
    es, v = m.store("feblocks"), m.vertices
    mesh = meshio.read(out / "beam_fe_0000.vtu")
    assert [c.type for c in mesh.cells] == ["hexahedron20"] and mesh.cells[0].data.shape == (10, 20)
    rows = mesh.point_data["vertex_row"]
    assert np.array_equal(rows[mesh.cells[0].data], es["nodes"][:10])
    d = mesh.point_data["displacement"]
    assert np.array_equal(d, v["disp"][rows])
    tip = np.flatnonzero(np.all(abs(mesh.points - [10, 1, 1]) < 1e-9, axis=1))[0]
    assert abs(-d[tip, 2] - 0.3996) < 0.002 * 0.3996                   # the solved deflection
    # stress: per element the volume-weighted mean of its 27 Gauss-point stresses, XX YY ZZ XY YZ XZ
    st = mesh.cell_data["stress"][0]
    gs = es["gstress"][:10, :27]
    assert np.allclose(st[:, [0, 1, 2, 3, 5, 4]], es["stress"][:10], rtol=0, atol=0)
    assert np.allclose(mesh.cell_data["stress_gauss_mean"][0][:, [0, 1, 2, 3, 5, 4]], gs.mean(axis=1))
    # bending: sigma_xx at the root element's top is tension, bottom compression; the element mean
    # of a linear distribution through the depth is about zero next to M c / I = 1000 * 0.5 * 12
    assert np.abs(st[:, 0]).max() < 0.05 * 6000.0
    # equilibrium of every cross-section: the element mean sigma_xz carries the 100 N (down, on the
    # +x face) over 1 m^2
    assert np.allclose(st[:, 5], -100.0, rtol=0.01)


def test_pyvista_reads_quadratic_hexahedra_of_the_element_volumes(solved):
    pv = pytest.importorskip("pyvista")
    s, out = solved
    grid = pv.read(out / "beam_fe_0000.vtu")
    assert grid.n_cells == 10 and (np.asarray(grid.celltypes) == 25).all()
    vol = grid.compute_cell_sizes(length=False, area=False)["Volume"]
    assert np.allclose(vol, s.model.store("feblocks")["volume"][:10], rtol=1e-9)
    assert np.allclose(np.asarray(grid.point_data["displacement"]),
                       s.model.vertices["disp"][np.asarray(grid.point_data["vertex_row"])])


def test_rigid_only_model_writes_no_fe_file(tmp_path):
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command("model new\nblock create brick 0 1 0 1 0 1\nblock vtk 'r'")
    assert (tmp_path / "r_0000.vtu").is_file() and not list(tmp_path.glob("r_fe_*"))
