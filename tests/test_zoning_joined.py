"""Conforming zoning of joined blocks: shared gridpoints (linked to one master) and the same
surface triangles on both sides of every joined face, for the three zonings of Itasca's
elastic-hole verification decks and for small hand-made cases."""
import numpy as np
import pytest

from dec3d.geometry.zoning import min_dihedral_deg, position_hash, regular_tets
from dec3d.model.zone_mesh import conformity
from tests.conftest import DECKS, NO_DECKS

HOLE = "peterzhu6667__pinn-cp-3dec__Elastic_Hole__ElasticHole-{}.dat"


def _tris(model, row):
    b, f, fv = model.blocks, model.faces, model.face_vertices
    f0, fc = int(b["face_start"][row]), int(b["face_count"][row])
    return fv["vertex"][f["vstart"][f0:f0 + fc][:, None] + np.arange(3)]


def _planes(model, row):
    """Outward planes of a zoned block from its own surface triangles."""
    pos = model.vertices["pos"]
    t = _tris(model, row)
    p = pos[t]
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    return n, np.einsum("ij,ij->i", n, p[:, 0])


def check_joined_conforming(model, tol=1e-12):
    """Independent of dec3d.model.zone_mesh: for every surface triangle of a zoned block, a point
    just outside it (along its outward normal) that falls inside another zoned block of the same
    joined set means a shared face; that block must have a triangle with the same three corner
    positions (to ``tol``), and linked gridpoints must sit on their masters. Returns the number of
    shared triangles checked."""
    b, v = model.blocks, model.vertices
    pos, link = v["pos"], v["link"]
    lk = np.flatnonzero(link >= 0)
    assert (link[lk] >= 0).all() and (link[link[lk]] == -1).all()      # masters are their own masters
    assert np.abs(pos[lk] - pos[link[lk]]).max(initial=0.0) <= tol
    zs = model.store("zones")
    rows = np.unique(zs["block"][:zs.n])
    lead = b["leader"]
    planes = {r: _planes(model, r) for r in rows}
    keys = {}
    for r in rows:
        t = _tris(model, r)
        keys[r] = {tuple(sorted(map(tuple, np.round(pos[x] / tol).astype(np.int64).tolist()))) for x in t}
    shared = 0
    for r in rows:
        t = _tris(model, r)
        p = pos[t]
        n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
        h = np.sqrt(np.linalg.norm(n, axis=1))
        probe = p.mean(axis=1) + 1e-3 * h[:, None] * n / np.linalg.norm(n, axis=1, keepdims=True)
        for q in rows:
            if q == r or lead[q] != lead[r]:
                continue
            N, D = planes[q]
            inside = (probe @ N.T - D < 0).all(axis=1)
            for i in np.flatnonzero(inside):
                k = tuple(sorted(map(tuple, np.round(pos[t[i]] / tol).astype(np.int64).tolist())))
                assert k in keys[q], f"triangle {i} of block row {r} has no match in block row {q}"
                # and the match uses the same master gridpoints
                shared += 1
    return shared


def _run_hole(session, name):
    if not DECKS.is_dir():
        pytest.skip(NO_DECKS)
    lines = []
    for line in (DECKS / HOLE.format(name)).read_text().split("\n"):
        if "zone cmodel" in line:
            break
        lines.append(line)
    session.command("\n".join(lines))
    return session.model


# smallest dihedral angle: the tet deck's graded zoning after sliver removal; the hexahedra are
# bounded by the block shapes; edge length 1.0 (HO deck) leaves the thin inner blocks (0.16 m wide)
# with boundary points only, so their flat tetrahedra cannot be broken up by interior points
@pytest.mark.parametrize("name,nnode,nzones,min_angle", [("tet", 4, None, 11.0), ("Hex", 4, 1000, 11.0),
                                                          ("HO", 10, None, 8.0)])
def test_hole_decks_zoned_conforming(session, name, nnode, nzones, min_angle):
    m = _run_hole(session, name)
    zs = m.store("zones")
    b = m.blocks
    assert len(np.unique(zs["block"][:zs.n])) == b.n                # every block zoned
    assert (zs["nnode"][:zs.n] == nnode).all()
    if nzones:
        assert zs.n == nzones                                          # 100 blocks, one hexahedron each
    vol = zs["volume"][:zs.n]
    assert (vol > 0).all()
    for r in range(b.n):
        sel = zs["block"][:zs.n] == r
        layers = 2 if name == "Hex" else 1                             # two overlays of the same volume
        assert abs(vol[sel].sum() / layers - b["volume"][r]) < 1e-12 * b["volume"][r]
    assert min_dihedral_deg(m.vertices["pos"], zs["gp"][:zs.n, :4]) > min_angle
    shared = check_joined_conforming(m)
    assert shared > 100
    rep = conformity(m)
    assert rep["unmatched"] == [] and rep["link_gap"] == 0.0 and rep["triangles"] == shared
    # every gridpoint of a shared face is linked: masters are the lowest rows at each position
    v = m.vertices
    pos = v["pos"][: v.n]
    _, inv, cnt = np.unique(pos, axis=0, return_inverse=True, return_counts=True)
    assert (v["link"][: v.n] >= 0).sum() == (cnt - 1).sum()


def test_fine_then_coarse_joined_bricks(session):
    session.command("block create brick 0 1 0 1 0 1\nblock create brick 1 2.5 0 1 0 1\n"
                    "block create brick 0 1 1 2 0 1\nblock join on\n"
                    "block zone generate edgelength 0.2 range pos-x 0 1 pos-y 0 1\n"
                    "block zone generate edgelength 0.35")
    m = session.model
    assert check_joined_conforming(m) > 2 * 25         # at least the fine 5 x 5 face, two triangles a cell
    assert conformity(m)["unmatched"] == [] and "warning" not in session.output.getvalue()
    # the coarse neighbour took the fine block's points on x = 1
    pos = m.vertices["pos"]
    b = m.blocks
    on = lambda r: {tuple(p) for p in pos[b["vert_start"][r]:b["vert_start"][r] + b["vert_count"][r]]
                    if abs(p[0] - 1.0) < 1e-12 and p[1] <= 1 and p[2] <= 1}
    assert on(0) == on(1) and len(on(0)) >= 36
    zs = m.store("zones")
    for r in range(3):
        sel = zs["block"][:zs.n] == r
        assert abs(zs["volume"][:zs.n][sel].sum() - b["volume"][r]) < 1e-12 * b["volume"][r]


def test_unjoined_blocks_are_not_linked_and_check_catches_mismatch(session):
    session.command("block create brick 0 1 0 1 0 1\nblock create brick 1 2 0 1 0 1\n"
                    "block zone generate edgelength 0.2 range pos-x 0 1\n"
                    "block zone generate edgelength 0.3")
    m = session.model
    assert (m.vertices["link"][: m.vertices.n] == -1).all()
    session.command("block join on")                 # joined after zoning: faces do not conform
    rep = conformity(m)
    assert rep["pairs"] == 2 and len(rep["unmatched"]) == 2


def test_same_coplanar_points_same_facet_triangles():
    """The restriction of the regular triangulation to a hull facet depends only on the points on
    that facet and their weights: two point sets on either side of the plane z = 0, with different
    interior points and different edge lengths, give the same triangles on z = 0."""
    rng = np.random.default_rng(7)
    g = np.arange(0, 1.0001, 0.2)
    face = np.array([[x, y, 0.0] for x in g for y in g])             # a cocircular lattice: ties everywhere
    out = []
    for sign, L, n in ((1, 0.2, 60), (-1, 0.5, 25)):
        inner = np.c_[rng.uniform(0.05, 0.95, (n, 2)), sign * rng.uniform(0.05, 1.0, n)]
        top = np.array([[x, y, sign * 1.0] for x in (0, 1) for y in (0, 1)])
        pts = np.r_[face, inner, top]
        scale = np.r_[np.full(len(face), 0.2), np.full(n + 4, L)]    # the facet points keep their weights
        tets = regular_tets(pts, L, scale)
        f = np.concatenate([tets[:, [1, 2, 3]], tets[:, [0, 2, 3]], tets[:, [0, 1, 3]], tets[:, [0, 1, 2]]])
        on = (np.abs(pts[f][:, :, 2]) < 1e-15).all(axis=1)
        tri = {tuple(sorted(t)) for t in f[on].tolist() if max(t) < len(face)}
        out.append(tri)
    assert len(out[0]) == 2 * 25
    assert out[0] == out[1]


def test_position_hash_depends_on_position_only():
    p = np.array([[0.1, 0.2, 0.3], [0.0, -0.0, 1.0], [0.1, 0.2, 0.3 + 1e-16]])
    h = position_hash(p)
    assert ((h >= 0) & (h < 1)).all()
    assert position_hash(p[:1])[0] == h[0]
    assert position_hash(np.array([[0.0, 0.0, 1.0]]))[0] == h[1]          # -0.0 hashes as 0.0
    assert h[2] != h[0]
    # spread: mean of many hashes near 1/2
    q = np.random.default_rng(1).uniform(-5, 5, (20000, 3))
    assert abs(position_hash(q).mean() - 0.5) < 0.01


def test_mixed_styles_warn(session):
    """A tetrahedral block joined to a hexahedral one: the quad diagonals and the regular
    triangulation need not agree; the command says so with file:line."""
    session.command("block create brick 0 1 0 1 0 1\nblock create brick 1 2 0 1 0 1\nblock join on\n"
                    "block zone generate hexahedra divisions 3 3 3 range pos-x 0 1\n"
                    "block zone generate edgelength 0.3")
    rep = conformity(session.model)
    out = session.output.getvalue()
    assert rep["pairs"] == 2 and rep["unmatched"]                # this case does not conform (8 triangles)
    assert "warning: " in out and ":5:" in out and "do not share all surface triangles" in out
    # the gridpoints still coincide and are linked
    assert rep["link_gap"] == 0.0 and (session.model.vertices["link"] >= 0).sum() == 16


@pytest.mark.parametrize("first", ["range pos-x 0 1", "range pos-x 1 2"])
def test_t_junction_joined_faces(session, first):
    """Block A's face x = 1 (y from 0 to 2) is shared half by B (y < 1) and half by C (y > 1).
    Zoned A first, A puts points along y = 1 (where B's and C's faces end) so that no triangle
    crosses it; zoned B and C first, A takes over both sets of points. Either way the faces
    conform and every block keeps its volume (no corner lost)."""
    session.command("block create brick 0 1 0 2 0 1\nblock create brick 1 2 0 1 0 1\nblock create brick 1 2 1 2 0 1\n"
                    f"block join on\nblock zone generate edgelength 0.23 {first}\nblock zone generate edgelength 0.31")
    m = session.model
    assert check_joined_conforming(m) > 30
    rep = conformity(m)
    assert rep["unmatched"] == [] and rep["pairs"] == 6
    zs = m.store("zones")
    vol = zs["volume"][:zs.n]
    assert (vol > 0).all()
    for r, expect in ((0, 2.0), (1, 1.0), (2, 1.0)):
        assert abs(vol[zs["block"][:zs.n] == r].sum() - expect) < 1e-12
    assert "warning" not in session.output.getvalue()


def test_edge_length_beyond_the_block(session):
    """An edge length far beyond the block (1e300: L³ overflows a float) zones it with its
    corners only (a cube: five or six tetrahedra), and a finer joined neighbour still conforms."""
    session.command("block create brick 0 1 0 1 0 1\nblock create brick 1 2 0 1 0 1\nblock join on\n"
                    "block zone generate edgelength 1e300 range pos-x 0 1\nblock zone generate edgelength 0.3")
    m = session.model
    zs = m.store("zones")
    first = zs["block"][:zs.n] == 0
    assert first.sum() in (5, 6) and abs(zs["volume"][:zs.n][first].sum() - 1.0) < 1e-12
    assert abs(zs["volume"][:zs.n].sum() - 2.0) < 1e-12
    assert np.isfinite(m.blocks["zlength"][: m.blocks.n]).all()
    assert check_joined_conforming(m) == 4 and conformity(m)["unmatched"] == []
