"""Consistent nodal loads of face stresses on FE blocks (``kernels/feblock_shape.face_stress_loads``,
``model/face_loads``: `block face apply stress` on the eight surface triangles of a 20-node
element face loads the 8-node face as a whole).

The twin integrates N_a sigma n over a face of the brick with the test twin's 20-node shape
functions (tests/feblock_twin.py) restricted to the face, n dA from complex-step derivatives of
the map, numpy's 4-point Gauss-Legendre rule (the integrand is of degree 5 per direction, so
both rules are exact and must agree to round-off). Closed forms: a flat parallelogram face of
area A under a traction t gets -A t/12 per corner and A t/3 per mid-edge node (8 nodes), A t/4
per corner (4 nodes); a bar pulled by sigma ends at sigma L / E.
"""
import io

import numpy as np
import pytest
from feblock_twin import TABLE, distorted, twin_dn, twin_n

from dec3d.kernels.feblock_shape import FACES, face_stress_loads
from dec3d.session import Session

#: FACES rows by the text's Table 3: (master axis normal to the face, side)
FACE_SIDE = [(2, -1), (2, 1), (1, -1), (1, 1), (0, -1), (0, 1)]

SIG = np.array([3.0e5, -1.0e5, 2.0e5, 0.7e5, -0.4e5, 1.3e5])


def _sigma(s6):
    return np.array([[s6[0], s6[3], s6[4]], [s6[3], s6[1], s6[5]], [s6[4], s6[5], s6[2]]])


def twin_face_loads(x, axis, side, s6, nq=4):
    """(20, 3): int N_a sigma n dA over the face y_axis = side of the element with nodes x (20, 3)."""
    i, j = (axis + 1) % 3, (axis + 2) % 3         # e_i x e_j = e_axis
    g, w = np.polynomial.legendre.leggauss(nq)
    f = np.zeros((20, 3))
    for p, wp in zip(g, w):
        for q, wq in zip(g, w):
            y = np.zeros(3)
            y[axis], y[i], y[j] = side, p, q
            dx = twin_dn(y).T @ x                     # (3, 3): row k = dx/dy_k
            nda = side * np.cross(dx[i], dx[j])
            f += wp * wq * np.outer(twin_n(y), _sigma(s6) @ nda)
    return f


@pytest.mark.parametrize("face", range(6))
def test_face_stress_loads_match_the_twin_on_a_distorted_element(face):
    x = distorted(seed=3, amp=0.1)
    f = np.zeros((20, 3))
    face_stress_loads(np.ascontiguousarray(x), FACES[face][None, :].astype(np.int64), SIG[None, :].copy(), f)
    ref = twin_face_loads(x, *FACE_SIDE[face], SIG)
    assert np.abs(f - ref).max() < 1e-10 * np.abs(ref).max()
    # nodes off the face get nothing; the face's nodes are those with y_axis = side in the table
    axis, side = FACE_SIDE[face]
    off = TABLE[:, axis] != side
    assert not f[off].any()


def test_flat_faces_closed_form_8_and_4_nodes():
    """A parallelogram face of area A (sheared, tilted) under a traction t = sigma n: -A t/12
    per corner and A t/3 per mid-edge node with 8 nodes, A t/4 per corner with 4."""
    c = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.5], [2.6, 1.5, 1.0], [0.6, 1.5, 0.5]])
    mid = 0.5 * (c + np.roll(c, -1, axis=0))
    pos = np.vstack([c, mid])
    an = np.cross(c[1] - c[0], c[3] - c[0])               # n A (counter-clockwise: this side out)
    t = _sigma(SIG) @ an
    f8 = np.zeros((8, 3))
    face_stress_loads(pos, np.arange(8, dtype=np.int64)[None, :], SIG[None, :].copy(), f8)
    assert np.allclose(f8[:4], -t / 12, rtol=1e-13, atol=1e-13 * np.abs(t).max())
    assert np.allclose(f8[4:], t / 3, rtol=1e-13, atol=1e-13 * np.abs(t).max())
    f4 = np.zeros((4, 3))
    face_stress_loads(c, np.arange(4, dtype=np.int64)[None, :], SIG[None, :].copy(), f4)
    assert np.allclose(f4, t / 4, rtol=1e-13, atol=1e-13 * np.abs(t).max())


# ----------------------------------------------------------------------------- in the model
def _session(tmp_path):
    return Session(out_dir=tmp_path, stdout=io.StringIO())


def test_block_face_apply_stress_loads_an_fe_face_consistently(tmp_path):
    """One 20-node element (2 x 1 x 1 m): `block face apply stress` on its x = 2 face (A = 1 m^2)
    gives -A sigma/12 at its four corners, A sigma/3 at its four mid-edge nodes, nothing elsewhere
    (the slave node's share is not left on it)."""
    s = _session(tmp_path)
    s.command("""model configure feblock
block create brick 0 2 0 1 0 1
feblock generate 2 1 1
block face apply stress -1e5 0 0 2e4 0 0 range position-x 2""")
    v = s.model.vertices
    f = v["fface"]
    t = np.array([-1e5, 2e4, 0.0])                       # sigma . (1, 0, 0) A
    on = np.abs(v["pos"][:, 0] - 2) < 1e-9
    master = on & ~v["feslave"]
    corner = master & (np.abs(v["pos"][:, 1] - 0.5) > 0.25) & (np.abs(v["pos"][:, 2] - 0.5) > 0.25)
    mid = master & ~corner
    assert corner.sum() == 4 and mid.sum() == 4
    assert np.allclose(f[corner], -t / 12, atol=1e-9) and np.allclose(f[mid], t / 3, atol=1e-9)
    assert not f[~master].any()


def _mesh8(nx, ny, nz, L, B, H):
    """The FE-block text's mesh file of nx ny nz 8-node bricks in [0,L]x[0,B]x[0,H]."""
    pts = [(i * L / nx, j * B / ny, k * H / nz) for k in range(nz + 1) for j in range(ny + 1) for i in range(nx + 1)]

    def idx(i, j, k):
        return 1 + i + (nx + 1) * (j + (ny + 1) * k)
    el = [[idx(i, j, k), idx(i + 1, j, k), idx(i + 1, j + 1, k), idx(i, j + 1, k), idx(i, j, k + 1),
           idx(i + 1, j, k + 1), idx(i + 1, j + 1, k + 1), idx(i, j + 1, k + 1)]
          for k in range(nz) for j in range(ny) for i in range(nx)]
    return (f"bar\n{len(pts)} {len(el)}\n" + "".join("%r %r %r\n" % p for p in pts)
            + "".join(" ".join(map(str, e)) + "\n" for e in el))


@pytest.mark.parametrize("mesh", ["generate 4x1x1", "read 8-node 2x2x2"])
def test_bar_pulled_by_a_face_stress_ends_at_sigma_l_over_e(tmp_path, mesh):
    """A bar (L = 4 m, 1 x 1 m section, E = 10 MPa, nu = 0.25) on symmetry rollers at x = 0,
    y = 0, z = 0, pulled by sigma = 0.1 MPa on its x = L face: every end node at sigma L / E =
    0.04 m within 0.5 %. Meshed by `feblock generate` (one element across: hourglass control) or
    read from a file of 8-node bricks (mid-edge nodes inserted). With thirds of the surface
    triangles it ended 0.8 to 15 % long (4 x 1 x 1)."""
    E, sig, L = 1e7, 1e5, 4.0
    if mesh.startswith("read"):
        (tmp_path / "bar.fem").write_text(_mesh8(2, 2, 2, L, 1.0, 1.0))
        make = "feblock read 'bar.fem'"
    else:
        make = f"block create brick 0 {L} 0 1 0 1\nfeblock generate 1 1 1"
    s = _session(tmp_path)
    s.command(f"""model configure feblock
{make}
feblock change cmodel elastic young {E} poisson 0.25 density 1000
block gridpoint apply velocity-x 0 range position-x 0
block gridpoint apply velocity-y 0 range position-y 0
block gridpoint apply velocity-z 0 range position-z 0
block face apply stress {sig} 0 0 0 0 0 range position-x {L}
model large-strain off
model solve ratio 1e-9""")
    v = s.model.vertices
    end = np.flatnonzero((np.abs(v["pos"][:, 0] - L) < 1e-9) & ~v["feslave"])
    assert len(end) == (8 if mesh.startswith("generate") else 21)
    u = v["disp"][end, 0]
    assert np.abs(u / (sig * L / E) - 1).max() < 0.005, u


def test_pressed_fe_cubes_settle_as_two_columns_and_a_joint(tmp_path):
    """Two FE cubes (1 m, 2 x 2 x 2 elements, E = 1 GPa, nu = 0.25) stacked on an elastic joint
    (kn = 10 GPa/m), rollers on the sides and base, sigma = 1 MPa pressing the top face: the top
    settles by sigma (2 H / M + 1 / kn) = 1.7667 mm (M = E (1 - nu) / ((1 + nu)(1 - 2 nu)) =
    1.2 GPa) within 1 % at every top node (with thirds: 3 to 11 % more)."""
    s = _session(tmp_path)
    s.command("""model configure feblock
block create brick 0 1 0 1 0 1
block create brick 0 1 0 1 1 2
feblock generate 0.5 0.5 0.5
block zone cmodel assign elastic
block zone property young 1e9 poisson 0.25 density 2000
block contact jmodel assign elastic
block contact material-table default property stiffness-normal 1e10 stiffness-shear 1e10
block gridpoint apply velocity-z 0 range position-z 0
block gridpoint apply velocity-x 0 range position-x 0
block gridpoint apply velocity-x 0 range position-x 1
block gridpoint apply velocity-y 0 range position-y 0
block gridpoint apply velocity-y 0 range position-y 1
block face apply stress 0 0 -1e6 0 0 0 range position-z 2
model large-strain off
model solve ratio 1e-8""")
    v = s.model.vertices
    top = np.flatnonzero((np.abs(v["pos"][:, 2] - 2) < 1e-9) & ~v["feslave"])
    assert len(top) == 21
    ref = 1e6 * (2 / 1.2e9 + 1 / 1e10)
    assert np.abs(-v["disp"][top, 2] / ref - 1).max() < 0.01


def test_table_driven_face_stress_loads_an_fe_face_as_the_fixed_one(tmp_path):
    """`block face apply stress … table` on an FE face takes the consistent face loads too: at
    multiplier 1 the table-driven nodal forces (``quiet.dynamic_face_loads``) are those of the
    same fixed stress (-A sigma/12 at the corners, A sigma/3 at the mid-edge nodes), not thirds of
    the eight triangles (0 at the corners, A/4 at the mid-edge nodes)."""
    from dec3d.model.quiet import dynamic_face_loads

    s = _session(tmp_path)
    s.command("""model configure feblock
block create brick 0 2 0 1 0 1
feblock generate 2 1 1
table 1 add (0, 1) (10, 1)
block face apply stress -1e5 0 0 2e4 0 0 table 1 range position-x 2""")
    v = s.model.vertices
    (_x, _y, rows, force), = dynamic_face_loads(s.model)
    got = np.zeros((v.n, 3))
    got[rows] = force
    t = np.array([-1e5, 2e4, 0.0])
    on = np.abs(v["pos"][:, 0] - 2) < 1e-9
    master = on & ~v["feslave"]
    corner = master & (np.abs(v["pos"][:, 1] - 0.5) > 0.25) & (np.abs(v["pos"][:, 2] - 0.5) > 0.25)
    mid = master & ~corner
    assert np.allclose(got[corner], -t / 12, atol=1e-9) and np.allclose(got[mid], t / 3, atol=1e-9)
    assert not got[~master].any()
    s.command("block face apply stress -1e5 0 0 2e4 0 0 range position-x 2")
    assert np.allclose(got, v["fface"], atol=1e-9)
