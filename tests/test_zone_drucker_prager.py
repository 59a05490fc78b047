"""Zone model ``drucker-prager`` (dec3d/kernels/zmodels/drucker.py): the kernel against a slow
numpy twin written from the formulas of Itasca's "Drucker-Prager Model" page on random states
(elastic, shear, tension and corner returns), a single zone driven through ``update`` along a
triaxial path against the closed-form axial stress at yield, the tension cut-off (and its cap at
the apex), and the host (keywords, columns, warning, no strength reduction)."""
import math

import numpy as np
import pytest

from dec3d.kernels.zmodels import CODES, NWORK, NZHIST, NZPROP, PLASTIC_CODES, no_tables
from dec3d.kernels.zmodels import drucker as dp
from dec3d.kernels.zone_mohr import mohr_work
from dec3d.physics import cmodels

TAB = no_tables()
MW = mohr_work()
TENSION_COLUMN = 5            # the shared tension column (kernels.zmodels._common.P_TENSION)


def _rows(qphi, kphi, qpsi, ten):
    p = np.zeros((1, NZPROP))
    p[0, dp.P_QPHI] = qphi
    p[0, dp.P_KPHI] = kphi
    p[0, dp.P_QPSI] = qpsi
    p[0, TENSION_COLUMN] = ten
    return p


def _kernel(p, K, G, d, s):
    out = dp.update(p, np.zeros((1, NZHIST)), 0, K, G, *d, *s, TAB, np.full(NWORK, np.nan), MW)
    return out[0], np.array(out[1:7]), out[7]


# ---- slow twin: numpy, from the page's formulas, nothing shared with the kernel ----------------

def _tensor(v):
    return np.array([[v[0], v[3], v[4]], [v[3], v[1], v[5]], [v[4], v[5], v[2]]])


def _voigt(t):
    return np.array([t[0, 0], t[1, 1], t[2, 2], t[0, 1], t[0, 2], t[1, 2]])


def twin(s, d, K, G, qphi, kphi, qpsi, ten):
    """(bits, new stress (6,), dsp). Trial by Hooke's law on tensors; invariants τ = sqrt(J2),
    σ = tr/3; the two criteria as lines n·(σ, τ) = r in the (σ, τ) plane, the flows m as the
    plastic parts of Hooke's law (Δσ = K Δε_v, Δτ = G Δγ); the criterion returned to is the one
    on whose side of the bisector of the unit normals at the corner the trial lies; a return that
    leaves the other line violated (or τ < 0) goes to the corner."""
    S, D = _tensor(s), _tensor(d)
    I = np.eye(3)
    trial = S + K * np.trace(D) * I + 2.0 * G * (D - np.trace(D) / 3.0 * I)
    sig = np.trace(trial) / 3.0
    dev = trial - sig * I
    tau = math.sqrt(0.5 * np.sum(dev * dev))
    st = min(ten, kphi / qphi) if qphi > 0 else ten
    n = [np.array([qphi, 1.0]), np.array([1.0, 0.0])]          # shear, tension
    r = [kphi, st]
    m = [np.array([K * qpsi, G]), np.array([K, 0.0])]
    x = np.array([sig, tau])
    F = [n[i] @ x - r[i] for i in range(2)]
    if F[0] <= 0 and F[1] <= 0:
        return 0, _voigt(trial), 0.0
    corner = np.linalg.solve(np.array(n), np.array(r))        # where both lines meet
    corner[1] = max(corner[1], 0.0)
    w = n[0] / np.linalg.norm(n[0]) - n[1] / np.linalg.norm(n[1])
    act = 0 if (x - corner) @ w >= 0 else 1
    lam = np.linalg.solve(np.array([[n[act] @ m[act]]]), np.array([F[act]]))[0]
    y = x - max(lam, 0.0) * m[act]
    bits = 1 if act == 0 else 2
    other = 1 - act
    if n[other] @ y - r[other] > 0 or y[1] < 0:
        y = corner
        bits = 3
    new = y[0] * I + (y[1] / tau if tau > 0 else 0.0) * dev
    return bits, _voigt(new), sig - y[0]


def test_registered():
    assert CODES["drucker-prager"] == 6 and 6 in PLASTIC_CODES
    m = cmodels.ZONE_MODELS["drucker-prager"]
    assert m.reduce is None and m.hist_names == ()
    assert m.props["tension"].column == TENSION_COLUMN
    assert {"friction-drucker", "cohesion-drucker", "dilation-drucker", "bulk", "shear", "density"} <= set(m.props)
    assert "cohesion" not in m.props and "friction" not in m.props


def test_twin_random_states():
    """>= 200 random states of each kind: the kernel agrees with the twin (bits exactly; stress and
    dsp to 1e-10 of the trial's size)."""
    rng = np.random.default_rng(6)
    seen = {0: 0, 1: 0, 2: 0, 3: 0}
    n = 0
    while min(seen.values()) < 200 and n < 20000:
        n += 1
        K = rng.uniform(1e8, 1e10)
        G = rng.uniform(0.2, 1.2) * K
        qphi = rng.choice([0.0, rng.uniform(0.0, 1.2)])
        kphi = rng.uniform(0.0, 2e6)
        qpsi = rng.uniform(0.0, 1.0) * qphi if rng.uniform() < 0.7 else rng.uniform(0.0, 1.5)
        ten = rng.uniform(0.0, 1e6) if rng.uniform() < 0.8 else 1e9       # some above the apex
        if rng.uniform() < 0.3:          # near or past the cut-off: small deviator, mean in tension
            s = rng.normal(0.0, 2e5, 6) + rng.uniform(0.0, 2e6) * np.array([1, 1, 1, 0, 0, 0])
        else:
            s = rng.normal(0.0, 1e6, 6) - rng.uniform(0.0, 2e6) * np.array([1, 1, 1, 0, 0, 0])
        d = rng.normal(0.0, 3e-4, 6) * (1e9 / K)
        p = _rows(qphi, kphi, qpsi, ten)
        bits, new, dsp = _kernel(p, K, G, d, s)
        tb, tnew, tdsp = twin(s, d, K, G, qphi, kphi, qpsi, ten)
        scale = np.abs(s).max() + np.abs(d).max() * (K + 2 * G) + kphi + 1.0
        assert bits == tb, (n, bits, tb)
        np.testing.assert_allclose(new, tnew, rtol=0, atol=1e-10 * scale)
        assert abs(dsp - tdsp) <= 1e-10 * scale
        assert np.isfinite(new).all()
        seen[bits] += 1
    assert min(seen.values()) >= 200, seen


def _triaxial(qphi, kphi, qpsi, ten, K, G, sigma3, de, steps):
    """Axial (z) strain steps de on a zone starting at the isotropic stress sigma3; the lateral
    strain of each step solved (secant iterations) so that the lateral stresses stay sigma3."""
    p = _rows(qphi, kphi, qpsi, ten)
    s = np.array([sigma3, sigma3, sigma3, 0.0, 0.0, 0.0])
    axial, bits = [], []
    for _ in range(steps):
        def lateral(el):
            return _kernel(p, K, G, (el, el, de, 0.0, 0.0, 0.0), s)
        x0, x1 = 0.0, -de * 0.25
        f0 = lateral(x0)[1][0] - sigma3
        f1 = lateral(x1)[1][0] - sigma3
        for _ in range(60):
            if f1 == f0 or abs(f1) < 1e-7:
                break
            x0, x1, f0 = x1, x1 - f1 * (x1 - x0) / (f1 - f0), f1
            f1 = lateral(x1)[1][0] - sigma3
        b, s, _ = lateral(x1)
        assert abs(s[0] - sigma3) < 1e-6 and abs(s[1] - sigma3) < 1e-6
        axial.append(s[2])
        bits.append(b)
    return np.array(axial), np.array(bits)


@pytest.mark.parametrize("sigma3", [-1e6, -3e6, 0.0])
def test_triaxial_yield_closed_form(sigma3):
    """Compression at constant confinement σ3: elastic with slope E until f_s = 0, i.e.
    (σ3 − σ1)/√3 + q_φ (σ1 + 2σ3)/3 = k_φ, σ1 = (k_φ − σ3 (1/√3 + 2q_φ/3)) / (q_φ/3 − 1/√3); then
    the axial stress stays there (perfect plasticity), to 1e-9."""
    qphi, kphi, qpsi, ten = 0.3, 1e6, 0.1, 2e6
    K, G = 5e9, 3e9
    E = 9 * K * G / (3 * K + G)
    s1 = (kphi - sigma3 * (1 / math.sqrt(3) + 2 * qphi / 3)) / (qphi / 3 - 1 / math.sqrt(3))
    de = -2e-6
    n_el = (s1 - sigma3) / (E * de)                       # steps to yield
    axial, bits = _triaxial(qphi, kphi, qpsi, ten, K, G, sigma3, de, int(n_el) + 40)
    el = np.flatnonzero(bits == 0)
    assert len(el) == int(n_el)                           # elastic exactly until the closed form
    np.testing.assert_allclose(np.diff(axial[el]), E * de, rtol=1e-9)
    assert (bits[len(el):] == 1).all()                    # then shear
    np.testing.assert_allclose(axial[len(el):], s1, rtol=1e-9)


def test_tension_cutoff_and_apex():
    """Isotropic extension: the mean stress rises at 3K per unit volumetric strain until the
    cut-off σ^t, then stays (bits tension); a tension above the apex k_φ/q_φ is capped there."""
    K, G = 2e9, 1e9
    for ten, cap in ((0.4e6, 0.4e6), (5e6, 1e6 / 0.5)):
        p = _rows(0.5, 1e6, 0.2, ten)
        s = np.zeros(6)
        de = 1e-5
        means, allbits = [], []
        for _ in range(int(cap / (3 * K * de)) + 10):
            b, s, dsp = _kernel(p, K, G, (de, de, de, 0.0, 0.0, 0.0), s)
            means.append(s[:3].mean())
            allbits.append(b)
            np.testing.assert_allclose(s[:3], s[0], rtol=0, atol=1e-9)
            assert np.abs(s[3:]).max() == 0.0
        allbits = np.array(allbits)
        first = np.flatnonzero(allbits)[0]
        assert first == int(cap / (3 * K * de))
        assert (allbits[first:] == 2).all()
        np.testing.assert_allclose(means[first:], cap, rtol=1e-12)
        assert dsp == pytest.approx(3 * K * de, rel=1e-9)        # the whole trial increment


def test_uniaxial_tension_reaches_cutoff_before_shear():
    """Uniaxial pull (lateral stress 0) with a low tension: σ_m = σ1/3 reaches σ^t while
    f_s < 0, so the zone yields in tension at σ1 = 3 σ^t."""
    qphi, kphi, ten = 0.4, 2e6, 0.2e6
    axial, bits = _triaxial(qphi, kphi, 0.0, ten, 3e9, 2e9, 0.0, 1e-6, 400)
    first = np.flatnonzero(bits)[0]
    assert bits[first] == 2 and (bits[:first] == 0).all()
    np.testing.assert_allclose(axial[first:], 3 * ten, rtol=1e-9)


def test_degenerate_input_stays_finite():
    """Zero moduli or strengths (refused before cycling, but a kernel never makes NaN or inf)."""
    rng = np.random.default_rng(1)
    for K, G, qphi, kphi, ten in ((0.0, 0.0, 0.5, 1e6, 1e5), (1e9, 0.0, 0.0, 0.0, 0.0), (0.0, 1e9, 0.0, 0.0, 0.0),
                                  (1e9, 1e9, 1e-300, 1e6, 1e6)):
        for _ in range(50):
            bits, new, dsp = _kernel(_rows(qphi, kphi, 0.3, ten), K, G, rng.normal(0, 1e-3, 6), rng.normal(0, 1e6, 6))
            assert np.isfinite(new).all() and math.isfinite(dsp)
        _, new, _ = _kernel(_rows(qphi, kphi, 0.3, ten), K, G, np.zeros(6), np.zeros(6))
        assert np.isfinite(new).all()


def test_host_check_and_ranges():
    m = cmodels.ZONE_MODELS["drucker-prager"]
    rows = np.zeros((3, NZPROP))
    rows[:, 0], rows[:, 1], rows[:, 2] = 1e9, 1e9, 2000.0
    rows[:, dp.P_QPHI] = 0.5
    rows[:, dp.P_KPHI] = 1e6
    rows[:, TENSION_COLUMN] = [1e5, 3e6, 0.0]          # zone 2: above the apex 2e6
    probs, warns = m.problems(rows, np.array([1, 2, 3]))
    assert probs == [] and len(warns) == 1 and "(2)" in warns[0]
    rows[0, dp.P_QPSI] = -0.1
    probs, _ = m.problems(rows, np.array([1, 2, 3]))
    assert len(probs) == 1 and probs[0].startswith("dilation-drucker")


@pytest.mark.parametrize("line, message", [
    ("block zone property friction-drucker -0.1", r"`friction-drucker` must be ≥ 0, got"),
    ("block zone property cohesion-drucker -1", r"`cohesion-drucker` must be ≥ 0, got"),
    ("block zone property dilation-drucker -0.2", r"`dilation-drucker` must be ≥ 0, got"),
    ("block zone property tension -5", r"`tension` must be ≥ 0, got"),
])
def test_out_of_range_keywords_refused_with_location(tmp_path, line, message):
    import io

    from dec3d.errors import Dec3dError
    from dec3d.session import Session

    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command("model new\nblock create brick 0 1 0 1 0 1\nblock zone generate edgelength 1\n"
              "block zone cmodel assign drucker-prager")
    before = s.model.store("zones")["prop"].copy()
    with pytest.raises(Dec3dError, match=message) as e:
        s.command(line)
    loc = e.value.location
    assert loc is not None and loc.line == 1 and loc.column == line.rindex(line.split()[4]) + 1
    np.testing.assert_array_equal(s.model.store("zones")["prop"], before)


def test_keywords_reach_their_columns(tmp_path):
    import io

    from dec3d.session import Session

    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command("model new\nblock create brick 0 1 0 1 0 1\nblock zone generate edgelength 1\n"
              "block zone cmodel assign drucker-prager\nblock zone property young 1e9 poisson 0.25 density 2000 "
              "friction-drucker 0.4 cohesion-drucker 2e5 dilation-drucker 0.1 tension 1e4")
    p = s.model.store("zones")["prop"]
    n = s.model.store("zones").n
    assert (p[:n, dp.P_QPHI] == 0.4).all() and (p[:n, dp.P_KPHI] == 2e5).all()
    assert (p[:n, dp.P_QPSI] == 0.1).all() and (p[:n, TENSION_COLUMN] == 1e4).all()
