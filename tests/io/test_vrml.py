"""`block generate from-vrml`: VRML 2.0 IndexedFaceSets as convex blocks (dec3d.io.vrml).

The files are written here: unit cubes as 12 triangles (the way CAD exporters write them) or as
6 quads, with Transforms whose effect is worked out by hand below.
"""
import io
import math

import numpy as np
import pytest

from dec3d.errors import Dec3dError
from dec3d.io.vrml import VrmlError, read_vrml_shapes, vrml_polys
from dec3d.session import Session

CUBE_PTS = "0 0 0, 1 0 0, 1 1 0, 0 1 0, 0 0 1, 1 0 1, 1 1 1, 0 1 1"
CUBE_TRI = ("0 3 2 -1 0 2 1 -1 4 5 6 -1 4 6 7 -1 0 1 5 -1 0 5 4 -1 "
            "1 2 6 -1 1 6 5 -1 2 3 7 -1 2 7 6 -1 3 0 4 -1 3 4 7 -1")
CUBE_QUAD = "0 3 2 1 -1 4 5 6 7 -1 0 1 5 4 -1 1 2 6 5 -1 2 3 7 6 -1 3 0 4 7"     # last face without -1


def shape(points=CUBE_PTS, index=CUBE_TRI):
    return ("Shape {\n  appearance Appearance { material Material { diffuseColor 0 1 0 } }\n"
            "  geometry IndexedFaceSet {\n    ccw TRUE convex TRUE solid FALSE\n"
            f"    coordIndex [ {index} ]\n"
            f"    coord Coordinate {{ point [ {points} ] }}\n  }}\n}}\n")


def wrl(*body):
    return "#VRML V2.0 utf8\nBackground { skyColor [ 0.6 0.6 0.6 ] }\n" + "".join(body)


def run(tmp_path, files, deck):
    for name, text in files.items():
        (tmp_path / name).write_text(text, encoding="utf-8")
    (tmp_path / "main.dat").write_text(deck, encoding="utf-8")
    s = Session(out_dir=tmp_path / "out", stdout=io.StringIO())
    s.run_items(s.load_file(tmp_path / "main.dat"))
    return s


def test_triangulated_cubes_become_six_faced_blocks_placed_by_transforms(tmp_path):
    # second cube: rotated 90° about z (x -> y, y -> -x), then moved up by 1
    text = wrl(shape(), "Transform {\n translation 0 0 1\n rotation 0 0 1 1.5707963267948966\n children [\n",
               shape(index=CUBE_QUAD), "] }\n")
    s = run(tmp_path, {"course.wrl": text}, "block generate from-vrml filename 'course.wrl'\nblock group 'C1'\n")
    b = s.model.blocks
    assert b.n == 2
    assert b["volume"][:2] == pytest.approx([1.0, 1.0], rel=1e-12)
    assert b["centroid"][0] == pytest.approx([0.5, 0.5, 0.5], abs=1e-12)
    assert b["centroid"][1] == pytest.approx([-0.5, 0.5, 1.5], abs=1e-12)
    # the 12 triangles of the first cube are merged back into its 6 square faces
    assert b["face_count"][:2].tolist() == [6, 6]
    assert s.model.faces["area"][:12] == pytest.approx(np.ones(12), rel=1e-12)


def test_scale_centre_and_nested_transforms_compose(tmp_path):
    # inner: scale 2 about centre (1 0 0) -> x' = 2x - 1, so the cube spans x -1..1 (volume 2);
    # outer: translation 10 0 0 -> x 9..11, centroid (10, 0.5, 0.5)
    text = wrl("Group { children [ DEF Outer Transform { translation 10 0 0 children [\n"
               "  Transform { scale 2 1 1 center 1 0 0 children [\n", shape(), "] } ] } ] }\n")
    s = run(tmp_path, {"g.wrl": text}, "block generate from-vrml filename 'g'\n")      # .wrl added
    b = s.model.blocks
    assert b["volume"][0] == pytest.approx(2.0, rel=1e-12)
    assert b["centroid"][0] == pytest.approx([10.0, 0.5, 0.5], abs=1e-12)


def test_use_reuses_a_defined_coordinate_node():
    text = wrl("Shape { geometry IndexedFaceSet { coord DEF P Coordinate { point [ " + CUBE_PTS +
               " ] } coordIndex [ " + CUBE_QUAD + " ] } }\n",
               "Transform { translation 0 0 5 children Shape { geometry IndexedFaceSet { coord USE P coordIndex [ "
               + CUBE_QUAD + " ] } } }\n")
    polys = vrml_polys(text, "u.wrl", 1e-9)
    assert [round(float(p.vertices[:, 2].min()), 12) for p in polys] == [0.0, 5.0]


def test_outward_fold_is_convex_and_kept_as_two_faces():
    # a roof: the top is two planes meeting at a ridge 0.2 above the walls (convex)
    pts = "0 0 0, 1 0 0, 1 1 0, 0 1 0, 0 0 1, 1 0 1, 1 1 1, 0 1 1, 0.5 0 1.2, 0.5 1 1.2"
    idx = ("0 3 2 1 -1 0 1 5 8 4 -1 3 7 9 6 2 -1 1 2 6 5 -1 0 4 7 3 -1 "
           "4 8 9 7 -1 8 5 6 9 -1")
    (p,) = vrml_polys(wrl(shape(pts, idx)), "roof.wrl", 1e-9)
    assert p.nfaces == 7
    # volume: unit cube plus a triangular prism 1 long, 1 wide, 0.2 high = 1.1
    from dec3d.geometry.polyhedron import poly_volume
    assert poly_volume(p) == pytest.approx(1.1, rel=1e-12)


# ----------------------------------------------------------------------------- refused shapes
def test_non_convex_shape_is_named_with_file_and_line():
    # the ridge pushed down into the block: a valley, not convex
    pts = "0 0 0, 1 0 0, 1 1 0, 0 1 0, 0 0 1, 1 0 1, 1 1 1, 0 1 1, 0.5 0 0.8, 0.5 1 0.8"
    idx = ("0 3 2 1 -1 0 1 5 8 4 -1 3 7 9 6 2 -1 1 2 6 5 -1 0 4 7 3 -1 "
           "4 8 9 7 -1 8 5 6 9 -1")
    text = wrl(shape(), shape(pts, idx))
    line = text.split("\n").index("  geometry IndexedFaceSet {", 10) + 1        # the second shape's line
    with pytest.raises(VrmlError, match=rf"valley\.wrl:{line}: shape 2: not convex"):
        vrml_polys(text, "valley.wrl", 1e-9)


def test_open_shape_is_refused():
    idx = CUBE_TRI.rsplit("-1", 2)[0]          # the last two triangles (one side) left out
    with pytest.raises(VrmlError, match=r"open\.wrl:\d+: shape 1: the surface is open"):
        vrml_polys(wrl(shape(index=idx)), "open.wrl", 1e-9)


@pytest.mark.parametrize("text, message", [
    ("#VRML V1.0 ascii\nSeparator { }\n", r"f\.wrl:1: VRML 1\.0 is not supported"),
    ("solid x\nfacet normal 0 0 1\n", r"f\.wrl:1: not a VRML 2\.0 file"),
    (wrl("Shape { geometry IndexedFaceSet {\n coordIndex [ 0 1 2 -1\n"), r"f\.wrl:4: the list of field 'coordIndex'"),
    (wrl("Shape { geometry IndexedFaceSet { coord Coordinate { point [ 0 0 0, 1 0 0, 0 1 0 ] }\n"
         " coordIndex [ 0 1 7 -1 ] } }\n"), r"f\.wrl:4: coordIndex 7 points past the 3 coordinates"),
    (wrl("Shape { geometry IndexedFaceSet { coord Coordinate { point [ 0 0 0, 1 0 ] } coordIndex [ 0 ] } }\n"),
     r"f\.wrl:3: Coordinate 'point' holds 5 numbers, not a multiple of 3"),
    (wrl("Shape { geometry Box { size 1 1 1 } }\n"), r"f\.wrl:3: geometry node Box is not supported"),
    (wrl("PROTO Brick [ ] { Group { } }\n"), r"f\.wrl:3: PROTO is not supported"),
    (wrl("Transform { translation 0 0 } \n"), r"f\.wrl:3: field 'translation' of Transform needs 3 numbers"),
    (wrl("Transform { scale 1 0 1 children [ ] }\n"), r"f\.wrl:3: a Transform with a zero scale"),
    (wrl("Shape { geometry USE Nothing }\n"), r"f\.wrl:3: USE of 'Nothing'"),
    (wrl("Shape { geometry IndexedFaceSet { coord Coordinate { point [ 0 0 0 ] } coordIndex [ 0.5 ] } }\n"),
     r"f\.wrl:3: coordIndex must hold whole numbers"),
    (wrl("Frobnicate { }\n"), r"f\.wrl:3: unknown VRML node 'Frobnicate'"),
    (wrl("Shape { geometry IndexedFaceSet { coordIndex [ 0 ] } }\n"), r"f\.wrl:3: IndexedFaceSet has no 'coord"),
    (wrl("WorldInfo { title \"no shapes\" }\n"), r"f\.wrl: the file holds no IndexedFaceSet"),
    (wrl("Shape { geometry IndexedFaceSet { coord Coordinate { point [ 0 0 0, 1 0 0, 0 1 0, 0 0 1 ] }\n"
         " coordIndex [ 0 1 2 -1 0 1 3 -1 0 2 3 -1 1 2 3 -1 ] }\n"), r"f\.wrl:4: the file ends"),
])
def test_malformed_files_name_the_line(text, message):
    with pytest.raises(VrmlError, match=message):
        vrml_polys(text, "f.wrl", 1e-9)


def test_a_bad_shape_adds_no_block_and_the_deck_error_names_both_places(tmp_path):
    text = wrl(shape(), shape(index=CUBE_TRI.rsplit("-1", 2)[0]))
    with pytest.raises(Dec3dError) as ei:
        run(tmp_path, {"c.wrl": text}, "block create brick 5 6\nblock generate from-vrml filename 'c.wrl'\n")
    err = ei.value
    assert "c.wrl:" in err.message and "shape 2" in err.message
    assert err.location is not None and err.location.line == 2 and err.location.file.endswith("main.dat")


def test_missing_file_and_a_file_outside_the_deck_folder_are_refused(tmp_path):
    with pytest.raises(Dec3dError, match=r"cannot read VRML file `none.wrl`: no such file"):
        run(tmp_path, {}, "block generate from-vrml filename 'none.wrl'\n")
    outside = tmp_path.parent / "outside_conv_vrml.wrl"
    outside.write_text(wrl(shape()), encoding="utf-8")
    try:
        with pytest.raises(Dec3dError, match="outside the deck's folder"):
            run(tmp_path, {}, f"block generate from-vrml filename '{outside}'\n")
    finally:
        outside.unlink()


def test_read_vrml_shapes_keeps_file_order_and_lines():
    text = wrl(shape(), "\n\n", shape(index=CUBE_QUAD))
    shapes = read_vrml_shapes(text, "o.wrl")
    lines = [i + 1 for i, ln in enumerate(text.split("\n")) if ln.strip() == "geometry IndexedFaceSet {"]
    assert [s.line for s in shapes] == lines
    assert [len(s.faces) for s in shapes] == [12, 6]
    assert math.isclose(float(np.sum([f.shape[0] for f in shapes[1].faces])), 24.0)


def test_a_concave_fold_below_half_a_percent_is_read_as_one_face(tmp_path):
    # a unit cube whose bottom corner (1, 0, 0) is pulled 0.5 mm out of the block: the bottom's two triangles
    # meet in a concave fold along the diagonal 0-2 (as CAD exports of curved bricks do)
    pts = CUBE_PTS.replace("1 0 0,", "1 0 -0.0005,", 1)
    text = wrl(shape(pts, CUBE_TRI))
    s = run(tmp_path, {"fold.wrl": text}, "block generate from-vrml filename 'fold.wrl'\n")
    b = s.model.blocks
    assert b["face_count"][0] == 6
    # the cube and the sliver under the folded bottom: 0.0005/6 m³ as the file's triangles have it, 0.0005/4
    # as dec3d's mass properties take the merged (non-planar) face, through its centroid
    assert b["volume"][0] == pytest.approx(1.0 + 0.0005 / 4, rel=1e-12)
    # a strict tolerance refuses the fold, and the hint says how to read it
    with pytest.raises(Dec3dError, match=r"fold\.wrl:\d+: shape 1: not convex") as ei:
        run(tmp_path, {"fold.wrl": text}, "block generate from-vrml filename 'fold.wrl' tolerance 1e-6\n")
    assert "tolerance 0.002" in ei.value.hint


def test_the_relative_tolerance_still_refuses_a_clear_dent():
    # corner (1, 0, 0) pulled 5 cm out: 2.9 % of the cube's diagonal, above the 0.5 % default
    from dec3d.io.vrml import RELATIVE_TOLERANCE

    text = wrl(shape(CUBE_PTS.replace("1 0 0,", "1 0 -0.05,", 1), CUBE_TRI))
    with pytest.raises(VrmlError, match=r"shape 1: not convex"):
        vrml_polys(text, "dent.wrl", 1e-6, RELATIVE_TOLERANCE)
