"""Sub-contacts on zoned blocks (kernels.gpcontact) against slow twins written here."""
import numpy as np
import pytest

from dec3d.kernels.gpcontact import mixed_move_points, mixed_subcontact_forces, surface_weights
from dec3d.kernels.joints import NPROP, P_KN, P_KS
from dec3d.kernels.joints.mohr import P_TANF


def _nearest_twin(p, tri):
    """Nearest point of a triangle by brute force: a fine barycentric lattice, then the best of it
    refined by a local lattice (no projection formulas)."""
    best = None
    n = 200
    for u in range(n + 1):
        for v in range(n + 1 - u):
            lam = np.array([u, v, n - u - v]) / n
            q = lam @ tri
            d = float(np.sum((q - p) ** 2))
            if best is None or d < best[0]:
                best = (d, lam)
    return best


def test_surface_weights_find_the_nearest_triangle_point():
    rng = np.random.default_rng(3)
    # one zoned block with two surface triangles and one rigid block
    vpos = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.3], [5, 5, 5.0]])
    fverts = np.array([0, 1, 2, 1, 3, 2, 4, 4, 4])
    fvstart = np.array([0, 3, 6])
    fnvert = np.array([3, 3, 4])          # the rigid block's face is not a triangle
    bfstart = np.array([0, 2])
    bfcount = np.array([2, 1])
    zoned = np.array([True, False])
    pts = rng.uniform(-0.3, 1.3, (25, 3))
    owner = np.zeros(25, np.int64)
    ca, cb = np.array([0]), np.array([1])
    na, wa, nb, wb = (np.empty((25, 3), np.int64), np.empty((25, 3)), np.empty((25, 3), np.int64), np.empty((25, 3)))
    surface_weights(owner, pts, ca, cb, zoned, vpos, bfstart, bfcount, fvstart, fnvert, fverts, na, wa, nb, wb)
    assert (nb == -1).all() and (wb == 0).all()
    assert (wa >= -1e-15).all() and np.allclose(wa.sum(axis=1), 1.0)
    tris = [vpos[[0, 1, 2]], vpos[[1, 3, 2]]]
    for i, p in enumerate(pts):
        d_twin = min(_nearest_twin(p, t)[0] for t in tris)
        q = wa[i] @ vpos[na[i]]
        # the lattice is 1/200 fine: the kernel's point is at least as near, within the lattice error
        assert np.sum((q - p) ** 2) <= d_twin + 1e-12
        assert np.sum((q - p) ** 2) >= d_twin - 2 * 0.01 * np.sqrt(d_twin) - 1e-4


def _force_twin(dt, vel_rigid, spin, centroid, gvel, x, n, kn, ks, area, wa_nodes, wa):
    """The elastic contact force on B (rigid block 1) from a zoned side A, one step from zero:
    relative velocity at x, displacement increment, springs (compression positive)."""
    va = sum(w * gvel[k] for k, w in zip(wa_nodes, wa))
    vb = vel_rigid + np.cross(spin, x - centroid)
    du = (vb - va) * dt
    dun = du @ n
    dus = du - dun * n
    fn = -kn * area * dun
    fs = -ks * area * dus
    return fn * n + fs


def test_mixed_forces_go_to_gridpoints_by_weight_and_balance():
    dt = 1e-3
    vpos = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]])
    gvel = np.array([[0, 0, 0.01], [0, 0, -0.02], [0.01, 0, 0.0]])
    gforce = np.zeros((3, 3))
    bpos = np.array([[0.3, 0.3, -0.5], [0.3, 0.3, 0.5]])
    bvel = np.array([[0, 0, 0.0], [0.0, 0.002, -0.05]])
    bspin = np.array([[0, 0, 0.0], [0.1, 0.0, 0.02]])
    bforce = np.zeros((2, 3))
    bmoment = np.zeros((2, 3))
    ca, cb = np.array([0]), np.array([1])
    cn = np.array([[0, 0, 1.0]])
    prop = np.zeros((1, NPROP))
    prop[0, P_KN], prop[0, P_KS], prop[0, P_TANF] = 1e9, 5e8, 1e3
    x = np.array([0.25, 0.35, 0.0])
    lam = np.array([0.4, 0.25, 0.35])            # x = lam @ vpos
    assert np.allclose(lam @ vpos, x)
    na, wa = np.array([[0, 1, 2]]), lam[None, :].copy()
    nb, wb = np.full((1, 3), -1), np.zeros((1, 3))
    sc = dict(contact=np.array([0]), pos=x[None, :].copy(), area=np.array([0.2]), fn=np.zeros(1),
              fs=np.zeros((1, 3)), un=np.zeros(1), udil=np.zeros(1), us=np.zeros((1, 3)), state=np.zeros(1, np.int64))
    mixed_subcontact_forces(dt, bpos, bvel, bspin, bforce, bmoment, gvel, gforce, ca, cb, cn, np.array([0]), prop,
                            sc["contact"], sc["pos"], sc["area"], sc["fn"], sc["fs"], sc["un"], sc["udil"], sc["us"],
                            sc["state"], np.zeros((1, 8)), na, wa, nb, wb)
    f_b = _force_twin(dt, bvel[1], bspin[1], bpos[1], gvel, x, cn[0], 1e9, 5e8, 0.2, [0, 1, 2], lam)
    assert np.allclose(bforce[1], f_b, rtol=1e-12, atol=1e-6)
    assert np.allclose(bforce[0], 0.0)                                   # side A is zoned: nothing on its block
    assert np.allclose(gforce, -np.outer(lam, f_b), rtol=1e-12, atol=1e-6)
    # force and moment balance to round-off: gridpoint forces act at the gridpoints
    tot = bforce.sum(axis=0) + gforce.sum(axis=0)
    mom = bmoment[1] + np.cross(bpos[1], bforce[1]) + np.cross(vpos, gforce).sum(axis=0)
    assert np.abs(tot).max() < 1e-9 * np.abs(f_b).max()
    assert np.abs(mom).max() < 1e-9 * np.abs(f_b).max()


def test_mixed_move_points_average_the_two_sides():
    dt = 0.01
    gvel = np.array([[1.0, 0, 0], [0, 2.0, 0], [0, 0, 3.0]])
    bpos = np.array([[0, 0, 0.0], [0, 0, 1.0]])
    bvel = np.array([[0, 0, 0.0], [0.5, 0, 0]])
    bspin = np.array([[0, 0, 0.0], [0, 0, 1.0]])
    pts = np.array([[0.2, 0.3, 0.0]])
    na, wa = np.array([[0, 1, 2]]), np.array([[0.5, 0.3, 0.2]])
    nb, wb = np.full((1, 3), -1), np.zeros((1, 3))
    x = pts[0].copy()
    mixed_move_points(dt, np.array([0]), np.array([1]), np.array([0]), pts, bpos, bvel, bspin, gvel, na, wa, nb, wb)
    va = 0.5 * gvel[0] + 0.3 * gvel[1] + 0.2 * gvel[2]
    vb = bvel[1] + np.cross(bspin[1], x - bpos[1])
    assert np.allclose(pts[0], x + 0.5 * dt * (va + vb), rtol=0, atol=1e-15)


def test_zoned_side_carries_the_face_face_area():
    """Contact 0: A zoned, B rigid, both faces' vertices with half the overlap 1 m² each -> A's
    vertices and the crossing keep it all, scaled back to 1 m², B's vertices get 0. Contact 1:
    B zoned but its gridpoints hold only 0.1 of 1 m² (a rigid face inside one zone triangle):
    unchanged. Contact 2: both rigid: unchanged; point sub-contacts (kind 3) never change."""
    from dec3d.physics.contacts import zoned_side_carries
    sc = np.array([0, 0, 0, 0, 0, 0, 1, 1, 1, 2, 2, 2])
    kind = np.array([0, 0, 1, 1, 2, 3, 0, 0, 1, 0, 1, 3])
    area = np.array([0.2, 0.25, 0.3, 0.2, 0.05, 0.01, 0.45, 0.45, 0.1, 0.5, 0.5, 0.01])
    before = area.copy()
    zoned_side_carries(sc, kind, area, np.array([True, False, False]), np.array([False, True, False]))
    # contact 0: kept 0.2 + 0.25 + 0.05 = 0.5 of 1.0 -> scale 2
    assert np.allclose(area[:6], [0.4, 0.5, 0.0, 0.0, 0.1, 0.01], rtol=1e-15)
    assert area[:5].sum() == pytest.approx(before[:5].sum(), rel=1e-15)
    assert np.array_equal(area[6:], before[6:])


def test_zoned_side_carries_nothing_to_do():
    from dec3d.physics.contacts import zoned_side_carries
    area = np.array([0.5, 0.5])
    zoned_side_carries(np.array([0, 0]), np.array([0, 1]), area, np.array([True]), np.array([True]))
    assert np.array_equal(area, [0.5, 0.5])
    zoned_side_carries(np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0), np.array([True]), np.array([False]))
