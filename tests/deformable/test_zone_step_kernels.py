"""The deformable-step kernels (dec3d.kernels.zonestep) against slow twins written from the
formulas by other means: shape-function gradients from the inverse of the corner matrix (not
Gauss's theorem), nodal forces by virtual work (−V σ ∇N), numpy determinants and norms."""
import itertools

import numpy as np
import pytest

from dec3d.kernels.zonestep import gp_externals, gp_motion, zone_mass_stiffness
from tests.zone_step_run import elastic_forces as zone_forces
from tests.zone_step_run import elastic_tets as tet_elastic_step


# ------------------------------------------------------------------ twins
def _grad_n(p):
    """(4, 3) gradients of the linear shape functions of the tetrahedron with corners p (4, 3)."""
    a = np.hstack([np.ones((4, 1)), p])           # N_n(x) = c_n · (1, x)
    c = np.linalg.inv(a)                            # columns: coefficients of N_n
    return c[1:, :].T


def _vol(p):
    return abs(np.linalg.det(np.array([p[1] - p[0], p[2] - p[0], p[3] - p[0]]))) / 6.0


def twin_mass_stiffness(pos, gp, nnode, overlay, rows, K, G, rho, n):
    mass, stiff = np.zeros(n), np.zeros(n)
    for z in rows:
        p = pos[gp[z, :4]]
        V = _vol(p)
        w = 0.5 if overlay[z] >= 0 else 1.0
        edges = [np.linalg.norm(p[i] - p[j]) for i, j in itertools.combinations(range(4), 2)]
        areas = [0.5 * np.linalg.norm(np.cross(p[j] - p[i], p[k] - p[i]))
                 for i, j, k in itertools.combinations(range(4), 3)]
        h = 3 * V / max(areas)
        k = 8 / 3 * (K[z] + 4 * G[z] / 3) * max(edges) ** 2 / h * w
        if nnode[z] == 10:
            corner, mid = 1 / 70, 8 / 105                 # ∫N²/V of a quadratic tetrahedron
            tot = 4 * corner + 6 * mid
            for i in range(4):
                mass[gp[z, i]] += rho[z] * V * w * corner / tot
                stiff[gp[z, i]] += 4 * k
            for i in range(4, 10):
                mass[gp[z, i]] += rho[z] * V * w * mid / tot
                stiff[gp[z, i]] += 4 * k
        else:
            for i in range(4):
                mass[gp[z, i]] += rho[z] * V * w / 4
                stiff[gp[z, i]] += k
    return mass, stiff


def _voigt(t):
    return np.array([t[0, 0], t[1, 1], t[2, 2], t[0, 1], t[0, 2], t[1, 2]])


def _tensor(s):
    return np.array([[s[0], s[3], s[4]], [s[3], s[1], s[5]], [s[4], s[5], s[2]]])


def twin_zone_forces(pos, vel, gp, rows, zset, weight, K, G, dt, stress, n, large=False):
    stress = stress.copy()
    force, fmag = np.zeros((n, 3)), np.zeros(n)
    eps, spin = {}, {}
    for k, z in enumerate(rows):
        p = pos[gp[z, :4]]
        L = vel[gp[z, :4]].T @ _grad_n(p)               # L_ij = Σ v_i ∂N/∂x_j
        eps[k] = 0.5 * (L + L.T) * dt
        spin[k] = 0.5 * (L - L.T) * dt
    # mixed discretization: volumetric part = volume-weighted mean over the set
    for h in set(int(x) for x in zset if x >= 0):
        ks = [k for k in range(len(rows)) if zset[k] == h]
        vs = np.array([_vol(pos[gp[rows[k], :4]]) for k in ks])
        mean = sum(np.trace(eps[k]) * v for k, v in zip(ks, vs)) / vs.sum()
        for k in ks:
            eps[k] = eps[k] - np.trace(eps[k]) / 3 * np.eye(3) + mean / 3 * np.eye(3)
    for k, z in enumerate(rows):
        e = eps[k]
        sig = _tensor(stress[z])
        if large:                                        # Jaumann: σ + Wσ − σW
            sig = sig + spin[k] @ sig - sig @ spin[k]
        sig = sig + (K[z] - 2 * G[z] / 3) * np.trace(e) * np.eye(3) + 2 * G[z] * e
        stress[z] = _voigt(sig)
        p = pos[gp[z, :4]]
        f = -_vol(p) * (sig @ _grad_n(p).T).T * weight[k]   # force of the zone on its nodes
        for i in range(4):
            force[gp[z, i]] += f[i]
            fmag[gp[z, i]] += np.linalg.norm(f[i])
    return stress, force, fmag


def _random_mesh(rng, nz=12, npts=20):
    pos = rng.uniform(-1, 1, (npts, 3))
    gp = np.full((nz, 10), -1, np.int64)
    for z in range(nz):
        while True:
            c = rng.choice(npts, 4, replace=False)
            if _vol(pos[c]) > 0.02:
                break
        gp[z, :4] = c
    return pos, gp


# ------------------------------------------------------------------ tests
def test_mass_and_stiffness_match_the_twin():
    rng = np.random.default_rng(3)
    pos, gp = _random_mesh(rng)
    nz = len(gp)
    nnode = np.full(nz, 4, np.int8)
    overlay = np.where(np.arange(nz) % 3 == 0, 1, -1).astype(np.int8)
    # two zones are 10-node: mid-edge nodes picked among the points (the lumping reads only rows)
    for z in (1, 5):
        nnode[z] = 10
        gp[z, 4:] = rng.choice(20, 6, replace=False)
    K, G, rho = rng.uniform(1, 3, nz) * 1e9, rng.uniform(0.5, 1, nz) * 1e9, rng.uniform(1e3, 3e3, nz)
    rows = np.arange(1, nz, dtype=np.int64)             # zone 0 is left out
    mass, stiff = np.zeros(20), np.zeros(20)
    zone_mass_stiffness(pos, gp, nnode, overlay, rows, K, G, rho, mass, stiff)
    tm, ts = twin_mass_stiffness(pos, gp, nnode, overlay, rows, K, G, rho, 20)
    assert np.allclose(mass, tm, rtol=1e-12, atol=0)
    assert np.allclose(stiff, ts, rtol=1e-12, atol=0)
    # mass is conserved: Σ nodal mass = Σ ρ V w over the zones counted
    w = np.where(overlay[rows] >= 0, 0.5, 1.0)
    assert mass.sum() == pytest.approx(sum(rho[z] * _vol(pos[gp[z, :4]]) * wi for z, wi in zip(rows, w)), rel=1e-12)


@pytest.mark.parametrize("large", [False, True])
def test_zone_forces_match_the_twin_with_mixed_sets(large):
    rng = np.random.default_rng(7)
    pos, gp = _random_mesh(rng)
    nz = len(gp)
    vel = rng.normal(size=(20, 3))
    stress0 = rng.normal(size=(nz, 6)) * 1e5
    K, G = rng.uniform(1, 3, nz) * 1e9, rng.uniform(0.5, 1, nz) * 1e9
    rows = np.arange(nz, dtype=np.int64)[::-1].copy()
    zset = np.array([0, 0, 0, 1, 1, -1, -1, 0, 1, -1, 2, 2], np.int64)
    weight = np.where(zset >= 0, 0.5, 1.0)
    stress = stress0.copy()
    force, fmag = np.zeros((20, 3)), np.zeros(20)
    zone_forces(pos, vel, gp, rows, zset, weight, 3, K, G, 1e-3, large, stress, force, fmag)
    ts, tf, tm = twin_zone_forces(pos, vel, gp, rows, zset, weight, K, G, 1e-3, stress0, 20, large)
    assert np.allclose(stress, ts, rtol=1e-10, atol=1e-6)
    assert np.allclose(force, tf, rtol=1e-10, atol=1e-6)
    assert np.allclose(fmag, tm, rtol=1e-10, atol=1e-6)
    # a zone's nodal forces balance (Σ f = 0): the force sum over all gridpoints vanishes
    assert np.abs(force.sum(axis=0)).max() < 1e-9 * np.abs(force).max()


def test_zone_forces_agree_with_the_first_kernel_slice_on_plain_tetrahedra():
    rng = np.random.default_rng(11)
    pos, gp = _random_mesh(rng)
    nz = len(gp)
    vel = rng.normal(size=(20, 3))
    K, G = rng.uniform(1, 3, nz) * 1e9, rng.uniform(0.5, 1, nz) * 1e9
    s1, s2 = np.zeros((nz, 6)), np.zeros((nz, 6))
    f1, f2 = np.zeros((20, 3)), np.zeros((20, 3))
    zone_forces(pos, vel, gp, np.arange(nz, dtype=np.int64), np.full(nz, -1, np.int64), np.ones(nz), 0, K, G, 1e-3,
                False, s1, f1, np.zeros(20))
    tet_elastic_step(pos, vel, gp, K, G, 1e-3, s2, f2)
    assert np.allclose(s1, s2, rtol=1e-12) and np.allclose(f1, f2, rtol=1e-12, atol=1e-9)


def test_mixed_set_keeps_uniform_strain_and_averages_the_volume_change():
    """Uniform velocity gradient: every tetrahedron already has the mean volumetric strain, so
    mixed discretization changes nothing; a non-uniform field gets one volumetric strain per set."""
    rng = np.random.default_rng(5)
    pos, gp = _random_mesh(rng, nz=6)
    grad = rng.normal(size=(3, 3))
    vel = pos @ grad.T
    K, G = np.full(6, 2e9), np.full(6, 1e9)
    sa, sb = np.zeros((6, 6)), np.zeros((6, 6))
    rows = np.arange(6, dtype=np.int64)
    zone_forces(pos, vel, gp, rows, np.zeros(6, np.int64), np.ones(6), 1, K, G, 1.0, False, sa, np.zeros((20, 3)),
                np.zeros(20))
    zone_forces(pos, vel, gp, rows, np.full(6, -1, np.int64), np.ones(6), 0, K, G, 1.0, False, sb, np.zeros((20, 3)),
                np.zeros(20))
    assert np.allclose(sa, sb, rtol=1e-10)
    e = 0.5 * (grad + grad.T)
    assert np.allclose(sa[0], _voigt((K[0] - 2 * G[0] / 3) * np.trace(e) * np.eye(3) + 2 * G[0] * e), rtol=1e-10)
    vel2 = rng.normal(size=(20, 3))
    s2 = np.zeros((6, 6))
    zone_forces(pos, vel2, gp, rows, np.zeros(6, np.int64), np.ones(6), 1, K, G, 1.0, False, s2, np.zeros((20, 3)),
                np.zeros(20))
    mean = s2[:, :3].sum(axis=1) / 3                     # K Δε_v: the same in every zone of the set
    assert np.allclose(mean, mean[0], rtol=1e-10)


def test_large_strain_turns_the_stress_with_a_rigid_rotation():
    """A spin about z (v = Ω × x, no strain) turns a uniaxial σ_xx toward y by ΩΔt: to first
    order σ_xy = σ_xx ΩΔt and the invariants stay; in small strain the stress does not change."""
    rng = np.random.default_rng(9)
    pos, gp = _random_mesh(rng, nz=3)
    om = 0.01
    vel = np.cross(np.array([0.0, 0.0, om]), pos)
    K, G = np.full(3, 2e9), np.full(3, 1e9)
    for large, want in ((True, np.array([1e6, 0, 0, 1e6 * om, 0, 0])), (False, np.array([1e6, 0, 0, 0, 0, 0]))):
        st = np.zeros((3, 6))
        st[:, 0] = 1e6
        zone_forces(pos, vel, gp, np.arange(3, dtype=np.int64), np.full(3, -1, np.int64), np.ones(3), 0, K, G, 1.0,
                    large, st, np.zeros((20, 3)), np.zeros(20))
        assert np.allclose(st, want, rtol=0, atol=1e-6 * 1e6)


def twin_externals(rows, link, mass, g, fapp, fface, force, fmag):
    force, fmag = force.copy(), fmag.copy()
    for r in rows:
        force[r] += mass[r] * g + fapp[r] + fface[r]
        fmag[r] += np.linalg.norm(mass[r] * g) + np.linalg.norm(fapp[r]) + np.linalg.norm(fface[r])
    for r in rows:
        if link[r] >= 0:
            force[link[r]] += force[r]
            fmag[link[r]] += fmag[r]
    return force, fmag


def test_externals_match_the_twin():
    rng = np.random.default_rng(2)
    n = 10
    rows = np.array([0, 2, 3, 5, 6, 8], np.int64)
    link = np.full(n, -1, np.int64)
    link[5], link[8] = 2, 0
    mass = rng.uniform(1, 2, n)
    g = np.array([0.0, -1.0, -9.81])
    fapp, fface, force = rng.normal(size=(n, 3)), rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    fmag = rng.uniform(0, 1, n)
    tf, tm = twin_externals(rows, link, mass, g, fapp, fface, force, fmag)
    gp_externals(rows, link, mass, g, fapp, fface, force, fmag)
    assert np.allclose(force, tf, rtol=1e-13) and np.allclose(fmag, tm, rtol=1e-13)


def twin_motion(masters, linked, link, force, fprev, mtot, imass, held, vapp, vel, disp, pos, dt, mode, alpha,
                large):
    force, fprev, vel, disp, pos = (a.copy() for a in (force, fprev, vel, disp, pos))
    for r in masters:
        for i in range(3):
            f = force[r, i]
            if (held[r] >> i) & 1:
                vel[r, i] = vapp[r, i]
                f = 0.0
            elif (held[r] >> (3 + i)) & 1 or imass[r] <= 0:
                f = 0.0
            else:
                if mode in (1, 3):
                    damp = alpha * abs(f) * np.sign(vel[r, i])
                elif mode == 2:
                    damp = alpha * abs(f) * (np.sign(vel[r, i]) - np.sign(f - fprev[r, i])) / 2
                else:
                    damp = 0.0
                if mode == 4:        # viscous force alpha·m·v, v at the step's middle: the mean of old and new
                    # m (v' - v)/dt = f - alpha m (v' + v)/2  solved for v'
                    vel[r, i] = (vel[r, i] * (1 / dt - alpha / 2) + f / imass[r]) / (1 / dt + alpha / 2)
                else:
                    vel[r, i] = vel[r, i] + dt * (f - damp) / imass[r]
            force[r, i] = fprev[r, i] = f
        disp[r] += vel[r] * dt
        if large:
            pos[r] += vel[r] * dt
    for r in linked:
        vel[r], disp[r], force[r], fprev[r] = vel[link[r]], disp[link[r]], force[link[r]], fprev[link[r]]
        if large:
            pos[r] = pos[link[r]]
    ke = sum(0.5 * mtot[r] * vel[r] @ vel[r] for r in masters)
    un = [np.linalg.norm(force[r]) for r in masters]
    return force, fprev, vel, disp, pos, ke, max(un), sum(un)


@pytest.mark.parametrize("mode,large", [(0, False), (1, True), (2, False), (3, True), (4, False)])
def test_motion_matches_the_twin(mode, large):
    rng = np.random.default_rng(10 + mode)
    n = 12
    masters = np.array([0, 1, 2, 3, 4, 6, 7, 9], np.int64)
    linked = np.array([5, 8, 10], np.int64)
    link = np.full(n, -1, np.int64)
    link[5], link[8], link[10] = 1, 3, 9
    force, fprev = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    mtot, imass = rng.uniform(1, 2, n), rng.uniform(1, 2, n)
    imass[7] = 0.0                                       # a massless gridpoint does not move
    held = np.zeros(n, np.uint8)
    held[1], held[2], held[3] = 1 | 4, 7, 8 | 32          # x,z at vapp; all at vapp; x,z held as they are
    vapp, vel = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    vel[4, 1] = 0.0                                      # sgn(0) = 0: no damping on that component
    disp, pos = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    t = twin_motion(masters, linked, link, force, fprev, mtot, imass, held, vapp, vel, disp, pos, 0.3, mode, 0.8,
                    large)
    out = np.zeros(4)
    bad = gp_motion(masters, linked, link, force, fprev, mtot, imass, held, vapp, vel, disp, pos, 0.3, mode, 0.8,
                    large, 1e6, out)
    assert bad == -1 and out[3] == -1
    for a, b in zip((force, fprev, vel, disp, pos), t[:5]):
        assert np.allclose(a, b, rtol=1e-13, atol=1e-15)
    assert out[2] == pytest.approx(t[5], rel=1e-12)
    assert out[0] == pytest.approx(t[6], rel=1e-12) and out[1] == pytest.approx(t[7], rel=1e-12)


def test_motion_reports_a_runaway_gridpoint():
    n = 3
    vel = np.zeros((n, 3))
    force = np.array([[0.0, 0, 0], [1e12, 0, 0], [0, 0, 0]])
    out = np.zeros(4)
    bad = gp_motion(np.arange(n, dtype=np.int64), np.zeros(0, np.int64), np.full(n, -1, np.int64), force,
                    np.zeros((n, 3)), np.ones(n), np.ones(n), np.zeros(n, np.uint8), np.zeros((n, 3)), vel,
                    np.zeros((n, 3)), np.zeros((n, 3)), 1.0, 0, 0.8, False, 1e6, out)
    assert bad == 1 and out[3] == 1
