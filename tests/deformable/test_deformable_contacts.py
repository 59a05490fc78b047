"""Contacts between two zoned (deformable) blocks in the engine: sub-contacts relocated as a block
slides, joined zoned blocks without contact forces, `block insitu stress` on deformable contacts."""
import numpy as np
import pytest

from dec3d.session import Session

E, NU = 1e9, 0.25
M = E * (1 - NU) / ((1 + NU) * (1 - 2 * NU))      # constrained modulus, 1.2 GPa

_ROLLERS = ["block gridpoint apply velocity-z 0 range position-z 0",
            "block gridpoint apply velocity-x 0 range position-x 0",
            "block gridpoint apply velocity-x 0 range position-x 1",
            "block gridpoint apply velocity-y 0 range position-y 0",
            "block gridpoint apply velocity-y 0 range position-y 1"]


def _run(tmp_path, lines):
    s = Session(out_dir=tmp_path)
    for line in lines:
        s.command(line)
    return s


def _stack(edge_top="0.5", kn="1e10", extra=()):
    return ["block create brick 0 1 0 1 0 1", "block create brick 0 1 0 1 1 2", *extra,
            "block zone generate edgelength 0.5 range position-z 0 1",
            f"block zone generate edgelength {edge_top} range position-z 1 2",
            "block zone cmodel assign elastic", f"block zone property young {E:g} poisson {NU:g} density 2000",
            "block contact jmodel assign elastic",
            f"block contact material-table default property stiffness-normal {kn} stiffness-shear {kn}", *_ROLLERS]


def _barycentric(p, tri):
    m = np.column_stack([tri[1, :2] - tri[0, :2], tri[2, :2] - tri[0, :2]])
    st = np.linalg.solve(m, p[:2] - tri[0, :2])
    return np.array([1 - st.sum(), st[0], st[1]])


def test_subcontacts_relocate_and_keep_their_history_as_a_zoned_block_slides(tmp_path):
    """A zoned cube dragged 0.3 m (1e-4 m a step) over a zoned base (large strain, Coulomb joint with friction 5°):
    after the slide every sub-contact of the cube's gridpoints lies on the base triangle under its
    gridpoint, with that point's barycentric weights, and its accumulated shear displacement is the
    slide: the state followed the gridpoint across the base's zone faces."""
    s = _run(tmp_path, ["model large-strain on", "block create brick -1 2 -0.5 1.5 -1 0",
                        "block create brick 0 1 0 1 0 1", "block group 'top' range position-z 0 1",
                        "block zone generate edgelength 0.5", "block zone cmodel assign elastic",
                        f"block zone property young {E:g} poisson {NU:g} density 2000", "model gravity 0 0 -10",
                        "block contact jmodel assign mohr",
                        "block contact material-table default property stiffness-normal 1e10 stiffness-shear 1e10 "
                        "friction 5",
                        "block gridpoint apply velocity 0 0 0 range position-z -1",
                        "block gridpoint apply velocity-x 0 range position-z 0.1 1", "model solve ratio 1e-6"])
    m = s.model
    v, cs, ss = m.vertices, m.store("contacts"), m.store("subcontacts")
    x0 = v["pos"].copy()
    s.command("block gridpoint apply velocity-x 1e-4 range position-z 0.1 1")
    s.command("model cycle 3000")
    after = v["pos"].copy()
    # the weights are made at each detection (every 10 steps) and kept in between: one more step,
    # the cube held, starts with a detection at the positions the slide ended with
    s.command("block gridpoint apply velocity-x 0 range position-z 0.1 1")
    assert m.step % 10 == 0
    s.command("model cycle 1")
    driven = (v["block"] == 1) & (x0[:, 2] > 0.05)
    assert np.allclose(after[driven, 0] - x0[driven, 0], 0.3, rtol=0, atol=1e-9)
    assert cs.n == 1
    base = m.blocks["face_start"][0], m.blocks["face_count"][0]
    fv, f = m.face_vertices["vertex"], m.faces
    tris = [fv[f["vstart"][k]: f["vstart"][k] + 3] for k in range(base[0], base[0] + base[1])]
    upper = [t for t in tris if np.allclose(v["pos"][t, 2], 0.0, atol=1e-3)]
    mine = np.flatnonzero(ss["kind"] == 1)               # the cube's gridpoints (block B) on base faces
    assert len(mine) >= 9
    moved_on = 0
    for k in mine:
        g = ss["key0"][k]
        assert list(ss["gp_b"][k]) == [g, -1, -1]
        p = after[g]
        hits = [t for t in upper if (_barycentric(p, v["pos"][t]) >= -1e-9).all()]
        assert hits, "the gridpoint is over the base"
        nodes = ss["gp_a"][k]
        assert any(set(nodes) == set(t) for t in hits)
        w = dict(zip(nodes, ss["gw_a"][k]))
        lam = _barycentric(p, v["pos"][nodes])
        assert np.allclose([w[n] for n in nodes], lam, atol=1e-3)
        moved_on += not any(set(nodes) == set(t) for t in upper
                            if (_barycentric(x0[g], x0[t]) >= -1e-9).all())
        # slip accumulated across the relocations: the gridpoint's own slide (about 0.3 m; the base
        # surface moves by the elastic shear of a few µm only)
        assert abs(np.linalg.norm(ss["us"][k]) - (v["pos"][g, 0] - x0[g, 0])) < 1e-3
        assert p[0] - x0[g, 0] > 0.29
    # most sit on a triangle that did not hold their gridpoint at the start (the others began on a
    # base vertex and are now in one of its triangles again)
    assert moved_on >= len(mine) // 2


def test_joined_zoned_blocks_share_gridpoints_and_have_no_contact_forces(tmp_path):
    """Two joined zoned cubes under 1 MPa on rollers shorten as one 2 m column (2 p H / M): their
    contact carries no sub-contact."""
    s = _run(tmp_path, _stack(extra=["block join on"]) + ["block face apply stress-zz -1e6 range position-z 2",
                                                          "model solve ratio 1e-8"])
    m = s.model
    assert m.store("contacts").n == 1 and m.store("subcontacts").n == 0
    top = np.abs(m.vertices["pos"][:, 2] - 2.0) < 1e-9
    assert np.allclose(m.vertices["disp"][top, 2], -2e6 / M, rtol=1e-4)


def test_pressed_zoned_blocks_with_matching_gridpoints(tmp_path):
    """Two zoned cubes (same zoning) under 1 MPa across an elastic joint kn = 1 GPa/m: the top
    moves 2 p H / M + p / kn, the joint carries p A and every sub-contact closes by p / kn."""
    s = _run(tmp_path, _stack(kn="1e9") + ["block face apply stress-zz -1e6 range position-z 2",
                                           "model solve ratio 1e-8"])
    m = s.model
    ss = m.store("subcontacts")
    top = np.abs(m.vertices["pos"][:, 2] - 2.0) < 1e-9
    assert np.allclose(m.vertices["disp"][top, 2], -(2e6 / M + 1e6 / 1e9), rtol=1e-4)
    assert abs(ss["fn"].sum() - 1e6) < 1.0
    assert np.allclose(ss["un"], -1e6 / 1e9, rtol=1e-4)
    assert abs(ss["area"].sum() - 1.0) < 1e-12
    assert set(ss["kind"]) == {0, 1}                     # both blocks' gridpoints carry sub-contacts


def test_insitu_stress_sets_deformable_contact_forces_in_equilibrium(tmp_path):
    """`block insitu stress` on two stacked zoned cubes: each deformable sub-contact takes
    −A n·σ·n and the normal displacement that keeps it; with the same stress on the top face
    nothing moves (without the contact forces the joint would close by p / kn = 1e-4 m). Same zoning
    on both sides: the sub-contact forces are then the consistent nodal loads of the stress on each
    face (on non-matching grids they are only near them)."""
    s = _run(tmp_path, _stack() + ["model cycle 1",
                                                  "block insitu stress -2e6 -2e6 -1e6 0 0 0",
                                                  "block face apply stress-zz -1e6 range position-z 2"])
    m = s.model
    ss, cs = m.store("subcontacts"), m.store("contacts")
    assert ss.n > 0
    assert np.allclose(ss["fn"], 1e6 * ss["area"], rtol=1e-12)
    assert np.allclose(ss["un"], -1e6 / 1e10, rtol=1e-12)
    assert np.allclose(ss["fs"], 0.0)
    s.command("model cycle 200")
    assert np.abs(m.vertices["disp"]).max() < 1e-9
    assert abs(ss["fn"].sum() - 1e6) < 1e-3
    assert cs.n == 1


def _pressed(tmp_path, chunks, save_at=None):
    import io

    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    for line in _stack(edge_top="0.34") + ["block contact jmodel assign mohr",
                                           "block contact material-table default property stiffness-normal 1e10 "
                                           "stiffness-shear 1e10 friction 20",
                                           "block face apply stress -1e6 -1e6 -1e6 0 0 -3e5 range position-z 2",
                                           "block mechanical damping none"]:
        s.command(line)
    for i, c in enumerate(chunks):
        s.command(f"model cycle {c}")
        if save_at == i:
            s.command("model save 'z'")
            s = Session(out_dir=tmp_path, stdout=io.StringIO())
            s.command("model restore 'z'")
    m = s.model
    return (m.vertices["disp"].copy(), m.vertices["velocity"].copy(), m.stores["zones"]["stress"].copy(),
            m.stores["subcontacts"]["fn"].copy(), m.stores["subcontacts"]["fs"].copy())


def test_pressed_and_sheared_zoned_blocks_split_and_restored_are_one_run(tmp_path):
    """Two zoned blocks (non-matching grids) pressed and sheared across a Coulomb joint, no damping:
    one run of 120 steps, or 47 + 73 with `model save`/`model restore` in between, give the same
    bits (small strain; large strain: ``test_zone_split_runs.py``)."""
    one = _pressed(tmp_path, [120])
    split = _pressed(tmp_path, [47, 73], save_at=0)
    assert one[3].sum() > 0 and np.abs(one[4]).max() > 0 and np.abs(one[1]).max() > 1e-4
    for a, b in zip(one, split):
        assert np.array_equal(a, b)


def test_joint_stiffness_between_zoned_blocks_enters_the_time_step(tmp_path):
    """Dynamic run (no damping, real masses): Δt = 2 min (m / k)^½ over the gridpoints (Eq. 84),
    k the zones' stiffness plus the joint's max(kn, ks)·area of every sub-contact, shared to the
    gridpoints by its weights (Eq. 85), on both zoned blocks. A very stiff joint sets Δt."""
    dts = {}
    for kn in ("1e8", "1e14"):
        s = _run(tmp_path, _stack(kn=kn) + ["block mechanical damping none", "model cycle 1"])
        m = s.model
        zst = m.rigid_engine._zstep
        ss, cs = m.store("subcontacts"), m.store("contacts")
        kj = np.zeros(m.vertices.n)
        for k in range(ss.n):
            ka = float(kn) * ss["area"][k]
            for nodes, w in ((ss["gp_a"][k], ss["gw_a"][k]), (ss["gp_b"][k], ss["gw_b"][k])):
                for g, wi in zip(nodes, w):
                    if g >= 0:
                        kj[g] += wi * ka
        assert set(ss["kind"]) == {0, 1} and cs["prop"][0, 0] == float(kn)
        rows = zst.masters
        want = 2.0 * np.sqrt(zst.mtot[rows] / (zst.kzone[rows] + kj[rows])).min()
        assert abs(m.rigid_engine.dt / want - 1) < 1e-12
        dts[kn] = m.rigid_engine.dt
    assert dts["1e14"] < 0.2 * dts["1e8"]


@pytest.mark.parametrize("zoning, bar", [("hexahedra divisions 2 2 2", 0.005), ("high-order-tetra edgelength 0.5", 0.02)])
def test_pressed_blocks_of_hexahedral_and_10_node_zones(tmp_path, zoning, bar):
    """The pressed stack (1 MPa, kn = 10 GPa/m; top moves 2 p H / M + p / kn = 1.7667 mm) with
    hexahedral mixed zones (measured +0.16 %: a hexahedral face's sub-contacts sit on its triangle
    split, not on the quadrilateral's quarter loads) and 10-node zones (+1.2 %: the sub-contacts load
    the mid-edge and corner nodes by the flat sub-triangles, not by the 6-node triangle's consistent
    loads, which are 0 at the corners). The joint carries p A."""
    lines = [ln if not ln.startswith("block zone generate") else f"block zone generate {zoning}"
             for ln in _stack()]
    lines = list(dict.fromkeys(lines))             # one `block zone generate` for both blocks
    if "high-order" in zoning:
        lines.insert(0, "model configure highorder")
    s = _run(tmp_path, lines + ["block face apply stress-zz -1e6 range position-z 2", "model solve ratio 1e-7"])
    m = s.model
    top = np.abs(m.vertices["pos"][:, 2] - 2.0) < 1e-9
    want = -(2e6 / M + 1e6 / 1e10)
    assert abs(m.vertices["disp"][top, 2].mean() / want - 1) < bar
    assert abs(m.store("subcontacts")["fn"].sum() - 1e6) < 10.0
