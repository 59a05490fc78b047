"""Contact detection on several threads (``physics.contacts._subcontacts`` in chunks,
``contactmap.gather_subcontacts`` in pieces, ``contacts.in_threads``) and the store's
``blank``/``install``: the same rows, bit for bit, as one serial pass, whatever the thread count."""
import io
import threading

import numpy as np
import pytest

from dec3d import config
from dec3d.geometry.cutting import cut_by_planes
from dec3d.kernels import contactmap
from dec3d.kernels.contactmap import gather_subcontacts
from dec3d.model.store import Field, Store
from dec3d.physics import contacts as detection
from dec3d.physics.contacts import in_threads
from dec3d.session import Session

TWO = pytest.mark.skipif(config.max_threads() < 2, reason="numba may use only one thread here")

PROPS = ["block property density 2600", "block fix range position-z -1 0", "block contact jmodel assign mohr",
         "block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 friction 30",
         "model gravity 0 0 -9.81"]


@pytest.fixture
def restore_threads():
    n = config.threads()
    yield
    config.set_threads(n)


def _stack(n):
    lines = ["model new", f"block create brick 0 {n} 0 {n} -1 0"] + [
        f"block create brick {i} {i + 1} {j} {j + 1} {k} {k + 1}" for i in range(n) for j in range(n) for k in range(n)]
    s = Session(stdout=io.StringIO())
    s.command("\n".join(lines + PROPS + ["model cycle 1"]) + "\n")
    return s.model


def _cut_model(seed):
    """A 4 x 4 x 2 box cut by ten random planes into many convex pieces, all in contact (faces,
    edges and corners of odd shapes), on a fixed base."""
    rng = np.random.default_rng(seed)
    s = Session(stdout=io.StringIO())
    s.command("model new\nblock create brick -1 5 -1 5 -1 0\nblock create brick 0 4 0 4 0 2\n")
    for _ in range(10):
        m = rng.normal(size=3)
        m /= np.linalg.norm(m)
        cut_by_planes(s.model, m, [float(m @ rng.uniform((0.3, 0.3, 0.2), (3.7, 3.7, 1.8)))])
    s.command("\n".join(PROPS + ["model cycle 1"]) + "\n")
    return s.model


def _inputs(model):
    """The geometry and the detected contacts, as ``_subcontacts`` takes them."""
    cs = model.store("contacts")
    return (model.vertices["pos"], model.blocks, model.faces, model.face_vertices, cs["a"].copy(), cs["b"].copy(),
            cs["normal"].copy(), cs["pos"].copy(), 1e-3, 0.01)


@pytest.mark.parametrize("case", ["stack6", "stack10", "cut0", "cut1"])
def test_chunked_subcontacts_equal_one_pass(case, monkeypatch):
    """Sub-contacts found chunk by chunk on 2, 3 and 5 threads, joined in chunk order, against one
    pass of the kernel over every contact: every array equal, row for row."""
    model = _stack(int(case[5:])) if case.startswith("stack") else _cut_model(int(case[3:]))
    args = _inputs(model)
    one = detection._subcontacts_chunk(*args)
    nc = len(args[4])
    assert len(one[0]) > 2 * nc and np.all(np.diff(one[0]) >= 0)
    if case.startswith("cut"):
        monkeypatch.setattr(contactmap, "PARALLEL_FROM", 1)      # a few hundred contacts only
        assert len(np.unique(one[1])) >= 3                      # vertex-face, edge-edge, points
    monkeypatch.setattr(detection, "CHUNK_MIN", 7)              # many chunks, of uneven sizes
    for nt in (2, 3, 5):
        got = detection._subcontacts(*args, nthreads=nt)
        for a, b in zip(one, got):
            assert a.dtype == b.dtype and a.shape == b.shape
            np.testing.assert_array_equal(a, b)


def _gather_ref(base, starts, counts, nold, old, new):
    """Plain twin of ``gather_subcontacts``: row by row, contact by contact, in Python."""
    total = int(sum(counts))
    names = ("kind", "key0", "key1", "pos", "area", "fn", "fs", "un", "udil", "us", "state", "hist")
    out = {"contact": [None] * total}
    out.update({k: [None] * total for k in names})
    for c in range(len(counts)):
        for j in range(int(counts[c])):
            row = int(starts[c]) + j
            src = int(base[c]) + j
            out["contact"][row] = c
            for i, k in enumerate(names):
                if src < nold:
                    out[k][row] = old[i][src]
                elif k == "fn":
                    out[k][row] = 0.0
                else:
                    out[k][row] = new[i if i < 5 else i - 1][src - nold]
    return {k: np.array(v) for k, v in out.items()}


def _gather_case(seed):
    rng = np.random.default_rng(seed)
    nold, nnew, nc = 40, 30, 25

    def rows(n, fn=True):
        r = [rng.integers(0, 4, n), rng.integers(-5, 99, n), rng.integers(-5, 99, n), rng.normal(size=(n, 3)),
             rng.uniform(0, 1, n), rng.normal(size=n), rng.normal(size=(n, 3)), rng.normal(size=n),
             rng.normal(size=n), rng.normal(size=(n, 3)), rng.integers(0, 8, n), rng.normal(size=(n, 8))]
        return tuple(r if fn else r[:5] + r[6:])

    old, new = rows(nold), rows(nnew, fn=False)
    counts = rng.integers(0, 4, nc)
    # each contact's rows from a random run of old rows or of new ones
    base = np.where(rng.uniform(size=nc) < 0.5, rng.integers(0, nold - 4, nc), nold + rng.integers(0, nnew - 4, nc))
    starts = np.cumsum(counts) - counts
    return base, starts, counts, nold, old, new


@pytest.mark.parametrize("seed", range(3))
def test_gather_subcontacts_kernel_against_its_twin(seed):
    base, starts, counts, nold, old, new = _gather_case(seed)
    want = _gather_ref(base, starts, counts, nold, old, new)
    total = int(counts.sum())
    shapes = {"pos": 3, "fs": 3, "us": 3, "hist": 8}
    ints = {"contact", "kind", "key0", "key1", "state"}
    names = ("contact", "kind", "key0", "key1", "pos", "area", "fn", "fs", "un", "udil", "us", "state", "hist")
    for cuts in ([0, 25], [0, 3, 11, 25], [0, 0, 24, 25]):     # in one piece, in three, with an empty one
        out = tuple(np.full((total, shapes[k]) if k in shapes else total, -9, np.int64 if k in ints else float)
                    for k in names)
        for lo, hi in zip(cuts[:-1], cuts[1:]):
            gather_subcontacts(lo, hi, base, starts, counts, nold, old, new, out)
        for k, a in zip(names, out):
            np.testing.assert_array_equal(a, want[k], err_msg=k)


def test_in_threads_does_every_item_once_and_raises_the_first_error():
    seen = []
    lock = threading.Lock()

    def work(j):
        with lock:
            seen.append(j)
    in_threads(work, 37, 3)
    assert sorted(seen) == list(range(37))
    in_threads(work, 0, 4)                       # nothing to do
    assert len(seen) == 37

    def bad(j):
        if j == 5:
            raise ValueError("item 5")
    with pytest.raises(ValueError, match="item 5"):
        in_threads(bad, 9, 2)


def test_store_blank_and_install_are_clear_then_append_without_the_fill():
    fields = {"a": Field((), np.int64, -1), "p": Field((3,), float, 0.5), "g": Field((2,), np.int64, -2)}
    s, ref = Store("s", fields, capacity=4), Store("s", fields, capacity=4)
    for st in (s, ref):
        st.append(3)
        st["g"][...] = 7
    for n in (3, 9, 5, 5, 2):                     # grows to 16 rows, then reuses the replaced arrays
        new = s.blank(n, ("a", "p"))
        new["a"][:n] = np.arange(n) * 10
        new["p"][:n] = np.arange(3 * n).reshape(n, 3)
        s.install(n, new)
        ref.clear()
        ref.append(n)
        ref["a"][...] = np.arange(n) * 10
        ref["p"][...] = np.arange(3 * n).reshape(n, 3)
        assert s.n == ref.n == n and s.capacity == ref.capacity
        for k in fields:                          # spare rows hold the fill value too
            np.testing.assert_array_equal(s.full(k), ref.full(k), err_msg=k)
    new = s.blank(2, ("g",))
    new["g"][:2] = 3
    s.install(2, new)                             # the replaced (16, 2) array kept for the next blank
    s.resize_field("g", (3,))                     # (a group slot more): no array of the old shape handed out
    new = s.blank(2, ("g",))
    assert new["g"].shape == (s.capacity, 3)
    new["g"][:2] = 4
    s.install(2, new)
    np.testing.assert_array_equal(s["g"], 4)
    wrong = {"a": np.zeros(3, np.int64)}
    with pytest.raises(ValueError, match="field 'a' needs shape"):
        s.install(2, wrong)


@TWO
def test_a_detection_on_two_threads_installs_the_rows_of_one(monkeypatch, restore_threads):
    """The 6 x 6 x 6 stack cycled 60 steps sliding on its base (set off at 0.5 m/s along x):
    detections with old (kept: the stack's blocks move together) and new (the
    base contacts) sub-contacts to gather; on one thread and on two with every chunk and piece
    small: every contact and sub-contact array and every vertex equal bit for bit."""
    states = []
    for threads in (1, 2):
        config.set_threads(threads)
        if threads == 2:
            monkeypatch.setattr(detection, "CHUNK_MIN", 16)
            monkeypatch.setattr(contactmap, "PARALLEL_FROM", 1)       # (the stack has ~2000 contacts)
        s = Session(stdout=io.StringIO())
        lines = ["model new", "block create brick 0 6 0 6 -1 0"] + [
            f"block create brick {i} {i + 1} {j} {j + 1} {k} {k + 1}"
            for i in range(6) for j in range(6) for k in range(6)]
        s.command("\n".join(lines + PROPS + ["block initialize velocity-x 0.5 range position-z 0 6", "model cycle 60"]) + "\n")
        m = s.model
        out = {"pos": np.array(m.vertices["pos"])}
        for st in ("contacts", "subcontacts"):
            out.update({f"{st}/{k}": np.array(m.store(st)[k]) for k in m.store(st).fields})
        assert m.rigid_engine.detections >= 2
        states.append(out)
    assert len(states[0]["subcontacts/area"]) > 2 * len(states[0]["contacts/a"]) > 1000
    assert [k for k in states[0] if not np.array_equal(states[0][k], states[1][k], equal_nan=True)] == []


def test_subcontact_gaps_by_runs_of_a_contact_equal_each_row_alone():
    """``subcontact_gaps`` works a contact's face planes out once for its run of sub-contacts: on
    the cut model's sub-contacts, in contact order and shuffled (runs of one), each gap equals the
    kernel's on that row alone, bit for bit (the gaps against an independent twin:
    ``test_contact_fixes.test_subcontact_gaps_against_hull_twin``)."""
    from dec3d.kernels.contactmap import subcontact_gaps
    model = _cut_model(2)
    cs, ss = model.store("contacts"), model.store("subcontacts")
    b, f = model.blocks, model.faces
    geo = (b["centroid"], model.vertices["pos"], b["face_start"], b["face_count"], f["vstart"], f["nvert"],
           model.face_vertices["vertex"])
    con = (cs["a"], cs["b"], cs["normal"], cs["gap"])
    sc, pos = ss["contact"].copy(), ss["pos"].copy()
    ns = len(sc)
    assert ns > 50 and len(np.unique(sc)) > 20
    together = np.empty(ns)
    subcontact_gaps(sc, pos, *con, *geo, together)
    alone = np.empty(ns)
    for s in range(ns):
        one = np.empty(1)
        subcontact_gaps(sc[s:s + 1], pos[s:s + 1], *con, *geo, one)
        alone[s] = one[0]
    np.testing.assert_array_equal(together, alone)
    perm = np.random.default_rng(0).permutation(ns)
    shuffled = np.empty(ns)
    subcontact_gaps(sc[perm], pos[perm], *con, *geo, shuffled)
    np.testing.assert_array_equal(shuffled, together[perm])
    assert np.median(np.abs(together)) < 1e-9        # pieces cut from one box: most points touch
