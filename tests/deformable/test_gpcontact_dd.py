"""Sub-contacts between two zoned (deformable) blocks: the kernels of ``gpcontact`` (nearest
surface triangle, the vertex side on its own gridpoint, joint law, forces to gridpoints) against a
slow twin written here, and force and moment balance between the two blocks."""
import numpy as np
from scipy.spatial import Delaunay

from dec3d.kernels.gpcontact import mixed_subcontact_forces, surface_weights, vertex_sides
from dec3d.kernels.joints import NPROP, P_KN, P_KS
from dec3d.kernels.joints.mohr import CODE as MODEL_MOHR
from dec3d.kernels.joints.mohr import P_TANF, P_TANF_RES


def _two_surfaces(rng):
    """Block A (row 0) and block B (row 1), each with a triangulated face on z = 0 over the unit
    square (different gridpoints: A a 3 × 3 lattice, B corners and four random points), A's
    triangles facing +z and B's -z (outward normals), vertex rows A first, then B."""
    pa = np.array([[x, y] for x in (0, 0.5, 1) for y in (0, 0.5, 1)], float)
    pb = np.vstack([[[0, 0], [1, 0], [0, 1], [1, 1]], rng.uniform(0.1, 0.9, (4, 2))])
    tris = []
    for off, p, up in ((0, pa, True), (len(pa), pb, False)):
        for t in Delaunay(p).simplices:
            a, b, c = p[t]
            ccw = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) > 0
            t = list(t) if ccw == up else [t[0], t[2], t[1]]
            tris.append([off + k for k in t])
    vpos = np.zeros((len(pa) + len(pb), 3))
    vpos[:, :2] = np.vstack([pa, pb])
    ntri_a = sum(1 for t in tris if t[0] < len(pa))
    return vpos, np.array(tris), ntri_a, len(pa)


def _barycentric_twin(p, tri):
    """Coordinates of p in triangle tri (3, 3) by least squares on [b - a, c - a]."""
    m = np.column_stack([tri[1] - tri[0], tri[2] - tri[0]])
    st, *_ = np.linalg.lstsq(m, p - tri[0], rcond=None)
    return np.array([1 - st.sum(), st[0], st[1]])


def _face_side_twin(p, vpos, tris):
    """The triangle of ``tris`` that holds p (all coordinates ≥ 0) and p's coordinates in it."""
    for t in tris:
        lam = _barycentric_twin(p, vpos[t])
        if (lam >= -1e-12).all():
            return np.array(t), lam
    raise AssertionError("point outside the surface")


def _coulomb_twin(kn, ks, tanf, area, dun, dus, un, fs):
    """Elastic springs, no tension, Coulomb slip with no cohesion (3DEC's Coulomb-slip joint)."""
    un = un + dun
    fs = fs - ks * area * dus
    fn = -kn * area * un
    if fn <= 0.0:
        return 0.0, np.zeros(3), un
    lim = fn * tanf
    mag = np.linalg.norm(fs)
    if mag > lim:
        fs = fs * (lim / mag)
    return fn, fs, un


def test_deformable_subcontact_forces_against_a_twin_and_balanced():
    rng = np.random.default_rng(11)
    vpos, tris, ntri_a, nva = _two_surfaces(rng)
    nv = len(vpos)
    tris_a, tris_b = tris[:ntri_a], tris[ntri_a:]
    # face table of the two blocks (triangles, A's first)
    fnvert = np.full(len(tris), 3)
    fvstart = np.arange(0, 3 * len(tris), 3)
    fverts = tris.ravel().astype(np.int64)
    bfstart, bfcount = np.array([0, ntri_a]), np.array([ntri_a, len(tris) - ntri_a])
    zoned = np.array([True, True])
    ca, cb = np.array([0]), np.array([1])
    cn = np.array([[0.0, 0.0, 1.0]])
    # sub-contacts: every gridpoint of A (kind 0, face on B) and of B (kind 1, face on A), at the
    # gridpoint (the faces touch: gap 0)
    kind = np.array([0] * nva + [1] * (nv - nva))
    key0 = np.arange(nv, dtype=np.int64)
    pos = vpos.copy()
    owner = np.zeros(nv, np.int64)
    area = rng.uniform(0.02, 0.08, nv)
    prop = np.zeros((1, NPROP))
    prop[0, P_KN], prop[0, P_KS], prop[0, P_TANF], prop[0, P_TANF_RES] = 2e9, 1e9, 0.3, 0.3
    na, wa, nb, wb = (np.empty((nv, 3), np.int64), np.empty((nv, 3)), np.empty((nv, 3), np.int64),
                      np.empty((nv, 3)))
    surface_weights(owner, pos, ca, cb, zoned, vpos, bfstart, bfcount, fvstart, fnvert, fverts, na, wa, nb, wb)
    vertex_sides(kind, key0, ca, cb, owner, zoned, na, wa, nb, wb)
    # the twin's sides: the vertex itself, and the triangle of the other block holding it
    sides = []
    for s in range(nv):
        tn, lam = _face_side_twin(pos[s], vpos, tris_b if kind[s] == 0 else tris_a)
        own = (np.array([s]), np.array([1.0]))
        sides.append((own, (tn, lam)) if kind[s] == 0 else ((tn, lam), own))
        # the kernel's weights give the same point on each side
        for (nodes, w), (kn_, kw) in (((na, wa), sides[-1][0]), ((nb, wb), sides[-1][1])):
            k_pt = sum(w[s, j] * vpos[nodes[s, j]] for j in range(3) if nodes[s, j] >= 0)
            assert np.allclose(k_pt, kw @ vpos[kn_], atol=1e-12)
        on_vertex = na if kind[s] == 0 else nb
        assert on_vertex[s, 0] == s and (on_vertex[s, 1:] == -1).all()
    dt = 1e-3
    st = dict(fn=np.zeros(nv), fs=np.zeros((nv, 3)), un=np.zeros(nv), udil=np.zeros(nv), us=np.zeros((nv, 3)),
              state=np.zeros(nv, np.int64))
    t_un, t_fn, t_fs = np.zeros(nv), np.zeros(nv), np.zeros((nv, 3))
    nothing3 = np.zeros((2, 3))
    for step in range(6):
        # block B pushed down and sheared over A, both surfaces deforming at random
        gvel = rng.normal(0.0, 0.01, (nv, 3))
        gvel[nva:] += [2.0 if step > 2 else 0.0, 0.5, -0.4]
        gforce = np.zeros((nv, 3))
        mixed_subcontact_forces(dt, nothing3, nothing3, nothing3, nothing3.copy(), nothing3.copy(), gvel, gforce,
                                ca, cb, cn, np.array([MODEL_MOHR]), prop, owner, pos, area, st["fn"], st["fs"],
                                st["un"], st["udil"], st["us"], st["state"], np.zeros((nv, 8)), na, wa, nb, wb)
        want = np.zeros((nv, 3))
        for s in range(nv):
            (an, aw), (bn, bw) = sides[s]
            du = (bw @ gvel[bn] - aw @ gvel[an]) * dt
            dun = du @ cn[0]
            t_fn[s], fs, t_un[s] = _coulomb_twin(2e9, 1e9, 0.3, area[s], dun, du - dun * cn[0], t_un[s], t_fs[s])
            t_fs[s] = fs
            f = t_fn[s] * cn[0] + fs
            np.add.at(want, bn, np.outer(bw, f))
            np.add.at(want, an, -np.outer(aw, f))
        scale = max(np.abs(want).max(), 1e-300)
        assert np.allclose(st["fn"], t_fn, rtol=0, atol=1e-11 * scale)
        assert np.allclose(gforce, want, rtol=0, atol=1e-11 * scale)
        assert np.allclose(st["fs"], t_fs, rtol=0, atol=1e-11 * scale)
        # balance between the two blocks: the forces on A's gridpoints are minus those on B's,
        # and so are their moments (every sub-contact point lies in both faces)
        fa, fb = gforce[:nva].sum(axis=0), gforce[nva:].sum(axis=0)
        assert np.abs(fa + fb).max() <= 1e-12 * scale * nv
        o = np.array([0.3, -2.0, 5.0])              # any point: the moments balance about it
        ma = np.cross(vpos[:nva] - o, gforce[:nva]).sum(axis=0)
        mb = np.cross(vpos[nva:] - o, gforce[nva:]).sum(axis=0)
        assert np.abs(ma + mb).max() <= 1e-12 * scale * nv * 5
    assert (st["fn"] > 0).all() and np.abs(st["fs"]).max() > 0
    slipping = np.linalg.norm(st["fs"], axis=1) >= 0.3 * st["fn"] * (1 - 1e-12)
    assert slipping.any()                       # Coulomb's limit was reached and held


def test_vertex_sides_leave_rigid_sides_and_crossings_alone():
    kind = np.array([0, 1, 2, 3, 0])
    key0 = np.array([7, 8, 9, 10, 11])
    owner = np.array([0, 0, 0, 0, 1])
    ca, cb = np.array([0, 2]), np.array([1, 0])
    zoned = np.array([True, True, False])
    na = np.arange(15).reshape(5, 3)
    nb = na + 100
    wa = np.full((5, 3), 1 / 3)
    wb = wa.copy()
    na0, nb0 = na.copy(), nb.copy()
    vertex_sides(kind, key0, ca, cb, owner, zoned, na, wa, nb, wb)
    assert list(na[0]) == [7, -1, -1] and list(wa[0]) == [1, 0, 0]       # A's vertex, A zoned
    assert list(nb[1]) == [8, -1, -1] and list(wb[1]) == [1, 0, 0]       # B's vertex, B zoned
    assert np.array_equal(nb[0], nb0[0]) and np.array_equal(na[1], na0[1])
    assert np.array_equal(na[2:4], na0[2:4]) and np.array_equal(nb[2:4], nb0[2:4])    # crossings, points
    assert np.array_equal(na[4], na0[4])                                 # contact 1: A (row 2) is rigid


def test_joined_zoned_pairs_carry_no_area():
    from dec3d.physics.contacts import joined_zoned_inert
    zoned = np.array([True, True, True, False])
    leader = np.array([0, 0, -1, 3])            # rows 0 and 1 joined, 2 and 3 alone
    ra, rb = np.array([0, 0, 1]), np.array([1, 2, 3])
    sc = np.array([0, 0, 1, 2, 1])
    area = np.array([0.1, 0.2, 0.3, 0.4, 0.5])
    joined_zoned_inert(sc, area, zoned, leader, ra, rb)
    assert list(area) == [0.0, 0.0, 0.3, 0.4, 0.5]



def test_take_contact_forces_adds_forces_and_magnitudes_and_clears():
    from dec3d.kernels.gpcontact import take_contact_forces
    rng = np.random.default_rng(5)
    gc = rng.normal(size=(6, 3))
    facc = rng.normal(size=(6, 3))
    fmag = rng.random(6)
    rows = np.array([4, 1, 2])
    want_f, want_m, want_gc = facc.copy(), fmag.copy(), gc.copy()
    for r in rows:                           # the twin: plain Python per row
        want_f[r] = [facc[r, d] + gc[r, d] for d in range(3)]
        want_m[r] = fmag[r] + sum(x * x for x in gc[r]) ** 0.5
        want_gc[r] = 0.0
    take_contact_forces(rows, gc, facc, fmag)
    assert np.allclose(facc, want_f, rtol=1e-15, atol=0) and np.allclose(fmag, want_m, rtol=1e-15, atol=0)
    assert np.array_equal(gc, want_gc)       # rows not listed keep their values
