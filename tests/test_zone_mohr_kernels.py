"""Mohr-Coulomb zones and nodal mixed discretization: kernels against slow twins (the D4
one-zone tests, the strip footing and the property check: tests/test_zone_mohr_cases.py).

The twins are written from the formulas (Itasca's "Mohr-Coulomb Model" page; the 3DEC theory
text, Eqs. 68-76) in plain python/numpy: numpy's eigh for the principal stresses, Itasca's
closed forms for the single-plane returns, numpy.linalg.solve for the corner/edge returns,
dictionaries for the nodal averages. They do not call the kernels or use their helpers.
"""
import itertools
import math

import numpy as np
import pytest

from dec3d.kernels import zone_mohr as zm
from dec3d.model import zones as mz
from dec3d.physics.cmodels import ZONE_MODELS
from tests import zone_plastic_twin as zp
from tests.zone_step_run import Stepper

K, G = 2e9, 1e9
A1, A2 = K + 4 * G / 3, K - 2 * G / 3


# --------------------------------------------------------------------------------------------
# twin of the Mohr-Coulomb return

def _tensor(s):
    return np.array([[s[0], s[3], s[4]], [s[3], s[1], s[5]], [s[4], s[5], s[2]]])


def _vec6(t):
    return np.array([t[0, 0], t[1, 1], t[2, 2], t[0, 1], t[0, 2], t[1, 2]])


def _nfac(tan_angle):
    sn = math.sin(math.atan(tan_angle))
    return (1 + sn) / (1 - sn)


def twin_mohr(s0, de, bulk, shear, c, tanphi, ten, tanpsi):
    """Returns (new stress 6, set of active planes, dsp, principal trial, principal new, axes)."""
    eps = _tensor(de)
    lam_ = bulk - 2 * shear / 3
    trial = _tensor(s0) + lam_ * np.trace(eps) * np.eye(3) + 2 * shear * eps
    w, v = np.linalg.eigh(trial)                  # ascending: s1 <= s2 <= s3
    nphi, npsi = _nfac(tanphi), _nfac(tanpsi)
    st = min(ten, c / tanphi) if tanphi > 0 else ten
    a1, a2 = bulk + 4 * shear / 3, bulk - 2 * shear / 3
    dmat = np.full((3, 3), a2) + (a1 - a2) * np.eye(3)
    planes = {}
    for (i, j) in [(0, 2), (0, 1), (1, 2), (1, 0), (2, 0), (2, 1)]:
        n = np.zeros(3); n[i] = -1; n[j] = nphi
        m = np.zeros(3); m[i] = -1; m[j] = npsi
        planes[("s", i, j)] = (n, 2 * c * math.sqrt(nphi), m)
    for i in range(3):
        e = np.zeros(3); e[i] = 1
        planes[("t", i)] = (e, st, e)
    order = [("s", 0, 2), ("s", 0, 1), ("s", 1, 2), ("s", 1, 0), ("s", 2, 0), ("s", 2, 1),
             ("t", 0), ("t", 1), ("t", 2)]
    F = lambda key, sv: planes[key][0] @ sv - planes[key][1]      # noqa: E731
    tol = 1e-10 * (abs(w).sum() + c + abs(st))
    s1, s2, s3 = w
    fs = s1 - s3 * nphi + 2 * c * math.sqrt(nphi)       # Itasca's f_s (< 0 yield)
    ft = st - s3                                         # Itasca's f^t (< 0 yield)
    if fs >= -tol and ft >= -tol:
        return trial.copy()[[0, 1, 2, 0, 0, 1], [0, 1, 2, 1, 2, 2]], set(), 0.0, w, w.copy(), v
    sig_p = st * nphi - 2 * c * math.sqrt(nphi)
    alpha_p = math.sqrt(1 + nphi ** 2) + nphi
    h = s3 - st + alpha_p * (s1 - sig_p)
    # Itasca's single-plane returns, closed form
    if fs < -tol and (h <= 0 or ft >= -tol):
        lam_s = fs / ((a1 - a2 * npsi) - (-a1 * npsi + a2) * nphi)
        new = np.array([s1 - lam_s * (a1 - a2 * npsi), s2 - lam_s * a2 * (1 - npsi),
                        s3 - lam_s * (a2 - a1 * npsi)])
        active = [("s", 0, 2)]
        mult = {("s", 0, 2): -lam_s}
    else:
        new = np.array([s1 - (s3 - st) * a2 / a1, s2 - (s3 - st) * a2 / a1, st])
        active = [("t", 2)]
        mult = {("t", 2): (s3 - st) / a1}

    def admissible(sv):
        return all(F(key, sv) <= tol for key in order)

    def solve(keys):
        M = np.array([[planes[a][0] @ dmat @ planes[b][2] for b in keys] for a in keys])
        if np.linalg.cond(M) > 1e11:
            return None
        lam = np.linalg.solve(M, np.array([F(a, w) for a in keys]))
        if lam.min() < -1e-12 * np.abs(lam).max():
            return None
        sv = w - sum(l_ * (dmat @ planes[a][2]) for l_, a in zip(lam, keys))
        return (sv, dict(zip(keys, lam))) if admissible(sv) else None

    if not admissible(new):
        first = active[0]
        others = [k for k in order if k != first]
        cands = ([[first, k] for k in others] + [[k] for k in others]
                 + [list(p) for p in itertools.combinations(others, 2)]
                 + [list(p) for p in itertools.combinations(order, 3)])
        for keys in cands:
            got = solve(keys)
            if got is not None:
                new, mult = got
                break
        else:
            raise AssertionError("twin: no consistent return")
    out = trial + v @ np.diag(new - w) @ v.T
    return _vec6(out), {k for k in mult if mult[k] > 0}, -(new - w).sum() / 3, w, new, v


def _rand_rotation(rng):
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    return q * np.sign(np.diag(r))


def _random_case(rng):
    c = rng.uniform(0.2e6, 2e6)
    phi = rng.uniform(0, 45)
    psi = rng.uniform(0, phi)
    tanphi, tanpsi = math.tan(math.radians(phi)), math.tan(math.radians(psi))
    apex = c / tanphi if tanphi > 0 else np.inf
    ten = rng.uniform(0, 1.3) * min(apex, 3e6)
    p = rng.uniform(-8e6, 1e6)
    s_principal = p + rng.normal(size=3) * rng.uniform(0, 3e6)
    R = _rand_rotation(rng)
    s0 = _vec6(R @ np.diag(s_principal) @ R.T)
    de = rng.normal(size=6) * 10 ** rng.uniform(-5, -2.7)
    return s0, de, c, tanphi, ten, tanpsi


def _region(active):
    sh = any(k[0] == "s" for k in active)
    te = any(k[0] == "t" for k in active)
    return {(False, False): "elastic", (True, False): "shear", (False, True): "tension",
            (True, True): "corner"}[(sh, te)]


def _yield_values(s, c, tanphi, ten):
    w = np.linalg.eigvalsh(_tensor(s))
    nphi = _nfac(tanphi)
    st = min(ten, c / tanphi) if tanphi > 0 else ten
    return w[0] - w[2] * nphi + 2 * c * math.sqrt(nphi), w[2] - st


def test_the_twins_reading_of_the_store_is_the_models():
    """tests/zone_plastic_twin.py writes its codes, columns and bits down itself (it shares no
    constant with the kernels): they must be the model's."""
    assert (zp.ZP_BULK, zp.ZP_SHEAR, zp.ZP_COHESION, zp.ZP_TANFRIC, zp.ZP_TENSION, zp.ZP_TANDIL) == \
        (mz.ZP_BULK, mz.ZP_SHEAR, mz.ZP_COHESION, mz.ZP_TANFRIC, mz.ZP_TENSION, mz.ZP_TANDIL)
    assert (zp.ZMODEL_ELASTIC, zp.ZMODEL_MOHR) == (ZONE_MODELS["elastic"].code, ZONE_MODELS["mohr-coulomb"].code)
    assert (zp.SHEAR_PAST, zp.TENSION_PAST) == (mz.ZSTATE_SHEAR_PAST, mz.ZSTATE_TENSION_PAST)


def test_mohr_return_matches_twin_on_random_states():
    rng = np.random.default_rng(11)
    seen = {"elastic": 0, "shear": 0, "tension": 0, "corner": 0}
    edge = 0
    for _ in range(3000):
        s0, de, c, tf, ten, td = _random_case(rng)
        s_k, bits, dsp_k = zm.mohr_update(s0, de, K, G, c, tf, ten, td)
        s_t, active, dsp_t, *_ = twin_mohr(s0, de, K, G, c, tf, ten, td)
        scale = np.abs(s0).max() + np.abs(s_t).max() + c
        assert np.abs(s_k - s_t).max() <= 1e-9 * scale, (s0, de, c, tf, ten, td)
        assert abs(dsp_k - dsp_t) <= 1e-9 * scale
        region = _region(active)
        seen[region] += 1
        edge += len([k for k in active if k[0] == "s"]) > 1
        assert bits == (1 if region in ("shear", "corner") else 0) | (2 if region in ("tension", "corner") else 0)
        # after the return the stress is admissible
        fs, ft = _yield_values(s_k, c, tf, ten)
        assert fs >= -1e-8 * scale and ft <= 1e-8 * scale
        if region == "elastic":
            assert dsp_k == 0.0
    assert min(seen.values()) >= 50, seen
    assert edge >= 20, edge


def test_single_plane_shear_return_is_itascas_and_flows_per_dilation():
    """Trial in the shear region: new principal stresses by Itasca's closed form, on the yield
    line; plastic strain increment along (-1, 0, N_psi) in the trial's principal axes."""
    c, ten = 1e6, 0.5e6
    for psi in (0.0, 10.0, 30.0):
        tf, td = math.tan(math.radians(30)), math.tan(math.radians(psi))
        nphi, npsi = 3.0, _nfac(td)
        s0 = np.array([-2e6, -3e6, -9e6, 0.4e6, 0.3e6, -0.2e6])
        de = np.array([8e-4, 6e-4, -4e-3, 0.2e-4, 0, 0])
        s_k, bits, dsp = zm.mohr_update(s0, de, K, G, c, tf, ten, td)
        assert bits == 1
        w = np.linalg.eigh(_tensor(s0) + (K - 2 * G / 3) * de[:3].sum() * np.eye(3) + 2 * G * _tensor(de))
        s1, s2, s3 = w[0]
        fs = s1 - s3 * nphi + 2 * c * math.sqrt(nphi)
        assert fs < 0 and s3 < ten
        lam_s = fs / ((A1 - A2 * npsi) - (-A1 * npsi + A2) * nphi)
        want = np.array([s1 - lam_s * (A1 - A2 * npsi), s2 - lam_s * A2 * (1 - npsi), s3 - lam_s * (A2 - A1 * npsi)])
        got = np.diag(w[1].T @ _tensor(s_k) @ w[1])
        assert np.allclose(got, want, rtol=1e-12, atol=1e-6)
        assert abs(want[0] - want[2] * nphi + 2 * c * math.sqrt(nphi)) < 1e-6
        # plastic strain = total - elastic, in the principal axes of the trial
        ds = _tensor(s_k) - _tensor(s0)
        de_el = (ds - (K - 2 * G / 3) / (3 * K) * np.trace(ds) * np.eye(3)) / (2 * G)
        ep = w[1].T @ (_tensor(de) - de_el) @ w[1]
        assert np.abs(ep - np.diag(np.diag(ep))).max() < 1e-12
        assert abs(ep[1, 1]) < 1e-12
        assert ep[0, 0] < 0 and abs(ep[2, 2] / ep[0, 0] + npsi) < 1e-8
        # plastic volume change: zero with psi = 0, (N_psi - 1) |de1_p| otherwise; dsp = K de_v^p
        assert abs(np.trace(ep) - (npsi - 1) * -ep[0, 0]) < 1e-12
        assert abs(dsp - K * np.trace(ep)) <= 1e-6 * abs(K * ep[0, 0])


def test_tension_return_is_associated_and_hits_the_cut_off():
    c, tf, ten = 2e6, math.tan(math.radians(35)), 0.3e6
    s0 = np.array([0.1e6, -0.2e6, 0.2e6, 0, 0, 0])
    de = np.array([0.0, 0.0, 4e-4, 0, 0, 0])
    s_k, bits, dsp = zm.mohr_update(s0, de, K, G, c, tf, ten, 0.0)
    assert bits == 2
    assert abs(s_k[2] - ten) < 1e-6
    trial_zz = 0.2e6 + A1 * 4e-4
    assert np.allclose(s_k[:2], [0.1e6 + A2 * 4e-4 - (trial_zz - ten) * A2 / A1,
                                 -0.2e6 + A2 * 4e-4 - (trial_zz - ten) * A2 / A1], rtol=1e-12)
    assert abs(dsp - (trial_zz - ten) * (A1 + 2 * A2) / (3 * A1)) < 1e-6


def test_state_bits_now_and_past():
    from dec3d.kernels.zmodels import merge_state
    assert merge_state(0, 1) == 1 | 4
    assert merge_state(1 | 4, 0) == 4
    assert merge_state(4, 2) == 4 | 2 | 8
    assert merge_state(2 | 8 | 4, 0) == 12
    assert merge_state(16 | 64 | 1, 32) == 32 | 64 | 128          # the weak plane's bits alike


# --------------------------------------------------------------------------------------------
# batched 4-node step and NMD against twins

CUBE = np.array([[x, y, z] for z in (0., 1.) for y in (0., 1.) for x in (0., 1.)])
CUBE5 = np.array([[0, 1, 2, 4], [1, 3, 2, 7], [1, 4, 5, 7], [2, 4, 6, 7], [1, 2, 4, 7]])


def _two_cubes(rng):
    """Two 5-tet cubes side by side sharing the face x = 1 (the right cube split as the mirror
    image of the left, so the shared face's triangles agree), gridpoints jittered."""
    pos = np.vstack([CUBE, (CUBE + [1.0, 0, 0])[[1, 3, 5, 7]]])   # rows 8..11: right cube's x = 2 corners
    ids = [1, 8, 3, 9, 5, 10, 7, 11]                               # right cube local corner -> row
    # the right cube uses the mirrored split so the shared face triangles agree: reflect x
    mirror = [1, 0, 3, 2, 5, 4, 7, 6]
    tets_r = np.array([[ids[mirror[a]] for a in t] for t in CUBE5])
    gp = np.vstack([CUBE5, tets_r])
    pos = pos + rng.normal(size=pos.shape) * 0.05
    return pos, gp


def twin_kinematics(x, v, dt):
    m = np.hstack([np.ones((4, 1)), x])
    dn = np.linalg.inv(m)[1:, :].T
    L = v.T @ dn
    return _vec6(0.5 * (L + L.T) * dt), abs(np.linalg.det(m)) / 6.0, dn


def twin_forces(x, s, vol, dn):
    return [-vol * _tensor(s) @ dn[n] for n in range(4)]


def twin_node_average(gp, vals, vols, node):
    acc, wt = {}, {}
    for t, (val, vol) in enumerate(zip(vals, vols)):
        for g in gp[t, :4]:
            m = node[g]
            acc[m] = acc.get(m, 0.0) + val * vol
            wt[m] = wt.get(m, 0.0) + vol
    return np.array([sum(acc[node[g]] / wt[node[g]] for g in gp[t, :4]) / 4 for t in range(len(gp))])


def _props(n, rng):
    prop = np.zeros((n, mz.NZPROP))
    prop[:, mz.ZP_BULK] = K; prop[:, mz.ZP_SHEAR] = G
    prop[:, mz.ZP_COHESION] = rng.uniform(0.1e6, 0.5e6, n)
    prop[:, mz.ZP_TANFRIC] = np.tan(np.radians(rng.uniform(10, 40, n)))
    prop[:, mz.ZP_TANDIL] = prop[:, mz.ZP_TANFRIC] * rng.uniform(0, 1, n)
    prop[:, mz.ZP_TENSION] = rng.uniform(0, 0.3e6, n)
    return prop


def _mohr_step(pos, vel, gp, prop, stress, state, force, dt, nmd=False, cm=None, node=None, zset=None, weight=None,
               parts=1, large=False):
    """The engine's zone step on every zone of gp (Mohr-Coulomb unless ``cm`` says otherwise)."""
    nz, nv = len(gp), len(pos)
    rows = np.arange(nz, dtype=np.int64)
    cm = np.full(nz, ZONE_MODELS["mohr-coulomb"].code, np.int8) if cm is None else cm
    node = np.arange(nv, dtype=np.int64) if node is None else node
    zset = np.full(nz, -1, np.int64) if zset is None else zset
    weight = np.ones(nz) if weight is None else weight
    st = Stepper(gp, rows, zset, weight, node, nv, cm, prop, parts)
    st.step(pos, vel, stress, state, force, np.zeros(nv), dt, large, nmd)
    return st


def test_tet_mohr_step_matches_twin():
    rng = np.random.default_rng(3)
    pos, gp = _two_cubes(rng)
    nz = len(gp)
    vel = rng.normal(size=(len(pos), 3)) * 1e-3
    prop = _props(nz, rng)
    s0 = np.array([_vec6(np.diag([-1e6, -1.5e6, -2e6]))] * nz) + rng.normal(size=(nz, 6)) * 2e5
    sk, fk, stk = s0.copy(), np.zeros((len(pos), 3)), np.array([0, 4, 8, 12] * 2 + [0, 0], np.int32)
    st0 = stk.copy()
    _mohr_step(pos, vel, gp, prop, sk, stk, fk, 1.0)
    ft = np.zeros_like(fk)
    nyield = 0
    for z in range(nz):
        de, vol, dn = twin_kinematics(pos[gp[z]], vel[gp[z]], 1.0)
        p = prop[z]
        s_new, active, *_ = twin_mohr(s0[z], de, K, G, p[mz.ZP_COHESION], p[mz.ZP_TANFRIC], p[mz.ZP_TENSION],
                                      p[mz.ZP_TANDIL])
        assert np.abs(sk[z] - s_new).max() < 1e-9 * np.abs(s_new).max()
        now = (1 if any(a[0] == "s" for a in active) else 0) | (2 if any(a[0] == "t" for a in active) else 0)
        assert stk[z] == (st0[z] & 12) | now | (now << 2)
        nyield += now > 0
        for n, f in enumerate(twin_forces(pos[gp[z]], s_new, vol, dn)):
            ft[gp[z, n]] += f
    assert nyield >= 3
    assert np.abs(fk - ft).max() < 1e-9 * np.abs(ft).max()
    assert np.abs(fk.sum(axis=0)).max() < 1e-9 * np.abs(fk).max()


def test_nmd_kernels_match_twin_and_pass_the_patch_test():
    rng = np.random.default_rng(5)
    pos, gp = _two_cubes(rng)
    nz = len(gp)
    # link two gridpoints to masters (a shared gridpoint copied in another block's range)
    node = np.arange(len(pos), dtype=np.int64)
    rows = np.array([0, 2, 3, 4, 5, 6, 8, 9], np.int64)        # a subset: zones 1 and 7 left out
    vol = rng.uniform(0.1, 0.3, len(rows))
    de = rng.normal(size=(len(rows), 6)) * 1e-4
    dk = de.copy()
    zp.nmd_strain_average(gp, rows, node, vol, dk)
    ev = de[:, :3].sum(axis=1)
    bar = twin_node_average(gp[rows], ev, vol, node)
    want = de.copy()
    want[:, :3] += ((bar - ev) / 3)[:, None]
    assert np.allclose(dk, want, rtol=0, atol=1e-16)
    assert np.allclose(dk[:, 3:], de[:, 3:], rtol=0, atol=0)            # deviatoric parts kept
    assert np.allclose(dk[:, :3] - dk[:, :3].sum(1, keepdims=True) / 3,
                       de[:, :3] - ev[:, None] / 3, atol=1e-18)
    # linked gridpoints average at their master
    node2 = node.copy(); node2[8] = 1; node2[10] = 5
    dk2 = de.copy()
    zp.nmd_strain_average(gp, rows, node2, vol, dk2)
    bar2 = twin_node_average(gp[rows], ev, vol, node2)
    assert np.allclose(dk2[:, :3].sum(1), bar2, atol=1e-16)
    # stress correction
    dsp = rng.normal(size=len(rows)) * 1e4
    dsp[::3] = 0.0
    s = rng.normal(size=(nz, 6)) * 1e6
    sk = s.copy()
    zp.nmd_stress_correction(gp, rows, node, vol, dsp, sk)
    barp = twin_node_average(gp[rows], dsp, vol, node)
    want = s.copy()
    want[rows, :3] += (dsp - barp)[:, None]
    assert np.allclose(sk, want, rtol=0, atol=1e-8)
    # patch test: uniform values are left as they are
    du = np.tile(rng.normal(size=6) * 1e-4, (len(rows), 1))
    dku = du.copy()
    zp.nmd_strain_average(gp, rows, node, vol, dku)
    assert np.allclose(dku, du, rtol=1e-13, atol=0)
    su = s.copy()
    zp.nmd_stress_correction(gp, rows, node, vol, np.full(len(rows), 3e4), su)
    assert np.allclose(su, s, rtol=0, atol=1e-9)


def test_tet_zone_step_elastic_and_mohr_paths():
    rng = np.random.default_rng(9)
    pos, gp = _two_cubes(rng)
    nz = len(gp)
    vel = rng.normal(size=(len(pos), 3)) * 1e-4
    rows = np.arange(nz, dtype=np.int64)
    node = np.arange(len(pos), dtype=np.int64)
    prop = _props(nz, rng)
    s0 = rng.normal(size=(nz, 6)) * 1e5
    # all elastic, no NMD: the engine's zone step (forces in the order of its scatter plan)
    cm = np.full(nz, zp.ZMODEL_ELASTIC, np.int8)
    sa, fa, st = s0.copy(), np.zeros((len(pos), 3)), np.zeros(nz, np.int32)
    zp.tet_zone_step(pos, vel, gp, rows, node, cm, prop, 0.5, False, sa, st, fa)
    sb, fb = s0.copy(), np.zeros_like(fa)
    _mohr_step(pos, vel, gp, prop, sb, np.zeros(nz, np.int32), fb, 0.5, cm=cm)
    assert np.allclose(sa, sb, rtol=1e-12, atol=1e-6) and np.allclose(fa, fb, rtol=1e-12, atol=1e-6)
    # all Mohr-Coulomb, no NMD: the same stresses and states
    cm[:] = zp.ZMODEL_MOHR
    vel *= 30
    sa, fa, sta = s0.copy(), np.zeros_like(fa), np.zeros(nz, np.int32)
    zp.tet_zone_step(pos, vel, gp, rows, node, cm, prop, 1.0, False, sa, sta, fa)
    sb, fb, stb = s0.copy(), np.zeros_like(fa), np.zeros(nz, np.int32)
    _mohr_step(pos, vel, gp, prop, sb, stb, fb, 1.0, cm=cm)
    assert np.array_equal(sa, sb) and np.allclose(fa, fb, rtol=1e-12, atol=1e-6) and np.array_equal(sta, stb)
    assert (sta > 0).sum() >= 3
    # with NMD: twin of the whole sequence (strain average, return, stress correction, forces)
    sa, fa, sta = s0.copy(), np.zeros_like(fa), np.zeros(nz, np.int32)
    zp.tet_zone_step(pos, vel, gp, rows, node, cm, prop, 1.0, True, sa, sta, fa)
    kin = [twin_kinematics(pos[gp[z]], vel[gp[z]], 1.0) for z in rows]
    de = np.array([k[0] for k in kin]); vol = np.array([k[1] for k in kin])
    ev = de[:, :3].sum(1)
    de[:, :3] += ((twin_node_average(gp, ev, vol, node) - ev) / 3)[:, None]
    snew, dsp = [], []
    for z in rows:
        p = prop[z]
        s_, _, d_, *_ = twin_mohr(s0[z], de[z], K, G, p[3], p[4], p[5], p[6])
        snew.append(s_); dsp.append(d_)
    snew, dsp = np.array(snew), np.array(dsp)
    snew[:, :3] += (dsp - twin_node_average(gp, dsp, vol, node))[:, None]
    assert np.abs(sa - snew).max() < 1e-9 * np.abs(snew).max()
    ft = np.zeros_like(fa)
    for z in rows:
        for n, f in enumerate(twin_forces(None, snew[z], vol[z], kin[z][2])):
            ft[gp[z, n]] += f
    assert np.abs(fa - ft).max() < 1e-9 * np.abs(ft).max()
    assert np.abs(dsp).max() > 0      # some zones dilated, so the stress averaging was exercised


# --------------------------------------------------------------------------------------------
# mixed-discretization stress average against its twin

def test_md_stress_average_matches_twin():
    rng = np.random.default_rng(21)
    nz = 12
    stress = rng.normal(size=(nz, 6)) * 1e6
    rows = np.array([0, 1, 2, 3, 4, 5, 6, 7, 9, 11], np.int64)
    zset = np.array([0, 0, 0, 1, 1, 1, 1, -1, 0, 1], np.int64)
    vol = rng.uniform(0.1, 1.0, len(rows))
    dsp = rng.normal(size=len(rows)) * 1e4
    sk = stress.copy()
    zp.md_stress_average(rows, zset, 2, vol, dsp, sk)
    want = stress.copy()
    for h in (0, 1):
        ks = [k for k in range(len(rows)) if zset[k] == h]
        avg = sum(dsp[k] * vol[k] for k in ks) / sum(vol[k] for k in ks)
        for k in ks:
            want[rows[k], :3] += dsp[k] - avg
    assert np.allclose(sk, want, rtol=0, atol=1e-8)
    assert np.array_equal(sk[[7, 8, 10]], stress[[7, 8, 10]])      # no set / not in rows: untouched
    assert np.array_equal(sk[:, 3:], stress[:, 3:])
    # Eq. 67: a set that started with one mean stress ends with the volume-averaged one
    s2 = np.zeros((nz, 6)); s2[:, :3] = -1e6
    s2[rows, :3] -= dsp[:, None]                                   # each zone's own return
    zp.md_stress_average(rows, zset, 2, vol, dsp, s2)
    for h in (0, 1):
        ks = [k for k in range(len(rows)) if zset[k] == h]
        pm = sum(s2[rows[k], :3].mean() * vol[k] for k in ks) / sum(vol[k] for k in ks)
        assert np.allclose([s2[rows[k], :3].mean() for k in ks], pm, rtol=1e-12)


def test_zone_forces_plastic_matches_twin():
    """The drop-in step (sets, weights, NMD, large strain, elastic and Mohr-Coulomb zones mixed)
    against the twins composed by hand."""
    rng = np.random.default_rng(17)
    pos, gp = _two_cubes(rng)
    nzn, nv = len(gp), len(pos)
    vel = rng.normal(size=(nv, 3)) * 3e-3
    rows = np.arange(nzn, dtype=np.int64)
    zset = np.array([0, 0, 0, 0, 0, -1, -1, -1, -1, -1], np.int64)     # first cube: one "hexahedral" set
    weight = np.where(zset >= 0, 0.5, 1.0)
    node = np.arange(nv, dtype=np.int64)
    prop = _props(nzn, rng)
    cm = np.array([2, 1, 2, 2, 1, 2, 1, 2, 2, 2], np.int8)
    s0 = rng.normal(size=(nzn, 6)) * 2e5 + np.array([-1e6, -1e6, -1e6, 0, 0, 0])
    st0 = np.zeros(nzn, np.int32)
    for large, nmd in ((False, False), (True, True), (False, True)):
        sk, stk, fk, mk = s0.copy(), st0.copy(), np.zeros((nv, 3)), np.zeros(nv)
        zp.zone_forces_plastic(pos, vel, gp, rows, zset, weight, 1, node, cm, prop, 1.0, large, nmd, sk, stk, fk, mk)
        # twin
        kin = []
        for z in rows:
            x, v = pos[gp[z]], vel[gp[z]]
            m = np.hstack([np.ones((4, 1)), x])
            dn = np.linalg.inv(m)[1:, :].T
            L = v.T @ dn
            kin.append((_vec6(0.5 * (L + L.T)), abs(np.linalg.det(m)) / 6, dn, 0.5 * (L - L.T)))
        de = np.array([k[0] for k in kin]); vol = np.array([k[1] for k in kin])
        ev = de[:, :3].sum(1)
        bar = ev.copy()
        inset = zset >= 0
        bar[inset] = (ev[inset] * vol[inset]).sum() / vol[inset].sum()
        if nmd:
            free = ~inset
            bar[free] = twin_node_average(gp[free], ev[free], vol[free], node)
        de[:, :3] += ((bar - ev) / 3)[:, None]
        snew, dsp = np.zeros((nzn, 6)), np.zeros(nzn)
        for z in rows:
            S = _tensor(s0[z])
            if large:
                W = kin[z][3]
                S = S + W @ S - S @ W
            p = prop[z]
            if cm[z] == 1:
                e = _tensor(de[z])
                snew[z] = _vec6(S + (K - 2 * G / 3) * np.trace(e) * np.eye(3) + 2 * G * e)
            else:
                snew[z], _, dsp[z], *_ = twin_mohr(_vec6(S), de[z], K, G, p[3], p[4], p[5], p[6])
        avg = (dsp[inset] * vol[inset]).sum() / vol[inset].sum()
        snew[inset, :3] += (dsp[inset] - avg)[:, None]
        if nmd:
            snew[free, :3] += (dsp[free] - twin_node_average(gp[free], dsp[free], vol[free], node))[:, None]
        assert np.abs(sk - snew).max() < 1e-9 * np.abs(snew).max(), (large, nmd)
        ft, mt = np.zeros((nv, 3)), np.zeros(nv)
        for z in rows:
            for n in range(4):
                f = -weight[z] * vol[z] * _tensor(snew[z]) @ kin[z][2][n]
                ft[gp[z, n]] += f
                mt[gp[z, n]] += np.linalg.norm(f)
        assert np.abs(fk - ft).max() < 1e-9 * np.abs(ft).max()
        assert np.abs(mk - mt).max() < 1e-9 * mt.max()
        assert (stk[cm == 2] > 0).sum() >= 2 and (stk[cm == 1] == 0).all()
        assert np.abs(dsp).max() > 0


@pytest.mark.parametrize("c, phi, ten, psi", [(1e6, 0.0, 0.0, 0.0),        # Tresca, no tension
                                              (1e6, 0.0, 1e12, 0.0),       # Tresca
                                              (0.0, 35.0, 0.0, 0.0),       # cohesionless sand
                                              (0.5e6, 30.0, 0.2e6, 30.0),  # associated flow
                                              (2e6, 89.0, 1e6, 0.0)])      # friction near 90
def test_limiting_properties_match_twin_and_stay_finite(c, phi, ten, psi):
    rng = np.random.default_rng(int(phi * 10 + psi))
    tf, td = math.tan(math.radians(phi)), math.tan(math.radians(psi))
    for _ in range(300):
        R = _rand_rotation(rng)
        s0 = _vec6(R @ np.diag(rng.uniform(-6e6, 1e5, 3)) @ R.T)
        de = rng.normal(size=6) * 10 ** rng.uniform(-5, -3)
        s_k, bits, dsp = zm.mohr_update(s0, de, K, G, c, tf, ten, td)
        s_t, active, dsp_t, *_ = twin_mohr(s0, de, K, G, c, tf, ten, td)
        scale = np.abs(s0).max() + np.abs(s_t).max() + c
        assert np.all(np.isfinite(s_k)) and math.isfinite(dsp)
        assert np.abs(s_k - s_t).max() <= 1e-9 * scale
        fs, ft = _yield_values(s_k, c, tf, ten)
        assert fs >= -1e-8 * scale and ft <= 1e-8 * scale


def test_parallel_step_is_bit_identical_to_serial():
    """The engine's zone step in 1, 2, 3 chunks on 1 and 2 threads gives the twin's bits, with a
    mixed-discretization set, a linked gridpoint, elastic and Mohr-Coulomb zones."""
    import numba
    rng = np.random.default_rng(23)
    pos, gp = _two_cubes(rng)
    nzn, nv = len(gp), len(pos)
    vel = rng.normal(size=(nv, 3)) * 3e-3
    rows = np.arange(nzn, dtype=np.int64)
    zset = np.array([0, 0, 0, 0, 0, -1, -1, -1, -1, -1], np.int64)
    weight = np.where(zset >= 0, 0.5, 1.0)
    node = np.arange(nv, dtype=np.int64); node[8] = 1                # one linked gridpoint
    prop = _props(nzn, rng)
    cm = np.array([2, 1, 2, 2, 1, 2, 1, 2, 2, 2], np.int8)
    s0 = rng.normal(size=(nzn, 6)) * 2e5 + np.array([-1e6, -1e6, -1e6, 0, 0, 0])
    keep = numba.get_num_threads()
    try:
        for large, nmd in ((False, False), (True, True)):
            ref = [s0.copy(), np.zeros(nzn, np.int32), rng.normal(size=(nv, 3)), np.zeros(nv)]
            ref[3][:] = 1.0
            par = [a.copy() for a in ref]
            zp.zone_forces_plastic(pos, vel, gp, rows, zset, weight, 1, node, cm, prop, 1.0, large, nmd, *ref)
            for nt in (1, 2):
                numba.set_num_threads(min(nt, numba.config.NUMBA_NUM_THREADS))
                for parts in (1, 2, 3):
                    out = [a.copy() for a in par]
                    st = Stepper(gp, rows, zset, weight, node, nv, cm, prop, parts)
                    st.step(pos, vel, *out, 1.0, large, nmd)
                    for a, b in zip(ref, out):
                        assert np.array_equal(a, b), (large, nmd, nt, parts)
            assert (ref[1] > 0).sum() >= 2
    finally:
        numba.set_num_threads(keep)


def test_step_with_kept_scratch_ignores_what_the_scratch_held():
    """The stepper keeps the zone step's scratch from step to step: scratch full of NaN gives the
    twin's bits, elastic-only (forces in the second sweep) and with Mohr-Coulomb zones."""
    rng = np.random.default_rng(29)
    pos, gp = _two_cubes(rng)
    nzn, nv = len(gp), len(pos)
    vel = rng.normal(size=(nv, 3)) * 3e-3
    rows = np.arange(nzn, dtype=np.int64)
    zset = np.array([0, 0, 0, 0, 0, -1, -1, -1, -1, -1], np.int64)
    weight = np.where(zset >= 0, 0.5, 1.0)
    node = np.arange(nv, dtype=np.int64); node[8] = 1
    prop = _props(nzn, rng)
    s0 = rng.normal(size=(nzn, 6)) * 2e5 + np.array([-1e6, -1e6, -1e6, 0, 0, 0])
    for cm in (np.ones(nzn, np.int8), np.array([2, 1, 2, 2, 1, 2, 1, 2, 2, 2], np.int8)):
        for large, nmd in ((False, True), (True, True), (True, False)):
            ref = [s0.copy(), np.zeros(nzn, np.int32), np.zeros((nv, 3)), np.zeros(nv)]
            zp.zone_forces_plastic(pos, vel, gp, rows, zset, weight, 1, node, cm, prop, 1.0, large, nmd, *ref)
            assert np.abs(ref[2]).max() > 0.0
            for parts in (1, 2):
                st = Stepper(gp, rows, zset, weight, node, nv, cm, prop, parts)
                for a in st.scr:
                    a[...] = np.nan
                out = [s0.copy(), np.zeros(nzn, np.int32), np.zeros((nv, 3)), np.zeros(nv)]
                st.step(pos, vel, *out, 1.0, large, nmd)
                for a, b in zip(ref, out):
                    assert np.array_equal(a, b), (cm[0], large, nmd, parts)
