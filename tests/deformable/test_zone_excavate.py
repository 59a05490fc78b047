"""Excavating zoned joined blocks with `block delete`: the blocks that remain keep sharing their
gridpoints. A gridpoint shared by several joined blocks has one master row (the lowest) and the
others link to it; when the master's block is deleted the remaining copies must be linked again
among themselves, or the continuum comes apart along that line."""
import numpy as np

from dec3d.model.zone_mesh import conformity
from dec3d.session import Session


def _masters_per_position(model) -> np.ndarray:
    """For every position held by gridpoints of zoned blocks, how many different master rows its
    copies have (1 everywhere for a joined continuum)."""
    v = model.vertices
    g = np.flatnonzero(v["zoned"])
    master = np.where(v["link"][g] >= 0, v["link"][g], g)
    _, inv = np.unique(np.round(v["pos"][g], 9), axis=0, return_inverse=True)
    inv = inv.ravel()
    pairs = np.unique(np.column_stack([inv, master]), axis=0)
    return np.bincount(pairs[:, 0])


def test_deleting_the_core_of_a_zoned_tunnel_keeps_the_rock_joined(tmp_path):
    s = Session(out_dir=tmp_path)
    for line in ["block create tunnel dip 0 dip-direction 0 radius 1 length 0 1 blocks-axial 1 blocks-radial 4 "
                 "blocks-tangential 5 boundary 9 radius-ratio 1.4",
                 "block delete range plane dip 90 dip-direction 90 below",
                 "block join on", "block zone generate edgelength 0.8"]:
        s.command(line)
    assert _masters_per_position(s.model).max() == 1
    n = s.model.blocks.n
    s.command("block delete range cylinder end-1 0 0 0 end-2 0 1 0 radius 0 1 position-z 0 1")
    assert s.model.blocks.n < n
    assert _masters_per_position(s.model).max() == 1          # 33 positions had split before the fix
    assert conformity(s.model)["unmatched"] == []


def test_after_deleting_the_master_block_the_others_move_as_one(tmp_path):
    """Four joined, zoned 1 m cubes around the edge x = 1, z = 1; the first (which holds the master
    rows of the edge gridpoints) is deleted, the other three are squeezed from the top: every
    gridpoint position shared by two or three of them moves as one."""
    s = Session(out_dir=tmp_path)
    for line in ["block create brick 0 1 0 1 0 1", "block create brick 1 2 0 1 0 1",
                 "block create brick 0 1 0 1 1 2", "block create brick 1 2 0 1 1 2",
                 "block join on", "block zone generate edgelength 0.5",
                 "block zone cmodel assign elastic", "block zone property bulk 1e9 shear 6e8 density 2000",
                 "block delete range position-x 0 1 position-z 0 1",
                 "block gridpoint apply velocity-z 0 range position-z 0",
                 "block gridpoint apply velocity-x 0 range position-x 0",
                 "block gridpoint apply velocity-y 0",
                 "block face apply stress-zz -1e6 range position-z 2"]:
        s.command(line)
    v = s.model.vertices
    g = np.flatnonzero(v["zoned"])
    _, inv = np.unique(np.round(v["pos"][g], 9), axis=0, return_inverse=True)
    inv = inv.ravel()
    groups = [g[inv == k] for k in np.unique(inv) if (inv == k).sum() > 1]
    assert len(groups) > 10 and max(len(r) for r in groups) == 3      # the edge x = 1, z = 1: three blocks
    s.command("model cycle 300")
    for rows in groups:
        np.testing.assert_array_equal(v["disp"][rows], np.broadcast_to(v["disp"][rows[0]], (len(rows), 3)))
    assert np.abs(v["disp"][g, 2]).max() > 1e-5                 # it did move
