"""Sub-contact geometry kernel (dec3d.kernels.subgeom) against its twin
(tests/reference/subgeom_ref.py) and against exact figures computed here independently."""
import math

import numpy as np
import pytest
from scipy.spatial import ConvexHull, QhullError

import dec3d
from dec3d.geometry.cutting import cut_by_planes
from dec3d.geometry.polyhedron import brick, tetrahedron
from dec3d.kernels.subgeom import subcontacts_batch, subcontacts_one
from reference.subgeom_ref import subcontacts_ref

Z = np.array([0.0, 0.0, 1.0])


# ------------------------------------------------------------------ set-up helpers
def model_arrays(model):
    b, f = model.blocks, model.faces
    return (model.vertices["pos"].copy(), b["vert_start"].copy(), b["vert_count"].copy(),
            b["face_start"].copy(), b["face_count"].copy(), f["vstart"].copy(), f["nvert"].copy(),
            model.face_vertices["vertex"].copy())


def session_bricks(*boxes):
    s = dec3d.Session()
    for bx in boxes:
        s.command("block create brick " + " ".join(str(x) for x in bx))
    return s.model


def poly_arrays(polys):
    """Geometry arrays of a list of ``Poly`` (already placed)."""
    vpos, bvs, bvc, bfs, bfc, fvs, fnv, fv = [], [], [], [], [], [], [], []
    nv = 0
    for P in polys:
        bvs.append(nv)
        bvc.append(len(P.vertices))
        bfs.append(len(fnv))
        bfc.append(P.nfaces)
        for loop in P.faces():
            fvs.append(len(fv))
            fnv.append(len(loop))
            fv.extend(int(i) + nv for i in loop)
        vpos.append(P.vertices)
        nv += len(P.vertices)
    i = lambda x: np.array(x, np.int64)  # noqa: E731
    return (np.vstack(vpos), i(bvs), i(bvc), i(bfs), i(bfc), i(fvs), i(fnv), i(fv))


def rotate_block(arrays, blk, axis, angle, centre):
    """Rotate block ``blk`` in place about ``axis`` through ``centre`` (Rodrigues)."""
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    R = np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K
    vs, vc = arrays[1][blk], arrays[2][blk]
    arrays[0][vs:vs + vc] = (arrays[0][vs:vs + vc] - centre) @ R.T + centre


def run(arrays, contacts, ctol=1e-6, point_area=0.01, cap=256):
    ca = np.array([x[0] for x in contacts], np.int64)
    cb = np.array([x[1] for x in contacts], np.int64)
    cn = np.array([x[2] for x in contacts], float).reshape(-1, 3)
    cc = np.array([x[3] for x in contacts], float).reshape(-1, 3)
    out = (np.zeros(cap, np.int64), np.zeros(cap, np.int64), np.zeros(cap, np.int64),
           np.zeros(cap, np.int64), np.zeros((cap, 3)), np.zeros(cap))
    k = subcontacts_batch(*arrays, ca, cb, cn, cc, ctol, point_area, *out)
    assert k <= cap
    return [tuple(o[:k] for o in out)][0]


def rows_of(out, contact=0):
    con, kind, k0, k1, pos, area = out
    sel = np.flatnonzero(con == contact)
    return [(int(kind[i]), int(k0[i]), int(k1[i]), pos[i], float(area[i])) for i in sel]


def assert_same(got, ref, scale=1.0):
    assert [g[:3] for g in got] == [r[:3] for r in ref]
    for g, r in zip(got, ref):
        np.testing.assert_allclose(g[3], r[3], rtol=0, atol=1e-12 * scale)
        assert abs(g[4] - r[4]) <= 1e-12 * max(abs(r[4]), scale * scale)


def check_twin(arrays, contacts, ctol=1e-6, point_area=0.01, scale=1.0):
    out = run(arrays, contacts, ctol, point_area)
    for i, (a, b, n, c) in enumerate(contacts):
        assert_same(rows_of(out, i), subcontacts_ref(arrays, a, b, n, c, ctol, point_area), scale)
    return out


# ------------------------------------------------------------------ exact overlap, independently
def plane_face(arrays, blk, n, off, tol=1e-9):
    """3-D loop of the face of ``blk`` lying on the plane n·x = off."""
    vpos, _, _, bfs, bfc, fvs, fnv, fv = arrays
    for f in range(bfs[blk], bfs[blk] + bfc[blk]):
        pts = vpos[fv[fvs[f]:fvs[f] + fnv[f]]]
        if np.all(np.abs(pts @ n - off) < tol):
            return pts
    return None


def exact_overlap(fa, fb, n):
    """Area of the intersection of two planar convex polygons (3-D loops on a plane of normal n):
    hull of (A's corners in B) ∪ (B's corners in A) ∪ (edge crossings)."""
    u = np.linalg.svd(np.eye(3) - np.outer(n, n))[0][:, :2]
    a, b = fa @ u, fb @ u

    def hp(poly):
        h = ConvexHull(poly)
        return poly[h.vertices]

    a, b = hp(a), hp(b)

    def contains(poly, x):
        return all((poly[(i + 1) % len(poly)][0] - poly[i][0]) * (x[1] - poly[i][1]) -
                   (poly[(i + 1) % len(poly)][1] - poly[i][1]) * (x[0] - poly[i][0]) >= -1e-12
                   for i in range(len(poly)))

    pts = [x for x in a if contains(b, x)] + [x for x in b if contains(a, x)]
    for i in range(len(a)):
        p0, p1 = a[i], a[(i + 1) % len(a)]
        for j in range(len(b)):
            q0, q1 = b[j], b[(j + 1) % len(b)]
            m = np.column_stack([p1 - p0, q0 - q1])
            if abs(np.linalg.det(m)) < 1e-14:
                continue
            t, s = np.linalg.solve(m, q0 - p0)
            if 0 <= t <= 1 and 0 <= s <= 1:
                pts.append(p0 + t * (p1 - p0))
    if len(pts) < 3:
        return 0.0
    try:
        return ConvexHull(np.array(pts)).volume
    except QhullError:
        return 0.0


# ------------------------------------------------------------------ face-face
def test_identical_stacked_cubes_fan_fractions():
    arrays = model_arrays(session_bricks((0, 1, 0, 1, 0, 1), (0, 1, 0, 1, 1, 2)))
    out = check_twin(arrays, [(0, 1, Z, (0.5, 0.5, 1.0))])
    kind, k0, area = out[1], out[2], out[5]
    assert list(kind) == [0] * 4 + [1] * 4
    assert area.sum() == pytest.approx(1.0, abs=1e-14)
    for s in (0, 1):
        np.testing.assert_allclose(np.sort(2 * area[kind == s]), [1 / 6, 1 / 6, 1 / 3, 1 / 3], atol=1e-14)
    # the fan's first vertex owns 1/3 (two triangles): on A's top face and on B's bottom face
    vpos, _, _, bfs, bfc, fvs, fnv, fv = arrays
    for blk, s, zf in ((0, 0, 1.0), (1, 1, 1.0)):
        for f in range(bfs[blk], bfs[blk] + bfc[blk]):
            loop = fv[fvs[f]:fvs[f] + fnv[f]]
            if np.all(vpos[loop][:, 2] == zf):
                first = loop[0]
        assert area[(kind == s) & (k0 == first)][0] == pytest.approx(1 / 6, abs=1e-14)
    # coincident corners stay two sub-contacts, at the same points
    pa = out[4][kind == 0]
    pb = out[4][kind == 1]
    assert sorted(map(tuple, pa)) == sorted(map(tuple, pb))


def test_half_side_offsets():
    # along a diagonal: one corner of each inside the other face, two edge-edge crossings
    arrays = model_arrays(session_bricks((0, 1, 0, 1, 0, 1), (0.5, 1.5, 0.5, 1.5, 1, 2)))
    out = check_twin(arrays, [(0, 1, Z, (0.7, 0.7, 1.0))])
    assert list(out[1]) == [0, 1, 2, 2]
    assert out[5].sum() == pytest.approx(0.25, abs=1e-14)
    crossings = sorted(map(tuple, out[4][out[1] == 2]))
    np.testing.assert_allclose(crossings, [(0.5, 1.0, 1.0), (1.0, 0.5, 1.0)], atol=1e-15)
    # along an axis: edges overlap collinearly (no crossings); the area is still exact
    arrays = model_arrays(session_bricks((0, 1, 0, 1, 0, 1), (0.5, 1.5, 0, 1, 1, 2)))
    out = check_twin(arrays, [(0, 1, Z, (0.7, 0.5, 1.0))])
    assert 2 not in out[1]
    assert out[5].sum() == pytest.approx(0.5, abs=1e-14)


def test_rotated_cube_overhanging_a_bigger_one():
    arrays = model_arrays(session_bricks((0, 1.5, 0, 1.5, 0, 1), (0.8, 1.8, 0.8, 1.8, 1, 2)))
    rotate_block(arrays, 1, Z, math.radians(30), np.array([1.3, 1.3, 1.5]))
    out = check_twin(arrays, [(0, 1, Z, (1.0, 1.0, 1.0))])
    assert 2 in out[1] and 0 in out[1] and 1 in out[1]
    exact = exact_overlap(plane_face(arrays, 0, Z, 1.0), plane_face(arrays, 1, Z, 1.0), Z)
    assert out[5].sum() == pytest.approx(exact, rel=1e-12)


def test_small_cube_wholly_on_big_base_carries_the_full_area():
    arrays = model_arrays(session_bricks((0, 3, 0, 3, 0, 1), (1, 2, 1, 2, 1, 2)))
    rotate_block(arrays, 1, Z, math.radians(30), np.array([1.5, 1.5, 1.5]))
    out = check_twin(arrays, [(0, 1, Z, (1.5, 1.5, 1.0))])
    assert list(out[1]) == [1, 1, 1, 1]          # base corners are outside, no crossings
    np.testing.assert_allclose(np.sort(out[5]), [1 / 6, 1 / 6, 1 / 3, 1 / 3], atol=1e-14)
    # each vertex sub-contact names the base's top face as the face under it
    top = [f for f in range(arrays[3][0], arrays[3][0] + arrays[4][0])
           if np.all(arrays[0][arrays[7][arrays[5][f]:arrays[5][f] + arrays[6][f]]][:, 2] == 1.0)]
    assert set(out[3]) == set(top)


def _random_pair(seed):
    """Two cut pieces face to face on a random plane, B turned and shifted in the plane."""
    rng = np.random.default_rng(seed)
    model = session_bricks((0, 2, 0, 2, 0, 2))
    n = rng.normal(size=3)
    n /= np.linalg.norm(n)
    off = float(n @ np.array([1.0, 1, 1]))
    cut_by_planes(model, n, [off])
    for _ in range(2):
        m = rng.normal(size=3)
        cut_by_planes(model, m / np.linalg.norm(m), [float(m @ rng.uniform(0.6, 1.4, 3)) / np.linalg.norm(m)])
    arrays = model_arrays(model)
    nb = len(arrays[1])
    below = [b for b in range(nb) if plane_face(arrays, b, n, off) is not None and
             arrays[0][arrays[1][b]:arrays[1][b] + arrays[2][b]].mean(0) @ n < off]
    above = [b for b in range(nb) if plane_face(arrays, b, n, off) is not None and
             arrays[0][arrays[1][b]:arrays[1][b] + arrays[2][b]].mean(0) @ n > off]
    def face_area(blk):
        f = plane_face(arrays, blk, n, off)
        return np.linalg.norm(sum(np.cross(f[i], f[(i + 1) % len(f)]) for i in range(len(f))))

    a = max(below, key=face_area)      # the largest pieces, so that the faces overlap
    b = max(above, key=face_area)
    c = n * off
    rotate_block(arrays, b, n, rng.uniform(-math.pi, math.pi), plane_face(arrays, b, n, off).mean(0))
    shift = rng.normal(size=3) * 0.2
    shift -= (shift @ n) * n
    vs, vc = arrays[1][b], arrays[2][b]
    arrays[0][vs:vs + vc] += shift
    return arrays, a, b, n, off, c


@pytest.mark.parametrize("seed", range(16))
def test_random_cut_pieces_face_to_face(seed):
    arrays, a, b, n, off, c = _random_pair(seed)
    out = check_twin(arrays, [(a, b, n, c)], scale=2.0)
    exact = exact_overlap(plane_face(arrays, a, n, off), plane_face(arrays, b, n, off), n)
    assert out[5].sum() == pytest.approx(exact, rel=1e-12, abs=1e-14)
    # every point lies on the c-p
    np.testing.assert_allclose((out[4] - c) @ n, 0.0, atol=1e-13)


# ------------------------------------------------------------------ lower contact types
def test_edge_face_vertex_face_edge_edge_points():
    base = brick(0, 1, 0, 1, 0, 1)
    s2 = math.sqrt(0.5)
    # a cube turned 45° about x, resting on its lowest edge along x (x from 0.25 to 1.25, y 0.5)
    e = brick(0.25, 1.25, -0.5, 0.5, -0.5, 0.5)
    ev = e.vertices.copy()
    ca, sa = math.cos(math.pi / 4), math.sin(math.pi / 4)
    ev = np.column_stack([ev[:, 0], ca * ev[:, 1] - sa * ev[:, 2], sa * ev[:, 1] + ca * ev[:, 2]])
    ev += [0, 0.5, 1 + s2]
    edge_block = type(e)(ev, e.face_ptr, e.face_idx)
    tet = tetrahedron((0.5, 0.5, 1.0), (0, 0, 2), (1, 0, 2), (0.5, 1, 2))
    # a cube turned 45° about y, its lowest edge along y: crosses edge_block's top edge? no —
    # it sits below the turned cube's lowest edge: edge-edge with the x-edge
    f = brick(-0.5, 0.5, 0, 1, -0.5, 0.5)
    fv = f.vertices.copy()
    fv = np.column_stack([ca * fv[:, 0] + sa * fv[:, 2], fv[:, 1], -sa * fv[:, 0] + ca * fv[:, 2]])
    fv += [0.6, 0.1, 1 - s2]        # its highest edge along y at z = 1, x = 0.6
    up_edge = type(f)(fv, f.face_ptr, f.face_idx)
    arrays = poly_arrays([base, edge_block, tet, up_edge])
    contacts = [(0, 1, Z, (0.5, 0.5, 1.0)),    # edge-face
                (0, 2, Z, (0.5, 0.5, 1.0)),    # vertex-face
                (3, 1, Z, (0.6, 0.5, 1.0))]    # edge-edge
    out = check_twin(arrays, contacts, ctol=1e-6, point_area=0.02)
    con, kind, k0, k1, pos, area = out
    assert np.all(kind == 3) and np.all(area == 0.02)
    np.testing.assert_allclose(pos[con == 0], [[0.25, 0.5, 1.0], [1.0, 0.5, 1.0]], atol=1e-12)
    np.testing.assert_allclose(pos[con == 1], [[0.5, 0.5, 1.0]], atol=1e-12)
    np.testing.assert_allclose(pos[con == 2], [[0.6, 0.5, 1.0]], atol=1e-12)
    # vertex-face names the tetrahedron's lowest corner and the base's top face
    top = [fi for fi in range(6) if np.all(arrays[0][arrays[7][arrays[5][fi]:arrays[5][fi] + 4]][:, 2] == 1.0)]
    tip = int(np.flatnonzero(np.all(arrays[0] == [0.5, 0.5, 1.0], axis=1))[0])
    assert k0[con == 1][0] == tip and k1[con == 1][0] == top[0]
    assert k1[con == 0][0] == top[0] and k1[con == 0][1] == top[0]


# ------------------------------------------------------------------ batch behaviour
def _stack(n):
    boxes = [(i, i + 1, j, j + 1, k, k + 1) for i in range(n) for j in range(n) for k in range(n)]
    arrays = poly_arrays([brick(*bx) for bx in boxes])
    row = {bx[::2]: r for r, bx in enumerate(boxes)}
    contacts = []
    for (i, j, k), r in row.items():
        for d in range(3):
            o = [i, j, k]
            o[d] += 1
            if tuple(o) in row:
                nrm = np.zeros(3)
                nrm[d] = 1.0
                contacts.append((r, row[tuple(o)], nrm, np.array([i, j, k]) + 0.5 + 0.5 * nrm))
    return arrays, contacts


def test_capacity_overflow_returns_the_count_and_writes_nothing_beyond():
    arrays, contacts = _stack(3)
    ca = np.array([x[0] for x in contacts], np.int64)
    cb = np.array([x[1] for x in contacts], np.int64)
    cn = np.array([x[2] for x in contacts])
    cc = np.array([x[3] for x in contacts])
    cap, pad = 5, 7

    def bufs(size):
        return (np.full(size, -7, np.int64), np.full(size, -7, np.int64), np.full(size, -7, np.int64),
                np.full(size, -7, np.int64), np.full((size, 3), -7.0), np.full(size, -7.0))

    small = bufs(cap + pad)
    need = subcontacts_batch(*arrays, ca, cb, cn, cc, 1e-6, 0.01, *(o[:cap] for o in small))
    assert need == 8 * len(contacts)
    for o in small:
        assert np.all(o[cap:] == -7)
    full = bufs(need)
    again = subcontacts_batch(*arrays, ca, cb, cn, cc, 1e-6, 0.01, *full)
    assert again == need
    for s, f in zip(small, full):
        np.testing.assert_array_equal(s[:cap], f[:cap])
    # the order: by contact row, kinds 0 then 1 within each
    assert np.all(np.diff(full[0]) >= 0)
    np.testing.assert_allclose(np.bincount(full[0], weights=full[5]), 1.0, atol=1e-14)


def test_one_contact_entry_matches_the_batch():
    arrays, contacts = _stack(2)
    out = run(arrays, contacts)
    a, b, n, c = contacts[3]
    cap = 16
    o = (np.zeros(cap, np.int64), np.zeros(cap, np.int64), np.zeros(cap, np.int64),
         np.zeros(cap, np.int64), np.zeros((cap, 3)), np.zeros(cap))
    k = subcontacts_one(3, a, b, n, c, 1e-6, 0.01, *arrays, 0, *o)
    sel = out[0] == 3
    assert k == sel.sum()
    for got, want in zip(o, out):
        np.testing.assert_array_equal(got[:k], want[sel])


def test_scratch_is_sized_by_the_blocks_in_contact():
    """A block of 40 000 triangles (a zoned block's surface) beside a stack of 8 unit cubes in
    contact: the scratch is sized by the cubes of the contacts, so the batch gives the same
    sub-contacts as without the big block; sizing the crossings by the largest block squared
    (1.2e5² rows) ran out of memory."""
    arrays, contacts = _stack(2)
    vpos, bvstart, bvcount, bfstart, bfcount, fvstart, fnvert, fverts = arrays
    nt = 40000
    big = (np.vstack([vpos, np.zeros((3, 3)) + 50.0]), np.append(bvstart, len(vpos)), np.append(bvcount, 3),
           np.append(bfstart, len(fnvert)), np.append(bfcount, nt),
           np.append(fvstart, len(fverts) + 3 * np.arange(nt)), np.append(fnvert, np.full(nt, 3)),
           np.append(fverts, np.tile(len(vpos) + np.arange(3), nt)))
    ca = np.array([x[0] for x in contacts], np.int64)
    cb = np.array([x[1] for x in contacts], np.int64)
    cn = np.array([x[2] for x in contacts])
    cc = np.array([x[3] for x in contacts])
    want = run(arrays, contacts)
    cap = 256
    out = (np.zeros(cap, np.int64), np.zeros(cap, np.int64), np.zeros(cap, np.int64),
           np.zeros(cap, np.int64), np.zeros((cap, 3)), np.zeros(cap))
    k = subcontacts_batch(*big, ca, cb, cn, cc, 1e-6, 0.01, *out)
    assert k == len(want[0])
    for a, b in zip(out, want):
        np.testing.assert_array_equal(a[:k], b)
