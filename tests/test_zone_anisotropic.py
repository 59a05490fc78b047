"""Zone models ``anisotropic`` (transversely isotropic) and ``orthotropic``
(dec3d/kernels/zmodels/anisotropic.py, orthotropic.py): uniaxial stresses in several directions
against the compliance of Itasca's pages, the stiffness against numpy's inverse of the rotated
compliance, the orientation convention on hand-worked cases, isotropic constants against Hooke's
law, a slow numpy twin on random states (stress and the dsp that symmetrizes NMD), the host's
check and its bound for the mass scaling, and cubes of zones through the whole zone step with NMD
on (stable, and the uniaxial strains of the compliance)."""
import math

import numpy as np
import pytest

from dec3d.kernels.zmodels import CODES, CORRECTING_CODES, NWORK, NZHIST, NZPROP, PLASTIC_CODES, no_tables
from dec3d.kernels.zmodels import anisotropic as ti
from dec3d.kernels.zmodels import orthotropic as ort
from dec3d.kernels.zmodels._common import hooke
from dec3d.kernels.zone_mohr import mohr_work
from dec3d.physics import cmodels

TAB = no_tables()
MW = mohr_work()


# ---- independent formulas (numpy) ----------------------------------------------------------------

def axes(dip, ddir, rot):
    """Rows: 1', 2', 3' in global components (x east, y north, z up), from the docstring's
    definitions: dip vector d, upward normal n, 1' = d turned by rot about n."""
    a, b, r = np.radians([dip, ddir, rot])
    d = np.array([math.cos(a) * math.sin(b), math.cos(a) * math.cos(b), -math.sin(a)])
    n = np.array([math.sin(a) * math.sin(b), math.sin(a) * math.cos(b), math.cos(a)])
    one = math.cos(r) * d + math.sin(r) * np.cross(n, d)
    return np.array([one, np.cross(n, one), n])


def local_compliance(E1, E2, E3, n12, n13, n23, G12, G13, G23):
    """6×6 local compliance, Itasca's page: (ε11 ε22 ε33 γ12 γ13 γ23) = S (σ11 σ22 σ33 σ12 σ13 σ23)."""
    S = np.zeros((6, 6))
    S[:3, :3] = [[1 / E1, -n12 / E2, -n13 / E3], [-n12 / E2, 1 / E2, -n23 / E3], [-n13 / E3, -n23 / E3, 1 / E3]]
    S[3, 3], S[4, 4], S[5, 5] = 1 / G12, 1 / G13, 1 / G23
    return S


def tensor(v):
    return np.array([[v[0], v[3], v[4]], [v[3], v[1], v[5]], [v[4], v[5], v[2]]])


def vec(t):
    return np.array([t[0, 0], t[1, 1], t[2, 2], t[0, 1], t[0, 2], t[1, 2]])


def global_compliance(S, R):
    """6×6 global compliance (engineering shear) by mapping each unit stress: σ' = R σ Rᵀ,
    ε' from S, ε = Rᵀ ε' R."""
    out = np.zeros((6, 6))
    for j in range(6):
        sig = np.zeros(6)
        sig[j] = 1.0
        loc = vec(R @ tensor(sig) @ R.T)
        e_eng = S @ loc
        e_loc = np.concatenate([e_eng[:3], e_eng[3:] / 2])
        e = vec(R.T @ tensor(e_loc) @ R)
        out[:, j] = np.concatenate([e[:3], 2 * e[3:]])
    return out


def run(model, p, d, s=None, dsp=False):
    """The new stress (and the returned dsp) of one update; the bits are always 0."""
    s = np.zeros(6) if s is None else s
    out = model.update(p, np.zeros((1, NZHIST)), 0, 1e9, 1e9, *d, *s, TAB, np.full(NWORK, np.nan), MW)
    assert out[0] == 0
    return (np.array(out[1:7]), out[7]) if dsp else np.array(out[1:7])


def ortho_rows(E1, E2, E3, n12, n13, n23, G12, G13, G23, dip, ddir, rot):
    p = np.zeros((1, NZPROP))
    p[0, ort.P_OWN:ort.P_OWN + 12] = [E1, E2, E3, n12, n13, n23, G12, G13, G23, dip, ddir, rot]
    return p


def ti_rows(E, En, nu, nun, Gn, dip, ddir):
    p = np.zeros((1, NZPROP))
    p[0, ti.P_OWN:ti.P_OWN + 7] = [E, En, nu, nun, Gn, dip, ddir]
    return p


def ti_as_ortho(E, En, nu, nun, Gn):
    return E, E, En, nu, nun, nun, E / (2 * (1 + nu)), Gn, Gn


ORTHO = (40e9, 25e9, 10e9, 0.2, 0.35, 0.3, 12e9, 6e9, 4e9)
TI = (30e9, 12e9, 0.22, 0.3, 5e9)


def test_registered():
    assert CODES["anisotropic"] == 7 and CODES["orthotropic"] == 8
    assert {7, 8} <= CORRECTING_CODES and not {7, 8} & PLASTIC_CODES    # the averaging sweep (NMD), no yield
    o = cmodels.ZONE_MODELS["orthotropic"]
    a = cmodels.ZONE_MODELS["anisotropic"]
    assert set(o.props) == {"density", "young-1", "young-2", "young-3", "poisson-12", "poisson-13", "poisson-23",
                            "shear-12", "shear-13", "shear-23", "dip", "dip-direction", "rotation"}
    assert set(a.props) == {"density", "young-plane", "young-normal", "poisson-plane", "poisson-normal",
                            "shear-normal", "dip", "dip-direction"}
    assert all(p.column >= 8 for m in (o, a) for p in m.props.values() if p.name != "density")


DIRECTIONS = [(1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 0), (1, -2, 3), (-0.3, 0.5, 0.8)]


@pytest.mark.parametrize("which", ["ortho", "ti"])
@pytest.mark.parametrize("orient", [(0, 0, 0), (35, 120, 25), (90, 90, 0), (60, 300, -70)])
def test_uniaxial_stress_against_compliance(which, orient):
    """A uniaxial stress σ0 m⊗m along several m: its strain from the rotated compliance (applied
    to the stress, no inversion), driven through ``update``, gives back σ0 m⊗m to 1e-10."""
    if which == "ortho":
        consts, p, model = ORTHO, ortho_rows(*ORTHO, *orient), ort
    else:
        consts, p, model = ti_as_ortho(*TI), ti_rows(*TI, *orient[:2]), ti
        orient = (orient[0], orient[1], 0.0)
    R = axes(*orient)
    S = local_compliance(*consts)
    for m in DIRECTIONS:
        m = np.array(m, float) / np.linalg.norm(m)
        sig = -2e6 * np.outer(m, m)
        loc = vec(R @ sig @ R.T)
        e_eng = S @ loc
        e = R.T @ tensor(np.concatenate([e_eng[:3], e_eng[3:] / 2])) @ R
        out = run(model, p, vec(e))
        np.testing.assert_allclose(out, vec(sig), rtol=0, atol=1e-10 * 2e6)


@pytest.mark.parametrize("orient", [(0, 0, 0), (35, 120, 25), (90, 90, 0), (72, 200, 140)])
def test_stiffness_is_inverse_of_rotated_compliance(orient):
    """Random strains: ``update``'s stress increment equals numpy.linalg.inv(S_global) applied
    to the engineering strain, to 1e-10."""
    rng = np.random.default_rng(8)
    R = axes(*orient)
    C = np.linalg.inv(global_compliance(local_compliance(*ORTHO), R))
    p = ortho_rows(*ORTHO, *orient)
    for _ in range(20):
        d = rng.normal(0, 1e-4, 6)
        want = C @ np.concatenate([d[:3], 2 * d[3:]])
        np.testing.assert_allclose(run(ort, p, d), want, rtol=0, atol=1e-10 * np.abs(want).max())


def test_rotation_convention():
    """Hand-worked orientations (module text): dip 90 / dip-direction 90 makes x the normal 3'
    (the axis of symmetry of the TI model) and 1' = −z; dip 0, dip-direction 0 has 1' = +y,
    2' = −x; rotation 90 turns 1' to −x (counter-clockwise seen from above)."""
    E, En, nu, nun, Gn = TI
    p = ti_rows(E, En, nu, nun, Gn, 90.0, 90.0)
    s0 = -1e6
    # σxx alone: normal to the plane of isotropy
    out = run(ti, p, (s0 / En, -nun * s0 / En, -nun * s0 / En, 0, 0, 0))
    np.testing.assert_allclose(out, [s0, 0, 0, 0, 0, 0], atol=1e-9 * abs(s0))
    # σzz alone: in the plane (ε_xx = −ν' σ/E', by the symmetric compliance)
    out = run(ti, p, (-nun * s0 / En, -nu * s0 / E, s0 / E, 0, 0, 0))
    np.testing.assert_allclose(out, [0, 0, s0, 0, 0, 0], atol=1e-9 * abs(s0))
    # shear in the plane of isotropy (yz) takes G = E / 2(1 + ν); out of it (xy, xz) G'
    out = run(ti, p, (0, 0, 0, 0, 0, 1e-5))
    np.testing.assert_allclose(out, [0, 0, 0, 0, 0, 2 * E / (2 * (1 + nu)) * 1e-5], atol=1e-9 * E * 1e-5)
    out = run(ti, p, (0, 0, 0, 1e-5, 0, 0))
    np.testing.assert_allclose(out, [0, 0, 0, 2 * Gn * 1e-5, 0, 0], atol=1e-9 * E * 1e-5)

    E1, E2, E3, n12, n13, n23, G12, G13, G23 = ORTHO
    cases = [((0, 0, 0), (1, 0, 2)),        # local 1', 2', 3' along global y, x, z
             ((0, 0, 90), (0, 1, 2)),       # rotation 90: 1' along x, 2' along y
             ((90, 90, 0), (2, 1, 0))]      # 1' along z, 2' along y, 3' along x
    for orient, g in cases:
        p = ortho_rows(*ORTHO, *orient)
        # uniaxial σ0 along local 1' (global axis g[0]): ε1' = σ/E1, ε2' = −ν12 σ/E2, ε3' = −ν13 σ/E3
        d = np.zeros(6)
        d[g[0]], d[g[1]], d[g[2]] = s0 / E1, -n12 * s0 / E2, -n13 * s0 / E3
        want = np.zeros(6)
        want[g[0]] = s0
        np.testing.assert_allclose(run(ort, p, d), want, atol=1e-9 * abs(s0))
        d = np.zeros(6)
        d[g[2]], d[g[0]], d[g[1]] = s0 / E3, -n13 * s0 / E3, -n23 * s0 / E3
        want = np.zeros(6)
        want[g[2]] = s0
        np.testing.assert_allclose(run(ort, p, d), want, atol=1e-9 * abs(s0))


def test_isotropic_constants_reduce_to_hooke():
    """E = E', ν = ν', G' = E/2(1 + ν) in any orientation (and the orthotropic model with equal
    constants): the update is Hooke's law with K = E/3(1 − 2ν), G = E/2(1 + ν), to 1e-12."""
    rng = np.random.default_rng(3)
    for _ in range(50):
        E = rng.uniform(1e9, 1e11)
        nu = rng.uniform(-0.5, 0.45)
        G = E / (2 * (1 + nu))
        K = E / (3 * (1 - 2 * nu))
        dip, ddir, rot = rng.uniform(0, 90), rng.uniform(0, 360), rng.uniform(-180, 180)
        d = rng.normal(0, 1e-4, 6)
        s = rng.normal(0, 1e6, 6)
        want = np.array(hooke(K, G, *d, *s))
        scale = np.abs(want - s).max()
        got, dsp = run(ti, ti_rows(E, E, nu, nu, G, dip, ddir), d, s, dsp=True)
        np.testing.assert_allclose(got - s, want - s, rtol=0, atol=1e-12 * scale)
        assert abs(dsp) <= 1e-12 * scale            # no mean stress from the deviator: the elastic step
        got, dsp = run(ort, ortho_rows(E, E, E, nu, nu, nu, G, G, G, dip, ddir, rot), d, s, dsp=True)
        np.testing.assert_allclose(got - s, want - s, rtol=0, atol=1e-12 * scale)
        assert abs(dsp) <= 1e-12 * scale


def twin(consts, orient, d, s):
    """Slow twin: numpy inverse of the local compliance, strain rotated to the local axes as a
    tensor, stress rotated back; and dsp = −(mean stress of C applied to the deviator of d)."""
    R = axes(*orient)
    C = np.linalg.inv(local_compliance(*consts))

    def stress(dd):
        el = R @ tensor(dd) @ R.T
        sl = C @ np.concatenate([vec(el)[:3], 2 * vec(el)[3:]])
        return vec(R.T @ tensor(sl) @ R)
    dev = np.array(d, float)
    dev[:3] -= dev[:3].sum() / 3
    return s + stress(d), -stress(dev)[:3].mean()


def _random_ortho(rng):
    while True:
        E = rng.uniform(1e9, 8e10, 3)
        nus = rng.uniform(-0.3, 0.8, 3)
        G = rng.uniform(5e8, 4e10, 3)
        c = (*E, *nus, *G)
        if np.linalg.eigvalsh(local_compliance(*c)).min() > 0:
            return c


def test_twin_random_states():
    """200 random orthotropic zones (constants, orientation, stress, strain increment) and 200
    transversely isotropic ones: the kernel against the twin to 1e-10 of the increment."""
    rng = np.random.default_rng(78)
    for i in range(400):
        s = rng.normal(0, 1e6, 6)
        d = rng.normal(0, 1e-4, 6)
        orient = (rng.uniform(0, 90), rng.uniform(-360, 720), rng.uniform(-200, 200))
        if i % 2:
            c = _random_ortho(rng)
            got, dsp = run(ort, ortho_rows(*c, *orient), d, s, dsp=True)
        else:
            while True:
                E, En = rng.uniform(1e9, 8e10, 2)
                nu, nun = rng.uniform(-0.5, 0.9, 2)
                Gn = rng.uniform(5e8, 4e10)
                c = ti_as_ortho(E, En, nu, nun, Gn)
                if nu > -1 and np.linalg.eigvalsh(local_compliance(*c)).min() > 0:
                    break
            orient = (orient[0], orient[1], 0.0)
            got, dsp = run(ti, ti_rows(E, En, nu, nun, Gn, orient[0], orient[1]), d, s, dsp=True)
        want, wdsp = twin(c, orient, d, s)
        np.testing.assert_allclose(got - s, want - s, rtol=0, atol=1e-10 * np.abs(want - s).max())
        assert abs(dsp - wdsp) <= 1e-10 * np.abs(want - s).max()


def test_inadmissible_constants_keep_stress():
    s = np.arange(6.0)
    bad = [(10e9, 10e9, 10e9, 0.9, 0.9, 0.9, 1e9, 1e9, 1e9), (0.0, 10e9, 10e9, 0.2, 0.2, 0.2, 1e9, 1e9, 1e9),
           (10e9, 10e9, 10e9, 0.2, 0.2, 0.2, 1e9, 0.0, 1e9)]
    for c in bad:
        out = run(ort, ortho_rows(*c, 30, 40, 50), np.full(6, 1e-4), s)
        assert np.array_equal(out, s)
    out = run(ti, ti_rows(10e9, 10e9, -1.0, 0.2, 1e9, 30, 40), np.full(6, 1e-4), s)
    assert np.array_equal(out, s)


def test_host_check_names_zones():
    m = cmodels.ZONE_MODELS["orthotropic"]
    rows = np.zeros((3, NZPROP))
    for r in range(3):
        rows[r] = ortho_rows(*ORTHO, 10, 20, 30)[0]
    rows[:, 2] = 2500.0
    rows[1, ort.P_NU12] = 2.0                      # not positive definite
    probs, _ = m.problems(rows, np.array([11, 12, 13]))
    assert len(probs) == 1 and "positive definite" in probs[0] and "(12)" in probs[0]
    rows[1, ort.P_NU12] = 0.2
    rows[2, ort.P_G13] = 0.0
    probs, _ = m.problems(rows, np.array([11, 12, 13]))
    assert len(probs) == 1 and probs[0].startswith("shear-13") and "(13)" in probs[0]
    a = cmodels.ZONE_MODELS["anisotropic"]
    rows = np.zeros((2, NZPROP))
    rows[0] = ti_rows(*TI, 0, 0)[0]
    rows[1] = ti_rows(30e9, 1e9, 0.2, 2.0, 1e9, 0, 0)[0]      # ν'² E/E' too large
    rows[:, 2] = 2500.0
    probs, _ = a.problems(rows, np.array([5, 6]))
    assert len(probs) == 1 and "(6)" in probs[0]
    rows[1, ti.P_DIP] = 95.0
    probs, _ = a.problems(rows, np.array([5, 6]))
    assert any(p.startswith("dip ") for p in probs)


def test_moduli_bound_the_acoustic_tensor():
    """K + 4G/3 from the host is the largest Mandel eigenvalue Λ of the stiffness, bounds
    u·Q(n)·u over sampled directions, and for isotropic constants is max(3K, 2G)."""
    rng = np.random.default_rng(11)
    m = cmodels.ZONE_MODELS["orthotropic"]
    dirs = rng.normal(size=(3000, 3))
    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    for _ in range(10):
        c = _random_ortho(rng)
        orient = (rng.uniform(0, 90), rng.uniform(0, 360), rng.uniform(0, 360))
        K, G = m.bulk_shear(ortho_rows(*c, *orient))
        M = K[0] + 4 * G[0] / 3
        Cg = np.linalg.inv(global_compliance(local_compliance(*c), axes(*orient)))
        # Mandel form: σ_M = W σ, ε_M = W ε (shears by √2) and γ = √2 ε_M, so C_M = W C_voigt W
        W = np.diag([1, 1, 1, math.sqrt(2), math.sqrt(2), math.sqrt(2)])
        mandel = W @ Cg @ W
        lam = np.linalg.eigvalsh(0.5 * (mandel + mandel.T)).max()
        assert M == pytest.approx(lam, rel=1e-10)
        assert G[0] == pytest.approx(max(c[6:]), rel=1e-14) and K[0] > 0
        C4 = np.zeros((3, 3, 3, 3))
        idx = {(0, 0): 0, (1, 1): 1, (2, 2): 2, (0, 1): 3, (1, 0): 3, (0, 2): 4, (2, 0): 4, (1, 2): 5, (2, 1): 5}
        for (i, j), a in idx.items():
            for (k, l), b in idx.items():
                C4[i, j, k, l] = Cg[a, b]
        Q = np.einsum("ijkl,nj,nl->nik", C4, dirs, dirs)
        qmax = np.linalg.eigvalsh(Q).max()
        assert qmax <= M * (1 + 1e-12)
        assert qmax >= 0.5 * M                 # the bound is not absurdly loose either
    E, nu = 20e9, 0.25
    K0, G0 = E / (3 * (1 - 2 * nu)), E / (2 * (1 + nu))
    K, G = cmodels.ZONE_MODELS["anisotropic"].bulk_shear(ti_rows(E, E, nu, nu, G0, 30, 60))
    assert K[0] + 4 * G[0] / 3 == pytest.approx(max(3 * K0, 2 * G0), rel=1e-12)
    assert G[0] == pytest.approx(G0, rel=1e-12)


# ---- through the zone step ---------------------------------------------------------------------

def _assembled_stiffness(symmetrize):
    """The 4-node zone step's stiffness on a jittered lattice of orthotropic zones (one set of
    constants and axes), NMD on: column j the nodal forces of a unit velocity on freedom j over a
    unit step from zero stress. ``symmetrize`` False runs the step without its averaging sweep
    (the dsp ignored), as a non-plastic model would be stepped."""
    from dec3d.physics.zone_setup import zone_bundles
    from tests.test_zone_elastic_kernels import _case
    from tests.zone_step_run import Stepper

    pos, _, gp, rows, zset, weight, node, prop, _ = _case(5, plain=True)
    nz, nv = len(gp), len(pos)
    prop[:] = ortho_rows(*ORTHO, 35, 120, 25)[0]
    cm = np.full(nz, CODES["orthotropic"], np.int8)
    zs = Stepper(gp, rows, zset, weight, node, nv, cm, prop)
    assert zs.plastic
    if not symmetrize:
        zs.plastic = False
        zs.mesh, zs.zplan, zs.scr = zone_bundles(zs.plan, 0, False)
    Kmat = np.zeros((3 * nv, 3 * nv))
    for j in range(3 * nv):
        vel = np.zeros((nv, 3))
        vel[j // 3, j % 3] = 1.0
        f, fm = np.zeros((nv, 3)), np.zeros(nv)
        zs.step(pos, vel, np.zeros((nz, 6)), np.zeros(nz, np.int32), f, fm, 1.0, False, True)
        Kmat[:, j] = -f.ravel()
    return Kmat


def test_nmd_stiffness_symmetric():
    """With NMD on, the returned dsp (the mean stress of the deviatoric strain, averaged by the
    step's sweep) makes the assembled stiffness symmetric (to 1e-12 of its largest entry); without
    the sweep it is not (the flutter that blew up anisotropic cubes): more than 1e-3 off."""
    K = _assembled_stiffness(True)
    scale = np.abs(K).max()
    assert np.abs(K - K.T).max() <= 1e-12 * scale
    assert np.linalg.eigvalsh(0.5 * (K + K.T)).min() > -1e-9 * scale      # six rigid modes, none negative
    K0 = _assembled_stiffness(False)
    assert np.abs(K0 - K0.T).max() > 1e-3 * scale


def test_cube_through_engine_nmd_on():
    """A 1 m cube of tetrahedral orthotropic zones (dip 0, dip-direction 0, rotation 90: 1' = −x,
    2' = −y, 3' = z) on rollers under 1 MPa on its top face, NMD on, solved: stable, and the
    strains of the compliance, εzz = σ/E3, εxx = −ν13 σ/E3, εyy = −ν23 σ/E3, to 1e-6."""
    from dec3d.session import Session

    s = Session()
    for line in ("model new", "block create brick 0 1 0 1 0 1", "block zone generate edgelength 0.5",
                 "block zone cmodel assign orthotropic", "block zone property density 2500"):
        s.command(line)
    zs = s.model.store("zones")
    zs["prop"][:, ort.P_OWN:ort.P_OWN + 12] = ortho_rows(*ORTHO, 0, 0, 90)[0, ort.P_OWN:ort.P_OWN + 12]
    for line in ("block gridpoint apply velocity-z 0 range position-z 0",
                 "block gridpoint apply velocity-y 0 range position-y 0",
                 "block gridpoint apply velocity-x 0 range position-x 0",
                 "block face apply stress-zz -1e6 range position-z 1", "model solve ratio 1e-9"):
        s.command(line)
    E1, E2, E3, n12, n13, n23 = ORTHO[:6]
    v = s.model.vertices
    gp = np.flatnonzero(v["zoned"])
    p, u = v["pos"][gp], v["disp"][gp]
    for axis, want in ((0, n13 * 1e6 / E3), (1, n23 * 1e6 / E3), (2, -1e6 / E3)):
        slope = np.polyfit(p[:, axis], u[:, axis], 1)[0]
        assert slope == pytest.approx(want, rel=1e-6)


def test_ti_positive_definite_condition():
    """The host's refusal agrees with the closed-form condition it states: ν > −1 and
    1 − ν − 2 ν'² E/E' > 0."""
    a = cmodels.ZONE_MODELS["anisotropic"]
    rng = np.random.default_rng(4)
    for _ in range(300):
        E, En = rng.uniform(1e9, 5e10, 2)
        nu, nun = rng.uniform(-1.5, 1.5), rng.uniform(-1.5, 1.5)
        rows = ti_rows(E, En, nu, nun, 3e9, 0, 0)
        rows[0, 2] = 2000.0
        probs, _ = a.problems(rows, np.array([1]))
        ok = nu > -1 and 1 - nu - 2 * nun ** 2 * E / En > 0
        assert (probs == []) == ok, (E, En, nu, nun, probs)


@pytest.mark.parametrize("model, line, message", [
    ("orthotropic", "block zone property young-1 0", r"`young-1` must be > 0"),
    ("orthotropic", "block zone property shear-23 -1e9", r"`shear-23` must be > 0"),
    ("orthotropic", "block zone property dip 95", r"`dip` must be in \[0, 90\]"),
    ("anisotropic", "block zone property young-normal -2", r"`young-normal` must be > 0"),
    ("anisotropic", "block zone property dip -1", r"`dip` must be in \[0, 90\]"),
])
def test_out_of_range_keywords_refused_with_location(tmp_path, model, line, message):
    import io

    from dec3d.errors import Dec3dError
    from dec3d.session import Session

    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command("model new\nblock create brick 0 1 0 1 0 1\nblock zone generate edgelength 1\n"
              f"block zone cmodel assign {model}")
    before = s.model.store("zones")["prop"].copy()
    with pytest.raises(Dec3dError, match=message) as e:
        s.command(line)
    loc = e.value.location
    value = line.split()[4]
    assert loc is not None and loc.line == 1 and loc.column == line.rindex(value) + 1      # the value's place
    np.testing.assert_array_equal(s.model.store("zones")["prop"], before)


def test_cycling_refuses_a_bad_compliance_naming_zones(tmp_path):
    import io

    from dec3d.errors import Dec3dError
    from dec3d.session import Session

    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command("model new\nblock create brick 0 1 0 1 0 1\nblock zone generate edgelength 1\n"
              "block zone cmodel assign orthotropic\nblock zone property density 2000 young-1 10e9 young-2 10e9 "
              "young-3 10e9 poisson-12 0.2 poisson-13 0.2 poisson-23 0.2 shear-12 4e9 shear-13 4e9 shear-23 4e9\n"
              "block zone property poisson-12 1.5 range id 1")
    with pytest.raises(Dec3dError, match=r"orthotropic zones: compliance not positive definite .*: 1 zone\(s\) \(1\)"):
        s.command("model cycle 1")
