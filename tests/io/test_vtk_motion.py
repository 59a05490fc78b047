"""VTK point and cell data carry what the blocks really did; every file reads back in PyVista and meshio.

Motions with a closed form under the engine's update (velocity first, then position; the
rotation of a step is the Cayley map of a = ω Δt / 2, a turn by 2 atan(|a|)):
- free fall from rest, no damping: after n steps u_z = −g Δt² n (n + 1) / 2 at every vertex
  (→ −g t²/2 as Δt → 0) and v_z = −g n Δt;
- a free spin ω about z (no gravity): the angle is n · 2 atan(ω Δt / 2) and the velocity at a
  vertex is ω × (x − c).
"""
import math
import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest
import pyvista as pv

from dec3d.geometry.polyhedron import brick, tetrahedron
from dec3d.io.vtk import write_vtu
from dec3d.model.blocks import add_blocks
from dec3d.model.kinematics import rotation_vector, unwrap_rotation
from dec3d.model.model import Model

G, DT, N = 10.0, 1e-3, 400

FALL = f"""model new
block create brick 0 1 0 1 0 1
block create tetrahedron 3 0 0  4 0 0  3 1 0  3 0 1
block property density 2000
model gravity 0 0 -{G}
block mechanical damping none
block mechanical timestep {DT}
model cycle {N}
block vtk 'fall'
"""

W = 2.0
SPIN = f"""model new
block create brick 0 1 0 2 0 0.5
block property density 2000
block mechanical damping none
block mechanical timestep {DT}
block initialize rvelocity-z {W}
model cycle {N}
block vtk 'spin'
"""


def _meshio_cells(mesh, name):
    """meshio groups polyhedra by vertex count: put a cell array back in block-id order."""
    ids = np.concatenate(mesh.cell_data["block_id"])
    vals = np.concatenate(mesh.cell_data[name])
    return vals[np.argsort(ids)]


def _pv_cells(grid, name):
    """Cells are written by vertex count: a cell array of a PyVista grid in block-id order."""
    return np.asarray(grid.cell_data[name])[np.argsort(grid.cell_data["block_id"])]


def _read_both(path):
    return pv.read(path), meshio.read(path)


def test_free_fall_vertex_displacement_and_velocity(session, tmp_path):
    session.run_items(session.load_text(FALL))
    grid, mesh = _read_both(tmp_path / "fall_0000.vtu")
    uz = -G * DT ** 2 * N * (N + 1) / 2
    t = N * DT
    for u, v in ((grid.point_data["displacement"], grid.point_data["velocity"]),
                 (mesh.point_data["displacement"], mesh.point_data["velocity"])):
        assert u.shape == (session.model.vertices.n, 3)
        np.testing.assert_allclose(u[:, 2], uz, rtol=1e-9)
        assert np.abs(u[:, :2]).max() <= 1e-9 * abs(uz)
        assert u[:, 2] == pytest.approx(-G * t * t / 2, rel=1.5 / N)   # the continuous solution
        np.testing.assert_allclose(v, np.tile([0.0, 0.0, -G * t], (len(v), 1)), rtol=1e-9, atol=1e-12)
    # cell data: the block's own motion, in block order in both readers
    np.testing.assert_allclose(grid.cell_data["displacement"][:, 2], uz, rtol=1e-9)
    np.testing.assert_allclose(_meshio_cells(mesh, "velocity")[:, 2], -G * t, rtol=1e-9)
    assert np.abs(grid.cell_data["rotation_angle"]).max() < 1e-12
    # the points written are where the vertices are now
    np.testing.assert_array_equal(mesh.points, session.model.vertices["pos"])


def test_spinning_block_vertex_velocity_and_rotation(session, tmp_path):
    session.run_items(session.load_text(SPIN))
    grid, mesh = _read_both(tmp_path / "spin_0000.vtu")
    c = np.array([0.5, 1.0, 0.25])                       # the centroid does not move
    x = grid.points
    expect_v = np.cross([0.0, 0.0, W], x - c)
    for v in (grid.point_data["velocity"], mesh.point_data["velocity"]):
        np.testing.assert_allclose(v, expect_v, rtol=1e-9, atol=1e-12)
    angle = N * 2 * math.atan(W * DT / 2)
    for rot, ang in ((grid.cell_data["rotation"], grid.cell_data["rotation_angle"]),
                     (_meshio_cells(mesh, "rotation"), _meshio_cells(mesh, "rotation_angle"))):
        assert rot[0, 2] == pytest.approx(angle, rel=1e-9) and abs(rot[0, :2]).max() < 1e-12
        assert ang[0] == pytest.approx(angle, rel=1e-9)
    assert angle == pytest.approx(W * N * DT, rel=1e-6)
    # a vertex moved by the rotation about the centroid: u = (R − I)(x₀ − c)
    x0 = x - grid.point_data["displacement"]
    ca, sa = math.cos(angle), math.sin(angle)
    rot_z = np.array([[ca, -sa, 0], [sa, ca, 0], [0, 0, 1]])
    np.testing.assert_allclose(x, c + (x0 - c) @ rot_z.T, atol=1e-12)


def test_cut_pieces_keep_their_displacement(session, tmp_path):
    """A block cut after it fell: old vertices keep their origin, new ones get position − disp."""
    session.run_items(session.load_text(FALL + "block cut joint-set dip 90 dip-direction 90 origin 0.5 0 0\n"
                                               "block vtk 'cut'\n"))
    uz = -G * DT ** 2 * N * (N + 1) / 2
    for path in (tmp_path / "cut_0000.vtu",):
        grid, mesh = _read_both(path)
        assert grid.n_cells == 3
        np.testing.assert_allclose(grid.point_data["displacement"][:, 2], uz, rtol=1e-9)
        np.testing.assert_allclose(mesh.point_data["displacement"][:, 2], uz, rtol=1e-9)


def test_every_array_matches_the_model_in_pyvista_and_meshio(tmp_path):
    m = Model()
    add_blocks(m, [brick(0, 2, 0, 2, 0, 2), tetrahedron((3, 0, 0), (4, 0, 0), (3, 1, 0), (3, 0, 1))],
               density=2500.0, group="rock")
    add_blocks(m, [brick(5, 6, 0, 1, 0, 1)], density=1000.0, group="top", slot="level")
    b = m.blocks
    b["velocity"][:] = [[1.0, 2.0, 3.0], [0.0, -1.0, 0.5], [4.0, 0.0, 0.0]]
    b["spin"][:] = [[0.0, 0.0, 1.0], [0.5, 0.0, 0.0], [0.0, 0.0, 0.0]]
    b["disp"][:] = [[0.1, 0.0, 0.0], [0.0, 0.2, 0.0], [0.0, 0.0, 0.3]]
    m.vertices["pos"][:] += np.arange(m.vertices.n * 3).reshape(-1, 3) * 1e-3   # not a rigid motion
    path = write_vtu(m, tmp_path / "all.vtu")
    grid, mesh = _read_both(path)
    v = m.vertices
    arm = v["pos"] - b["centroid"][v["block"]]
    point = {"displacement": v["pos"] - v["origin"],
             "velocity": b["velocity"][v["block"]] + np.cross(b["spin"][v["block"]], arm)}
    for key, want in point.items():
        np.testing.assert_array_equal(grid.point_data[key], want)
        np.testing.assert_array_equal(mesh.point_data[key], want)
    cell = {"block_id": b["id"], "density": b["density"], "volume": b["volume"], "mass": b["mass"],
            "hidden": b["hidden"].astype(np.uint8), "kind": b["kind"], "displacement": b["disp"],
            "velocity": b["velocity"], "spin": b["spin"], "group:Default": b["group"][:, 0],
            "group:level": b["group"][:, 1]}
    for key, want in cell.items():
        np.testing.assert_array_equal(_pv_cells(grid, key), want)
        np.testing.assert_array_equal(_meshio_cells(mesh, key), want)
    # the same cell order in both readers: by vertex count (4 before 8), then row
    np.testing.assert_array_equal(grid.cell_data["block_id"], [2, 1, 3])
    np.testing.assert_array_equal(np.concatenate(mesh.cell_data["block_id"]), [2, 1, 3])
    for reader_fd in (grid.field_data, mesh.field_data):
        codes = {k.split(":", 1)[1]: int(np.asarray(reader_fd[k]).ravel()[0])
                 for k in reader_fd.keys() if k.startswith("group_code:")}
        assert codes == {"rock": 0, "top": 1}
    np.testing.assert_array_equal(mesh.points, v["pos"])


def test_pvd_and_each_snapshot_open_in_both_readers(session, tmp_path):
    session.run_items(session.load_text(FALL.replace("block vtk 'fall'", "block vtk 'series' interval 100")
                                        + "model cycle 200\n"))
    pvd = tmp_path / "series.pvd"
    files = [tmp_path / d.get("file") for d in ET.parse(pvd).getroot().iter("DataSet")]
    reader = pv.get_reader(str(pvd))
    assert len(files) == len(reader.time_values) == 3
    for k, f in enumerate(files):
        reader.set_active_time_value(reader.time_values[k])
        mesh = meshio.read(f)
        np.testing.assert_array_equal(reader.read()[0].point_data["displacement"], mesh.point_data["displacement"])
    assert mesh.point_data["displacement"][:, 2].max() < -1.0


def test_rotation_vector_and_unwrap():
    """Rotation vectors of known rotations (about an axis by θ, incl. θ near and at π)."""
    def rot(axis, th):
        n = np.asarray(axis, float) / np.linalg.norm(axis)
        k = np.array([[0, -n[2], n[1]], [n[2], 0, -n[0]], [-n[1], n[0], 0]])
        return np.eye(3) + math.sin(th) * k + (1 - math.cos(th)) * k @ k
    cases = [((1, 2, 3), 0.3), ((0, 0, 1), 1e-9), ((1, -1, 0.5), math.pi - 1e-7), ((0, 1, 0), 2.5), ((1, 0, 0), 0.0)]
    rv = rotation_vector(np.array([rot(a, t) for a, t in cases]))
    for (a, t), r in zip(cases, rv):
        n = np.asarray(a, float) / np.linalg.norm(a)
        np.testing.assert_allclose(r, t * n, atol=1e-12 + 1e-9 * t)
    # past π the short way round flips the axis; unwrapping against the previous sample keeps ω t
    prev = np.array([0.0, 0.0, 3.1])
    short = rotation_vector(rot((0, 0, 1), 3.2)[None])[0]
    assert short[2] == pytest.approx(3.2 - 2 * math.pi)
    assert unwrap_rotation(short, prev)[2] == pytest.approx(3.2)


def test_state_file_without_vertex_origins_restores_them(session, tmp_path):
    """A file saved before vertices had an origin: each vertex is taken to have moved with its block."""
    import json
    import zipfile

    from dec3d.io.state import restore_state, save_state

    session.run_items(session.load_text(FALL))
    src, old = tmp_path / "new.d3s", tmp_path / "old.d3s"
    save_state(session.model, src)
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(old, "w") as zout:
        for item in zin.infolist():
            if item.filename in ("vertices.origin.npy", "signature.json"):     # an old file has neither
                continue
            data = zin.read(item.filename)
            if item.filename.endswith(".json"):
                meta = json.loads(data)
                del meta["stores"]["vertices"]["fields"]["origin"]
                del meta["sha256"]["vertices.origin"]
                data = json.dumps(meta).encode()
            zout.writestr(item, data)
    model, _ = restore_state(old)
    uz = -G * DT ** 2 * N * (N + 1) / 2
    np.testing.assert_allclose((model.vertices["pos"] - model.vertices["origin"])[:, 2], uz, rtol=1e-9)
    restored, _ = restore_state(src)
    np.testing.assert_array_equal(restored.vertices["origin"], session.model.vertices["origin"])


def test_a_block_cut_after_it_turned_keeps_its_material_frame(session, tmp_path):
    """Spin the brick by θ about z, then cut it: every vertex of the pieces, old or made by the cut, has
    origin = c + Rz(θ)ᵀ (x − c) (the centroid c stays put), and each piece reads rotation θ about z."""
    session.run_items(session.load_text(SPIN + "block cut joint-set dip 90 dip-direction 90 origin 0.5 0 0\n"
                                               "block vtk 'cutspin'\n"))
    m = session.model
    assert m.blocks.n == 2
    th = N * 2 * math.atan(W * DT / 2)
    c = np.array([0.5, 1.0, 0.25])
    rz = np.array([[math.cos(th), -math.sin(th), 0], [math.sin(th), math.cos(th), 0], [0, 0, 1]])
    v = m.vertices
    np.testing.assert_allclose(v["origin"], c + (v["pos"] - c) @ rz, atol=1e-12)
    grid = pv.read(tmp_path / "cutspin_0000.vtu")
    np.testing.assert_allclose(grid.cell_data["rotation"], [[0, 0, th], [0, 0, th]], atol=1e-12)
