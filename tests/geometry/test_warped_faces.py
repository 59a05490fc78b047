"""Warped faces (real masonry geometry): a face whose corners lie off its plane by more than the tolerance
but by at most 0.5 % of the block's size is accepted, the block built as the convex hull of its corners
(the warped face split into triangles), with one warning naming block, face and warp; beyond, refused
with the distance and the limit (dec3d.geometry.polyhedron.WARP_RELATIVE)."""
import io
import math

import numpy as np
import pytest

from dec3d.errors import Dec3dError
from dec3d.geometry.errors import GeometryError
from dec3d.geometry.polyhedron import WARP_RELATIVE, build_many, poly_volume, polyhedron_from_faces
from dec3d.session import Session


def warped_cube(d: float, z0: float = 0.0):
    """The unit cube with its corner (1, 1, 1) raised by d: the top face is warped, the sides x=1 and y=1
    stay planar (they contain the raised corner)."""
    c = lambda x, y, z: (x, y, z + z0)
    top = 1 + d
    return [[c(0, 0, 0), c(0, 1, 0), c(1, 1, 0), c(1, 0, 0)], [c(0, 0, 1), c(1, 0, 1), c(1, 1, top), c(0, 1, 1)],
            [c(0, 0, 0), c(1, 0, 0), c(1, 0, 1), c(0, 0, 1)], [c(1, 0, 0), c(1, 1, 0), c(1, 1, top), c(1, 0, 1)],
            [c(1, 1, 0), c(0, 1, 0), c(0, 1, 1), c(1, 1, top)], [c(0, 1, 0), c(0, 0, 0), c(0, 0, 1), c(0, 1, 1)]]


def _triangulated_volume(d: float) -> float:
    """Volume of the cube under the top face split along its convex diagonal (0,0)-(1,1): the height above
    z=1 is d·y on the triangle (0,0),(1,0),(1,1) and d·x on (0,0),(1,1),(0,1); each integral is d/6
    (area 1/2 times the mean of a linear height with corner values 0, 0, d)."""
    return 1.0 + 2 * (0.5 * d / 3)


def _warp(d: float) -> float:
    """Distance of the top face's corners from its mean plane (Newell normal through the mean point): the
    bilinear warp puts each corner about d/4 off."""
    n = np.array([-d / 2, -d / 2, 1.0])            # Newell normal of the top loop (up to its length)
    pts = np.array([(0, 0, 1), (1, 0, 1), (1, 1, 1 + d), (0, 1, 1)], dtype=float)
    return float(abs((pts[0] - pts.mean(axis=0)) @ n) / np.linalg.norm(n))


def test_a_slightly_warped_face_is_split_and_the_volume_is_exact():
    d = 1e-3
    warped = []
    poly = polyhedron_from_faces(warped_cube(d), 1e-6, "polyhedron", WARP_RELATIVE, warped)
    assert math.isclose(poly_volume(poly), _triangulated_volume(d), rel_tol=1e-12)
    assert poly.nfaces == 7                            # the warped top became two triangles
    assert sorted(len(f) for f in poly.faces()) == [3, 3, 4, 4, 4, 4, 4]
    [(face, corner, dist, limit)] = warped
    assert face == 2 and math.isclose(dist, _warp(d), rel_tol=1e-9)
    assert math.isclose(limit, WARP_RELATIVE * math.sqrt(2 + (1 + d) ** 2), rel_tol=1e-12)


def test_without_the_rule_or_beyond_it_the_face_is_refused_with_the_numbers():
    with pytest.raises(GeometryError, match=r"face 2 is not planar: corner 1 \(0, 0, 1\) lies 0.00025 m off"):
        polyhedron_from_faces(warped_cube(1e-3), 1e-6)
    with pytest.raises(GeometryError) as info:
        polyhedron_from_faces(warped_cube(0.05), 1e-6, "polyhedron", WARP_RELATIVE, [])
    msg = str(info.value)
    assert "face 2 is not planar" in msg and f"lies {_warp(0.05):.3g} m off" in msg
    assert "a warp is accepted up to 0.5 % of the block's size, 0.00881 m" in msg


def _deck(*cubes):
    lines = ["model new"]
    for d, z0 in cubes:
        lines.append("block create polyhedron " + " ".join(
            "face " + " ".join(f"{x:g},{y:g},{z:g}" for x, y, z in f) for f in warped_cube(d, z0)))
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("batch_min", [2, 10**9])
def test_block_create_warns_once_naming_block_face_and_warp(tmp_path, batch_min):
    """The batched pass (build_many, strict like its kernel) stops at the warped line, which is built on its
    own; the lines after it go on. Both paths make the same three blocks."""
    out = io.StringIO()
    s = Session(out_dir=tmp_path, stdout=out)
    s.batch_min = batch_min
    s.run_items(s.load_text(_deck((0, 0), (1e-3, 2), (0, 4)), "warp.dat"))
    assert s.model.blocks.n == 3
    warnings = [line for line in out.getvalue().splitlines() if line.startswith("warning:")]
    assert warnings == [
        "warning: warp.dat:3:1: block 2: face 2 is warped: corner 1 lies 0.00025 off the face's plane "
        "(tolerance 1e-06; accepted up to 0.5 % of the block's size, 0.00866): the block is built as the "
        "convex hull of its corners, the warped face split into triangles"]
    assert np.allclose(s.model.blocks["volume"][:3], [1.0, _triangulated_volume(1e-3), 1.0], rtol=1e-12, atol=0)


def test_the_compiled_pass_stays_strict():
    pts = np.concatenate([np.array(f, dtype=float) for f in warped_cube(1e-3)])
    built, _ = build_many([(pts, np.full(6, 4, dtype=np.int64))], 1e-6)
    assert built == 0                                  # the line path takes it (with the warning above)


def test_a_block_warped_beyond_the_rule_stops_the_run_at_its_line(tmp_path):
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    with pytest.raises(Dec3dError, match="accepted up to 0.5 % of the block's size") as info:
        s.run_items(s.load_text(_deck((0, 0), (0.05, 2)), "warp.dat"))
    assert info.value.location.line == 3 and s.model.blocks.n == 1
