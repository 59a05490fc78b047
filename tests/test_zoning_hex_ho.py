"""Hexahedral mixed zones (`block zone generate hexahedra divisions`) and 10-node tetrahedra
(`model configure highorder` + `block zone generate high-order-tetra`): volumes, positivity,
the overlay structure of the 3DEC theory text ("an 8-node zone with 2 overlays of 5 tetrahedra
in each overlay"), mid-edge gridpoints and split surface triangles, bad input."""
import numpy as np
import pytest

from dec3d.errors import Dec3dError
from dec3d.geometry.errors import GeometryError
from dec3d.geometry.zoning_hex import mesh_hex
from dec3d.model.zone_mesh import conformity


def _tet_vol(p, t):
    a, b, c, d = (p[t[:, k]] for k in range(4))
    return np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) / 6.0


def _poly_volume(v, ptr, loops):
    """Volume by the divergence theorem over fan triangles of each face (outward loops)."""
    vol = 0.0
    for f in range(len(ptr) - 1):
        lp = loops[ptr[f]:ptr[f + 1]]
        for i in range(1, len(lp) - 1):
            vol += np.dot(v[lp[0]], np.cross(v[lp[i]], v[lp[i + 1]])) / 6.0
    return vol


def _frustum():
    """A six-faced block that is not a brick: square base 2 x 2, top 1 x 1.4 shifted, planar faces."""
    bot = np.array([[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0]], float)
    # top: a scaled copy about a point so that the side faces stay planar (a frustum of a pyramid)
    apex = np.array([0.8, 1.1, 3.0])
    top = apex + (bot - apex) * 0.55
    v = np.r_[bot, top]
    loops = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]
    return v, np.arange(0, 25, 4), np.array(loops).ravel()


def test_hex_frustum_volumes_overlays_and_surface():
    v, ptr, loops = _frustum()
    V = _poly_volume(v, ptr, loops)
    assert V > 0
    n = (2, 3, 4)
    pts, tets, hexid, overlay, tris, src = mesh_hex(v, ptr, loops, n)
    ncell = 24
    assert len(tets) == 10 * ncell
    vol = _tet_vol(pts, tets)
    assert (vol > 0).all()
    for ov in (0, 1):
        assert abs(vol[overlay == ov].sum() - V) < 1e-12 * V
    # every hexahedron: five tetrahedra in each overlay, the same volume in both
    for h in range(ncell):
        sel = hexid == h
        assert (overlay[sel] == 0).sum() == 5 and (overlay[sel] == 1).sum() == 5
        assert abs(vol[sel & (overlay == 0)].sum() - vol[sel & (overlay == 1)].sum()) < 1e-12 * V
        assert len(np.unique(tets[sel])) == 8          # the eight corners of one cell
    # each overlay alone is a conforming tetrahedral mesh: inner faces shared by exactly two tetrahedra
    for ov in (0, 1):
        t = tets[overlay == ov]
        f = np.sort(np.concatenate([t[:, [1, 2, 3]], t[:, [0, 2, 3]], t[:, [0, 1, 3]], t[:, [0, 1, 2]]]), axis=1)
        _, cnt = np.unique(f, axis=0, return_counts=True)
        assert cnt.max() == 2
        assert (cnt == 1).sum() == 2 * 2 * (2 * 3 + 3 * 4 + 2 * 4)   # two triangles per boundary quad
    # the trilinear map of the eight corners: corner (0,0,0) is the lowest vertex (v[0]); its x-, y- and
    # z-most edges lead to v[1], v[3], v[4] here; grid point (i, j, k) at parameters (i/2, j/3, k/4)
    assert len(pts) == 3 * 4 * 5
    corner = {(0, 0, 0): v[0], (1, 0, 0): v[1], (0, 1, 0): v[3], (1, 1, 0): v[2],
              (0, 0, 1): v[4], (1, 0, 1): v[5], (0, 1, 1): v[7], (1, 1, 1): v[6]}
    for i in range(3):
        for j in range(4):
            for k in range(5):
                s, t, u = i / 2, j / 3, k / 4
                x = sum(corner[a, b, c] * (s if a else 1 - s) * (t if b else 1 - t) * (u if c else 1 - u)
                        for a in (0, 1) for b in (0, 1) for c in (0, 1))
                assert np.min(np.linalg.norm(pts - x, axis=1)) < 1e-14
    # surface: two triangles per boundary quad, on the block faces, outward, covering the area
    assert len(tris) == 2 * 2 * (6 + 12 + 8)
    cen = pts[tris].mean(axis=1)
    for f in range(6):
        lp = loops[ptr[f]:ptr[f + 1]]
        nrm = np.cross(v[lp[1]] - v[lp[0]], v[lp[2]] - v[lp[0]])
        nrm /= np.linalg.norm(nrm)
        on = src == f
        assert np.allclose((cen[on] - v[lp[0]]) @ nrm, 0, atol=1e-12)
        tn = np.cross(pts[tris[on, 1]] - pts[tris[on, 0]], pts[tris[on, 2]] - pts[tris[on, 0]])
        assert (tn @ nrm > 0).all()
        area = 0.5 * np.linalg.norm(tn, axis=1).sum()
        face_area = 0.5 * np.linalg.norm(sum(np.cross(v[lp[i]], v[lp[(i + 1) % 4]]) for i in range(4)))
        assert abs(area - face_area) < 1e-12 * face_area
    # the surface diagonal of a quad passes through its corner with the smallest position
    e = np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), axis=1)
    _, cnt = np.unique(e, axis=0, return_counts=True)
    assert (cnt == 2).all()                                   # closed surface


def test_hex_overlays_use_opposite_diagonals_on_every_face():
    v = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], float)
    loops = np.array([[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]).ravel()
    pts, tets, hexid, overlay, tris, src = mesh_hex(v, np.arange(0, 25, 4), loops, (1, 1, 1))
    diag = {}
    for ov in (0, 1):
        t = tets[overlay == ov]
        f = np.sort(np.concatenate([t[:, [1, 2, 3]], t[:, [0, 2, 3]], t[:, [0, 1, 3]], t[:, [0, 1, 2]]]), axis=1)
        u, cnt = np.unique(f, axis=0, return_counts=True)
        edges = set()
        for tri in u[cnt == 1]:
            p = pts[tri]
            for i in range(3):
                for j in range(i + 1, 3):
                    if np.count_nonzero(p[i] != p[j]) == 2:       # a face diagonal of the unit cube
                        edges.add(tuple(sorted((tuple(p[i]), tuple(p[j])))))
        diag[ov] = edges
        assert len(edges) == 6                                 # one diagonal on each of the six faces
    assert not (diag[0] & diag[1])                              # the other diagonal in the other overlay
    # central tetrahedron of overlay 0 on the corners of even parity (i + j + k even)
    t0 = tets[overlay == 0]
    par = pts.sum(axis=1).round().astype(int) % 2
    central = [t for t in t0 if len(set(par[t])) == 1]
    assert len(central) == 1 and par[central[0][0]] == 0


def test_hex_command_brick_and_refusals(session):
    session.command("block create brick 0 2 0 1 0 3\nblock zone generate hexahedra divisions 2 1 3")
    zs = session.model.store("zones")
    assert zs.n == 60
    vol = zs["volume"][:zs.n]
    assert (vol > 0).all()
    for ov in (0, 1):
        assert abs(vol[zs["overlay"][:zs.n] == ov].sum() - 6.0) < 1e-12 * 6
    assert len(np.unique(zs["hex"][:zs.n])) == 6
    # a five-faced block is refused by name, before anything is zoned
    session.command("block create prism face-1 5 0 0 6 0 0 5 1 0 face-2 5 0 1 6 0 1 5 1 1")
    with pytest.raises(Dec3dError, match=r"block 2 is not hexahedral \(5 faces"):
        session.command("block zone generate hexahedra divisions 1 1 1")
    assert session.model.store("zones").n == 60
    with pytest.raises(Dec3dError, match="needs divisions"):
        session.command("block zone generate hexahedra")
    with pytest.raises(Dec3dError):
        session.command("block zone generate hexahedra divisions 1 0 1")


def test_hex_command_general_hexahedron(session):
    v, ptr, loops = _frustum()
    f1 = " ".join(f"{x:.17g}" for x in v[:4].ravel())
    f2 = " ".join(f"{x:.17g}" for x in v[4:].ravel())
    session.command(f"block create prism face-1 {f1} face-2 {f2}\nblock zone generate hexahedra divisions 3 3 2")
    zs = session.model.store("zones")
    V = float(session.model.blocks["volume"][0])
    assert abs(V - _poly_volume(v, ptr, loops)) < 1e-9 * V
    vol = zs["volume"][:zs.n]
    assert zs.n == 180 and (vol > 0).all()
    assert abs(vol[zs["overlay"][:zs.n] == 1].sum() - V) < 1e-12 * V


def test_hex_distorted_refused():
    # the unit cube with corner (1,1,1) pushed in past the plane of its three neighbours: the corner
    # tetrahedron there turns inside out
    v = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], float)
    v[7] = (0.3, 0.3, 0.3)
    loops = np.array([[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]).ravel()
    with pytest.raises(GeometryError, match="too distorted"):
        mesh_hex(v, np.arange(0, 25, 4), loops, (1, 1, 1), "block 9")


def _ho_checks(model):
    zs = model.store("zones")
    pos = model.vertices["pos"]
    gp = zs["gp"][:zs.n]
    assert (zs["nnode"][:zs.n] == 10).all()
    # mid-edge nodes of edges 01 12 20 03 13 23 at the midpoints of their corners
    for k, (a, b) in enumerate([(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]):
        assert np.abs(pos[gp[:, 4 + k]] - 0.5 * (pos[gp[:, a]] + pos[gp[:, b]])).max() < 1e-14
    # one gridpoint per edge within a block: as many mid-edge nodes as distinct corner pairs
    for blk in np.unique(zs["block"][:zs.n]):
        g = gp[zs["block"][:zs.n] == blk]
        pairs = np.sort(np.concatenate([g[:, [0, 1]], g[:, [1, 2]], g[:, [2, 0]], g[:, [0, 3]], g[:, [1, 3]],
                                        g[:, [2, 3]]]), axis=1)
        assert len(np.unique(pairs, axis=0)) == len(np.unique(g[:, 4:]))
        assert len(np.unique(g)) == len(np.unique(g[:, :4])) + len(np.unique(g[:, 4:]))
    return zs


def test_high_order_tetra(session):
    session.command("model configure highorder\nblock create brick 0 1 0 1 0 1\nblock zone generate edgelength 0.5")
    m = session.model
    zs = m.store("zones")
    n4, nf4 = zs.n, m.faces.n
    v4 = zs["volume"][:n4].copy()
    session.command("block zone generate high-order-tetra")
    zs = _ho_checks(m)
    assert zs.n == n4
    assert np.allclose(zs["volume"][:zs.n], v4, rtol=0, atol=1e-15)
    assert abs(zs["volume"][:zs.n].sum() - 1.0) < 1e-12
    # faces split in four: four times the triangles, same total area, on the unit cube's faces
    f, fv = m.faces, m.face_vertices
    assert f.n == 4 * nf4 and (f["nvert"][:f.n] == 3).all()
    p = m.vertices["pos"][fv["vertex"][f["vstart"][:f.n][:, None] + np.arange(3)]]
    an = 0.5 * np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    assert abs(np.linalg.norm(an, axis=1).sum() - 6.0) < 1e-12
    cen = p.mean(axis=1)
    assert (np.isclose(cen, 0) | np.isclose(cen, 1)).any(axis=1).all()
    assert (np.einsum("ij,ij->i", an, cen - 0.5) > 0).all()        # outward
    # again: nothing changes
    session.command("block zone generate high-order-tetra")
    assert m.store("zones").n == n4 and m.faces.n == 4 * nf4


def test_high_order_with_edgelength_and_errors(session):
    with pytest.raises(Dec3dError, match="needs `model configure highorder`"):
        session.command("block create brick 0 1 0 1 0 1\nblock zone generate high-order-tetra edgelength 0.5")
    session.command("model configure highorder\nblock zone generate high-order-tetra edgelength 0.5")
    _ho_checks(session.model)
    session.command("block create brick 2 3 0 1 0 1\nblock zone generate hexahedra divisions 1 1 1 range pos-x 2 3")
    with pytest.raises(Dec3dError, match="hexahedral zones"):
        session.command("block zone generate high-order-tetra")
    with pytest.raises(Dec3dError, match="cannot be combined"):
        session.command("block zone generate hexahedra divisions 1 1 1 high-order-tetra")


def test_mesh_quality_of_a_hexahedral_cube(session):
    """One unit-cube hexahedron: corner tetrahedra are trirectangular (edges 1 and sqrt 2, smallest
    dihedral angle arccos(1/sqrt 3) = 54.7356 degrees, volume 1/6), the central one regular."""
    from dec3d.model.zone_mesh import mesh_quality
    session.command("block create brick 0 1 0 1 0 1\nblock zone generate hexahedra divisions 1 1 1")
    q = mesh_quality(session.model)
    assert q["zones"] == 1 and q["tetrahedra"] == 10 and q["gridpoints"] == 8
    assert abs(q["edge_min"] - 1.0) < 1e-15 and abs(q["edge_max"] - np.sqrt(2)) < 1e-15
    assert abs(q["dihedral_min"] - np.degrees(np.arccos(1 / np.sqrt(3)))) < 1e-9
    assert abs(q["volume_min"] - 1 / 6) < 1e-15
    assert mesh_quality(session.model, block_rows=[5])["zones"] == 0


@pytest.mark.parametrize("line,msg", [
    ("block zone generate divisions 2 2 2", "`divisions` goes with `hexahedra`"),
    ("block zone generate", "needs edgelength"),
    ("block zone generate hexahedra divisions 2 2 2 edgelength 0.5", "cannot be combined"),
    ("block zone generate hexahedra divisions 400 400 400", r"would make about 6\.4e\+08 zones"),
    ("block zone generate hexahedra divisions 2 2", "expected 3 numbers, got 2"),
    ("block zone generate hexahedra divisions 2 0 2", "divisions"),
])
def test_generate_bad_input(session, line, msg):
    session.command("block create brick 0 1 0 1 0 1")
    with pytest.raises(Dec3dError, match=msg):
        session.command(line)
    assert "zones" not in session.model.stores or session.model.store("zones").n == 0


def test_zoned_joined_model_save_restore(session, tmp_path):
    session.command("block create brick 0 1 0 1 0 1\nblock create brick 1 2 0 1 0 1\nblock join on\n"
                    "block zone generate edgelength 0.3 range pos-x 0 1\nblock zone generate edgelength 0.5\n"
                    f"model save '{tmp_path / 'z.sav'}'")
    m = session.model
    before = (m.vertices["link"][: m.vertices.n].copy(), m.store("zones")["gp"][: m.store("zones").n].copy(),
              m.blocks["zlength"][: m.blocks.n].copy())
    session.command(f"model new\nmodel restore '{tmp_path / 'z.sav'}'")
    m = session.model
    assert np.array_equal(m.vertices["link"][: m.vertices.n], before[0])
    assert np.array_equal(m.store("zones")["gp"][: m.store("zones").n], before[1])
    assert np.array_equal(m.blocks["zlength"][: m.blocks.n], before[2])
    assert conformity(m)["unmatched"] == [] and conformity(m)["pairs"] == 2
