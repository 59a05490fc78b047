"""The pore-pressure kernels (dec3d.kernels.water) against twins written from the formulas (also run with
NUMBA_DISABLE_JIT=1 by tests/test_kernel_cache.py)."""
import math

import numpy as np
import pytest

from dec3d.kernels import water as kw
from dec3d.physics.water import table_pressure


# ---------------------------------------------------------------- twins of the kernels

def _polygon_integral_twin(poly, a, b, c):
    """∫ (a + b u + c v) dA over the convex polygon `poly` (k, 2), from its area and centroid (shoelace)."""
    u, v = poly[:, 0], poly[:, 1]
    u1, v1 = np.roll(u, -1), np.roll(v, -1)
    cross = u * v1 - u1 * v
    area = cross.sum() / 2
    cu = ((u + u1) * cross).sum() / (6 * area)
    cv = ((v + v1) * cross).sum() / (6 * area)
    return area * (a + b * cu + c * cv), area


def _frame(n):
    n = np.asarray(n, float) / np.linalg.norm(n)
    t = np.cross(n, [0.3, 0.5, 0.8])
    t /= np.linalg.norm(t)
    return n, t, np.cross(n, t)


@pytest.mark.parametrize("seed", range(6))
def test_pressure_areas_integrate_a_linear_pressure_exactly(seed):
    """Random convex polygons on tilted planes, every corner given twice (as a contact's two faces give
    them) and an inner point: Σ p_i A′_i equals the exact integral of a linear p (the polygon's area
    times p at its centroid), and Σ A′ equals Σ area."""
    rng = np.random.default_rng(seed)
    k = int(rng.integers(3, 9))
    ang = np.sort(rng.uniform(0, 2 * np.pi, k))
    poly = np.c_[np.cos(ang) * rng.uniform(1, 3), np.sin(ang) * rng.uniform(1, 3)] + rng.uniform(-5, 5, 2)
    n, t1, t2 = _frame(rng.normal(size=3))
    o = rng.uniform(-10, 10, 3)
    pts2 = np.vstack([poly, poly[::-1], poly.mean(0)[None]])
    pts = o + pts2[:, :1] * t1 + pts2[:, 1:] * t2
    ns = len(pts)
    area = rng.uniform(0.1, 1.0, ns)               # stiffness lumps: any positive numbers
    area *= _polygon_integral_twin(poly, 1, 0, 0)[1] / area.sum()
    out = np.empty(ns)
    kw.pressure_areas(np.array([0]), np.array([ns]), n[None], pts, area, out)
    a, b, c = rng.normal(size=3)
    p = a + b * pts2[:, 0] + c * pts2[:, 1]
    exact, _ = _polygon_integral_twin(poly, a, b, c)
    assert (p * out).sum() == pytest.approx(exact, rel=1e-10, abs=1e-9)
    assert out.sum() == pytest.approx(area.sum(), rel=1e-12)
    assert out[-1] == 0.0                          # inside the hull: no weight
    assert np.allclose(out[:k], out[k:2 * k][::-1])  # a point given twice shares its weight


def test_pressure_areas_of_a_rectangle_are_equal_shares():
    """A parallelogram's four corners get a quarter each (the moment of a uniform pressure is right);
    a contact with fewer than three points keeps its areas."""
    pts = np.array([[0, 0, 0], [4, 0, 0], [4, 2, 0], [0, 2, 0], [9, 9, 9], [9, 9, 9.5]], float)
    area = np.array([4.0, 2, 4, 2, 0.3, 0.2])
    out = np.empty(6)
    kw.pressure_areas(np.array([0, 4]), np.array([4, 2]), np.array([[0, 0, 1.0], [1.0, 0, 0]]), pts, area, out)
    assert out[:4].tolist() == pytest.approx([3, 3, 3, 3], rel=1e-12)
    assert out[4:].tolist() == [0.3, 0.2]


def _pore_force_twin(ca, cb, cn, sc_contact, sc_pos, ppf, bpos, nb):
    """Force and moment on each block from F n on B and −F n on A at each sub-contact point."""
    f = np.zeros((nb, 3))
    m = np.zeros((nb, 3))
    for s, c in enumerate(sc_contact):
        g = ppf[s] * cn[c]
        for blk, sign in ((cb[c], 1.0), (ca[c], -1.0)):
            f[blk] += sign * g
            m[blk] += np.cross(sc_pos[s] - bpos[blk], sign * g)
    return f, m


def test_pore_forces_against_twin():
    rng = np.random.default_rng(3)
    nb, nc, ns = 4, 3, 9
    ca, cb = np.array([0, 1, 0]), np.array([1, 2, 3])
    cn = rng.normal(size=(nc, 3))
    cn /= np.linalg.norm(cn, axis=1)[:, None]
    sc_contact = np.array([0, 0, 0, 1, 1, 1, 2, 2, 2])
    sc_pos = rng.normal(size=(ns, 3))
    ppf = rng.uniform(-1e4, 1e5, ns)
    ppf[4] = 0.0
    bpos = rng.normal(size=(nb, 3))
    want_f, want_m = _pore_force_twin(ca, cb, cn, sc_contact, sc_pos, ppf, bpos, nb)
    # rigid cycle: added to each sub-contact's force on B, summed like the joint forces
    sg = np.zeros((ns, 3))
    kw.pore_forces(cn, sc_contact, ppf, sg)
    f = np.zeros((nb, 3))
    m = np.zeros((nb, 3))
    for s, c in enumerate(sc_contact):
        for blk, sign in ((cb[c], 1.0), (ca[c], -1.0)):
            f[blk] += sign * sg[s]
            m[blk] += np.cross(sc_pos[s] - bpos[blk], sign * sg[s])
    assert np.allclose(f, want_f) and np.allclose(m, want_m)
    # mixed path, every side rigid (node −1)
    none = -np.ones((ns, 3), np.int64)
    w = np.zeros((ns, 3))
    bf = np.zeros((nb, 3))
    bm = np.zeros((nb, 3))
    kw.mixed_pore_forces(bpos, bf, bm, np.zeros((1, 3)), ca, cb, cn, sc_contact, sc_pos, ppf, none, w, none, w)
    assert np.allclose(bf, want_f) and np.allclose(bm, want_m)
    # a zoned B side: its share goes to the gridpoints by the weights
    nodes_b = np.tile(np.array([0, 1, 2]), (ns, 1))
    w_b = np.tile(np.array([0.2, 0.3, 0.5]), (ns, 1))
    gf = np.zeros((3, 3))
    bf[:] = 0.0
    kw.mixed_pore_forces(bpos, bf, np.zeros((nb, 3)), gf, ca, cb, cn, sc_contact, sc_pos, ppf, none, w, nodes_b, w_b)
    on_b = (ppf[:, None] * cn[sc_contact]).sum(0)
    assert np.allclose(gf.sum(0), on_b) and np.allclose(gf[2], 0.5 * on_b)


def test_table_pressure_follows_gravity():
    """p = ρw |g| h, h the distance up to the table along −g; 0 above it; the table's tilt counts."""
    g = (0.0, 0.0, -9.81)
    pos = np.array([[0, 0, -2.0], [5, 0, 3.0], [0, 0, 1.5]])
    p = table_pressure(pos, 1000.0, [0, 0, 1, 0, 0, 1], g)
    assert p.tolist() == pytest.approx([1000 * 9.81 * 3, 0, 0])
    # a table dipping 45° (normal (1, 0, 1)) through the origin: at x = 2, z = −1 the table is at z = −2
    p = table_pressure(np.array([[2, 0, -3.0]]), 1000.0, [1, 0, 1, 0, 0, 0], g)
    assert p[0] == pytest.approx(1000 * 9.81 * 1.0)
    # tilted gravity: the depth is measured along it
    gt = (9.81 * math.sin(0.3), 0.0, -9.81 * math.cos(0.3))
    p = table_pressure(np.array([[0, 0, -1.0]]), 1000.0, [0, 0, 1, 0, 0, 0], gt)
    assert p[0] == pytest.approx(1000 * 9.81 / math.cos(0.3))
