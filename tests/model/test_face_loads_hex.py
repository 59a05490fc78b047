"""`block face apply stress` on hexahedral mixed zones: each square zone face is loaded as the
quadrilateral (mean of its two diagonal splits, A/4 per corner), not by thirds of one split."""
import numpy as np

SIG = -1e6


def _hex_cube(session, div="2 2 2"):
    session.command("block create brick 0 1 0 1 0 1")
    session.command(f"block zone generate hexahedra divisions {div}")
    return session.model


def test_top_face_corner_loads_are_quarters(session):
    m = _hex_cube(session)
    session.command(f"block face apply stress-zz {SIG} range position-z 1")
    f, p = m.vertices["fface"], m.vertices["pos"]
    # sigma * A exactly (area 1, outward normal +z): -1e6 N
    np.testing.assert_allclose(f.sum(axis=0), [0.0, 0.0, SIG], rtol=0, atol=1e-6)
    assert np.all(f[:, :2] == 0.0)
    top = np.isclose(p[:, 2], 1.0)
    assert np.all(f[~top] == 0.0)
    # zone faces are 0.5 x 0.5: a quarter of sigma * 0.25 per zone face at each of its corners
    q = SIG * 0.25 / 4
    nfaces = (1 + np.isclose(p[:, 0], 0.5)) * (1 + np.isclose(p[:, 1], 0.5))  # 1, 2 or 4 zone faces
    np.testing.assert_allclose(f[top, 2], q * nfaces[top], rtol=1e-12)


def test_parallelogram_face(session):
    # a sheared hexahedral block: side faces are parallelograms, still A/4 per corner
    session.command("block create prism face-1 0 0 0 2 0 0 2 1 0 0 1 0 face-2 0.5 0 1 2.5 0 1 2.5 1 1 0.5 1 1")
    session.command("block zone generate hexahedra divisions 1 1 1")
    m = session.model
    session.command(f"block face apply stress-yy {SIG} range position-y 0")
    f, p = m.vertices["fface"], m.vertices["pos"]
    front = np.isclose(p[:, 1], 0.0)
    # face y = 0 has area 2 x 1, outward normal -y: force +2e6 in y, shared by 4 corners
    np.testing.assert_allclose(f.sum(axis=0), [0.0, -SIG * 2.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(f[front, 1], -SIG * 2.0 / 4, rtol=1e-12)


def _bilinear_loads(c):
    """sigma-free consistent loads int N_i dA of a flat quadrilateral c (4, 2) (counter-clockwise),
    by 2 x 2 Gauss quadrature of the bilinear map (exact: the integrand is bilinear)."""
    xi = np.array([-1, 1, 1, -1.0])
    eta = np.array([-1, -1, 1, 1.0])
    out = np.zeros(4)
    g = 1 / np.sqrt(3)
    for a in (-g, g):
        for b in (-g, g):
            N = 0.25 * (1 + xi * a) * (1 + eta * b)
            dNa = 0.25 * xi * (1 + eta * b)
            dNb = 0.25 * eta * (1 + xi * a)
            J = np.array([[dNa @ c[:, 0], dNa @ c[:, 1]], [dNb @ c[:, 0], dNb @ c[:, 1]]])
            out += N * np.linalg.det(J)
    return out


def test_trapezoid_face_gets_bilinear_consistent_loads(session):
    quad = np.array([[0.0, 0.0], [2.0, 0.0], [1.4, 1.0], [0.3, 1.0]])
    pts = " ".join(f"{x} {y} 0" for x, y in quad)
    top = " ".join(f"{x} {y} 1" for x, y in quad)
    session.command(f"block create prism face-1 {pts} face-2 {top}")
    session.command("block zone generate hexahedra divisions 1 1 1")
    m = session.model
    session.command(f"block face apply stress-zz {SIG} range position-z 1")
    f, p = m.vertices["fface"], m.vertices["pos"]
    expect = SIG * _bilinear_loads(quad)
    for k, (x, y) in enumerate(quad):
        row = np.flatnonzero(np.all(np.isclose(p, [x, y, 1.0]), axis=1))
        assert len(row) == 1
        np.testing.assert_allclose(f[row[0]], [0.0, 0.0, expect[k]], rtol=1e-12, atol=1e-9)
    # not the quarters of a parallelogram: the loads differ between corners
    assert np.ptp(expect) > 0.05 * abs(SIG)


def test_mixed_stresses_on_the_two_triangles_keep_thirds(session):
    # a stress on only one triangle of a zone face: no pairing, thirds of that triangle
    m = _hex_cube(session, "1 1 1")
    fc = m.faces
    top = np.flatnonzero(np.isclose(m.vertices["pos"][m.face_vertices["vertex"][fc["vstart"]], 2], 1.0)
                         & (fc["nvert"] == 3))
    from dec3d.model.face_loads import apply_face_stress
    mask = np.zeros(fc.n, bool)
    tri = [r for r in top if np.allclose(m.vertices["pos"][m.face_vertices["vertex"][fc["vstart"][r] + np.arange(3)], 2], 1.0)]
    assert len(tri) == 2
    mask[tri[0]] = True
    assert apply_face_stress(m, mask, np.array([0, 0, SIG, 0, 0, 0.0])) == 1
    f = m.vertices["fface"]
    nz = f[:, 2] != 0
    assert nz.sum() == 3
    np.testing.assert_allclose(f[nz, 2], SIG * 0.5 / 3, rtol=1e-12)


def test_uniaxial_hex_cube_solved_by_face_stress(session):
    m = _hex_cube(session)
    for line in ("block zone cmodel assign elastic",
                 "block zone property young 10e9 poisson 0.25 density 2500",
                 "block gridpoint apply velocity-z 0 range position-z 0",
                 "block gridpoint apply velocity-x 0 range position-x 0",
                 "block gridpoint apply velocity-y 0 range position-y 0",
                 f"block face apply stress-zz {SIG} range position-z 1",
                 "model solve ratio 1e-8"):
        session.command(line)
    p0 = m.vertices["pos"] - m.vertices["disp"]
    u = m.vertices["disp"]
    # least-squares gradient of u over the gridpoints
    A = np.column_stack([p0, np.ones(len(p0))])
    grad = np.linalg.lstsq(A, u, rcond=None)[0][:3].T
    np.testing.assert_allclose(grad[2, 2], SIG / 10e9, rtol=1e-3)
    np.testing.assert_allclose(grad[0, 0], -0.25 * SIG / 10e9, rtol=1e-3)
    np.testing.assert_allclose(grad[1, 1], -0.25 * SIG / 10e9, rtol=1e-3)
    s = m.store("zones")["stress"]
    spread = np.abs(s - np.array([0, 0, SIG, 0, 0, 0])).max() / abs(SIG)
    assert spread <= 1e-6


def test_joined_hex_blocks_top_loads_are_quarters(session):
    # two joined bricks zoned conformingly: each block's zone faces loaded as quadrilaterals,
    # the shared face takes nothing
    session.command("block create brick 0 1 0 1 0 1")
    session.command("block create brick 1 2 0 1 0 1")
    session.command("block join")
    session.command("block zone generate hexahedra divisions 1 1 1")
    m = session.model
    session.command(f"block face apply stress-zz {SIG} range position-z 1")
    f, p = m.vertices["fface"], m.vertices["pos"]
    np.testing.assert_allclose(f.sum(axis=0), [0.0, 0.0, SIG * 2.0], atol=1e-6)
    top = np.isclose(p[:, 2], 1.0)
    np.testing.assert_allclose(f[top, 2], SIG / 4, rtol=1e-12)   # one zone face per block row
    assert np.all(f[~top] == 0.0)
