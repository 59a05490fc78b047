"""Joined FE blocks (`block join`) are one body, as joined zoned blocks: coincident nodes linked
(``zone_mesh.relink``, also when the blocks are joined before `feblock generate`), no contact
force between them (``contacts.joined_zoned_inert``), interface faces not loadable, and what
slave nodes pass on (Eq. 9) reaches the link masters."""
import io

import numpy as np
import pytest

from dec3d.session import Session

SETUP = """model configure feblock
{blocks}
{before}
feblock generate 0.5 0.5 0.5
{after}
feblock change cmodel elastic young 1e7 poisson 0.25 density 2000
block contact jmodel assign elastic
block contact material-table default property stiffness-normal 1e8 stiffness-shear 1e8
"""
LOAD = """model gravity 0 0 -10
block gridpoint apply velocity 0 0 0 range position-z 0
block gridpoint apply velocity-x 0 range position-x 0
block gridpoint apply velocity-y 0 range position-y 0
block face apply stress 0 0 -1e5 2e4 0 0 range position-z 2
model large-strain off
model solve ratio 1e-8"""
TWO = "block create brick 0 1 0 1 0 1\nblock create brick 0 1 0 1 1 2"
ONE = "block create brick 0 1 0 1 0 2"


def _session(tmp_path, blocks, when=None):
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command(SETUP.format(blocks=blocks, before="block join" if when == "before" else "",
                           after="block join" if when == "after" else ""))
    return s


def _masters(m):
    """Displacements of the master nodes by position (one row per distinct position) and the
    element stresses ordered by element centroid."""
    v, es = m.vertices, m.store("feblocks")
    r = np.flatnonzero(~v["feslave"] & (v["link"] < 0))
    key = np.lexsort(np.round(v["pos"][r], 9).T[::-1])
    c = np.round(es["centroid"], 9)
    order = np.lexsort(c.T[::-1])
    return np.round(v["pos"][r[key]], 9), v["disp"][r[key]], es["stress"][order]


@pytest.mark.parametrize("when", ["before", "after"])
def test_two_joined_fe_blocks_behave_as_one_block(tmp_path, when):
    """Two 1 m FE cubes joined (before or after `feblock generate`) under gravity and a top face
    stress, with a stiff elastic joint model in force: node displacements and element stresses
    those of one 1 x 1 x 2 m FE block of the same elements within 1 % (of the largest), and no
    sub-contact between them. Unjoined with the join made before meshing, the nodes were not
    linked and the pair settled 6 % more than the one block."""
    one = _session(tmp_path, ONE)
    one.command(LOAD)
    two = _session(tmp_path, TWO, when)
    two.command(LOAD)
    p1, u1, s1 = _masters(one.model)
    p2, u2, s2 = _masters(two.model)
    assert np.array_equal(p1, p2) and len(s1) == len(s2) == 16
    assert np.abs(u2 - u1).max() < 0.01 * np.abs(u1).max()
    assert np.abs(s2 - s1).max() < 0.01 * np.abs(s1).max()
    ss = two.model.store("subcontacts") if "subcontacts" in two.model.stores else None
    assert ss is None or ss.n == 0
    assert (two.model.vertices["link"] >= 0).sum() == 21      # the 21 master nodes of the interface


def test_interface_of_joined_fe_blocks_takes_no_face_stress(tmp_path):
    """The faces between two joined FE blocks are inside the body: `block face apply stress` on
    the plane z = 1 loads nothing there (unjoined, both blocks' faces take it)."""
    from dec3d.model.face_loads import apply_face_stress

    for when, expect in ((None, 2 * 4 * 8), ("after", 0)):
        s = _session(tmp_path, TWO, when)
        m = s.model
        f = m.faces
        ctr = np.array([m.vertices["pos"][m.face_vertices["vertex"][f["vstart"][k] + np.arange(3)]].mean(axis=0)
                        for k in range(f.n)])
        assert apply_face_stress(m, np.abs(ctr[:, 2] - 1) < 1e-9, np.array([0, 0, -1e5, 0, 0, 0.0])) == expect


def test_slave_forces_reach_the_link_masters(tmp_path):
    """A force put on a slave node of the upper block's side face next to the interface goes to
    the element's masters by Eq. (9), the linked ones' share to their link masters: after the
    step's sums the force and its moment are kept on unlinked rows and nothing is left on
    linked or slave rows."""
    from dec3d.physics.feblocks import FeStepper

    s = _session(tmp_path, TWO, "before")
    m = s.model
    v = m.vertices
    fe = FeStepper(m, RuntimeError)
    # slave at the centre of the side face x = 1 of an upper-block element touching z = 1
    sl = np.flatnonzero(v["feslave"] & (np.abs(v["pos"][:, 0] - 1) < 1e-9) & (np.abs(v["pos"][:, 2] - 1.25) < 1e-9)
                        & (np.abs(v["pos"][:, 1] - 0.25) < 1e-9))
    assert len(sl) == 1
    p = np.array([3.0, -2.0, 5.0])
    facc = np.zeros((v.n, 3))
    facc[sl[0]] = p
    fe.slave_forces(facc)
    lk = v["link"] >= 0
    assert not facc[lk].any() and not facc[v["feslave"]].any()
    assert np.allclose(facc.sum(axis=0), p, atol=1e-12)
    mom = np.cross(v["pos"], facc).sum(axis=0)
    assert np.allclose(mom, np.cross(v["pos"][sl[0]], p), atol=1e-12)
    # the element's nodes at z = 1 are linked (rows of the upper block): their share went over
    assert np.abs(facc[np.abs(v["pos"][:, 2] - 1) < 1e-9]).sum() > 0.1 * np.abs(p).sum()


def test_joined_fe_blocks_link_nodes_that_differ_by_round_off(tmp_path):
    """FE blocks are meshed one by one: nodes on a shared face can differ by round-off (the upper
    block's moved by 4e-16 m here), and are still one node when the blocks are joined (all 21
    masters of the 2 x 2 element face linked). Left unlinked, a joined ring of FE liner blocks
    (examples/feblock/tunnel_liner.dat) whose joint at theta = 0 had 1e-15 m of round-off was cut
    open there, the contacts of joined blocks carrying nothing."""
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command("""model configure feblock
block create brick 0 1 0 1 0 0.3
block create brick 0 1 0 1 0.3 1
feblock generate 0.5 0.5 0.15""")
    v = s.model.vertices
    up = v["block"] == 1
    v["pos"][up, 2] += 4e-16
    z = v["pos"][:, 2]
    near = (np.abs(z - 0.3) < 1e-12) & ~v["feslave"]
    assert len(np.unique(z[near])) > 1 and near.sum() == 42
    s.command("block join")
    assert (v["link"] >= 0).sum() == 21 and (v["link"][near] >= 0).sum() == 21
