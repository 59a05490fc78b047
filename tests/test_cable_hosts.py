"""Cables in 10-node zones and in FE blocks (20-node bricks): the point-location kernel
(``dec3d.kernels.hostpoint``) against a plain-Python twin, and a confined pull-out (SE3's) in each
host matching the 4-node zones' result and the closed form.

The twin writes the shape functions from their formulas (10-node tetrahedron: N = L (2L − 1) at a
corner, 4 Lᵢ Lⱼ at the node of edge ij; 20-node serendipity brick: corners
1/8 (1 + ξξᵢ)(1 + ηηᵢ)(1 + ζζᵢ)(ξξᵢ + ηηᵢ + ζζᵢ − 2), mid-edge 1/4 (1 − ξ²)(1 + ηηᵢ)(1 + ζζᵢ) and
likewise) with its own node tables, and solves x(ξ) = p by Newton's method with a finite-difference
Jacobian; it shares no code or constants with the kernel."""
from __future__ import annotations

import io
import math

import numpy as np
import pytest

from dec3d.session import Session


# ------------------------------------------------------------------ the twin
TET_EDGES = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]
# brick nodes: the 8 corners in the C3D20 order, then the 12 edge midpoints
_C = [(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1), (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)]
_E = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)]
BRICK = [list(c) for c in _C] + [[(_C[i][k] + _C[j][k]) / 2 for k in range(3)] for i, j in _E]


def twin_tet10(y):
    L = [1 - y[0] - y[1] - y[2], y[0], y[1], y[2]]
    return [L[i] * (2 * L[i] - 1) for i in range(4)] + [4 * L[i] * L[j] for i, j in TET_EDGES]


def twin_hex20(y):
    out = []
    for node in BRICK:
        f = [1 + node[k] * y[k] for k in range(3)]
        zero = [k for k in range(3) if node[k] == 0]
        if not zero:
            out.append(f[0] * f[1] * f[2] * (sum(node[k] * y[k] for k in range(3)) - 2) / 8)
        else:
            k = zero[0]
            others = [f[j] for j in range(3) if j != k]
            out.append((1 - y[k] ** 2) * others[0] * others[1] / 4)
    return out


def twin_locate(X, shape, p, start):
    """Newton on x(ξ) = p with a central-difference Jacobian; ξ and the shape functions there."""
    def x_of(y):
        n = shape(y)
        return [sum(n[a] * X[a][i] for a in range(len(n))) for i in range(3)]
    y = list(start)
    for _ in range(50):
        r = [p[i] - x_of(y)[i] for i in range(3)]
        h = 1e-6
        J = [[0.0] * 3 for _ in range(3)]
        for k in range(3):
            yp, ym = list(y), list(y)
            yp[k] += h
            ym[k] -= h
            xp, xm = x_of(yp), x_of(ym)
            for i in range(3):
                J[i][k] = (xp[i] - xm[i]) / (2 * h)
        d = np.linalg.solve(np.array(J), np.array(r))
        y = [y[k] + d[k] for k in range(3)]
        if max(abs(v) for v in d) < 1e-14:
            break
    return y, shape(y)


def _distorted(rng, kind):
    if kind == 10:
        C = np.array([[0, 0, 0], [1.3, 0, 0.1], [0.2, 1.1, 0], [0.1, 0.2, 0.9]])
        X = np.vstack([C] + [(C[i] + C[j]) / 2 + rng.normal(0, 0.03, 3) for i, j in TET_EDGES])
    else:
        X = (np.array(BRICK) + 1) / 2 * [2.0, 1.0, 0.8] + rng.normal(0, 0.03, (20, 3))
    return X


@pytest.mark.parametrize("nn", [10, 20])
def test_locate_matches_twin(nn):
    from dec3d.kernels.hostpoint import locate

    rng = np.random.default_rng(nn)
    X = _distorted(rng, nn)
    shape, start = (twin_tet10, (0.25, 0.25, 0.25)) if nn == 10 else (twin_hex20, (0.0, 0.0, 0.0))
    conn = np.arange(nn, dtype=np.int64)[None, :]
    found = 0
    for _ in range(40):
        y0 = rng.dirichlet([1, 1, 1, 1])[1:] if nn == 10 else rng.uniform(-1, 1, 3)
        p = np.array(shape(list(y0))) @ X                  # a point of the element, by the twin's map
        w = np.zeros(nn)
        k = locate(X, conn, np.array([0]), nn, p, 1e-9, w)
        y, n = twin_locate(X.tolist(), shape, p.tolist(), start)
        np.testing.assert_allclose(y, y0, atol=1e-9)
        assert k == 0
        np.testing.assert_allclose(w, n, atol=1e-9)
        np.testing.assert_allclose(w @ X, p, atol=1e-12)
        found += 1
    # a point outside (ξ past the element by 10 %) is not held
    far = np.array(shape([0.6, 0.6, 0.0] if nn == 10 else [1.1, 0.0, 0.0])) @ X
    assert locate(X, conn, np.array([0]), nn, far, 1e-9, np.zeros(nn)) == -1
    assert found == 40


# ------------------------------------------------------------------ through the engine
ZONING = {"tet4": "block zone generate edgelength 0.5\n",
          "tet10": "model configure highorder\nblock zone generate edgelength 0.5 high-order-tetra\n",
          "fe": "model configure feblock\nfeblock generate 0.5 0.5 0.5\n"}


def _pullout(tmp_path, kind, held="block gridpoint apply velocity 0 0 0\n", steps=6000):
    """SE3 (verification/SE3_cable_pullout_confined) with the host zoned as ``kind``."""
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.run_items(s.load_text("model new\nblock create brick 0 2 -0.5 0.5 -0.5 0.5\n" + ZONING[kind] +
                            "block zone cmodel assign elastic\n"
                            "block zone property young 50e9 poisson 0.25 density 2500\n" + held +
                            "block mechanical timestep 1e-3\n"))
    if kind == "fe":            # (`block zone initialize` sets zones; the bricks' stress is set here)
        es = s.model.stores["feblocks"]
        es["stress"][:] = [-1e6, -1e6, -1e6, 0, 0, 0]
        es["gstress"][:, :, :3] = -1e6
    else:
        s.run_items(s.load_text("block zone initialize stress-xx -1e6 stress-yy -1e6 stress-zz -1e6\n"))
    s.run_items(s.load_text(
        "structure cable create by-line 0 0 0 2 0 0 segments 40\n"
        "structure cable property young 100e9 cross-sectional-area 1e-4 grout-stiffness 1e7 grout-cohesion 5e3\n"
        "structure cable property grout-friction 30 grout-perimeter 0.05\n"
        "structure node fix velocity-x range id 1\nstructure node initialize velocity-x -4e-3 range id 1\n"
        f"model cycle {steps}\n"))
    return s


def test_confined_pullout_in_quadratic_hosts_matches_the_4_node_zones(tmp_path):
    """The pull-out capacity (c_g + σ_m tan φ_g p_g) L = 67 735 N needs the host's stress across the
    cable (σ_m = 1 MPa; without it the capacity is 10 kN): read from the 10-node zones and from the
    bricks it is the 4-node zones' to 0.1 % and the closed form's to 2 %; every element slips; the
    gridpoints (held) take the grout's reaction whole, by the nodes' shape functions."""
    cap = (5e3 + 1e6 * math.tan(math.radians(30)) * 0.05) * 2
    pulls = {}
    for kind in ("tet4", "tet10", "fe"):
        s = _pullout(tmp_path, kind)
        nodes, segs = s.model.stores["cable_nodes"], s.model.stores["cable_segments"]
        assert set(nodes["hz"].tolist()) == {{"tet4": 1, "tet10": 2, "fe": 3}[kind]}
        if kind != "tet4":
            assert nodes["hw"].min() < 0                    # quadratic shape functions, some negative
        np.testing.assert_allclose(nodes["hw"].sum(axis=1), 1.0, atol=1e-12)
        pulls[kind] = nodes["force"][0, 0]                 # (the pulled node: held, its unbalanced force)
        assert ((segs["state"] & 4) != 0).sum() == 40
        v = s.model.vertices
        grout = segs["gf"].sum()                             # on the cable, along +x
        assert v["fapp"][: v.n, 0].sum() == pytest.approx(-grout, rel=1e-9)
    for kind in ("tet10", "fe"):
        assert pulls[kind] == pytest.approx(pulls["tet4"], rel=1e-3)
    assert pulls["fe"] == pytest.approx(cap, rel=0.02)


@pytest.mark.parametrize("kind", ["tet10", "fe"])
def test_free_quadratic_host_follows_the_pull(tmp_path, kind):
    """The same block held only at its far face x = 2: the pull drags the host (its gridpoints move to
    −x near the pulled end), everything stays finite, and the stiffness sums of the nodes the grout
    acts on are positive (density scaling keeps the step stable)."""
    s = _pullout(tmp_path, kind, held="block gridpoint apply velocity 0 0 0 range position-x 2\n", steps=400)
    v = s.model.vertices
    near = v["pos"][: v.n, 0] < 0.3
    assert np.isfinite(v["pos"][: v.n]).all() and np.isfinite(s.model.stores["cable_segments"]["fa"]).all()
    assert v["disp"][: v.n][near, 0].mean() < 0
    from dec3d.physics.cables import gridpoint_grout_stiffness

    k = gridpoint_grout_stiffness(s.model, v.n)
    nodes = s.model.stores["cable_nodes"]
    assert (k[np.unique(nodes["hgp"][nodes["hw"] != 0])] > 0).all() and (k >= 0).all()


def test_old_four_slot_hosts_are_widened():
    """A store restored from a file written with 4 host slots reads as NHOST slots, the new ones
    pointing at the first node with weight 0."""
    from dec3d.model.cables import cable_stores
    from dec3d.model.hosts import NHOST

    s = Session(stdout=io.StringIO())
    s.run_items(s.load_text("model new\nblock create brick 0 2 -0.5 0.5 -0.5 0.5\nblock zone generate edgelength 0.5\n"
                            "structure cable create by-line 0 0 0 2 0 0 segments 4\n"))
    nodes = s.model.stores["cable_nodes"]
    gp, w = nodes["hgp"][:, :4].copy(), nodes["hw"][:, :4].copy()
    nodes.resize_field("hgp", (4,))
    nodes.resize_field("hw", (4,))
    nodes, _ = cable_stores(s.model)
    assert nodes["hgp"].shape[1] == NHOST and (nodes["hgp"][:, :4] == gp).all()
    assert (nodes["hgp"][:, 4:] == gp[:, :1]).all() and not nodes["hw"][:, 4:].any()
    np.testing.assert_array_equal(nodes["hw"][:, :4], w)


def test_dowel_and_beam_in_quadratic_hosts(tmp_path):
    """A hybrid bolt's dowel with its base side in a 10-node zone hands its shear force whole to the
    zone's nodes (Σ wᵢ F = F); a beam node inside an FE block follows its brick (code 3) and the
    cycle stays finite."""
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.run_items(s.load_text("""model new
model configure highorder
block create brick -1 1 -1 1 -1 0
block create brick -0.5 0.5 -0.5 0.5 0 0.5
block zone generate edgelength 0.5 high-order-tetra range position-z -1 0
block zone cmodel assign elastic range position-z -1 0
block zone property bulk 1e9 shear 1e9 density 2500 range position-z -1 0
block property density 2500 range position-z 0 0.5
block gridpoint apply velocity 0 0 0 range position-z -1
block contact jmodel assign mohr
block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 friction 0
structure hybrid create by-line 0.1 0.1 0.4 0.1 0.1 -0.8 segments 6
structure hybrid property young 200e9 cross-sectional-area 5e-4 grout-stiffness 1e9 grout-cohesion 1e9
structure hybrid property dowel-stiffness 1e7 dowel-yield 2e4
block fix velocity range position-z 0 0.5
block initialize velocity-x 1e-3 range position-z 0 0.5
model cycle 200
"""))
    st = s.model.stores["cable_dowels"]
    assert st["hz"][0].tolist() == [0, 2]
    f = st["fs"][0]
    assert f[0] > 100.0
    v = s.model.vertices
    np.testing.assert_allclose(v["fapp"][: v.n, :2].sum(axis=0), f[:2], rtol=1e-4)
    b = Session(out_dir=tmp_path, stdout=io.StringIO())
    b.run_items(b.load_text("""model new
model configure feblock
block create brick 0 2 -0.5 0.5 -0.5 0.5
feblock generate 0.5 0.5 0.5
block zone cmodel assign elastic
block zone property young 50e9 poisson 0.25 density 2500
block gridpoint apply velocity 0 0 0 range position-x 2
structure beam create by-line 1 0 0 3 0 0 segments 4
structure beam property young 200e9 poisson 0.3 cross-sectional-area 1e-2 moi-y 1e-5 moi-z 1e-5 moi-polar 2e-5
structure node apply force-z -1000 range id 5
model cycle 300
"""))
    nodes = b.model.stores["beam_nodes"]
    assert nodes["hz"].tolist() == [3, 3, 3, 0, 0]
    assert np.isfinite(nodes["pos"]).all() and nodes["disp"][4, 2] < 0


def test_confinement_reads_the_shear_stresses_in_store_order():
    """σ_m = −(tr σ − tᵀσt)/2 with only σ_xz = −1 MPa and the cable along (1, 0, 1)/√2: tᵀσt = σ_xz, so
    σ_m = −(0 − (−1e6))/2 = −0.5 MPa (σ_yz, which the cable does not see, stays out)."""
    from dec3d.physics.cables import zone_host_state

    s = Session(stdout=io.StringIO())
    s.run_items(s.load_text("model new\nblock create brick 0 2 -0.5 0.5 -0.5 0.5\nblock zone generate edgelength 0.5\n"
                            "block zone initialize stress 0 0 0 0 -1e6 0\n"
                            "structure cable create by-line 0.6 0 -0.3 1.2 0 0.3 segments 2\n"))
    nodes, segs = s.model.stores["cable_nodes"], s.model.stores["cable_segments"]
    conf, _ = zone_host_state(s.model, nodes, segs, np.arange(nodes.n))
    np.testing.assert_allclose(conf, -0.5e6, rtol=1e-12)


def test_fe_hosted_cable_save_restore_continues_the_same_run(tmp_path):
    a = _pullout(tmp_path, "fe", steps=150)
    path = tmp_path / "fe.sav"
    a.run_items(a.load_text(f"model save '{path}'\nmodel cycle 100\n"))
    b = Session(out_dir=tmp_path, stdout=io.StringIO())
    b.run_items(b.load_text(f"model restore '{path}'\nmodel cycle 100\n"))
    sa, sb = a.model.stores, b.model.stores
    assert (sb["cable_nodes"]["hz"] == 3).all()
    for k in ("fa", "gf"):
        np.testing.assert_array_equal(sa["cable_segments"][k], sb["cable_segments"][k])
    np.testing.assert_array_equal(a.model.vertices["pos"], b.model.vertices["pos"])
