"""Face triangulation: counts, closed surfaces, unchanged mass properties, kept groups."""
import numpy as np
import pytest

from dec3d.geometry.assemble import block_poly
from dec3d.geometry.errors import GeometryError
from dec3d.geometry.polyhedron import brick
from dec3d.geometry.triangulate import triangulate_blocks
from dec3d.model.blocks import add_blocks
from dec3d.model.model import Model


def two_bricks():
    m = Model()
    add_blocks(m, [brick(0, 1, 0, 1, 0, 1), brick(1, 2, 0, 1, 0, 1)], density=1000.0)
    m.groups.assign(m.faces, np.arange(6), "left-faces")
    return m


def closed(poly):
    edges = {}
    for loop in poly.faces():
        for a, b in zip(loop, np.roll(loop, -1)):
            edges[(a, b)] = edges.get((a, b), 0) + 1
    return all(c == 1 for c in edges.values()) and all((b, a) in edges for a, b in edges)


@pytest.mark.parametrize("mode, edge, faces, verts", [
    ("radial", None, 24, 14), ("radial-8", None, 48, 26), ("edge-max", 0.3, 384, 194)])
def test_triangulate_modes(mode, edge, faces, verts):
    m = two_bricks()
    before = {k: m.blocks[k].copy() for k in ("volume", "centroid", "inertia", "mass")}
    assert triangulate_blocks(m, [0], mode, edge) == faces
    b = m.blocks
    assert b["face_count"][0] == faces and b["vert_count"][0] == verts
    assert b["face_count"][1] == 6
    for k, v in before.items():
        np.testing.assert_allclose(b[k], v, rtol=1e-12, atol=1e-12)
    p = block_poly(m, 0)
    assert closed(p)
    assert (np.diff(p.face_ptr) == 3).all()
    code = m.groups.code("left-faces")
    fs = slice(b["face_start"][0], b["face_start"][0] + b["face_count"][0])
    assert (m.faces["group"][fs, 0] == code).all()
    if mode == "edge-max":
        pts = p.vertices[p.face_idx.reshape(-1, 3)]
        longest = np.linalg.norm(pts - np.roll(pts, 1, axis=1), axis=2).max()
        assert longest <= edge


def test_bad_mode_is_refused():
    with pytest.raises(GeometryError, match="unknown mode"):
        triangulate_blocks(two_bricks(), [0], "spiral")
    with pytest.raises(GeometryError, match="positive"):
        triangulate_blocks(two_bricks(), [0], "edge-max", 0.0)
