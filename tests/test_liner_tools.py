"""Liner tools: FISH `struct.liner.*` coupling state, `structure liner recover surface|resultants` with
FISH `struct.shell.resultant`/`struct.node.resultant`, `structure liner group`, `structure liner delete`
(save/restore, the hosts' loads, histories), all against values worked out by hand."""
from __future__ import annotations

import io

import numpy as np
import pytest

from dec3d.errors import Dec3dError
from dec3d.session import Session


def _run(text, tmp_path, s=None, out=None):
    s = s or Session(out_dir=tmp_path, stdout=out or io.StringIO())
    s.run_items(s.load_text(text))
    return s


def _g(s, name):
    return s.fish_rt.globals[name]


PULL = """model new
block create brick 0 1 0 1 0 1
block property density 1000
block fix
structure liner create by-block-face range position-z 1
structure liner property isotropic 30e9 0.2 thickness 0.1 coupling-stiffness-normal 1e9 coupling-stiffness-shear 1e9 coupling-yield-normal 2e5 coupling-cohesion-shear 1e5
"""


def test_fish_coupling_state_of_a_pulled_liner(tmp_path):
    """A liner on a fixed block's top pulled up by σ = 0.9e5 Pa (node forces σ × tributary area) and
    sheared along +x by τ = 0.5e5 Pa: each normal spring opens by σ / k_n (separation positive), its
    normal is +z, and the shear spring pulls the liner back along −x."""
    from dec3d.model.liners import node_areas

    s = _run(PULL, tmp_path)
    nodes = s.model.stores["liner_nodes"]
    a = node_areas(s.model)
    nodes["fapp"][:, 2] = 0.9e5 * a
    nodes["fapp"][:, 0] = 0.5e5 * a
    _run("model cycle 3000\n"
         "[d = struct.liner.normal.disp(2, 3)]\n[d1 = struct.liner.normal.disp(2, 3, 1)]\n"
         "[n = struct.liner.normal.dir(1, 1)]\n[t = struct.liner.shear.dir(4, 2)]\n", tmp_path, s)
    assert _g(s, "d") == pytest.approx(0.9e5 / 1e9, rel=1e-3) and _g(s, "d1") == _g(s, "d")
    n, t = _g(s, "n"), _g(s, "t")
    assert (n.x, n.y, n.z) == pytest.approx((0.0, 0.0, 1.0), abs=1e-12)
    assert (t.x, t.y, t.z) == pytest.approx((-1.0, 0.0, 0.0), abs=1e-6)
    for line, what in (("[x = struct.liner.normal.disp(99, 1)]", "no liner element with id 99"),
                       ("[x = struct.liner.normal.disp(1, 4)]", "1, 2 or 3"),
                       ("[x = struct.liner.normal.disp(1, 1, 2)]", "one-sided"),
                       ("[x = struct.liner.shear.dir(1.5, 1)]", "liner element id")):
        with pytest.raises(Dec3dError, match=what):
            _run(line + "\n", tmp_path, s)


STRIP = """model new
block create brick 20 21 0 1 0 1
block property density 1000
block fix
structure liner create by-quadrilateral 0 0 0 1 0 0 1 0.25 0 0 0.25 0 size 4 1
structure liner property isotropic 200e9 0 thickness 0.01
structure node fix velocity rotation range position-x 0
structure node apply force-z -10 force-x 10 range position-x 1
model solve ratio 1e-7
"""


def test_recovered_resultants_of_a_cantilever_strip(tmp_path):
    """A strip 1 m × 0.25 m clamped at x = 0, a tip load of 20 N down and 20 N along x (on its two end
    nodes), ν = 0: per unit width M_x = P (L − x) / b (80 N·m/m at the root), Q_x = −P / b = −80 N/m,
    N_x = 80 N/m everywhere (the CST is exact there), N_y = N_xy = 0, M_y and M_xy small. Seen with the surface x
    along global y instead (y_s = z × x_s = −X), M_y takes M_x's values and Q_y = +80."""
    s = _run(STRIP, tmp_path)
    with pytest.raises(Dec3dError, match="no recovered resultants"):
        _run("[r = struct.shell.resultant(1, 0)]\n", tmp_path, s)
    with pytest.raises(Dec3dError, match="no surface system"):
        _run("structure liner recover resultants\n", tmp_path, s)
    _run("[v0 = struct.shell.resultant.valid(1)]\nstructure liner recover surface 1 0 0\n"
         "structure liner recover resultants\n[v1 = struct.shell.resultant.valid(1)]\n", tmp_path, s)
    assert _g(s, "v0") is False and _g(s, "v1") is True
    nodes, els = s.model.stores["liner_nodes"], s.model.stores["liner_elements"]
    root = np.flatnonzero(np.isclose(nodes["pos0"][:, 0], 0.0))
    for i in root:
        _run(f"[m = struct.node.resultant({int(nodes['id'][i])}, 1)]\n"
             f"[all = struct.node.resultant({int(nodes['id'][i])})]\n", tmp_path, s)
        assert _g(s, "m") == pytest.approx(80.0, rel=0.03)          # corner values of the DKT: to 3 %
        assert len(_g(s, "all")) == 6 and _g(s, "all")[3] == pytest.approx(80.0, rel=1e-6)
    res = els["eres"][: els.n]
    np.testing.assert_allclose(res[:, 0, 0], 20.0 * (1.0 - els["pos"][:, 0]) / 0.25, rtol=0, atol=0.03 * 80)
    np.testing.assert_allclose(res[:, :, 3], 80.0, rtol=1e-6)                   # N_x
    # Q_x: differentiated from the nodal averages over one element across the strip, each element's
    # within 25 % (the tip's, next to the point loads, is the worst: −97.7), their area-weighted mean −80.15
    a = els["area"][: els.n]
    assert (res[:, :, 6] == res[:, :1, 6]).all()                                # constant over the element
    np.testing.assert_allclose(res[:, 0, 6], -80.0, rtol=0.25)
    assert (res[:, 0, 6] * a).sum() / a.sum() == pytest.approx(-80.0, rel=0.005)
    assert np.abs(res[:, :, [4, 5]]).max() < 1e-6 * 80                          # N_y, N_xy
    assert np.abs(res[:, :, 1]).max() < 0.05 * 80 and np.abs(res[:, :, 2]).max() < 0.05 * 80
    e1 = res[0].copy()
    _run("[c = struct.shell.resultant(1, 0)]\n[q = struct.shell.resultant(1, 2, 7)]\n"
         "structure liner recover surface 0 1 0\nstructure liner recover resultants\n", tmp_path, s)
    assert _g(s, "c") == pytest.approx(list(e1[0])) and _g(s, "q") == pytest.approx(e1[2, 6])
    sw = els["eres"][0]
    np.testing.assert_allclose(sw[:, [1, 0, 4, 3]], e1[:, [0, 1, 3, 4]], rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(sw[:, 2], -e1[:, 2], atol=1e-9)                  # M_xy changes sign
    np.testing.assert_allclose(sw[:, 7], -e1[:, 6], rtol=1e-9)                  # Q_y = −Q_x: +80
    for line, what in (("[x = struct.shell.resultant(1, 4)]", "location"),
                       ("[x = struct.shell.resultant(1, 0, 9)]", "1 to 8"),
                       ("[x = struct.node.resultant(1, 7)]", "1 to 6")):
        with pytest.raises(Dec3dError, match=what):
            _run(line + "\n", tmp_path, s)


def _listed(out):
    """Element ids of the last `structure liner list`."""
    return [int(line.split()[0]) for line in out.getvalue().split("M-xx")[-1].splitlines()[1:] if line.strip()]


def test_group_and_list_save_restore(tmp_path):
    out = io.StringIO()
    s = _run(STRIP.replace("model solve ratio 1e-7\n", "") +
             "structure liner group 'root' range position-x 0 0.5\n"
             "structure liner group 'b' slot 's2' range position-x 0 0.3\n"
             "structure liner property thickness 0.02 range group 'root'\n", tmp_path, out=out)
    els = s.model.stores["liner_elements"]
    root = els["pos"][: els.n, 0] < 0.5
    assert root.sum() == 4 and (els["prop"][: els.n, 2] == np.where(root, 0.02, 0.01)).all()
    p = tmp_path / "g.sav"
    _run(f"model save '{p}'\n", tmp_path, s)
    b = _run(f"model restore '{p}'\nstructure liner group 'root' remove range position-x 0 0.3\n"
             "structure liner list range group 'root'\n", tmp_path, out=out)
    assert _listed(out) == [3, 4]                                                # two of the four left
    _run("structure liner list range group 'b' slot 's2'\n", tmp_path, b)
    assert _listed(out) == [1, 2]


def test_delete_takes_orphan_nodes_and_their_pull_off_the_block(tmp_path):
    """A 2 × 2-cell liner on a fixed block's top (8 elements, 9 nodes, all coupled) pulled up by node
    forces: the block carries their sum. Deleting the four elements of the half x < 0.5 removes the three
    nodes at x = 0 (the ones at x = 0.5 stay, still used) and takes their coupling forces off the block at
    once; after more steps the block carries just the forces of the six nodes left. Ids of what remains
    are kept; a history on a deleted element refuses the deletion; save/restore keeps it all."""
    out = io.StringIO()
    s = _run("""model new
block create brick 0 1 0 1 0 1
block property density 1000
block fix
structure liner create by-quadrilateral 0 0 1 1 0 1 1 1 1 0 1 1 size 2 2
structure liner property isotropic 30e9 0.2 thickness 0.1 coupling-stiffness-normal 1e9 coupling-stiffness-shear 1e9 coupling-yield-normal 1e7 coupling-cohesion-shear 1e7
structure node apply force-z 1000
model cycle 2000
structure liner history coupling-stress-normal component-id 1 node 1
""", tmp_path, out=out)
    m = s.model
    nodes, els = m.stores["liner_nodes"], m.stores["liner_elements"]
    assert els.n == 8 and nodes.n == 9 and (nodes["host"] == 0).all()
    assert m.blocks["fapp"][0, 2] == pytest.approx(9000.0, rel=1e-3)
    left = els["pos"][: els.n, 0] < 0.5
    keep_ids = els["id"][: els.n][~left].copy()
    with pytest.raises(Dec3dError, match="history 1"):
        _run("structure liner delete range position-x 0 0.5\n", tmp_path, s)
    assert els.n == 8
    orphan_f = nodes["hforce"][np.isclose(nodes["pos0"][:, 0], 0.0), 2].sum()
    before = m.blocks["fapp"][0, 2]
    _run("history delete\nstructure liner delete range position-x 0 0.5\n", tmp_path, s)
    assert "deleted 4 liner element(s) and 3 node(s)" in out.getvalue()
    assert els.n == 4 and nodes.n == 6 and list(els["id"][: els.n]) == list(keep_ids)
    assert not np.isclose(nodes["pos0"][: nodes.n, 0], 0.0).any()
    assert m.blocks["fapp"][0, 2] == pytest.approx(before - orphan_f, rel=1e-12)
    # the connectivity still names the right nodes: each element's centroid from its nodes
    np.testing.assert_allclose(nodes["pos0"][els["nodes"][: els.n]].mean(axis=1), els["pos"][: els.n], atol=1e-12)
    p = tmp_path / "d.sav"
    _run(f"model cycle 2000\nmodel save '{p}'\n", tmp_path, s)
    assert m.blocks["fapp"][0, 2] == pytest.approx(6000.0, rel=1e-3)
    # the springs left work on the nodes' new tributary areas (the x = 0.5 nodes lost half of theirs)
    from dec3d.model.liners import node_areas

    area = node_areas(m)
    assert area.sum() == pytest.approx(0.5, rel=1e-12)
    np.testing.assert_allclose(-nodes["fn"][: nodes.n], 1e9 * area * nodes["un"][: nodes.n], rtol=1e-9)
    b = _run(f"model restore '{p}'\nmodel cycle 10\n", tmp_path)
    assert b.model.stores["liner_elements"].n == 4 and b.model.blocks["fapp"][0, 2] == pytest.approx(6000.0, rel=1e-3)
    _run("structure liner delete\n", tmp_path, b)
    assert b.model.stores["liner_nodes"].n == 0 and abs(b.model.blocks["fapp"][0, 2]) < 1e-6
    _run("model cycle 10\n", tmp_path, b)


def test_delete_on_a_zoned_block_gives_the_gridpoints_their_loads_back(tmp_path):
    """A liner on a zoned block's top pulled up by 100 N per node: the springs load the top gridpoints
    (their applied loads sum to the pull); deleting the liner takes all of it back off them."""
    s = _run("""model new
block create brick 0 1 0 1 0 1
block zone generate edgelength 0.5
block zone cmodel assign elastic
block zone property young 1e9 poisson 0.25 density 2000
block gridpoint fix velocity range position-z 0
structure liner create by-block-face range position-z 1
structure liner property isotropic 30e9 0.2 thickness 0.1 density 2400 coupling-stiffness-normal 1e9 coupling-stiffness-shear 1e9 coupling-yield-normal 2e7 coupling-cohesion-shear 1e7
structure node apply force-z 100
model cycle 300
""", tmp_path)
    nodes, v = s.model.stores["liner_nodes"], s.model.vertices
    assert (nodes["hz"] == 1).all()
    assert v["fapp"][: v.n, 2].sum() == pytest.approx(nodes["hforce"][: nodes.n, 2].sum(), rel=1e-12)
    assert abs(v["fapp"][: v.n, 2].sum()) > 100
    _run("structure liner delete\nmodel cycle 10\n", tmp_path, s)
    assert nodes.n == 0 and abs(v["fapp"][: v.n]).max() < 1e-9


def test_stores_from_an_older_file_get_the_recovery_fields():
    """A liner store restored from a file written before recovery existed (no ``sx``/``nres``/``eres``
    columns) gets them, unset, on first use."""
    from dec3d.model.liners import LELEMS, LNODES, _elem_fields, _node_fields, liner_stores
    from dec3d.model.model import Model
    from dec3d.model.store import Store

    m = Model()
    old_n = {k: f for k, f in _node_fields().items() if k not in ("sx", "nres", "nresok")}
    old_e = {k: f for k, f in _elem_fields().items() if k not in ("eres", "eresok")}
    m.add_store(Store(LNODES, old_n))
    m.add_store(Store(LELEMS, old_e))
    m.stores[LNODES].append(2)
    m.stores[LELEMS].append(1)
    nodes, els = liner_stores(m)
    assert nodes["sx"].shape == (2, 3) and not nodes["sx"].any() and not nodes["nresok"].any()
    assert els["eres"].shape == (1, 4, 8) and not els["eresok"].any()
