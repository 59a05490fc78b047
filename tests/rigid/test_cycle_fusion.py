"""The fused passes of the cycle kernel (kernels/cycle.py: two parallel loops per step instead of
six): each gives bit for bit what the separate passes give, at one and at two threads, and the
lists they run on are checked against plain-python twins."""
import copy
import io

import numpy as np
import pytest

from dec3d import config
from dec3d.kernels.joints import cycle_mask
from dec3d.kernels import cycle
from dec3d.kernels.bundles import Bodies, Fused, Groups, new_damping
from dec3d.kernels.jointlaw import block_lists, block_sums, subcontact_update
from dec3d.kernels.motion import rigid_motion_groups

#: a 2 x 2 x 2 stack of unit cubes on a fixed base, the top layer joined, sliding sideways
DECK = ["model new", "block create brick 0 2 0 2 -1 0"] + [
    f"block create brick {i} {i + 1} {j} {j + 1} {k} {k + 1}" for i in range(2) for j in range(2) for k in range(2)
] + ["block property density 2600", "block fix range position-z -1 0", "block join on range position-z 1 2",
     "block contact jmodel assign mohr",
     "block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 friction 20 "
     "cohesion 0 tension 0",
     "model gravity 3 1 -9.81", "block mechanical damping none", "model cycle 30"]


@pytest.fixture
def restore_threads():
    n = config.threads()
    yield
    config.set_threads(n)


def _threads(n):
    if n > config.max_threads():
        pytest.skip("numba may use only one thread here")
    config.set_threads(n)


@pytest.fixture(scope="module")
def state(tmp_path_factory):
    """The arrays of the stack after 30 steps (moving: the blocks slide)."""
    from dec3d.session import Session

    s = Session(out_dir=tmp_path_factory.mktemp("fusion"), stdout=io.StringIO())
    s.command("\n".join(DECK) + "\n")
    m, e = s.model, s.model.rigid_engine
    b, cs, ss = m.blocks, e.contacts, e.subcontacts
    gstart, gmember = e._groups()
    ng = len(gstart) - 1
    rng = np.random.default_rng(5)
    st = {"b": {k: np.array(b[k]) for k in ("mass", "fixity", "force", "moment", "fapp", "mapp", "velocity", "spin",
                                             "centroid", "disp", "vert_start", "vert_count")},
          "vpos": np.array(m.vertices["pos"]),
          "c": {k: np.array(cs[k]) for k in ("a", "b", "normal", "pos", "jmodel", "prop")},
          "s": {k: np.array(ss[k]) for k in ("contact", "pos", "area", "fn", "fs", "un", "udil", "us", "state", "hist", "ppf")},
          "g": dict(start=gstart, member=gmember, mass=rng.uniform(2e3, 3e3, ng), imass=rng.uniform(3e3, 4e3, ng),
                    iscalar=rng.uniform(500, 900, ng), prin=rng.uniform(400, 500, (ng, 3)),
                    axes=np.repeat(np.eye(3)[None], ng, axis=0), centroid=np.zeros((ng, 3))),
          "dt": 1e-4}
    bc = st["b"]["centroid"]
    for g in range(ng):
        st["g"]["centroid"][g] = bc[gmember[gstart[g]:gstart[g + 1]]].mean(axis=0)
    st["b"]["fixity"] = st["b"]["fixity"].astype(np.uint8)
    assert len(st["s"]["contact"]) > 20 and (np.diff(gstart) > 1).any()        # joined groups and contacts
    assert np.abs(st["b"]["velocity"]).max() > 1e-4                             # moving
    return st


def _bodies(st):
    b = st["b"]
    return Bodies(b["mass"], b["fixity"], b["force"], b["moment"], b["fapp"], b["mapp"], b["velocity"], b["spin"],
                  b["centroid"], b["disp"], b["vert_start"], b["vert_count"], st["vpos"])


def _groups(st):
    return Groups(*(st["g"][k] for k in Groups._fields))


def _same(x, y):
    """Every array of the nested dicts x and y equal bit for bit (the names of those that differ)."""
    out = []
    for k in x:
        if isinstance(x[k], dict):
            out += [f"{k}.{n}" for n in _same(x[k], y[k])]
        elif isinstance(x[k], np.ndarray) and not np.array_equal(x[k], y[k], equal_nan=x[k].dtype.kind == "f"):
            out.append(k)
    return out


# ------------------------------------------------------------------ the lists
def _ranges_twin(nc, owner):
    """Plain python: the first row of each contact's sub-contacts, and one past the last."""
    start = [0] * (nc + 1)
    for c in range(nc):
        rows = [s for s in range(len(owner)) if owner[s] == c]
        start[c + 1] = start[c] + len(rows)
        if rows:
            assert rows == list(range(start[c], start[c + 1]))
    return start


def test_contact_ranges_against_a_twin():
    rng = np.random.default_rng(11)
    for nc in (0, 1, 7, 60):
        owner = np.sort(rng.integers(0, nc, 3 * nc)) if nc else np.zeros(0, np.int64)
        # contacts without sub-contacts, also at both ends
        owner = owner[(owner != 0) & (owner != nc - 1) & (owner != nc // 2)]
        got = cycle.contact_ranges(nc, owner)
        assert list(got) == _ranges_twin(nc, owner)
        assert got[-1] == len(owner)


@pytest.mark.parametrize("owner", [[0, 2, 1], [3], [0, 0, -1]])
def test_contact_ranges_refuse_rows_out_of_contact_order(owner):
    with pytest.raises(ValueError, match="not grouped by contact"):
        cycle.contact_ranges(3, np.array(owner, np.int64))


def test_cycle_lists_name_the_blocks_with_sub_contacts_in_no_group(state):
    from dec3d.kernels.bundles import Contacts, SubContacts

    c, s = state["c"], state["s"]
    contacts = Contacts(c["a"], c["b"], c["normal"], c["pos"], np.arange(len(c["a"])), c["jmodel"], c["prop"])
    subs = SubContacts(*(s[k] for k in SubContacts._fields))
    nb = len(state["b"]["mass"])
    member = state["g"]["member"]
    _, _, _, none, _, _ = cycle.cycle_lists(nb, contacts, subs, member)
    assert len(none) == 0
    # a group of blocks that leaves out the base (row 0, touched by four contacts) and one cube
    _, _, _, orphans, _, _ = cycle.cycle_lists(nb, contacts, subs, member[(member != 0) & (member != 3)])
    assert list(orphans) == [0, 3]


# ------------------------------------------------------------------ the passes, fused = separate
@pytest.mark.parametrize("threads", [1, 2])
def test_contact_pass_equals_moving_the_points_then_the_joint_law(state, threads, restore_threads):
    _threads(threads)
    st = state
    sep, fus = copy.deepcopy(st), copy.deepcopy(st)
    dt = st["dt"]
    b = sep["b"]
    c, s = sep["c"], sep["s"]
    sg = np.empty((len(s["contact"]), 3))
    own = np.arange(len(c["a"]))
    cycle._move_points(dt, c["a"], c["b"], own, c["pos"], b["centroid"], b["velocity"], b["spin"])
    cycle._move_points(dt, c["a"], c["b"], s["contact"], s["pos"], b["centroid"], b["velocity"], b["spin"])
    subcontact_update(cycle_mask(c["jmodel"]), dt, b["centroid"], b["velocity"], b["spin"], c["a"], c["b"], c["normal"],
                      c["jmodel"],
                      c["prop"], s["contact"], s["pos"], s["area"], s["fn"], s["fs"], s["un"], s["udil"], s["us"],
                      s["state"], s["hist"], sg)
    b, c, s = fus["b"], fus["c"], fus["s"]
    sg2 = np.empty_like(sg)
    cstart = cycle.contact_ranges(len(c["a"]), s["contact"])
    kernel = cycle._contact_pass if threads > 1 else cycle._run_steps_1.py_func.__globals__["_contact_pass"]
    kernel(cycle_mask(c["jmodel"]), True, dt, b["centroid"], b["velocity"], b["spin"], c["a"], c["b"], c["normal"], c["pos"], c["jmodel"],
           c["prop"], cstart, s["pos"], s["area"], s["fn"], s["fs"], s["un"], s["udil"], s["us"], s["state"], s["hist"],
           sg2)
    assert _same(sep, fus) == [] and np.array_equal(sg, sg2)
    assert not np.array_equal(sep["s"]["pos"], st["s"]["pos"])          # the points did move
    assert (sep["s"]["fn"] > 0).sum() >= 8                               # and carry load


@pytest.mark.parametrize("threads", [1, 2])
def test_motion_with_the_block_sums_inside_equals_the_separate_passes(state, threads, restore_threads):
    _threads(threads)
    st = state
    rng = np.random.default_rng(2)
    ns = len(st["s"]["contact"])
    sg = rng.normal(size=(ns, 3)) * 1e4                 # some sub-contact forces
    c = st["c"]
    bstart, bent = block_lists(len(st["b"]["mass"]), c["a"], c["b"], st["s"]["contact"])
    radius = rng.uniform(0.8, 0.9, len(st["b"]["mass"]))
    g = np.array([3.0, 1.0, -9.81])
    sep, fus = copy.deepcopy(st), copy.deepcopy(st)
    out1, out2 = np.zeros(4), np.zeros(4)
    b = sep["b"]
    block_sums(b["centroid"], b["force"], b["moment"], sep["s"]["pos"], sg, bstart, bent)
    bad1 = rigid_motion_groups(st["dt"], g, True, new_damping(2, 0.7, len(st["g"]["mass"])), _groups(sep),
                               _bodies(sep), 1e6, out1)
    member = sep["g"]["member"]
    v, w = b["velocity"][member], b["spin"][member]
    step1 = st["dt"] * (np.sqrt((v ** 2).sum(1)) + radius[member] * np.sqrt((w ** 2).sum(1)))
    step2 = np.full(len(radius), -1.0)
    fused = Fused(bstart, bent, fus["s"]["pos"], sg, radius, step2)
    bad2 = rigid_motion_groups(st["dt"], g, True, new_damping(2, 0.7, len(st["g"]["mass"])), _groups(fus),
                               _bodies(fus), 1e6, out2, fused)
    assert bad1 == bad2 == -1 and np.array_equal(out1, out2)
    assert _same(sep, fus) == []
    # the step motion of every member (the formula of the batch's detection trigger), summed in numpy
    assert np.allclose(step2[member], step1, rtol=1e-14, atol=0.0)
    assert (fus["b"]["force"] == 0).all() and (fus["b"]["moment"] == 0).all()      # cleared for the next step
    assert not np.array_equal(fus["b"]["velocity"], st["b"]["velocity"])


@pytest.mark.parametrize("threads", [1, 2])
def test_a_batch_split_anywhere_takes_the_same_steps(state, threads, restore_threads, monkeypatch):
    """The points of a step move at the start of the next step's pass, and once more at the end of
    a kernel call: one call of 12 steps and calls of 5 + 1 + 6 steps end with the same bits."""
    from dec3d.kernels.bundles import Bounds, Contacts, SubContacts

    _threads(threads)
    monkeypatch.setattr(cycle, "SERIAL_BELOW", 0)

    def run(st, parts):
        b, c, s = st["b"], st["c"], st["s"]
        contacts = Contacts(c["a"], c["b"], c["normal"], c["pos"], np.arange(len(c["a"])), c["jmodel"], c["prop"])
        subs = SubContacts(*(s[k] for k in SubContacts._fields))
        bounds = Bounds(np.ones(len(b["mass"])), np.zeros(len(b["mass"])), 1e9, np.zeros(2))
        damping = new_damping(0, 0.0, len(st["g"]["mass"]))
        for k in parts:
            assert cycle.run_steps(k, st["dt"], np.array([3.0, 1.0, -9.81]), True, damping, _groups(st), _bodies(st),
                                   contacts, subs, bounds, 1e6, np.zeros(4)) == (k, -1)
        return st

    one = run(copy.deepcopy(state), [12])
    split = run(copy.deepcopy(state), [5, 1, 6])
    assert _same(one, split) == []
    assert not np.array_equal(one["s"]["pos"], state["s"]["pos"])


# ------------------------------------------------------------------ the serial part of a run
def test_a_detection_with_nothing_to_look_at_keeps_the_rows_and_takes_new_defaults(tmp_path, monkeypatch):
    """A quiet model's first detection of a run (nothing moved, every contact kept) only makes the
    contacts that follow the defaults take them: the same arrays as the full install, which the
    second model is forced through."""
    from dec3d.physics.contacts import ContactDetection
    from dec3d.session import Session

    deck = "\n".join(DECK[:-3] + ["model gravity 0 0 -9.81", "block mechanical damping local 0.8", "model cycle 5",
                                  "block contact material-table default property friction 33",
                                  "model cycle 12"]) + "\n"
    states = []
    for fast in (True, False):
        if not fast:
            monkeypatch.setattr(ContactDetection, "_as_they_are", lambda *a: False)
        s = Session(out_dir=tmp_path, stdout=io.StringIO())
        s.command(deck)
        e = s.model.rigid_engine
        states.append(({k: np.array(a) for k, a in e.contacts.to_arrays().items()},
                       {k: np.array(a) for k, a in e.subcontacts.to_arrays().items()},
                       np.array(s.model.blocks["velocity"]), e.detections))
    (c1, s1, v1, n1), (c2, s2, v2, n2) = states
    assert _same(c1, c2) == [] and _same(s1, s2) == [] and np.array_equal(v1, v2)
    assert n1 < n2                                  # the first model left the rows as they were
    from dec3d.kernels.joints.mohr import P_TANF

    assert np.allclose(c1["prop"][:, P_TANF], np.tan(np.radians(33.0)), rtol=1e-12)      # the new default
