"""The engine's 4-node zone step (``kernels/zone_step.py``) on plain elastic tetrahedra against a
shape-function (matrix) twin."""
import numpy as np

from tests.zone_step_run import elastic_tets as tet_elastic_step


def twin_tet_step(pos, vel, gp, bulk, shear, dt, stress, force):
    for z in range(gp.shape[0]):
        x = pos[gp[z, :4]]
        # linear shape functions N = a + b.x ; solve [1 x] coefficients
        m = np.hstack([np.ones((4, 1)), x])
        coef = np.linalg.inv(m)          # columns: coefficients of N_n
        dn = coef[1:, :].T               # dn[n] = grad N_n
        vol = abs(np.linalg.det(m)) / 6.0
        L = vel[gp[z, :4]].T @ dn        # L[i,j] = sum_n v_i^n dN_n/dx_j
        eps = 0.5 * (L + L.T) * dt
        lam = bulk[z] - 2 * shear[z] / 3
        ds = lam * np.trace(eps) * np.eye(3) + 2 * shear[z] * eps
        s = np.array([[stress[z, 0], stress[z, 3], stress[z, 4]],
                      [stress[z, 3], stress[z, 1], stress[z, 5]],
                      [stress[z, 4], stress[z, 5], stress[z, 2]]]) + ds
        stress[z] = [s[0, 0], s[1, 1], s[2, 2], s[0, 1], s[0, 2], s[1, 2]]
        for n in range(4):               # virtual work: f_n = -V sigma grad N_n
            force[gp[z, n]] += -vol * s @ dn[n]


def test_tet_step_matches_twin_and_balances():
    rng = np.random.default_rng(7)
    pos = rng.random((9, 3))
    gp = np.array([[0, 1, 2, 3], [1, 2, 3, 4], [4, 5, 6, 7], [2, 5, 8, 0]])
    vel = rng.normal(size=(9, 3))
    bulk = np.array([1e9, 2e9, 3e9, 4e9]); shear = np.array([5e8, 1e9, 2e9, 1e9])
    s0 = rng.normal(size=(4, 6)) * 1e6
    sa, sb = s0.copy(), s0.copy()
    fa, fb = np.zeros((9, 3)), np.zeros((9, 3))
    tet_elastic_step(pos, vel, gp, bulk, shear, 1e-3, sa, fa)
    twin_tet_step(pos, vel, gp, bulk, shear, 1e-3, sb, fb)
    assert np.allclose(sa, sb, rtol=1e-10, atol=1e-6)
    assert np.allclose(fa, fb, rtol=1e-10, atol=1e-6)
    # each zone's nodal forces sum to zero (closed contour): total over all nodes
    assert np.abs(fa.sum(axis=0)).max() < 1e-9 * np.abs(fa).max()


def test_uniaxial_strain_rate_gives_hooke_stress():
    pos = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    vel = pos * np.array([0., 0, 1e-4])      # dvz/dz = 1e-4, others 0
    K, G = 2e9, 1e9
    s = np.zeros((1, 6)); f = np.zeros((4, 3))
    tet_elastic_step(pos, vel, np.array([[0, 1, 2, 3]]), np.array([K]), np.array([G]), 1.0, s, f)
    assert abs(s[0, 2] - (K + 4 * G / 3) * 1e-4) < 1e-6
    assert abs(s[0, 0] - (K - 2 * G / 3) * 1e-4) < 1e-6
    assert np.abs(s[0, 3:]).max() < 1e-6
