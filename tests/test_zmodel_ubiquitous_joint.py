"""Zone model ``ubiquitous-joint`` (kernel ``dec3d/kernels/zmodels/ubiquitous_joint.py``, host
``dec3d/physics/zmodels/ubiquitous_joint.py``): Jaeger's single plane of weakness through
``update`` on a single zone in triaxial compression, the matrix strength where the plane does not
govern, and a slow twin from Itasca's formulas (local axes of the plane, generic active-set
return) compared on random states."""
import math

import numpy as np
import pytest

from dec3d.geometry.planes import dip_normal
from dec3d.kernels.zmodels import NWORK, NZHIST, NZPROP, no_tables
from dec3d.kernels.zmodels import ubiquitous_joint as uj
from dec3d.kernels.zone_mohr import mohr_work
from zmodel_twins import twin_hooke, twin_mc, triaxial_path, vec6

K, G = 2e9, 1e9
A1, A2 = K + 4 * G / 3, K - 2 * G / 3


def _row(c=1e6, phi=30.0, ten=1e6, psi=0.0, cj=2e5, phij=20.0, tenj=0.0, psij=0.0, dip=45.0, dd=0.0):
    t = lambda a: math.tan(math.radians(a))     # noqa: E731
    p = np.zeros((1, NZPROP))
    p[0, :8] = [K, G, 2500.0, c, t(phi), ten, t(psi), 0.0]
    p[0, uj.P_JCOHESION:uj.P_DIPDIR + 1] = [cj, t(phij), tenj, t(psij), dip, dd]
    return p


def _stepper(p):
    wf = np.full(NWORK, np.nan)
    mw = mohr_work()
    h = np.zeros((1, NZHIST))
    tab = no_tables()

    def step(s, d, commit):
        r = uj.update(p, h, 0, K, G, d[0], d[1], d[2], d[3], d[4], d[5], s[0], s[1], s[2], s[3], s[4], s[5],
                      tab, wf, mw)
        return r[0], np.array(r[1:7])
    return step


def test_declaration_and_orientation():
    assert (uj.NAME, uj.CODE, uj.NHIST, uj.PLASTIC) == ("ubiquitous-joint", 5, 0, True)
    from dec3d.physics import cmodels
    m = cmodels.ZONE_MODELS["ubiquitous-joint"]
    for name in ("joint-cohesion", "joint-friction", "joint-tension", "joint-dilation", "dip", "dip-direction"):
        assert m.props[name].column >= cmodels.P_OWN
    assert m.props["joint-friction"].kind == "angle" and m.props["dip"].kind == "number"
    rows = _row(psij=15.0)
    q = m.reduce(rows, 2.0)
    assert q[0, uj.P_JCOHESION] == 1e5 and q[0, uj.P_JTANFRIC] == pytest.approx(math.tan(math.radians(20)) / 2)
    assert q[0, uj.P_JTANDIL] == pytest.approx(q[0, uj.P_JTANFRIC]) and q[0, 3] == 5e5
    problems, _ = m.check(_row(psij=25.0), np.array([7]))
    assert problems and "joint-dilation" in problems[0]
    # the plane's normal is that of `block cut joint-set` (x east, y north, z up)
    rng = np.random.default_rng(1)
    for _ in range(20):
        dip, dd = rng.uniform(0, 90), rng.uniform(0, 360)
        n = uj.plane_normal(dip, dd)
        assert np.allclose(n, dip_normal(math.radians(dip), math.radians(dd)), atol=1e-15)


def jaeger(s3, cj, phij, beta):
    """σ1 at failure on a plane of weakness whose normal makes the angle β with σ1 (Jaeger & Cook,
    "Fundamentals of Rock Mechanics", single plane of weakness: with σn = σ1 cos² β + σ3 sin² β,
    τ = (σ1 − σ3) sin β cos β and τ = c_j + σn tan φ_j); compression positive; inf when the plane
    cannot slip."""
    tf = math.tan(math.radians(phij))
    b = math.radians(beta)
    den = (1 - tf / math.tan(b)) * math.sin(2 * b) if 0 < beta < 90 else 0.0
    return s3 + 2 * (cj + s3 * tf) / den if den > 0 else math.inf


S3 = 1e6
MATRIX = S3 * 3.0 + 2 * 1e6 * math.sqrt(3.0)         # c = 1 MPa, φ = 30°


@pytest.mark.parametrize("beta, dd", [(30, 0), (40, 45), (55, 90), (70, 200), (80, 300),
                                      (0, 10), (25, 0), (87, 120), (90, 0)])
def test_jaeger_single_plane_of_weakness(beta, dd):
    """Triaxial compression of one zone (σ2 = σ3 = 1 MPa held, the shear stresses held 0, axial
    strain steps): peak σ1 = σ3 + 2 (c_j + σ3 tan φ_j) / ((1 − tan φ_j cot β) sin 2β) while the
    plane (c_j = 0.2 MPa, φ_j = 20°) is weaker than the matrix, the matrix's σ3 N_φ + 2 c √N_φ
    (6.464 MPa) where it is not; β the angle between σ1 (z) and the plane's normal, so dip β, any
    dip direction."""
    p = _row(dip=float(beta), dd=dd)
    path = triaxial_path(_stepper(p), [-S3, -S3, -S3, 0, 0, 0], -2e-5, 150)
    sig1 = np.array([-s[2] for _, s, _ in path])
    want = min(jaeger(S3, 2e5, 20.0, beta), MATRIX)
    assert sig1.max() == pytest.approx(want, rel=1e-5)          # bar 2 %
    last = path[-1][2]
    if jaeger(S3, 2e5, 20.0, beta) < MATRIX:
        assert last & 16 and not last & 3                      # the plane slips, the matrix is elastic
    else:
        assert last & 1 and not last & 48                      # the matrix yields, the plane holds


def test_jaeger_curve_has_its_minimum_at_45_plus_half_phi():
    """The weakest orientation β = 45° + φ_j/2 gives σ1 = σ3 + 2 (c_j + σ3 tan φ_j)(tan φ_j +
    (1 + tan² φ_j)^½)."""
    tf = math.tan(math.radians(20))
    p = _row(dip=45.0 + 10.0)
    path = triaxial_path(_stepper(p), [-S3, -S3, -S3, 0, 0, 0], -2e-5, 60)
    peak = max(-s[2] for _, s, _ in path)
    assert peak == pytest.approx(S3 + 2 * (2e5 + S3 * tf) * (tf + math.sqrt(1 + tf * tf)), rel=1e-5)


# --------------------------------------------------------------------------------------------
# slow twin from the formulas

def local_axes(dip, dd):
    """[C]: columns x' (down the dip), y' (horizontal, right-handed), n (Itasca's local axes)."""
    d, a = math.radians(dip), math.radians(dd)
    n = np.array([math.sin(d) * math.sin(a), math.sin(d) * math.cos(a), math.cos(d)])
    xp = np.array([math.cos(d) * math.sin(a), math.cos(d) * math.cos(a), -math.sin(d)])
    return np.column_stack([xp, np.cross(n, xp), n])


def twin_ubiquitous(s, d, c, tphi, ten, tpsi, cj, tphij, tenj, tpsij, dip, dd):
    """One step: (new stress 6, bits, dsp). Matrix return (``twin_mc``), then the plane in its
    local axes: σ' = Cᵀ σ C, τ = (σ'13² + σ'23²)^½, σ = σ'33; every active set of {shear, tension}
    solved for its multipliers (τ − 2G λs, σ − α1 (tan ψ_j λs + λt)), the one with multipliers >= 0
    and an admissible result taken (asserted unique but for vanishing multipliers, fewest planes
    first); σ'11, σ'22 − α2 (tan ψ_j λs + λt); back
    σ = C σ' Cᵀ."""
    trial = twin_hooke(s, d, K, G)
    so, mult, *_ = twin_mc(trial, K, G, c, tphi, ten, tpsi)
    bits = (1 if any(k[0] == "s" for k in mult) else 0) | (2 if any(k[0] == "t" for k in mult) else 0)
    C = local_axes(dip, dd)
    loc = C.T @ so @ C
    tau = math.hypot(loc[0, 2], loc[1, 2])
    sig = loc[2, 2]
    st = min(tenj, cj / tphij) if tphij > 0 else (0.0 if cj == 0 else tenj)
    tol = 1e-10 * (abs(sig) + tau + cj + abs(st))
    fs = lambda t_, s_: t_ + s_ * tphij - cj        # noqa: E731
    if fs(tau, sig) <= tol and sig - st <= tol:
        return vec6(so), bits, (np.trace(trial) - np.trace(so)) / 3
    found = []
    for act in (("s",), ("t",), ("s", "t")):
        # unknowns (λs, λt); rows: the active criteria at the new stress = 0
        M, r = [], []
        if "s" in act:
            M.append([2 * G + A1 * tpsij * tphij, A1 * tphij]); r.append(fs(tau, sig))
        if "t" in act:
            M.append([A1 * tpsij, A1]); r.append(sig - st)
        M = np.array(M)
        cols = [0 if a == "s" else 1 for a in act]
        lam = np.zeros(2)
        lam[cols] = np.linalg.solve(M[:, cols], np.array(r))
        if lam.min() < -1e-12 * max(1e-300, np.abs(lam).max()):
            continue
        tn = tau - 2 * G * lam[0]
        sn = sig - A1 * (tpsij * lam[0] + lam[1])
        if tn < -tol or fs(tn, sn) > tol or sn - st > tol:
            continue
        found.append((act, lam, tn, sn))
    # one consistent set (two only where they agree: a corner with a vanishing multiplier)
    assert found and all(abs(f[2] - found[0][2]) <= 10 * tol and abs(f[3] - found[0][3]) <= 10 * tol
                         for f in found), found
    act, lam, tn, sn = found[0]
    mu = tpsij * lam[0] + lam[1]
    new = loc.copy()
    new[0, 0] -= A2 * mu
    new[1, 1] -= A2 * mu
    new[2, 2] = sn
    f = tn / tau if tau > 0 else 0.0
    new[0, 2] *= f; new[2, 0] *= f; new[1, 2] *= f; new[2, 1] *= f
    out = C @ new @ C.T
    bits |= (16 if lam[0] > 0 else 0) | (32 if lam[1] > 0 else 0)
    return vec6(out), bits, (np.trace(trial) - np.trace(out)) / 3


def test_matches_twin_on_random_states():
    rng = np.random.default_rng(5)
    mw = mohr_work()
    wf = np.full(NWORK, np.nan)
    h = np.zeros((1, NZHIST))
    seen = {0: 0, 16: 0, 32: 0, 48: 0}
    matrix = 0
    for i in range(3000):
        phi = rng.uniform(15, 45)
        phij = rng.uniform(0, 35) if rng.random() < 0.9 else 0.0
        cj = rng.uniform(0, 1e6) if rng.random() < 0.9 else 0.0
        strong = rng.random() < 0.5                    # (a matrix that mostly holds)
        args = dict(c=rng.uniform(5e5, 3e6) * (10 if strong else 1), phi=phi, ten=rng.uniform(0, 2e6),
                    psi=rng.uniform(0, phi),
                    cj=cj, phij=phij, tenj=rng.uniform(0, 1e6), psij=rng.uniform(0, phij),
                    dip=rng.uniform(0, 90), dd=rng.uniform(0, 360))
        p = _row(**args)
        mean = rng.uniform(-8e6, 1e6) if rng.random() < 0.7 else rng.uniform(0, 2e6)
        s = mean + rng.normal(size=6) * rng.uniform(0, 3e6)
        d = rng.normal(size=6) * 10 ** rng.uniform(-5, -3)
        r = uj.update(p, h, 0, K, G, *d, *s, no_tables(), wf, mw)
        col = p[0]
        st, bits, dsp = twin_ubiquitous(s, d, col[3], col[4], col[5], col[6], *col[uj.P_JCOHESION:uj.P_DIPDIR + 1])
        scale = np.abs(s).max() + np.abs(st).max() + 1e6
        assert np.abs(np.array(r[1:7]) - st).max() <= 1e-8 * scale, (i, args, s, d)
        assert r[0] == bits, (i, r[0], bits)
        assert abs(r[7] - dsp) <= 1e-8 * scale
        seen[bits & 48] += 1
        matrix += bool(bits & 3)
    assert min(seen.values()) >= 50 and 300 <= matrix <= 2700, (seen, matrix)
