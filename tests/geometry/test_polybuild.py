"""The compiled polyhedron builder (kernels/polybuild.py, through ``build_many``) against its twin,
``polyhedron_from_faces`` in plain numpy; and `block create` lines run in one pass against the same
lines run one by one."""
import io

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from dec3d.errors import Dec3dError
from dec3d.geometry.assemble import polys_to_batch
from dec3d.geometry.errors import GeometryError
from dec3d.geometry.polyhedron import build_many, polyhedron_from_faces
from dec3d.session import Session

TOL = 1e-6


def _hull_faces(rng, n):
    """Triangles of the hull of n random points, in random windings, as (corners, per face)."""
    p = rng.normal(size=(n, 3)) * rng.uniform(0.5, 3.0, size=3) + rng.normal(size=3) * 10
    hull = ConvexHull(p)
    faces = []
    for tri in hull.simplices:
        t = p[tri]
        faces.append(t[::-1] if rng.random() < 0.5 else t)
    return faces


def _box_faces(rng):
    lo = rng.normal(size=3)
    hi = lo + rng.uniform(0.1, 2.0, size=3)
    c = np.array([[(lo, hi)[i][0], (lo, hi)[j][1], (lo, hi)[k][2]] for k in (0, 1) for j in (0, 1) for i in (0, 1)])
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    faces = [c[list(q)] for q in quads]
    # a repeated corner, and a loop closed by repeating its first corner: both dropped
    faces[0] = np.insert(faces[0], 1, faces[0][0], axis=0)
    faces[1] = np.vstack([faces[1], faces[1][:1]])
    return faces


def _prism_faces(rng, k):
    ang = np.sort(rng.uniform(0, 2 * np.pi, size=k))
    a = np.column_stack([np.cos(ang), np.sin(ang), np.zeros(k)]) * rng.uniform(0.5, 2)
    b = a + np.array([0.1, -0.2, rng.uniform(0.3, 2)])
    return [a, b[::-1]] + [np.array([a[i], a[(i + 1) % k], b[(i + 1) % k], b[i]]) for i in range(k)]


def _shape(faces):
    return np.concatenate(faces), np.array([len(f) for f in faces], dtype=np.int64)


def _twin(faces):
    """What line-by-line building gives: the batch of the checked Poly."""
    return polys_to_batch([polyhedron_from_faces(faces, TOL)])


def test_kernel_matches_the_twin_on_valid_shapes():
    rng = np.random.default_rng(7)
    shapes = []
    for i in range(60):
        kind = i % 3
        shapes.append(_hull_faces(rng, int(rng.integers(4, 30))) if kind == 0 else
                      _box_faces(rng) if kind == 1 else _prism_faces(rng, int(rng.integers(3, 9))))
    built, batch = build_many([_shape(f) for f in shapes], TOL)
    assert built == len(shapes)
    want = [np.concatenate(parts) for parts in zip(*[_twin(f) for f in shapes])]
    for name, got, exp in zip(("pos", "vsrc", "piece_nv", "fn", "fsrc", "piece_nf", "fv"), batch, want):
        np.testing.assert_array_equal(got, exp, err_msg=name)


BAD = {
    "non-planar": [np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0.3], [0, 1, 0]]), np.array([[0, 0, 0], [0, 0, 1], [1, 0, 0]]),
                   np.array([[0, 0, 0], [0, 1, 0], [0, 0, 1]]), np.array([[1, 0, 0], [0, 0, 1], [1, 1, 0.3]])],
    "open": [np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]]), np.array([[0, 0, 0], [0, 0, 1], [1, 0, 0]]),
             np.array([[0, 0, 0], [0, 1, 0], [0, 0, 1]]), np.array([[1, 0, 0], [0, 0, 1], [0.2, 0.2, 0.2]])],
    "three faces": [np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]])] * 3,
    "two corners": [np.array([[0, 0, 0], [1, 0, 0], [1, 0, 0]]), np.array([[0, 0, 0], [0, 0, 1], [1, 0, 0]]),
                    np.array([[0, 0, 0], [0, 1, 0], [0, 0, 1]]), np.array([[1, 0, 0], [0, 0, 1], [0, 1, 0]])],
    "nan": [np.array([[0, 0, 0], [1, 0, 0], [0, np.nan, 0]]), np.array([[0, 0, 0], [0, 0, 1], [1, 0, 0]]),
            np.array([[0, 0, 0], [0, 1, 0], [0, 0, 1]]), np.array([[1, 0, 0], [0, 0, 1], [0, 1, 0]])],
    "flat": [np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]]), np.array([[0, 0, 0], [0, 1, 0], [1, 0, 0]]),
             np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]]), np.array([[0, 0, 0], [0, 1, 0], [1, 0, 0]])],
}


def _non_convex():
    # an L-shaped prism: closed and planar, one corner in front of a face's plane
    a = np.array([[0, 0, 0], [2, 0, 0], [2, 1, 0], [1, 1, 0], [1, 2, 0], [0, 2, 0]], dtype=float)
    b = a + [0, 0, 1]
    return [a, b] + [np.array([a[i], a[(i + 1) % 6], b[(i + 1) % 6], b[i]]) for i in range(6)]


@pytest.mark.parametrize("name", sorted(BAD) + ["non-convex"])
def test_kernel_refuses_what_the_twin_refuses(name):
    faces = _non_convex() if name == "non-convex" else BAD[name]
    with pytest.raises(GeometryError):
        polyhedron_from_faces(faces, TOL)
    good = _box_faces(np.random.default_rng(1))
    built, batch = build_many([_shape(good), _shape(faces), _shape(good)], TOL)
    assert built == 1                              # stops before the refused one
    np.testing.assert_array_equal(batch[0], _twin(good)[0])


def _deck(rng, n):
    lines = ["model new"]
    for i in range(n):
        g = f" group 'g{i % 3}'" if i % 2 else ""
        fg = f" face-group 'f{i % 4}' slot 's{i % 2}'" if i % 5 == 0 else ""
        r = " region 2" if i % 7 == 0 else ""
        x, y = i % 10, i // 10
        if i % 4 == 3:
            f = _prism_faces(rng, 5)
            fl = lambda a: " ".join(f"{v:.6f}" for v in (np.asarray(a) + [x * 5, y * 5, 0]).ravel())
            lines.append(f"block create prism face-1 {fl(f[0])} face-2 {fl(f[1][::-1])}{g}{fg}{r}")
        elif i % 4 == 2:
            lines.append(f"block create tetrahedron {x} {y} 0 {x + 1} {y} 0 {x} {y + 1} 0 {x} {y} 1{g}{r}")
        elif i % 4 == 1:
            faces = _hull_faces(rng, 8)
            text = " ".join("face " + " ".join(f"{v:.9f}" for v in (fc + [x * 20, y * 20, 50]).ravel()) for fc in faces)
            lines.append(f"block create polyhedron {text}{g}{fg}")
        else:
            lines.append(f"block create brick {x} {x + 1} {y} {y + 1} 0 [0.5 + 0.5]{g}{fg}{r}")
    return "\n".join(lines) + "\n"


def _state(s):
    m = s.model
    out = {}
    for store in ("blocks", "vertices", "faces", "face_vertices"):
        st = getattr(m, store)
        for key in st.fields:
            out[f"{store}.{key}"] = np.array(st[key])
    out["groups"] = m.groups.to_dict()
    return out


def test_a_run_of_create_lines_in_one_pass_equals_line_by_line(tmp_path, monkeypatch):
    import dec3d.commands.block_create as bc

    passes = []
    monkeypatch.setattr(bc, "build_many", lambda shapes, tol: passes.append(len(shapes)) or build_many(shapes, tol))
    text = _deck(np.random.default_rng(3), 60)
    one = Session(out_dir=tmp_path, stdout=io.StringIO())
    assert one.batch_min <= 60
    items = one.load_text(text, "deck.dat")
    one.run_items(items)                            # runs of create lines in one pass
    assert passes == [60]
    two = Session(out_dir=tmp_path, stdout=io.StringIO())
    for item in two.load_text(text, "deck.dat"):
        two.run_items([item])                       # one line at a time: the handlers
    assert one.model.blocks.n == 60
    a, b = _state(one), _state(two)
    assert a.keys() == b.keys()
    for key in a:
        if key == "groups":
            assert a[key] == b[key]
        else:
            np.testing.assert_array_equal(a[key], b[key], err_msg=key)
    assert one.record == two.record


@pytest.mark.parametrize("bad, line, words", [
    ("block create brick 0 1 0 1 5 5", 4, "zero thickness in z"),
    ("block create brick 0 1 0 1 0 [1/0]", 4, "division by zero"),
    ("block create polyhedron face 0,0,0 1,0,0 1,1,0.3 0,1,0 face 0,0,0 0,0,1 1,0,0 "
     "face 0,0,0 0,1,0 0,0,1 face 1,0,0 0,0,1 1,1,0.3", 4, "face 1 is not planar"),
])
def test_a_refused_line_in_a_run_reports_its_line_and_keeps_the_lines_before(tmp_path, monkeypatch, bad, line,
                                                                             words):
    import dec3d.commands.block_create as bc

    passes = []
    monkeypatch.setattr(bc, "build_many", lambda shapes, tol: passes.append(len(shapes)) or build_many(shapes, tol))
    text = ("model new\nblock create brick 0 1\nblock create brick 1 2 group 'a'\n" + bad
            + "\nblock create brick 5 6\n")
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.batch_min = 2                                 # the run of four lines in one pass
    with pytest.raises(Dec3dError, match=words) as info:
        s.run_items(s.load_text(text, "deck.dat"))
    assert info.value.location.line == line
    assert s.model.blocks.n == 2                    # the two lines before it, not the one after
    assert list(s.model.blocks["id"]) == [1, 2]
    assert s.record[-2:] == ["block create brick 0 1", "block create brick 1 2 group 'a'"]
    assert passes and passes[0] >= 2                # the lines before it went in one pass


@pytest.mark.parametrize("batch_min", [50, 2])
def test_a_block_given_twice_is_warned_about(tmp_path, batch_min):
    """Issue 35: identical overlapping blocks were accepted silently; a warning names the line and both
    blocks (line by line and in one pass alike), and blocks that only touch are not named."""
    out = io.StringIO()
    s = Session(out_dir=tmp_path, stdout=out)
    s.batch_min = batch_min
    s.run_items(s.load_text("block create brick 0 1 0 1 0 1\nblock create brick 1 2 0 1 0 1\n"
                            "block create brick 0 1 0 1 1 2\nblock create brick 0 1 0 1 0 1\n", "d.dat"))
    warnings = [ln for ln in out.getvalue().splitlines() if ln.startswith("warning")]
    assert warnings == ["warning: d.dat:4:1: block 4 lies exactly where block 1 is (same centroid and volume): "
                        "blocks must not overlap; is the line given twice?"]
    assert s.model.blocks.n == 4
