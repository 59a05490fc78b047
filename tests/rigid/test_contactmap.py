"""Contact bookkeeping and cycle kernels against their slow twins (tests/reference/contactmap_ref.py)."""
import numpy as np
import pytest

from dec3d.kernels.commonplane import common_plane, contact_type
from dec3d.kernels.contactmap import carry_over, cp_batch, envelopes, match_sorted
from dec3d.kernels.cycle import _move_points, run_steps
from dec3d.kernels.jointlaw import subcontact_forces
from dec3d.kernels.motion import rigid_motion_groups
from dec3d.physics.rigid import engine
from tests.reference import contactmap_ref as ref


@pytest.mark.parametrize("seed", range(5))
def test_match_sorted_against_dict_lookup(seed):
    rng = np.random.default_rng(seed)
    old = np.unique(rng.integers(0, 30, size=(60, 2)), axis=0)
    new = np.unique(rng.integers(0, 30, size=(60, 2)), axis=0)
    got = match_sorted(old[:, 0].copy(), old[:, 1].copy(), new[:, 0].copy(), new[:, 1].copy())
    assert got.tolist() == ref.match_sorted(old[:, 0], old[:, 1], new[:, 0], new[:, 1]).tolist()
    assert (got >= 0).any() and (got < 0).any()


def test_envelopes_against_numpy():
    rng = np.random.default_rng(1)
    vpos = rng.normal(size=(40, 3))
    start = np.array([0, 8, 20, 32], np.int64)
    count = np.array([8, 12, 12, 8], np.int64)
    active = np.array([True, False, True, True])
    lo, hi = np.empty((4, 3)), np.empty((4, 3))
    envelopes(vpos, start, count, active, 0.01, lo, hi)
    rlo, rhi = ref.envelopes(vpos, start, count, active, 0.01)
    assert np.array_equal(lo, rlo) and np.array_equal(hi, rhi)


@pytest.mark.parametrize("seed", range(4))
def test_carry_over_against_twin(seed):
    rng = np.random.default_rng(seed)
    nold, nnew = 5, 6
    old_count = rng.integers(0, 6, nold)
    old_start = np.concatenate([[0], np.cumsum(old_count)[:-1]]).astype(np.int64)
    nso = int(old_count.sum())
    old_kind = rng.integers(0, 4, nso)
    old_key0 = rng.integers(0, 5, nso)
    old_key1 = rng.integers(0, 3, nso)
    old_area = rng.uniform(0.1, 1.0, nso)
    old_fs, old_us = rng.normal(size=(nso, 3)), rng.normal(size=(nso, 3))
    old_un, old_udil = rng.normal(size=nso), rng.normal(size=nso)
    old_state = rng.integers(0, 8, nso)
    old_n = rng.normal(size=(nold, 3))
    old_n /= np.linalg.norm(old_n, axis=1)[:, None]
    new_n = old_n[rng.integers(0, nold, nnew)] + 0.05 * rng.normal(size=(nnew, 3))
    new_n /= np.linalg.norm(new_n, axis=1)[:, None]
    cprev = np.array([0, 1, -1, 2, 3, 4], np.int64)
    sc_contact = np.sort(rng.integers(0, nnew, 30)).astype(np.int64)
    kind = rng.integers(0, 4, 30)
    key0 = rng.integers(0, 5, 30)
    key1 = rng.integers(0, 3, 30)
    area = rng.uniform(0.1, 1.0, 30)
    sgap = rng.normal(size=30) * 1e-3
    out = (np.empty((30, 3)), np.empty(30), np.empty(30), np.empty((30, 3)), np.empty(30, np.int64))
    args = (cprev, sc_contact, kind, key0, key1, area, sgap, old_start, old_count, old_kind, old_key0, old_key1,
            old_area, old_fs, old_un, old_udil, old_us, old_state, old_n, new_n)
    carry_over(*args, *out)
    want = ref.carry_over(*args)
    for got, exp in zip(out, want):
        assert np.allclose(got, exp, rtol=1e-12, atol=1e-14)


def _model(session, deck):
    session.run_items(session.load_text(deck))
    e = engine(session.model)
    e.detect()
    return session.model, e


STACK = """model new
block create brick 0 2 0 2 -1 0
block create brick 0 1 0 1 0 1
block create brick 0.3 1.3 0.2 1.2 1 2
block property density 2000
model gravity 0 0 -10
block contact jmodel assign mohr
block contact property stiffness-normal 1e8 stiffness-shear 1e8 friction 30
block fix range position-z -1 0
"""


def test_cp_batch_equals_common_plane_pair_by_pair(session):
    m, e = _model(session, STACK)
    b, cs = m.blocks, e.contacts
    ra, rb = cs["a"].copy(), cs["b"].copy()
    prev = np.arange(cs.n, dtype=np.int64)
    prev[0] = -1
    k = cs.n
    nn, cc, gap, ct = np.empty((k, 3)), np.empty((k, 3)), np.empty(k), np.empty(k, np.int64)
    vp, vs, vc = m.vertices["pos"], b["vert_start"], b["vert_count"]
    reach = np.full(k, e.tolerance())
    cp_batch(ra, rb, prev, vp, vs, vc, b["centroid"], cs["normal"], cs["pos"], reach, nn, cc, gap, ct)
    for i in range(k):
        a, bb = ra[i], rb[i]
        if prev[i] >= 0:
            n0, c = cs["normal"][i].copy(), cs["pos"][i].copy()
        else:
            n0, c = b["centroid"][bb] - b["centroid"][a], 0.5 * (b["centroid"][a] + b["centroid"][bb])
        n = np.empty(3)
        g, na, nb, _ = common_plane(vp[vs[a]:vs[a] + vc[a]], vp[vs[bb]:vs[bb] + vc[bb]], n0, e.tolerance(),
                                    prev[i] >= 0, n, c)
        assert g == gap[i] and np.array_equal(n, nn[i]) and np.array_equal(c, cc[i])
        assert ct[i] == contact_type(na, nb)


def test_run_steps_equals_the_kernels_step_by_step(session):
    """The many-steps kernel against a Python loop over its parts (joint law, motion, Eq. 11)."""
    m, e = _model(session, STACK)
    b, cs, ss = m.blocks, e.contacts, e.subcontacts
    gstart, gmember = e._groups()
    from dec3d.physics.bodies import group_properties, new_servo

    inertia = np.einsum("bij,bj,bkj->bik", b["principal_axes"], b["principal_moment"], b["principal_axes"])
    gm, gc, _, gp, ga, gi = group_properties(gstart, gmember, b["mass"], b["centroid"], inertia, b["inertia_approx"])
    g = np.array([0.0, 0.0, -10.0])
    dt = e.timestep()

    def state():
        return {"b": {k: b[k].copy() for k in ("force", "moment", "velocity", "spin", "centroid", "disp")},
                "v": m.vertices["pos"].copy(), "cc": cs["pos"].copy(),
                "s": {k: ss[k].copy() for k in ("pos", "fn", "fs", "un", "udil", "us", "state")},
                "g": (gc.copy(), ga.copy())}

    s0 = state()

    def put(st):
        for k, v in st["b"].items():
            b[k][...] = v
        m.vertices["pos"][...] = st["v"]
        cs["pos"][...] = st["cc"]
        for k, v in st["s"].items():
            ss[k][...] = v
        return st["g"][0].copy(), st["g"][1].copy()

    fix = b["fixity"].copy()
    common = lambda gcen, gax: (gstart, gmember, gm, gm.copy(), gi, gp, gax, gcen, b["mass"], fix, b["force"],
                                b["moment"], b["fapp"], b["mapp"], b["velocity"], b["spin"], b["centroid"],
                                b["disp"], b["vert_start"], b["vert_count"], m.vertices["pos"])
    sc = lambda: (ss["contact"], ss["pos"], ss["area"], ss["fn"], ss["fs"], ss["un"], ss["udil"], ss["us"], ss["state"])
    own = np.arange(cs.n, dtype=np.int64)
    gcen, gax = put(s0)
    out = np.zeros(4)
    done, bad = run_steps(7, dt, g, 1, 0.8, new_servo(len(gm)), False, *common(gcen, gax), cs["a"], cs["b"],
                          cs["normal"], cs["pos"], own, cs["jmodel"], cs["prop"], *sc(), 1e6, out,
                          np.ones(b.n), np.zeros(b.n), 1e9, np.zeros(2))
    assert (done, bad) == (7, -1)
    fast = state()
    gcen, gax = put(s0)
    for _ in range(7):
        subcontact_forces(dt, b["centroid"], b["velocity"], b["spin"], b["force"], b["moment"], cs["a"], cs["b"],
                          cs["normal"], cs["jmodel"], cs["prop"], *sc())
        assert rigid_motion_groups(dt, g, 1, 0.8, new_servo(len(gm)), False, *common(gcen, gax), 1e6, out) == -1
        cs["pos"][...] = ref.move_points(dt, cs["a"], cs["b"], own, cs["pos"], b["centroid"], b["velocity"], b["spin"])
        ss["pos"][...] = ref.move_points(dt, cs["a"], cs["b"], ss["contact"], ss["pos"], b["centroid"],
                                         b["velocity"], b["spin"])
    slow = state()
    for part in ("b", "s"):
        for k in fast[part]:
            assert np.allclose(fast[part][k], slow[part][k], rtol=1e-12, atol=1e-15), k
    assert np.allclose(fast["v"], slow["v"], rtol=1e-12, atol=1e-15)
    assert np.allclose(fast["cc"], slow["cc"], rtol=1e-12, atol=1e-15)
    assert np.abs(fast["b"]["disp"]).max() > 0          # something moved


def test_move_points_against_twin():
    rng = np.random.default_rng(3)
    cen, vel, spin = rng.normal(size=(4, 3)), rng.normal(size=(4, 3)), rng.normal(size=(4, 3))
    ca, cb = np.array([0, 1, 2], np.int64), np.array([1, 3, 3], np.int64)
    owner = np.array([0, 0, 1, 2, 2], np.int64)
    pts = rng.normal(size=(5, 3))
    want = ref.move_points(0.01, ca, cb, owner, pts, cen, vel, spin)
    _move_points(0.01, ca, cb, owner, pts, cen, vel, spin)
    assert np.allclose(pts, want, rtol=1e-14, atol=1e-15)


def test_blocks_moved_against_numpy():
    from dec3d.kernels.contactmap import blocks_moved

    rng = np.random.default_rng(5)
    snap = rng.normal(size=(20, 3))
    vpos = snap + rng.uniform(-1e-3, 1e-3, size=(20, 3))
    vpos[7, 1] += 0.01
    start = np.array([0, 5, 10, 15], np.int64)
    count = np.array([5, 5, 5, 5], np.int64)
    out = np.zeros(4, bool)
    blocks_moved(vpos, snap, start, count, 2e-3, out)
    want = [bool((np.abs(vpos - snap)[s:s + c] > 2e-3).any()) for s, c in zip(start, count)]
    assert out.tolist() == want == [False, True, False, False]


def test_face_snap_gives_the_exact_plane_under_a_small_block():
    """A 0.1 m cube on a 1 m one, the search started 7° off: the face snap ends on the
    exact normal with a zero gap (the hill-climb alone stops within 0.01°)."""
    big = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)
    small = np.array([[x, y, z] for x in (0.4, 0.5) for y in (0.4, 0.5) for z in (1.0, 1.1)], float)
    n, c = np.empty(3), np.array([0.45, 0.45, 1.0])
    gap, na, nb, _ = common_plane(big, small, small.mean(0) - big.mean(0), 0.005, False, n, c)
    assert gap == 0.0 and n.tolist() == [0.0, 0.0, 1.0]
    assert contact_type(na, nb) == 6


def test_vertex_point_areas_against_projected_face_shares(session):
    """A unit cube tilted 30° about y, standing on its edge on a base: each end of the edge
    gets (A/4)(cos 30° + sin 30°) from its two faces at the edge (the end face is
    perpendicular to the plane), computed here from the geometry directly."""
    from dec3d.kernels.contactmap import vertex_point_areas

    m, e = _model(session, "model new\nblock create brick -2 2 -2 2 -1 0\n"
                           "block create brick 0 1 0 1 0 1\n")
    b, v = m.blocks, m.vertices
    cube = 1
    rows = np.arange(b["vert_start"][cube], b["vert_start"][cube] + b["vert_count"][cube])
    t = np.radians(30.0)
    rot = np.array([[np.cos(t), 0, np.sin(t)], [0, 1, 0], [-np.sin(t), 0, np.cos(t)]])
    v["pos"][rows] = v["pos"][rows] @ rot.T
    v["pos"][rows, 2] -= v["pos"][rows, 2].min()
    low = rows[np.abs(v["pos"][rows, 2]) < 1e-12]
    assert len(low) == 2
    sc = np.zeros(2, np.int64)
    kind = np.full(2, 3, np.int64)
    area = np.full(2, 1e-4)
    vertex_point_areas(sc, kind, low.astype(np.int64), np.array([5], np.int64), np.array([[0.0, 0.0, -1.0]]),
                       v["pos"], v["block"], b["face_start"], b["face_count"], m.faces["vstart"],
                       m.faces["nvert"], m.face_vertices["vertex"], 1e-4, area)
    assert np.allclose(area, 0.25 * (np.cos(t) + np.sin(t)), rtol=1e-12)
    # a face-face sub-contact, or a vertex-vertex contact, is left alone
    area2 = np.full(2, 0.3)
    vertex_point_areas(sc, np.array([0, 3], np.int64), low.astype(np.int64), np.array([1], np.int64),
                       np.array([[0.0, 0.0, -1.0]]), v["pos"], v["block"], b["face_start"], b["face_count"],
                       m.faces["vstart"], m.faces["nvert"], m.face_vertices["vertex"], 1e-4, area2)
    assert area2.tolist() == [0.3, 0.3]
