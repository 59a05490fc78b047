"""Contact bookkeeping and cycle kernels against their slow twins (tests/reference/contactmap_ref.py)."""
import numpy as np
import pytest

from dec3d.kernels.commonplane import CONTACT_TYPE_NAMES, common_plane, contact_type
from dec3d.kernels.contactmap import carry_over, cp_batch, envelopes, match_sorted
from dec3d.kernels.cycle import _move_points, run_steps
from dec3d.physics.rigid import engine
from reference import commonplane_ref as cpref
from reference import contactmap_ref as ref


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
    old_hist = rng.normal(size=(nso, 8))
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
    out = (np.empty((30, 3)), np.empty(30), np.empty(30), np.empty((30, 3)), np.empty(30, np.int64),
           np.empty((30, 8)))
    args = (cprev, sc_contact, kind, key0, key1, area, sgap, old_start, old_count, old_kind, old_key0, old_key1,
            old_area, old_fs, old_un, old_udil, old_us, old_state, old_hist, old_n, new_n)
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


def _box(lo, hi):
    return np.array([[x, y, z] for z in (lo[2], hi[2]) for y in (lo[1], hi[1]) for x in (lo[0], hi[0])], float)


def _turn(v, axis, deg):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    t = np.radians(deg)
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    R = np.eye(3) + np.sin(t) * K + (1 - np.cos(t)) * K @ K
    c = v.mean(0)
    return (v - c) @ R.T + c


def _cp_batch_kernel(blocks, pairs, prev, old_n, old_c, reach):
    """The kernel call, kept thin: blocks (list of vertex arrays), pairs (k, 2) rows A → B."""
    vpos = np.vstack(blocks)
    count = np.array([len(v) for v in blocks], np.int64)
    start = np.concatenate([[0], np.cumsum(count)[:-1]]).astype(np.int64)
    cen = np.array([v.mean(0) for v in blocks])
    k = len(pairs)
    nn, cc, gap, ct = np.empty((k, 3)), np.empty((k, 3)), np.empty(k), np.empty(k, np.int64)
    cp_batch(pairs[:, 0].copy(), pairs[:, 1].copy(), prev, vpos, start, count, cen, old_n, old_c,
             reach, nn, cc, gap, ct)
    return nn, cc, gap, [CONTACT_TYPE_NAMES[t] for t in ct]


def test_cp_batch_against_the_best_plane_of_each_pair():
    """Every pair of a batch against the c-p's definition (tests/reference/commonplane_ref.py): the
    largest gap over all normals (separating axes when touching or overlapping, the closest points
    when apart), the reference point midway, and the contact type of ERRATA Table 1; new pairs start
    from the line of centroids, an existing one from its old normal, a pair beyond reach is none."""
    rng = np.random.default_rng(11)
    g0 = 1e-4
    base = _box((0, 0, 0), (1, 1, 1))
    blocks = [
        base,                                                              # 0
        _box((0.3, 0.2, 1 + g0), (0.8, 0.7, 1.5 + g0)),                    # 1 face on 0's top, apart by g0
        None,                                                              # 2 edge down on 0's top (below)
        rng.normal(size=(12, 3)) * [0.4, 0.6, 0.5],                        # 3 a convex-hull cloud
        rng.normal(size=(10, 3)) * [0.5, 0.3, 0.4] + [1.5, -2.0, 2.5],     # 4 another, 3 m away
        _box((0.1, 0.1, 1 - 2e-4), (0.9, 0.6, 1.4)),                       # 5 sunk 0.2 mm into 0 (existing)
        _box((5, 5, 5), (6, 6, 6)),                                        # 6 far from 0
    ]
    edge = _turn(_box((0.2, 0.2, 0), (0.7, 0.7, 0.5)), (1, 0, 0), 45)
    blocks[2] = edge - [0, 0, edge[:, 2].min() - 1 - g0]
    pairs = np.array([[0, 1], [0, 2], [3, 4], [0, 5], [0, 6]], np.int64)
    tilted = np.array([np.sin(np.radians(0.5)), 0.0, np.cos(np.radians(0.5))])
    prev = np.array([-1, -1, -1, 0, -1], np.int64)
    old_n, old_c = tilted[None].copy(), np.array([[0.5, 0.4, 1.0]])
    reach = np.array([1e-3, 1e-3, 1e9, 1e-3, 1e-3])
    nn, cc, gap, types = _cp_batch_kernel(blocks, pairs, prev, old_n, old_c, reach)

    for i, (a, b) in enumerate(pairs):
        va, vb = blocks[a], blocks[b]
        v = np.vstack([va, vb])
        res = 2.0 * np.tan(np.radians(0.01)) * np.linalg.norm(v.max(0) - v.min(0))   # the search's resolution
        if i == 4:                                                          # beyond reach: no contact
            assert gap[i] > reach[i] and types[i] == "none"
            continue
        best, bn = cpref.best_plane(va, vb)
        assert abs(np.linalg.norm(nn[i]) - 1.0) < 1e-12
        assert gap[i] == pytest.approx(cpref.gap(va, vb, nn[i]), abs=1e-12)  # the gap is that of its normal
        assert best - res <= gap[i] <= best + 1e-9                          # and the best there is
        hi_a, lo_b = (va @ nn[i]).max(), (vb @ nn[i]).min()
        assert cc[i] @ nn[i] == pytest.approx(0.5 * (hi_a + lo_b), abs=1e-9)  # midway (Eqs. 8-9)
        if i != 2:                      # a reach of 1e9 m makes every vertex "touch": no type to check
            assert types[i] == cpref.type_name(*cpref.touching(va, vb, bn, reach[i]))
    assert [round(x, 9) for x in gap[[0, 1, 3]]] == [g0, g0, -2e-4]
    assert types[:2] + types[3:4] == ["face-face", "edge-face", "face-face"]
    assert gap[2] == pytest.approx(cpref.best_plane(blocks[3], blocks[4])[0], abs=1e-6) and gap[2] > 1.0


def _run_steps_kernel(st, nsteps, dt, g, damping):
    """The kernel call, kept thin (bundles of the arrays of the state dict `st`, updated in place)."""
    from dec3d.kernels.bundles import Bodies, Bounds, Contacts, Groups, SubContacts

    G, B, C, S = st["groups"], st["blocks"], st["contacts"], st["sub"]
    nb = len(B["mass"])
    groups = Groups(G["gstart"], G["gmember"], G["gmass"], G["gimass"], G["giscalar"], G["gprin"], G["gaxes"],
                    G["gcentroid"])
    bodies = Bodies(B["mass"], B["fixity"], B["force"], B["moment"], B["fapp"], B["mapp"], B["vel"], B["spin"],
                    B["centroid"], B["disp"], B["vstart"], B["vcount"], st["verts"])
    contacts = Contacts(C["a"], C["b"], C["normal"], C["pos"], np.arange(len(C["a"]), dtype=np.int64), C["jmodel"],
                        C["prop"])
    subs = SubContacts(*(S[k] for k in SubContacts._fields))
    bounds = Bounds(np.ones(nb), np.zeros(nb), 1e9, np.zeros(2))
    return run_steps(nsteps, dt, g, False, damping, groups, bodies, contacts, subs, bounds, 1e6, st["out"])


def test_run_steps_against_the_cycle_written_from_the_equations(session):
    """40 steps of the many-steps kernel against tests/reference/cycle_ref.py (Eq. 15, the joint law,
    Eqs. 28-32, the group motion, Eq. 11 in plain Python), on a block overhanging another on a base.
    The joint law's properties are the deck's, written here, not read from the kernel's columns."""
    import copy
    import math

    from dec3d.kernels.bundles import new_damping, new_servo, servo_values
    from dec3d.physics.bodies import group_properties
    from reference.cycle_ref import step_ref

    m, e = _model(session, STACK)
    b, cs, ss = m.blocks, e.contacts, e.subcontacts
    gstart, gmember = e._groups()
    inertia = np.einsum("bij,bj,bkj->bik", b["principal_axes"], b["principal_moment"], b["principal_axes"])
    gm, gc, _, gp, ga, gi = group_properties(gstart, gmember, b["mass"], b["centroid"], inertia, b["inertia_approx"])
    st0 = {"groups": dict(gstart=gstart, gmember=gmember, gmass=gm, gimass=gm.copy(), giscalar=gi, gprin=gp,
                          gaxes=ga, gcentroid=gc),
           "blocks": dict(mass=b["mass"], fixity=b["fixity"], force=b["force"], moment=b["moment"], fapp=b["fapp"],
                          mapp=b["mapp"], vel=b["velocity"], spin=b["spin"], centroid=b["centroid"], disp=b["disp"],
                          vstart=b["vert_start"], vcount=b["vert_count"]),
           "verts": m.vertices["pos"], "out": np.zeros(4),
           "contacts": dict(a=cs["a"], b=cs["b"], normal=cs["normal"], pos=cs["pos"], jmodel=cs["jmodel"],
                            prop=cs["prop"]),
           "sub": {k: ss[k] for k in ("contact", "pos", "area", "fn", "fs", "un", "udil", "us", "state", "hist", "ppf")}}
    st0 = copy.deepcopy(st0)                      # plain copies of every array
    fast, slow = copy.deepcopy(st0), copy.deepcopy(st0)
    g, dt, n = np.array([0.0, 0.0, -10.0]), e.timestep(), 40
    assert _run_steps_kernel(fast, n, dt, g, new_damping(1, 0.8, len(gm))) == (n, -1)

    phi = math.radians(30.0)                      # the deck: mohr, kn = ks = 1e8 Pa/m, friction 30°
    law = [("mohr", dict(kn=1e8, ks=1e8, phi=phi, coh=0.0, ten=0.0, dil=0.0, zdil=0.0, phir=phi, cohr=0.0,
                         tenr=0.0))] * len(cs["a"])
    servo = np.concatenate([servo_values(new_servo()), np.zeros(6 * len(gm))])     # the twin's flat layout
    for _ in range(n):
        assert step_ref(dt, g, 1, 0.8, servo, False, slow["groups"], slow["blocks"], slow["verts"],
                        slow["contacts"], law, slow["sub"], 1e6, slow["out"]) == -1

    def close(x, y, what):
        x, y = np.asarray(x, float), np.asarray(y, float)
        np.testing.assert_allclose(x, y, rtol=1e-9, atol=1e-9 * (1e-12 + np.abs(y).max()), err_msg=what)

    for part in ("blocks", "sub"):
        for k in ("vel", "spin", "centroid", "disp") if part == "blocks" else ("pos", "fn", "fs", "un", "us"):
            close(fast[part][k], slow[part][k], f"{part}.{k}")
    close(fast["sub"]["state"] & 1, slow["sub"]["state"], "sub.state (failed)")
    close(fast["verts"], slow["verts"], "vertices")
    close(fast["contacts"]["pos"], slow["contacts"]["pos"], "contact points")
    assert np.abs(slow["blocks"]["disp"]).max() > 1e-6          # the blocks moved
    assert (slow["sub"]["fn"] > 0).sum() >= 8                    # the joints carry load


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
