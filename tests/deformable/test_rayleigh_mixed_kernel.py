"""kernels.rayleigh.mixed_stiffness_damping against a slow twin written from its definition: per closed
sub-contact, V = v_B(x) − v_A(x) with a rigid side's v = ẋ + ω × (x − x̄) and a zoned side's v = Σ wᵢ vᵢ
of its gridpoints; F = −β A (kn Vⁿ n + ks Vˢ) (no shear term while slipping) on B, −F on A; a rigid side
takes the force at its centroid and the moment (x − x̄) × F, a zoned side shares it by the weights."""
import numpy as np
import pytest

from dec3d.kernels.joints import NPROP, ST_SLIP
from dec3d.kernels.rayleigh import mixed_stiffness_damping


def twin(beta, bpos, bvel, bspin, gvel, ca, cb, cn, cprop, sc_contact, sc_pos, sc_area, sc_fn, sc_state,
         na, wa, nb, wb):
    bforce = np.zeros_like(bpos)
    bmoment = np.zeros_like(bpos)
    gforce = np.zeros_like(gvel)
    for s in range(len(sc_contact)):
        if sc_fn[s] <= 0:
            continue
        c = sc_contact[s]
        x = sc_pos[s]

        def vel(blk, nodes, w):
            if nodes[s, 0] < 0:
                return bvel[blk] + np.cross(bspin[blk], x - bpos[blk])
            return sum(w[s, j] * gvel[nodes[s, j]] for j in range(3) if nodes[s, j] >= 0)

        v = vel(cb[c], nb, wb) - vel(ca[c], na, wa)
        n = cn[c]
        vn = v @ n
        f = -beta * cprop[c, 0] * sc_area[s] * vn * n       # prop columns kn = 0, ks = 1
        if not sc_state[s] & ST_SLIP:
            f = f - beta * cprop[c, 1] * sc_area[s] * (v - vn * n)
        for blk, nodes, w, sign in ((cb[c], nb, wb, 1.0), (ca[c], na, wa, -1.0)):
            if nodes[s, 0] < 0:
                bforce[blk] += sign * f
                bmoment[blk] += np.cross(x - bpos[blk], sign * f)
            else:
                for j in range(3):
                    if nodes[s, j] >= 0:
                        gforce[nodes[s, j]] += w[s, j] * sign * f
    return bforce, bmoment, gforce


def test_kernel_matches_twin():
    rng = np.random.default_rng(11)
    nbk, nv, nc, ns = 4, 12, 5, 23
    bpos, bvel, bspin = (rng.normal(size=(nbk, 3)) for _ in range(3))
    gvel = rng.normal(size=(nv, 3))
    ca = np.array([0, 1, 2, 0, 3], np.int64)
    cb = np.array([1, 2, 3, 3, 1], np.int64)
    cn = rng.normal(size=(nc, 3))
    cn /= np.linalg.norm(cn, axis=1)[:, None]
    cprop = np.zeros((nc, NPROP))
    cprop[:, 0] = rng.uniform(1e8, 1e9, nc)
    cprop[:, 1] = rng.uniform(1e7, 1e8, nc)
    sc_contact = rng.integers(0, nc, ns).astype(np.int64)
    sc_pos = rng.normal(size=(ns, 3))
    sc_area = rng.uniform(0.01, 0.2, ns)
    sc_fn = rng.normal(size=ns) * 1e3
    sc_fn[0] = 0.0
    sc_state = rng.integers(0, 8, ns).astype(np.int32)
    # sides: rigid (-1), a surface triangle, or a single vertex gridpoint
    na = np.full((ns, 3), -1, np.int64)
    nb = np.full((ns, 3), -1, np.int64)
    wa, wb = np.zeros((ns, 3)), np.zeros((ns, 3))
    for s in range(ns):
        for nodes, w in ((na, wa), (nb, wb)):
            kind = rng.integers(0, 3)
            if kind == 1:
                nodes[s] = rng.choice(nv, 3, replace=False)
                w[s] = rng.dirichlet(np.ones(3))
            elif kind == 2:
                nodes[s, 0] = rng.integers(0, nv)
                w[s, 0] = 1.0
    beta = 2.3e-4
    args = (ca, cb, cn, cprop, sc_contact, sc_pos, sc_area, sc_fn, sc_state, na, wa, nb, wb)
    wf, wm, wg = twin(beta, bpos, bvel, bspin, gvel, *args)
    bf, bm, gf = np.zeros((nbk, 3)), np.zeros((nbk, 3)), np.zeros((nv, 3))
    cmodel, hist = np.arange(nc, dtype=np.int64) % 2, np.zeros((ns, 8))     # elastic and mohr: kn, ks constant
    mixed_stiffness_damping(beta, bpos, bvel, bspin, bf, bm, gvel, gf, ca, cb, cn, cmodel, cprop, sc_contact, sc_pos,
                            sc_area, sc_fn, sc_state, hist, na, wa, nb, wb)
    scale = np.abs(wg).max()
    assert scale > 0 and np.abs(wf).max() > 0                 # both kinds of side were loaded
    np.testing.assert_allclose(bf, wf, rtol=1e-12, atol=1e-12 * scale)
    np.testing.assert_allclose(bm, wm, rtol=1e-12, atol=1e-12 * scale)
    np.testing.assert_allclose(gf, wg, rtol=1e-12, atol=1e-12 * scale)


def test_rigid_on_gridpoints_balances_and_dissipates():
    """A rigid block B moving on a zoned face A (three gridpoints at rest): the gridpoints take exactly
    minus B's force, and B's force does negative work, −β A (kn Vn² + ks |Vs|²)."""
    bpos = np.array([[0.0, 0, 0], [0.0, 0, 1]])
    bvel = np.array([[0.0, 0, 0], [0.2, 0, -0.1]])
    bspin = np.zeros((2, 3))
    gvel = np.zeros((3, 3))
    cprop = np.zeros((1, NPROP))
    cprop[0, :2] = 4e8, 1e8
    bf, bm, gf = np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((3, 3))
    na = np.array([[0, 1, 2]], np.int64)
    wa = np.array([[0.2, 0.3, 0.5]])
    nb = np.full((1, 3), -1, np.int64)
    mixed_stiffness_damping(1e-3, bpos, bvel, bspin, bf, bm, gvel, gf, np.array([0]), np.array([1]),
                            np.array([[0.0, 0, 1]]), np.array([1]), cprop, np.array([0]), np.array([[0.0, 0, 1]]),
                            np.array([0.5]), np.array([10.0]), np.array([0], np.int32), np.zeros((1, 8)), na, wa, nb,
                            np.zeros((1, 3)))
    assert bf[1] == pytest.approx([-1e-3 * 0.5 * 1e8 * 0.2, 0.0, 1e-3 * 0.5 * 4e8 * 0.1], rel=1e-14)
    np.testing.assert_allclose(gf.sum(axis=0), -bf[1], rtol=1e-14)
    np.testing.assert_allclose(gf[2], 0.5 * -bf[1], rtol=1e-14)
    assert bf[1] @ bvel[1] == pytest.approx(-1e-3 * 0.5 * (4e8 * 0.1 ** 2 + 1e8 * 0.2 ** 2), rel=1e-14)
