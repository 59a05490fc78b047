"""kernels.rayleigh.contact_stiffness_damping against a slow twin written from its definition:
the damping force on block B of a sub-contact is −β A (kn Vⁿ n + ks Vˢ), V the velocity of B's material
point there relative to A's (3DEC theory Eq. 15); only closed sub-contacts, no shear term while slipping."""
import numpy as np

from dec3d.kernels.joints import NPROP, ST_SLIP
from dec3d.kernels.rayleigh import contact_stiffness_damping


def twin(beta, bpos, bvel, bspin, ca, cb, cn, cprop, sc_contact, sc_pos, sc_area, sc_fn, sc_state, sg):
    out = sg.copy()
    for s in range(len(sc_contact)):
        if sc_fn[s] <= 0:
            continue
        c = sc_contact[s]
        a, b = ca[c], cb[c]
        x = sc_pos[s]
        va = bvel[a] + np.cross(bspin[a], x - bpos[a])
        vb = bvel[b] + np.cross(bspin[b], x - bpos[b])
        v = vb - va
        n = cn[c]
        vn = v @ n
        kn_a = cprop[c, 0] * sc_area[s]            # columns kn, ks (jointlaw docstring: prop P_KN = 0, P_KS = 1)
        ks_a = cprop[c, 1] * sc_area[s]
        f = -beta * kn_a * vn * n
        if not sc_state[s] & ST_SLIP:
            f = f - beta * ks_a * (v - vn * n)
        out[s] += f
    return out


def test_kernel_matches_twin():
    rng = np.random.default_rng(7)
    nb, nc, ns = 5, 4, 17
    bpos, bvel, bspin = (rng.normal(size=(nb, 3)) for _ in range(3))
    ca = np.array([0, 1, 2, 0], np.int64)
    cb = np.array([1, 2, 3, 4], np.int64)
    cn = rng.normal(size=(nc, 3))
    cn /= np.linalg.norm(cn, axis=1)[:, None]
    cprop = np.zeros((nc, NPROP))
    cprop[:, 0] = rng.uniform(1e8, 1e9, nc)
    cprop[:, 1] = rng.uniform(1e7, 1e8, nc)
    sc_contact = rng.integers(0, nc, ns).astype(np.int64)
    sc_pos = rng.normal(size=(ns, 3))
    sc_area = rng.uniform(0.01, 0.2, ns)
    sc_fn = rng.normal(size=ns) * 1e3              # some open (fn ≤ 0)
    sc_fn[0] = 0.0
    sc_state = rng.integers(0, 8, ns).astype(np.int32)
    sg = rng.normal(size=(ns, 3))
    beta = 3.7e-4
    want = twin(beta, bpos, bvel, bspin, ca, cb, cn, cprop, sc_contact, sc_pos, sc_area, sc_fn, sc_state, sg)
    got = sg.copy()
    cmodel = np.arange(nc, dtype=np.int64) % 2           # elastic and mohr: kn, ks constant
    contact_stiffness_damping(beta, bpos, bvel, bspin, ca, cb, cn, cmodel, cprop, sc_contact, sc_pos, sc_area, sc_fn,
                              sc_state, np.zeros((ns, 8)), got)
    np.testing.assert_allclose(got, want, rtol=1e-13, atol=1e-9)
    assert not np.array_equal(got, sg)                       # it did something
    assert np.array_equal(got[sc_fn <= 0], sg[sc_fn <= 0])  # open sub-contacts untouched


def test_damping_force_opposes_relative_motion():
    """One sub-contact, B closing on A along n: the force on B points along +n (away from A), and the
    power it takes, F·V, is −β A (kn Vn² + ks |Vs|²) < 0."""
    bpos = np.array([[0.0, 0, 0], [0, 0, 1]])
    bvel = np.array([[0.0, 0, 0], [0.3, 0, -0.2]])
    bspin = np.zeros((2, 3))
    cprop = np.zeros((1, NPROP))
    cprop[0, :2] = 2e8, 1e8
    sg = np.zeros((1, 3))
    contact_stiffness_damping(1e-3, bpos, bvel, bspin, np.array([0]), np.array([1]), np.array([[0.0, 0, 1]]),
                              np.array([1]), cprop, np.array([0]), np.array([[0.0, 0, 0.5]]), np.array([0.25]),
                              np.array([5.0]), np.array([0], np.int32), np.zeros((1, 8)), sg)
    assert sg[0, 2] == 1e-3 * 0.25 * 2e8 * 0.2 and sg[0, 0] == -1e-3 * 0.25 * 1e8 * 0.3
    assert sg[0] @ bvel[1] < 0
