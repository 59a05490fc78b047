"""Zone model ``strain-softening`` (kernel ``dec3d/kernels/zmodels/strain_softening.py``, host
``dec3d/physics/zmodels/strain_softening.py``): single-zone triaxial softening against the
Mohr-Coulomb closed form with the tabled cohesion, tensile softening, and a slow twin written from
Itasca's formulas compared on random paths."""
import math

import numpy as np
import pytest

from dec3d.kernels.zmodels import NWORK, NZHIST, NZPROP, make_tables, no_tables
from dec3d.kernels.zmodels import strain_softening as ss
from dec3d.kernels.zmodels._common import P_SRF
from dec3d.kernels.zone_mohr import mohr_work
from zmodel_twins import twin_hooke, twin_mc, triaxial_path, vec6

K, G = 2e9, 1e9
E = 9 * K * G / (3 * K + G)
TAN30 = math.tan(math.radians(30.0))
NPHI30 = 3.0


def _row(c=1e6, tanphi=TAN30, ten=1e6, tanpsi=0.0, tables=(0, 0, 0, 0), srf=0.0):
    p = np.zeros((1, NZPROP))
    p[0, :8] = [K, G, 2500.0, c, tanphi, ten, tanpsi, srf]
    p[0, ss.P_TABLE_COHESION:ss.P_TABLE_TENSION + 1] = tables
    return p


def _stepper(p, h, tab):
    wf = np.full(NWORK, np.nan)
    mw = mohr_work()

    def step(s, d, commit):
        hh = h if commit else h.copy()
        r = ss.update(p, hh, 0, K, G, d[0], d[1], d[2], d[3], d[4], d[5], s[0], s[1], s[2], s[3], s[4], s[5],
                      tab, wf, mw)
        return r[0], np.array(r[1:7])
    return step


def test_declaration():
    assert (ss.NAME, ss.CODE, ss.NHIST, ss.PLASTIC) == ("strain-softening", 3, 2, True)
    assert ss.HIST_NAMES == ("strain-shear-plastic", "strain-tension-plastic")
    from dec3d.physics import cmodels
    m = cmodels.ZONE_MODELS["strain-softening"]
    for name in ("table-cohesion", "table-friction", "table-dilation", "table-tension"):
        assert m.props[name].kind == "table" and m.props[name].column >= cmodels.P_OWN
    # reduce: constant strengths as mohr-coulomb, F kept for the tables
    rows = _row(tables=(1, 0, 0, 0))
    q = m.reduce(rows, 1.25)
    assert q[0, P_SRF] == 1.25 and q[0, 3] == pytest.approx(0.8e6) and q[0, 4] == pytest.approx(TAN30 / 1.25)
    assert rows[0, P_SRF] == 0.0


def test_triaxial_softening_peak_residual_and_plastic_strain():
    """Cohesion table (0, 1 MPa) (0.01, 0.2 MPa), φ = 30° constant, ψ = 0, confining σ3 = 1 MPa,
    axial compression by strain steps: the peak σ1 = σ3 N_φ + 2 c √N_φ with the peak c, every
    plastic step on the Mohr-Coulomb line with c(κs at the start of the step), the residual with
    c = 0.2 MPa once κs >= 0.01, and κs = −ε_zz^p (Itasca's Δκs with ψ = 0 is the compressive
    plastic strain), so the residual is reached at the axial plastic strain 0.01."""
    tab = make_tables([([0.0, 0.01], [1e6, 2e5])])
    p = _row(tables=(1, 0, 0, 0))
    h = np.zeros((1, NZHIST))
    s3 = 1e6
    kappa = []
    path = triaxial_path(_stepper(p, h, tab), [-s3, -s3, -s3, 0, 0, 0], -2e-5, 800,
                         on_step=lambda i: kappa.append(h[0, 0]))
    sig1 = np.array([-st[2] for _, st, _ in path])
    ezz = np.array([e[2] for e, _, _ in path])
    bits = np.array([b for _, _, b in path])
    kappa = np.array(kappa)
    c_of = lambda k: np.interp(k, [0.0, 0.01], [1e6, 2e5])        # noqa: E731
    peak = s3 * NPHI30 + 2 * 1e6 * math.sqrt(NPHI30)
    resid = s3 * NPHI30 + 2 * 2e5 * math.sqrt(NPHI30)
    assert sig1.max() == pytest.approx(peak, rel=1e-6)                # bar 2 %
    plastic = np.flatnonzero(bits & 1)
    assert plastic.size > 500
    first = plastic[0]
    assert np.all(bits[first:] & 1)
    k_start = np.concatenate([[0.0], kappa[:-1]])
    want = s3 * NPHI30 + 2 * c_of(k_start[plastic]) * math.sqrt(NPHI30)
    assert np.abs(sig1[plastic] - want).max() <= 1e-6 * peak
    # κs from the axial plastic strain (lateral stress constant: axial elastic strain Δσzz / E)
    ezz_p = ezz - (-sig1 + s3) / E
    assert np.allclose(kappa[plastic], -ezz_p[plastic], rtol=1e-6, atol=1e-12)
    # the residual: reached at the first step starting with κs >= 0.01, held from there on
    at = np.flatnonzero(k_start >= 0.01)[0]
    assert sig1[at] == pytest.approx(resid, rel=1e-6)                  # bar 2 %
    assert sig1[at - 1] > resid * (1 + 1e-4)
    assert np.abs(sig1[at:] - resid).max() <= 1e-6 * resid
    # (κs passes 0.01 during step at - 1: the axial plastic strain passes 0.01 then)
    assert -ezz_p[at - 2] < 0.01 <= -ezz_p[at - 1] * (1 + 1e-6)
    assert h[0, 1] == 0.0                                              # no tension


def test_tension_softening_follows_the_plastic_tensile_strain():
    """Table-tension (0, 0.5 MPa) (0.001, 0): uniaxial pull. Peak σzz = 0.5 MPa; each plastic step
    at σt(κt at its start); κt = ε_zz − σzz / E, the axial plastic strain (the one-plane tension
    return flows along the axis only) while σt > 0, the plastic volumetric strain throughout; κs
    stays 0; σzz = 0 once κt >= 0.001."""
    tab = make_tables([([0.0, 1e-3], [5e5, 0.0])])
    p = _row(tables=(0, 0, 0, 1))
    h = np.zeros((1, NZHIST))
    kt = []
    path = triaxial_path(_stepper(p, h, tab), np.zeros(6), 2e-5, 80, on_step=lambda i: kt.append(h[0, 1]))
    szz = np.array([st[2] for _, st, _ in path])
    ezz = np.array([e[2] for e, _, _ in path])
    bits = np.array([b for _, _, b in path])
    kt = np.array(kt)
    assert szz.max() == pytest.approx(5e5, rel=1e-9)
    plastic = np.flatnonzero(bits & 2)
    assert plastic.size > 40 and not np.any(bits & 1)
    k_start = np.concatenate([[0.0], kt[:-1]])
    assert np.abs(szz[plastic] - np.interp(k_start[plastic], [0, 1e-3], [5e5, 0])).max() <= 1e-6 * 5e5
    # κt is the plastic (tensile) volumetric strain throughout; while σt > 0 it is the axial
    # plastic strain alone, after that (σt = 0) the laterals are cut off too and flow outwards
    eps = np.array([e for e, _, _ in path])
    sig = np.array([st for _, st, _ in path])
    ev_p = eps[:, :3].sum(axis=1) - sig[:, :3].sum(axis=1) / (3 * K)
    assert np.allclose(kt[plastic], ev_p[plastic], rtol=1e-6, atol=1e-12)
    soft = plastic[k_start[plastic] < 1e-3]
    assert np.allclose(kt[soft], ezz[soft] - szz[soft] / E, rtol=1e-6, atol=1e-12)
    assert kt[-1] > 1e-3 and abs(szz[-1]) <= 1e-6 * 5e5
    assert h[0, 0] == 0.0


def test_constant_properties_are_mohr_coulomb():
    """Without tables the model is mohr-coulomb (same stress, bits, dsp), κ still counted."""
    from dec3d.kernels.zmodels import mohr
    rng = np.random.default_rng(3)
    wf1 = np.full(NWORK, np.nan); wf2 = np.full(NWORK, np.nan); mw = mohr_work()
    for _ in range(300):
        c, phi, psi = rng.uniform(2e5, 2e6), rng.uniform(0, 45), 0.0
        psi = rng.uniform(0, phi)
        p = _row(c, math.tan(math.radians(phi)), rng.uniform(0, 2e6), math.tan(math.radians(psi)))
        h = np.zeros((1, NZHIST))
        s = rng.uniform(-8e6, 1e6) + rng.normal(size=6) * 2e6
        d = rng.normal(size=6) * 10 ** rng.uniform(-5, -2.7)
        a = ss.update(p, h, 0, K, G, *d, *s, no_tables(), wf1, mw)
        b = mohr.update(p, h, 0, K, G, *d, *s, no_tables(), wf2, mw)
        assert a == b
        assert (h[0, 0] > 0) == bool(a[0] & 1) and (h[0, 1] > 0) == bool(a[0] & 2)


# --------------------------------------------------------------------------------------------
# slow twin from the formulas

def twin_ssoft(s, d, ks, kt, cols, tables, F):
    """One step of Itasca's strain-softening model: (new stress 6, bits, dsp, Δκs, Δκt, number of
    active shear planes, whether the split into planes is unique); Δκs is Itasca's formula summed
    over the active shear planes, Δκt the sum of the tensile multipliers.
    cols: (c, tan φ, σt, tan ψ) constants; tables: {"c"|"phi"|"psi"|"ten": (xs, ys)} (angles in
    degrees); F: strength-reduction factor of the tables (0: none)."""
    c, tphi, ten, tpsi = cols
    if "c" in tables:
        c = np.interp(ks, *tables["c"]) / (F if F > 0 else 1.0)
    if "phi" in tables:
        tphi = math.tan(math.radians(np.interp(ks, *tables["phi"]))) / (F if F > 0 else 1.0)
    if "psi" in tables:
        tpsi = math.tan(math.radians(np.interp(ks, *tables["psi"])))
    if "ten" in tables:
        ten = np.interp(kt, *tables["ten"]) / (F if F > 0 else 1.0)
    if F > 0:
        tpsi = min(tpsi, tphi)
    trial = twin_hooke(s, d, K, G)
    new, mult, w, wn, flows, on = twin_mc(trial, K, G, c, tphi, ten, tpsi)
    dks = 0.0
    for k, lam in mult.items():
        if k[0] == "s":
            # Itasca's formula on this plane's plastic strain: ε1 the compressive, ε3 the other
            e1, e3 = lam * flows[k][k[1]], lam * flows[k][k[2]]
            em = (e1 + e3) / 3
            dks += math.sqrt(0.5 * ((e1 - em) ** 2 + em ** 2 + (e3 - em) ** 2))
    dkt = sum(lam for k, lam in mult.items() if k[0] == "t")
    bits = (1 if any(k[0] == "s" for k in mult) else 0) | (2 if any(k[0] == "t" for k in mult) else 0)
    nshear = sum(k[0] == "s" for k in mult)
    # the split into planes (so Δκs, Δκt) is unique when at most three planes pass through the
    # new stress (not at the apex, nor where two axes are cut off on the shear pyramid)
    unique = len(on) <= 3
    return vec6(new), bits, (np.trace(trial) - np.trace(new)) / 3, dks, dkt, nshear, unique


def _random_table(rng, xmax, lo, hi):
    n = rng.integers(2, 5)
    xs = np.sort(rng.uniform(0, xmax, n))
    xs[0] = 0.0
    return xs, rng.uniform(lo, hi, n)


def test_matches_twin_on_random_paths():
    rng = np.random.default_rng(7)
    mw = mohr_work()
    seen = {"elastic": 0, "shear": 0, "tension": 0, "both": 0}
    edges = 0
    apex = 0
    for case in range(60):
        tables = {}
        if rng.random() < 0.8:
            tables["c"] = _random_table(rng, 0.02, 0.0, 2e6)
        if rng.random() < 0.6:
            tables["phi"] = _random_table(rng, 0.02, 5.0, 45.0)
        if rng.random() < 0.5:
            tables["psi"] = _random_table(rng, 0.02, 0.0, 5.0)
        if rng.random() < 0.6:
            tables["ten"] = _random_table(rng, 2e-3, 0.0, 1e6)
        names = [k for k in ("c", "phi", "psi", "ten") if k in tables]
        tab = make_tables([tables[k] for k in names]) if names else no_tables()
        refs = [names.index(k) + 1 if k in tables else 0 for k in ("c", "phi", "psi", "ten")]
        phi = rng.uniform(10, 40)
        cols = (rng.uniform(2e5, 2e6), math.tan(math.radians(phi)), rng.uniform(0, 1e6),
                math.tan(math.radians(rng.uniform(0, min(phi, 5.0)))))
        F = 0.0 if rng.random() < 0.6 else rng.uniform(1.0, 1.6)
        p = _row(*cols, tables=refs, srf=F)
        h = np.zeros((1, NZHIST))
        h[0, 0] = rng.uniform(0, 0.01) if rng.random() < 0.5 else 0.0
        h[0, 1] = rng.uniform(0, 1e-3) if rng.random() < 0.5 else 0.0
        s = rng.uniform(-6e6, 0.5e6) + rng.normal(size=6) * 1e6
        wf = np.full(NWORK, np.nan)
        dmean = rng.normal(size=6) * 3e-4
        for _ in range(25):
            d = dmean + rng.normal(size=6) * 10 ** rng.uniform(-5, -3)
            ks, kt = h[0, 0], h[0, 1]
            r = ss.update(p, h, 0, K, G, *d, *s, tab, wf, mw)
            st, bits_t, dsp_t, dks_t, dkt_t, nshear, unique = twin_ssoft(s, d, ks, kt, cols, tables, F)
            sk = np.array(r[1:7])
            scale = np.abs(s).max() + np.abs(st).max() + 1e6
            assert np.abs(sk - st).max() <= 1e-8 * scale, (case, s, d)
            assert r[0] == bits_t
            assert abs(r[7] - dsp_t) <= 1e-8 * scale
            dscale = np.abs(d).max()
            if unique:
                assert abs((h[0, 1] - kt) - dkt_t) <= 1e-6 * dscale
                assert abs((h[0, 0] - ks) - dks_t) <= 1e-6 * dscale
            else:
                apex += 1
                assert h[0, 0] >= ks and h[0, 1] >= kt
            seen[{0: "elastic", 1: "shear", 2: "tension", 3: "both"}[bits_t]] += 1
            edges += nshear > 1
            s = sk
    assert min(seen.values()) >= 5 and edges >= 20 and apex < seen["both"] + seen["shear"] // 4, (seen, edges, apex)
