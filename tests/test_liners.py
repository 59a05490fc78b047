"""Liner structural elements: the DKT + CST element against a twin built another way
(``tests/liner_twin.py``), patch tests, rigid-body modes, the step kernels (element forces, coupling
springs) against plain-Python twins, the commands, a coupled liner on a block, bad input."""
from __future__ import annotations

import io
import math

import numpy as np
import pytest

from dec3d.errors import Dec3dError
from dec3d.kernels.dkt import element_frame, global_stiffness, shell_local_stiffness
from dec3d.kernels.liner import coupling, element_forces
from dec3d.session import Session

import liner_twin as tw

E, NU, T = 2e9, 0.25, 0.1


def _tri(rng):
    while True:
        p = rng.normal(size=(3, 3))
        a = np.linalg.norm(np.cross(p[1] - p[0], p[2] - p[0]))
        if a > 0.3:
            return p


@pytest.mark.parametrize("seed", range(4))
def test_element_stiffness_matches_twin(seed):
    p = _tri(np.random.default_rng(seed))
    ax, x2, x3, y3 = element_frame(*p)
    k = np.empty((18, 18))
    shell_local_stiffness(x2, x3, y3, E, NU, T, k)
    r, xy = tw.frame(p)
    np.testing.assert_allclose(ax, r, atol=1e-14)
    kt = tw.local_k(xy, E, NU, T)
    np.testing.assert_allclose(k, kt, rtol=0, atol=1e-12 * np.abs(kt).max())
    kg = global_stiffness(ax, x2, x3, y3, E, NU, T)
    np.testing.assert_allclose(kg, tw.global_k(p, E, NU, T), rtol=0, atol=1e-12 * np.abs(kt).max())
    np.testing.assert_allclose(kg, kg.T, rtol=0, atol=1e-13 * np.abs(kg).max())


@pytest.mark.parametrize("seed", range(3))
def test_rigid_body_motion_gives_no_force(seed):
    """Six rigid-body modes (translations, small rotations u = ω × x with rotations ω) in zero
    energy; the other 12 modes are stiff (the drilling spring makes the element nonsingular)."""
    rng = np.random.default_rng(10 + seed)
    p = _tri(rng)
    ax, x2, x3, y3 = element_frame(*p)
    kg = global_stiffness(ax, x2, x3, y3, E, NU, T)
    for _ in range(4):
        t, w = rng.normal(size=3), rng.normal(size=3)
        d = np.concatenate([np.concatenate([t + np.cross(w, q), w]) for q in p])
        assert np.abs(kg @ d).max() < 1e-9 * np.abs(kg).max() * np.abs(d).max()
    ev = np.linalg.eigvalsh(kg)
    assert (np.abs(ev[:6]) < 1e-9 * ev[-1]).all() and (ev[6:] > 1e-9 * ev[-1]).all()


# an irregular patch: four outer corners and one inner node, four elements, tilted in space
_PXY = np.array([[0.0, 0.0], [2.0, 0.0], [2.2, 1.6], [-0.1, 2.0], [0.9, 0.8]])
_PTRI = [(0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4)]


def _patch_k(rot):
    n = len(_PXY)
    pts = np.column_stack([_PXY, np.zeros(n)]) @ rot.T
    k = np.zeros((6 * n, 6 * n))
    for tri in _PTRI:
        ax, x2, x3, y3 = element_frame(*pts[list(tri)])
        kg = global_stiffness(ax, x2, x3, y3, E, NU, T)
        dof = [6 * i + c for i in tri for c in range(6)]
        k[np.ix_(dof, dof)] += kg
    return pts, k


def _rot(a, b):
    ca, sa, cb, sb = math.cos(a), math.sin(a), math.cos(b), math.sin(b)
    return np.array([[ca, -sa, 0], [sa, ca, 0], [0, 0, 1]]) @ np.array([[1, 0, 0], [0, cb, -sb], [0, sb, cb]])


def _solve_inner(k, d_exact):
    """Hold the outer nodes at ``d_exact``, free the inner one (node 4): its DOFs from K."""
    inner = list(range(24, 30))
    outer = [i for i in range(30) if i not in inner]
    kii = k[np.ix_(inner, inner)]
    kio = k[np.ix_(inner, outer)]
    return np.linalg.solve(kii, -kio @ d_exact[outer])


def test_membrane_patch_constant_strain():
    rot = _rot(0.4, 0.7)
    pts, k = _patch_k(rot)
    g = np.array([[1e-3, 4e-4], [-2e-4, 6e-4]])             # in-plane displacement gradient (local)
    d = np.zeros(30)
    for i, (x, y) in enumerate(_PXY):
        d[6 * i:6 * i + 3] = rot @ np.array([g[0] @ (x, y), g[1] @ (x, y), 0.0])
        # the field's rotation ½ (v,x − u,y) about the normal: the drilling rotation it implies
        d[6 * i + 3:6 * i + 6] = rot @ np.array([0.0, 0.0, 0.5 * (g[1, 0] - g[0, 1])])
    got = _solve_inner(k, d)
    np.testing.assert_allclose(got, d[24:30], atol=1e-12)


def test_bending_patch_constant_curvature():
    """w = ½ (a x² + 2 b x y + c y²) (constant curvature): θx = w,y, θy = −w,x at the nodes; the inner
    node's DOFs come out exact and the forces at the inner node vanish (DKT passes the patch test)."""
    rot = _rot(-0.3, 1.1)
    pts, k = _patch_k(rot)
    a, b, c = 2e-3, -7e-4, 1.3e-3
    d = np.zeros(30)
    for i, (x, y) in enumerate(_PXY):
        w = 0.5 * (a * x * x + 2 * b * x * y + c * y * y)
        th = np.array([b * x + c * y, -(a * x + b * y), 0.0])
        d[6 * i:6 * i + 3] = rot @ np.array([0.0, 0.0, w])
        d[6 * i + 3:6 * i + 6] = rot @ th
    got = _solve_inner(k, d)
    np.testing.assert_allclose(got[:5], d[24:29], atol=1e-12)


def test_element_force_kernel_matches_twin():
    rng = np.random.default_rng(5)
    pos = rng.normal(size=(6, 3))
    conn = np.array([[0, 1, 2], [1, 3, 2], [2, 3, 4], [0, 2, 5]])
    kg = np.array([tw.global_k(pos[c], E, NU, T) for c in conn])
    disp, rot = rng.normal(size=(6, 3)) * 1e-3, rng.normal(size=(6, 3)) * 1e-3
    force, moment = np.zeros((6, 3)), np.zeros((6, 3))
    element_forces(kg, conn, disp, rot, force, moment)
    want = np.zeros(36)
    dall = np.concatenate([disp, rot], axis=1).ravel()
    for c in conn:
        dof = [6 * i + j for i in c for j in range(6)]
        want[dof] -= tw.global_k(pos[c], E, NU, T) @ dall[dof]
    got = np.concatenate([force, moment], axis=1).ravel()
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-9 * np.abs(want).max())


def _coupling_twin(dt, v_rel, n, c, st):
    """One node on a still host: the normal spring (total), the shear slider (incremental)."""
    kn, ks, ty, coh, cohr, tanp = c
    dn = float(np.dot(v_rel, n))
    st["un"] += dn * dt
    f = -kn * st["un"]
    if st["broken"]:
        f = max(f, 0.0)
    elif -f > ty:
        st["broken"] = True
        f = 0.0
    fs = st["fs"] - ks * (v_rel - dn * n) * dt
    fs = fs - np.dot(fs, n) * n
    lim = (cohr if st["slipped"] else coh) + max(f, 0.0) * tanp
    if np.linalg.norm(fs) > lim:
        st["slipped"] = True
        fs = fs * lim / np.linalg.norm(fs)
    st["fs"] = fs
    return f * n + fs


def test_coupling_kernel_matches_twin_and_hand_values():
    """A node on a still rigid block: pulled off (tension k_n A u until the yield force, then 0),
    pushed back (compression only), slid (c A + N tan φ, then the residual cohesion)."""
    n = np.array([0.0, 0.6, 0.8])
    s_dir = np.array([1.0, 0.0, 0.0])
    cpl = np.array([[1e6, 5e5, 300.0, 200.0, 50.0, math.tan(math.radians(30.0))]])
    dt = 1e-3
    arrays = dict(vel=np.zeros((1, 3)), host=np.array([0]), hz=np.zeros(1, np.int8), hvel=np.zeros((1, 3)),
                  hpos=np.zeros((1, 3)), nrm=n[None, :].copy(), un=np.zeros(1), fn=np.zeros(1),
                  fs=np.zeros((1, 3)), cstate=np.zeros(1, np.uint8), hforce=np.zeros((1, 3)),
                  hmoment=np.zeros((1, 3)))
    blk = dict(bvel=np.zeros((1, 3)), bspin=np.zeros((1, 3)), bcen=np.array([[0.0, 0.0, -1.0]]))
    st = {"un": 0.0, "fs": np.zeros(3), "broken": False, "slipped": False}
    seq = ([0.1 * n] * 2 + [0.1 * n] * 2 + [-0.1 * n] * 6      # pull 2e-4 (200 N), 4e-4 (400 > 300: break), back
           + [0.05 * s_dir] * 20 + [-0.02 * n + 0.05 * s_dir] * 3)
    out = []
    for v in seq:
        arrays["vel"][0] = v
        force = np.zeros((1, 3))
        coupling(dt, arrays["vel"], arrays["host"], arrays["hz"], arrays["hvel"], arrays["hpos"], arrays["nrm"],
                 cpl, arrays["un"], arrays["fn"], arrays["fs"], arrays["cstate"], force, arrays["hforce"],
                 arrays["hmoment"], blk["bvel"], blk["bspin"], blk["bcen"])
        want = _coupling_twin(dt, v, n, cpl[0], st)
        np.testing.assert_allclose(force[0], want, rtol=1e-12, atol=1e-9)
        np.testing.assert_allclose(arrays["hforce"][0], -force[0])
        out.append((float(arrays["fn"][0]), float(np.linalg.norm(arrays["fs"][0]))))
    assert out[1][0] == pytest.approx(-200.0)          # tension 1e6 × 2e-4, below 300 N
    assert out[3][0] == 0.0 and arrays["cstate"][0] & 1  # 400 N > 300 N: broken
    assert out[7][0] == 0.0                            # back at u_n = 0: no tension, no compression
    assert out[9][0] == pytest.approx(2e-4 * 1e6)      # pushed 2e-4 past: compression k_n A u
    # shear: 5e5 × 5e-5 per step; the limit 200 + 200 tan 30° = 315.47 N, residual 50 + 200 tan 30°
    assert out[21][1] == pytest.approx(12 * 25.0)      # 12 steps of 25 N: below the limit
    assert out[22][1] == pytest.approx(200.0 + 200.0 * math.tan(math.radians(30.0)))   # slides: c A + N tan φ
    assert arrays["cstate"][0] & 2
    assert out[23][1] == pytest.approx(50.0 + 200.0 * math.tan(math.radians(30.0)))    # residual cohesion
    assert out[-1][1] == pytest.approx(50.0 + out[-1][0] * math.tan(math.radians(30.0)))


def _run(text, tmp_path, s=None):
    s = s or Session(out_dir=tmp_path, stdout=io.StringIO())
    s.run_items(s.load_text(text))
    return s


PLATE = """model new
block create brick 20 21 0 1 0 1
block property density 1000
block fix
structure liner create by-quadrilateral 0 0 0 1 0 0 1 1 0 0 1 0 size 4 4
structure liner property isotropic 200e9 0.3 thickness 0.01
"""


def test_cantilever_strip_bends_as_a_plate_strip(tmp_path):
    """A strip 1 m × 0.25 m (4 × 1 cells) clamped at x = 0, an end load P = 20 N on its two end nodes:
    w = P L³ / 3 D b with ν = 0 (a beam of E t³ b / 12), to 1 %."""
    s = _run("""model new
block create brick 20 21 0 1 0 1
block property density 1000
block fix
structure liner create by-quadrilateral 0 0 0 1 0 0 1 0.25 0 0 0.25 0 size 4 1
structure liner property isotropic 200e9 0 thickness 0.01
structure node fix velocity rotation range position-x 0
structure node apply force-z -10 range position-x 1
model solve ratio 1e-7
""", tmp_path)
    nodes = s.model.stores["liner_nodes"]
    tip = np.isclose(nodes["pos0"][:, 0], 1.0)
    d = 200e9 * 0.01 ** 3 / 12.0
    want = -20.0 * 1.0 / (3.0 * d * 0.25)
    np.testing.assert_allclose(nodes["disp"][tip, 2], want, rtol=0.01)
    # the bending moment per unit width P (L − x) / b at the centroids of the elements along x, to 3 % of
    # the root moment (one element across, the load at two corners: the DKT's centroid values are off
    # by about 1.6 N·m/m of 80 here)
    from dec3d.model.liner_output import element_resultants

    els = s.model.stores["liner_elements"]
    along = np.isclose(els["axes"][:, 0, 0], 1.0)
    m = element_resultants(s.model)[along]
    np.testing.assert_allclose(m[:, 3], 20.0 * (1.0 - els["pos"][along, 0]) / 0.25, rtol=0, atol=0.03 * 80.0)
    assert np.abs(m[:, :3]).max() < 1e-6 * np.abs(m[:, 3]).max()         # no membrane force


def test_liner_on_a_rigid_block_face_pulls_off_at_its_strength(tmp_path):
    """A liner on a fixed block's top (1 m²): a uniform upward stress σ as node forces σ × tributary area
    moves it up by σ / k_n well below the tensile strength; above it the springs break and it flies off."""
    base = """model new
block create brick 0 1 0 1 0 1
block property density 1000
block fix
structure liner create by-block-face range position-z 1
structure liner property isotropic 30e9 0.2 thickness 0.1 coupling-stiffness-normal 1e9 coupling-stiffness-shear 1e9 coupling-yield-normal 2e5 coupling-cohesion-shear 1e5
"""
    from dec3d.model.liners import node_areas

    for sigma, holds in ((0.9e5, True), (2.5e5, False)):   # (a sudden load overshoots: up to 2σ)
        s = _run(base, tmp_path)
        nodes, els = s.model.stores["liner_nodes"], s.model.stores["liner_elements"]
        assert els.n == 4 and nodes.n == 5 and (nodes["host"] == 0).all()
        np.testing.assert_allclose(nodes["nrm"], [[0, 0, 1]] * 5, atol=1e-12)
        nodes["fapp"][:, 2] = sigma * node_areas(s.model)
        _run("model cycle 2000\n", tmp_path, s)
        if holds:
            np.testing.assert_allclose(nodes["disp"][:, 2], sigma / 1e9, rtol=1e-3)
            assert not (nodes["cstate"] & 1).any()
            # the reactions went into the block: the springs pull it up by σ × 1 m²
            assert s.model.blocks["fapp"][0, 2] == pytest.approx(sigma, rel=1e-3)
        else:
            assert (nodes["cstate"] & 1).all() and (nodes["disp"][:, 2] > 1e-3).all()


def test_liner_on_a_zoned_block_uses_its_gridpoints(tmp_path):
    s = _run("""model new
block create brick 0 1 0 1 0 1
block zone generate edgelength 0.5
block zone cmodel assign elastic
block zone property young 1e9 poisson 0.25 density 2000
structure liner create by-block-face id 3 group 'top' range position-z 1
""", tmp_path)
    nodes, els = s.model.stores["liner_nodes"], s.model.stores["liner_elements"]
    v = s.model.vertices
    top = np.flatnonzero(np.isclose(v["pos"][: v.n, 2], 1.0))
    assert nodes.n == len(np.unique(np.round(v["pos"][top], 9), axis=0))
    assert (nodes["hz"] == 1).all() and (nodes["host"] == 0).all()
    # each node sits on a gridpoint: its host weight is 1 there
    assert np.allclose(nodes["hw"].max(axis=1), 1.0)
    assert np.allclose(els["axes"][:, 2], [0, 0, 1])
    assert (els["liner"] == 3).all()


@pytest.mark.parametrize("line, where, what", [
    ("structure liner property isotropic 1e9 0.6", "1e9", "Poisson"),
    ("structure liner property isotropic -1e9 0.2", "-1e9", "Young"),
    ("structure liner property thickness 0", "0", "thickness"),
    ("structure liner create by-block-face range position-z 7", "structure", "no surface face"),
    ("structure liner create by-quadrilateral 0 0 0 1 0 0 1 1 0 0 1 0 size 0 2", "0 2", "size"),
])
def test_bad_input_refused_at_its_column(tmp_path, line, where, what):
    s = _run(PLATE, tmp_path)
    with pytest.raises(Dec3dError) as exc:
        _run(line + "\n", tmp_path, s)
    loc = exc.value.location
    assert loc is not None and loc.line == 1
    assert loc.column == line.index(where) + 1 + (where[0] == " "), exc.value.format()
    assert what in exc.value.format()


def test_liner_without_properties_is_refused_at_cycle(tmp_path):
    s = _run("model new\nblock create brick 5 6 0 1 0 1\nblock property density 1\nblock fix\n"
             "structure liner create by-quadrilateral 0 0 0 1 0 0 1 1 0 0 1 0\n", tmp_path)
    with pytest.raises(Dec3dError, match="lacks `isotropic"):
        _run("model cycle 1\n", tmp_path, s)


def test_list_save_restore_vtk(tmp_path):
    text = PLATE + ("structure node fix velocity rotation range position-x 0\n"
                    "structure node apply force-z -10 range position-x 1\n"
                    "structure node history name 'w' displacement-z position 1 1 0\nhistory interval 10\n"
                    "model cycle 300\n")
    out = io.StringIO()
    a = _run(text, tmp_path, Session(out_dir=tmp_path, stdout=out))
    p = tmp_path / "l.sav"
    _run(f"model save '{p}'\nmodel cycle 200\nstructure liner list range id 1\n", tmp_path, a)
    listing = out.getvalue()
    assert "M-xx" in listing and len(listing.split("M-xx")[1].strip().splitlines()) == 2
    b = _run(f"model restore '{p}'\nmodel cycle 200\nblock vtk 'lv'\n", tmp_path)
    for k in ("disp", "rot", "force"):
        np.testing.assert_array_equal(a.model.stores["liner_nodes"][k], b.model.stores["liner_nodes"][k])
    hs = b.model.history_set
    corner = np.flatnonzero(np.all(np.isclose(b.model.stores["liner_nodes"]["pos0"], [1, 1, 0]), axis=1))[0]
    assert hs.items[0].values[-1] == b.model.stores["liner_nodes"]["disp"][corner, 2] < 0
    meshio = pytest.importorskip("meshio")
    from dec3d.model.liner_output import element_resultants

    m = meshio.read(tmp_path / "lv_liners_0000.vtu")
    assert m.cells[0].type == "triangle" and m.cells[0].data.shape == (32, 3)
    np.testing.assert_array_equal(m.cell_data["M_xx"][0], element_resultants(b.model)[:, 3])
    np.testing.assert_array_equal(m.point_data["displacement"], b.model.stores["liner_nodes"]["disp"])


@pytest.mark.parametrize("damp, safety", [(0, 0.0), (2, 0.5), (1, 0.5)])
def test_motion_kernel_matches_twin(damp, safety):
    """The liner nodes' law of motion, density-scaled per degree of freedom, against a plain loop."""
    from dec3d.kernels.beam import move_nodes

    rng = np.random.default_rng(7)
    n = 5
    a = {k: rng.normal(size=(n, 3)) for k in ("pos", "vel", "disp", "rot", "avel", "fapp", "mapp", "force",
                                               "moment")}
    mass, inert = rng.uniform(0.5, 2.0, n), rng.uniform(0.1, 0.3, n)
    rt, rr = rng.uniform(1e3, 1e5, (n, 3)), rng.uniform(1e2, 1e4, (n, 3))
    fix = np.array([0, 1, 8, 63, 4], np.uint8)
    last = rng.normal(size=(n, 6))
    g, dt, alpha = np.array([0.0, 0.0, -9.81]), 1e-3, 0.7
    b = {k: v.copy() for k, v in a.items()}
    im, ii = np.zeros(n), np.zeros(n)
    move_nodes(dt, g, alpha, damp, safety, a["pos"], a["vel"], a["disp"], a["rot"], a["avel"], mass, inert, rt, rr,
              fix, a["fapp"], a["mapp"], a["force"], a["moment"], im, ii, last)
    q = (dt / (2 * safety)) ** 2 if safety else 0.0

    def sg(x):
        return float(x > 0) - float(x < 0)

    for i in range(n):
        for k in range(3):
            for lin in (True, False):
                bit = k if lin else 3 + k
                f = (b["force"][i, k] + b["fapp"][i, k] + mass[i] * g[k]) if lin else b["moment"][i, k] + b["mapp"][i, k]
                m = (max(mass[i], rt[i, k] * q) if lin else max(inert[i], rr[i, k] * q)) if safety else \
                    (mass[i] if lin else inert[i])
                v = b["vel"][i, k] if lin else b["avel"][i, k]
                if not (fix[i] >> bit) & 1:
                    if damp == 1:
                        f -= alpha * abs(f) * sg(v)
                    elif damp == 2:
                        f -= 0.5 * alpha * abs(f) * (sg(v) - sg(f - last[i, bit]))
                    v = v + f / m * dt
                assert (a["vel"] if lin else a["avel"])[i, k] == pytest.approx(v, rel=1e-14, abs=1e-300)
            assert a["disp"][i, k] == pytest.approx(b["disp"][i, k] + a["vel"][i, k] * dt, rel=1e-14)
            assert a["rot"][i, k] == pytest.approx(b["rot"][i, k] + a["avel"][i, k] * dt, rel=1e-14)


def test_liner_weight_goes_into_the_zoned_blocks_gridpoints(tmp_path):
    """A liner (ρ t = 250 kg/m², 1 m²) on a zoned block standing on its held base, under gravity: its
    nodes rest on the gridpoints through the normal springs (compression), whose reactions, Σ = the
    liner's weight 2500 N, go into the gridpoints' applied loads; the liner follows them, k_n-soft."""
    s = _run("""model new
model gravity 0 0 -10
block create brick 0 1 0 1 0 1
block zone generate edgelength 0.5
block zone cmodel assign elastic
block zone property young 1e9 poisson 0.25 density 2000
block gridpoint fix velocity range position-z 0
structure liner create by-block-face range position-z 1
structure liner property isotropic 30e9 0.2 thickness 0.1 density 2500 coupling-stiffness-normal 1e10 coupling-stiffness-shear 1e10 coupling-cohesion-shear 1e5
model solve ratio 1e-6
""", tmp_path)
    nodes = s.model.stores["liner_nodes"]
    v = s.model.vertices
    assert (nodes["hz"] == 1).all() and (nodes["fn"] > 0).all()
    assert v["fapp"][: v.n, 2].sum() == pytest.approx(-2500.0, rel=1e-3)
    assert nodes["fn"].sum() == pytest.approx(2500.0, rel=1e-3)
    # the liner's nodes moved with the top of the block, plus the springs' give 2500 / 1e10 m
    from dec3d.model.liners import node_areas

    sink = np.einsum("kj,kj->k", nodes["hw"], v["disp"][nodes["hgp"], 2])   # the host points (gridpoints) sank
    assert (sink < -1e-6).all()
    np.testing.assert_allclose(nodes["un"], -nodes["fn"] / (1e10 * node_areas(s.model)), rtol=1e-9)
    np.testing.assert_allclose(nodes["disp"][:, 2], sink + nodes["un"], rtol=0, atol=1e-3 * abs(sink).max())


def test_dynamic_strip_vibrates_at_its_first_frequency(tmp_path):
    """Undamped, real masses (the liner bounds Δt): a cantilever strip 2 m × 0.25 m (ν = 0, t = 0.08 m,
    steel) under a tip load applied at once swings about its static deflection with the first period of
    a cantilever, 2π L² / (1.8751² √(D / ρ t)) = 0.061125 s (measured 0.061690, +0.9 %: lumped node masses on 8 × 1 cells; bar 3 %)."""
    from dec3d.physics.liners import liner_timestep

    s = _run("""model new
block create brick 10 11 10 11 10 11
block property density 2000
block fix
block mechanical damping none
structure liner create by-quadrilateral 0 0 0 2 0 0 2 0.25 0 0 0.25 0 size 8 1
structure liner property isotropic 200e9 0 thickness 0.08
structure node fix velocity rotation range position-x 0
structure node apply force-z -3200 range position-x 2
structure node history name 'w' displacement-z position 2 0 0
history interval 1
""", tmp_path)
    with pytest.raises(Dec3dError, match="liner has no density"):
        _run("model cycle 1\n", tmp_path, s)
    _run("structure liner property density 7800\nmodel solve time 0.14\n", tmp_path, s)
    assert s.model.rigid_engine.dt <= liner_timestep(s.model) < 1e-4
    d = 200e9 * 0.08 ** 3 / 12.0
    h = s.model.history_set.items[0]
    t, y = np.array(h.times), np.array(h.values) + 6400.0 * 2.0 ** 3 / (3 * d * 0.25)
    down = np.flatnonzero((y[:-1] > 0) & (y[1:] <= 0))
    tc = t[down] + (t[down + 1] - t[down]) * y[down] / (y[down] - y[down + 1])
    period = 2 * np.pi * 2.0 ** 2 / (1.875104 ** 2 * np.sqrt(d / (7800 * 0.08)))
    assert len(tc) >= 2 and tc[1] - tc[0] == pytest.approx(period, rel=0.03)


def test_lined_tunnel_example_holds_the_crown(tmp_path):
    """examples/support/lined_tunnel.dat: the crown slab that falls unsupported (support/bolted_tunnel.dat)
    hangs on the shotcrete liner: it settles less than 2 mm, the liner is one connected mesh over the
    tunnel's rock face (corners of blocks that settled apart by micrometres merged), every coupling
    spring holds, and the couplings pull the slab up by at least its weight."""
    import csv

    from conftest import ROOT

    deck = ROOT / "examples" / "support" / "lined_tunnel.dat"
    s = _run(deck.read_text(), tmp_path)
    m = s.model
    nodes, els = m.stores["liner_nodes"], m.stores["liner_elements"]
    b = m.blocks
    crown = np.flatnonzero(np.linalg.norm(b["centroid"][: b.n] - [0.0, 0.5, 2.0], axis=1) < 0.3)
    assert len(crown) == 2
    assert abs(b["disp"][crown, 2]).max() < 2e-3
    rows = list(csv.reader(open(tmp_path / "crown_lined.csv")))[1:]
    assert abs(float(rows[-1][-1])) < 2e-3
    assert nodes.n == 72 and els.n == 96 and (nodes["host"] >= 0).all() and not nodes["cstate"].any()
    # the couplings pull the crown slab up by more than its weight (the liner's arching presses the
    # joints too); all of them together carry the liner's own weight into the rock
    assert b["fapp"][crown, 2].sum() > b["mass"][crown].sum() * 9.81
    liner_weight = (els["area"] * 0.1 * 2400 * 9.81).sum()
    assert b["fapp"][: b.n, 2].sum() == pytest.approx(-liner_weight, rel=2e-3)
    assert (tmp_path / "tunnel_lined_liners_0000.vtu").exists()


def test_excavating_the_host_frees_the_liner(tmp_path):
    """`block excavate` of the zoned block a liner is coupled to: its nodes are reported, free from then
    on (no coupling force, never a NaN) and the coupling's pull is taken back off the gridpoints."""
    out = io.StringIO()
    s = _run("""model new
block create brick 0 1 0 1 0 1
block zone generate edgelength 0.5
block zone cmodel assign elastic
block zone property young 1e9 poisson 0.25 density 2000
block gridpoint fix velocity range position-z 0
structure liner create by-block-face range position-z 1
structure liner property isotropic 30e9 0.2 thickness 0.1 density 2400 coupling-stiffness-normal 1e9 coupling-stiffness-shear 1e9 coupling-yield-normal 2e5 coupling-cohesion-shear 1e5
structure node apply force-z 100
model cycle 300
""", tmp_path, Session(out_dir=tmp_path, stdout=out))
    nodes, v = s.model.stores["liner_nodes"], s.model.vertices
    assert abs(v["fapp"][: v.n, 2].sum()) > 100
    _run("block excavate\nmodel cycle 100\n", tmp_path, s)
    assert f"{nodes.n} liner node(s) lay in the excavated blocks" in out.getvalue()
    assert (nodes["host"] == -1).all() and not nodes["hforce"].any() and not nodes["fs"].any()
    assert np.isfinite(nodes["pos"]).all() and abs(v["fapp"][: v.n]).max() < 1e-9


def test_quadrilateral_mesh_and_its_hosts(tmp_path):
    """`by-quadrilateral … size n1 n2`: 2 n1 n2 triangles (4 n1 n2 with `cross-diagonal`, a node at each
    cell's centre), z by the right-hand rule; nodes on or in a visible block are coupled to it, the
    others free."""
    s = _run("""model new
block create brick 0 1 0 1 0 1
structure liner create by-quadrilateral 0 0 1 2 0 1 2 1 1 0 1 1 size 4 2
structure liner create by-quadrilateral 0 0 3 1 0 3 1 1 3 0 1 3 size 2 2 cross-diagonal id 7
""", tmp_path)
    nodes, els = s.model.stores["liner_nodes"], s.model.stores["liner_elements"]
    a, b = els["liner"] == 1, els["liner"] == 7
    assert a.sum() == 16 and b.sum() == 16
    assert (nodes["liner"] == 1).sum() == 15 and (nodes["liner"] == 7).sum() == 9 + 4
    np.testing.assert_allclose(els["axes"][:, 2], [[0, 0, 1]] * els.n, atol=1e-12)
    np.testing.assert_allclose(els["area"][a].sum(), 2.0) and np.testing.assert_allclose(els["area"][b].sum(), 1.0)
    on_block = (nodes["liner"] == 1) & (nodes["pos0"][:, 0] <= 1.0 + 1e-9)
    assert (nodes["host"][on_block] == 0).all() and (nodes["host"][~on_block] == -1).all()
    assert list(nodes["id"]) == list(range(1, nodes.n + 1))


def test_block_faces_against_another_block_are_not_lined(tmp_path):
    """Two rigid bricks stacked: `by-block-face` lines the ten outer faces (fans of four triangles about
    their centroids), not the two that touch; one closed mesh of 12 corners + 10 centroids."""
    s = _run("""model new
block create brick 0 1 0 1 0 1
block create brick 0 1 0 1 1 2
structure liner create by-block-face
""", tmp_path)
    nodes, els = s.model.stores["liner_nodes"], s.model.stores["liner_elements"]
    assert els.n == 40 and nodes.n == 22
    assert not np.isclose(els["pos"][:, 2], 1.0).any() or (np.abs(els["axes"][:, 2, 2]) < 1e-12)[
        np.isclose(els["pos"][:, 2], 1.0)].all()
    # outward normals: from the middle of the pair to each element's centroid
    assert (np.einsum("ij,ij->i", els["axes"][:, 2], els["pos"] - [0.5, 0.5, 1.0]) > 0).all()
    assert set(nodes["host"]) == {0, 1}


def test_coupling_histories(tmp_path):
    """`structure liner history coupling-…`: a liner on a fixed block pulled up uniformly by σ (node
    forces σ × tributary area): normal displacement σ / k_n, normal stress σ (tension positive), no
    shear; the histories survive save/restore."""
    from dec3d.model.liners import node_areas

    s = _run("""model new
block create brick 0 1 0 1 0 1
block property density 1000
block fix
structure liner create by-block-face range position-z 1
structure liner property isotropic 30e9 0.2 thickness 0.1 coupling-stiffness-normal 1e9 coupling-stiffness-shear 1e9 coupling-yield-normal 2e5 coupling-cohesion-shear 1e5
structure liner history name 'un' coupling-displacement-normal component-id 2 node 3
structure liner history coupling-stress-normal position 0.5 0.9 1 node 1
structure liner history coupling-displacement-shear component-id 1
structure liner history coupling-stress-shear component-id 1 node 2
history interval 10
""", tmp_path)
    nodes = s.model.stores["liner_nodes"]
    nodes["fapp"][:, 2] = 0.9e5 * node_areas(s.model)
    p = tmp_path / "h.sav"
    _run(f"model cycle 2000\nmodel save '{p}'\n", tmp_path, s)
    v = [h.values[-1] for h in s.model.history_set.items]
    assert v[0] == pytest.approx(0.9e5 / 1e9, rel=1e-3) and v[1] == pytest.approx(0.9e5, rel=1e-3)
    assert abs(v[2]) < 1e-9 and abs(v[3]) < 1.0
    b = _run(f"model restore '{p}'\nmodel cycle 10\n", tmp_path)
    assert [h.label for h in b.model.history_set.items] == [h.label for h in s.model.history_set.items]
    assert b.model.history_set.items[0].values[-1] == pytest.approx(v[0], rel=1e-6)
    with pytest.raises(Dec3dError, match="nodes 1, 2 and 3|3"):
        _run("structure liner history coupling-stress-shear component-id 1 node 4\n", tmp_path, b)
