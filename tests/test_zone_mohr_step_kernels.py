"""The 4-node zone step (``kernels/zone_step.py``) with Mohr-Coulomb zones, bit for bit against the
serial twin in passes (``tests/zone_plastic_twin.py``, the engine's plastic step before the
plug-in models, its return checked against the slow twins of tests/test_zone_mohr_kernels.py)
for any number of parts and threads, with zones
yielding in shear, in tension and at corners, hexahedral sets, linked gridpoints, large strain,
NMD on and off; and the closed-form principal axes of ``principal.principal_axes`` against
numpy's eigh."""
import math

import numba
import numpy as np
import pytest

from dec3d.kernels import zone_mohr as zm
from dec3d.model import zones as mz
from dec3d.physics.cmodels import ZONE_MODELS
from tests import zone_plastic_twin as zp
from tests.test_zone_elastic_kernels import _case, _run
from tests.zone_step_run import Stepper

MOHR = ZONE_MODELS["mohr-coulomb"].code


def _mohr_case(seed, plain=False, frac=0.7):
    """The elastic kernels' lattice with ``frac`` of the zones Mohr-Coulomb (weak: most of them
    yield at the first step, some in tension; every fifth zone strong), the rest elastic."""
    pos, vel, gp, rows, zset, weight, node, prop, stress = _case(seed, plain=plain)
    rng = np.random.default_rng(seed + 100)
    nz = len(gp)
    cm = np.where(rng.uniform(size=nz) < frac, MOHR, mz.ZMODEL_ELASTIC).astype(np.int8)
    prop[:, mz.ZP_COHESION] = rng.uniform(0.2e5, 1e5, nz)
    prop[:, mz.ZP_TANFRIC] = np.tan(np.radians(rng.uniform(15, 40, nz)))
    prop[:, mz.ZP_TENSION] = rng.uniform(0.0, 0.5e5, nz)
    prop[:, mz.ZP_TANDIL] = np.tan(np.radians(rng.uniform(0, 10, nz)))
    prop[::5, mz.ZP_COHESION] = prop[::5, mz.ZP_TENSION] = 1e9        # strong: stay elastic
    stress[:, :3] -= 1e5                         # mostly compressive, some in tension
    vel *= 30.0
    return pos, vel, gp, rows, zset, weight, node, prop, stress, cm


def _plain_run(case, large, nmd, steps):
    pos, vel, gp, rows, zset, weight, node, prop, stress, cm = case
    nv = len(pos)
    st, state, f, fm = stress.copy(), np.zeros(len(gp), np.int8), np.ones((nv, 3)), np.full(nv, 0.5)
    for _ in range(steps):
        zp.zone_forces_plastic(pos, vel, gp, rows, zset, weight, int(zset.max()) + 1, node, cm, prop, 0.7, large, nmd,
                               st, state, f, fm)
    return st, state, f, fm


def _fast_run(case, large, nmd, steps, parts):
    pos, vel, gp, rows, zset, weight, node, prop, stress, cm = case
    nv = len(pos)
    zs = Stepper(gp, rows, zset, weight, node, nv, cm, prop, parts)
    st, state, f, fm = stress.copy(), np.zeros(len(gp), np.int8), np.ones((nv, 3)), np.full(nv, 0.5)
    for _ in range(steps):
        zs.step(pos, vel, st, state, f, fm, 0.7, large, nmd)
    return st, state, f, fm


@pytest.mark.parametrize("large, nmd, plain", [(False, True, False), (True, True, False), (True, False, False),
                                               (False, True, True), (True, False, True)])
def test_mohr_step_gives_the_plastic_steps_bits_for_any_parts_and_threads(large, nmd, plain):
    case = _mohr_case(3, plain=plain)
    ref = _plain_run(case, large, nmd, 3)
    state = ref[1]
    rows = case[3]
    on = case[-1][rows] == MOHR
    # the case is what it says: shear and tension yield, elastic Mohr-Coulomb zones too
    assert ((state[rows] & mz.ZSTATE_SHEAR_PAST) != 0).sum() > 10 and ((state[rows] & mz.ZSTATE_TENSION_PAST) != 0).sum() > 3
    assert (on & (state[rows] == 0)).any()
    keep = numba.get_num_threads()
    try:
        for nt in (1, 2):
            numba.set_num_threads(min(nt, numba.config.NUMBA_NUM_THREADS))
            for parts in (1, 2, 3, 7):
                got = _fast_run(case, large, nmd, 3, parts)
                for a, b in zip(ref, got):
                    assert np.array_equal(a, b), (nt, parts)
    finally:
        numba.set_num_threads(keep)


def test_mohr_step_without_mohr_zones_is_the_elastic_step():
    case = _mohr_case(8, frac=0.0)
    st, f, fm = _run(case[:-1], True, True, 2)
    got = _fast_run(case, True, True, 1, 2)
    assert np.array_equal(got[0], st) and np.array_equal(got[2], f) and np.array_equal(got[3], fm)
    assert not got[1].any()


def _sym(s):
    return np.array([[s[0], s[3], s[4]], [s[3], s[1], s[5]], [s[4], s[5], s[2]]])


@pytest.mark.parametrize("seed", range(4))
def test_principal_axes_match_numpy(seed):
    """Values ascending and the projectors onto the least and greatest axes, for well separated
    values (closed form), nearly and exactly repeated ones (Jacobi), a zero and an isotropic
    tensor, and a large mean stress beside a small deviator."""
    rng = np.random.default_rng(seed)
    lam, pr, vec = np.empty(3), np.empty(12), np.empty((3, 3))
    closed = 0
    for case in range(300):
        q, r = np.linalg.qr(rng.normal(size=(3, 3)))
        w = rng.normal(size=3) * 10 ** rng.uniform(-2, 7)
        kind = case % 5
        if kind == 1:
            w[1] = w[0] * (1 + 10 ** rng.uniform(-12, -3))        # nearly repeated
        elif kind == 2:
            w[2] = w[1]                                           # repeated
        elif kind == 4 and case % 25 == 4:
            w[:] = 0.0 if case % 50 == 4 else 3.0                 # zero / isotropic
        t = q @ np.diag(w) @ q.T
        # mean far above the deviator: a power of two M added, so that s - M I is exact and numpy
        # (accurate to eps |s| only) can be given the small part
        big = 2.0 ** round(math.log2(abs(w).max() + 1e-300) + rng.uniform(7, 20)) if kind == 3 else 0.0
        s = np.array([t[0, 0] + big, t[1, 1] + big, t[2, 2] + big, t[0, 1], t[0, 2], t[1, 2]])
        closed += zm.principal_axes(s, lam, pr, vec)
        ev, evec = np.linalg.eigh(_sym(s) - big * np.eye(3))
        ev += big
        scale = max(np.abs(s).max(), 1e-300)
        assert np.all(np.diff(lam) >= 0)
        assert np.abs(lam - ev).max() <= 1e-13 * scale
        spread = ev[2] - ev[0]
        gap = min(ev[1] - ev[0], ev[2] - ev[1])
        p1, p3 = _sym(pr[:6]), _sym(pr[6:])
        # (eigenvectors are accurate to about eps |s| / gap: Jacobi on s, numpy too)
        tol = 1e-12 + 4e-16 * scale / max(gap, 1e-300)
        if spread > 1e-12 * scale and tol < 1e-6:
            # distinct values: the projectors are unique
            assert np.abs(p1 - np.outer(evec[:, 0], evec[:, 0])).max() <= tol
            assert np.abs(p3 - np.outer(evec[:, 2], evec[:, 2])).max() <= tol
        if spread > 1e-12 * scale:
            # P1, P3 orthogonal projectors of rank one, on axes of s with their values
            for p, lv in ((p1, lam[0]), (p3, lam[2])):
                assert np.abs(p @ p - p).max() <= 1e-12 and abs(np.trace(p) - 1.0) <= 1e-12
                assert np.abs(_sym(s) @ p - lv * p).max() <= 1e-12 * scale
            assert np.abs(p1 @ p3).max() <= 1e-12
    assert 100 <= closed <= 240, closed


def test_mohr_scalar_is_mohr_return():
    """The scalar form (trial test + single-plane return, -1 for the rest) gives mohr_return's
    bits whenever it settles a zone, and settles the common shear and tension returns."""
    rng = np.random.default_rng(5)
    K, G = 2e9, 1e9
    settled = {0: 0, 1: 0, 2: 0}
    for _ in range(2000):
        c = rng.uniform(0.2e6, 2e6)
        tf, td = math.tan(math.radians(rng.uniform(5, 45))), math.tan(math.radians(rng.uniform(0, 5)))
        ten = rng.uniform(0, 1.0) * c / tf
        q, r = np.linalg.qr(rng.normal(size=(3, 3)))
        t = q @ np.diag(rng.uniform(-8e6, 1e6) + rng.normal(size=3) * rng.uniform(0, 3e6)) @ q.T
        s0 = np.array([t[0, 0], t[1, 1], t[2, 2], t[0, 1], t[0, 2], t[1, 2]])
        de = rng.normal(size=6) * 10 ** rng.uniform(-5, -2.7)
        s_k, bits, dsp = zm.mohr_update(s0, de, K, G, c, tf, ten, td)
        tr = s0.copy()
        lam_ = K - 2 * G / 3
        tr[:3] += lam_ * de[:3].sum() + 2 * G * de[:3]
        tr[3:] += 2 * G * de[3:]
        code, *t6, d = zm.mohr_scalar(*tr, c, *zm.mohr_constants(K, G, c, tf, ten, td))
        if code >= 0:
            settled[code] += 1
            assert code == bits and np.array_equal(np.array(t6), s_k) and d == dsp
    assert min(settled.values()) >= 40, settled


#: a small Mohr-Coulomb model that yields: tetrahedra and hexahedral (mixed-discretization) zones,
#: large strain, gravity, a held base, a side load, in-situ stress beyond the strength
_DECK = """model new
block create brick 0 1 0 1 0 1
block create brick 2 3 0 1 0 1
block zone generate edgelength 0.3 range position-x 0 1
block zone generate hexahedra divisions 3 2 3 range position-x 2 3
block zone cmodel assign mohr-coulomb
block zone property bulk 5e8 shear 3e8 density 2000 cohesion 1e4 friction 30 dilation 5 tension 5e3
block insitu stress -1e4 -4e4 -8e4 0 0 0
block gridpoint apply velocity 0 0 0 range position-z 0
block gridpoint apply force-x 2e5 range position-z 1
model gravity 0 0 -10
model large-strain on
"""


def _model_run(tmp_path, monkeypatch, threads, chunked, steps=40):
    import io

    import dec3d
    import dec3d.physics.zones as pz

    if chunked:
        monkeypatch.setattr(pz, "PARALLEL_MIN_ZONES", 0)      # one chunk per thread on this small model
    keep = numba.get_num_threads()
    numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
    try:
        s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
        s.command(_DECK + f"model cycle {steps}\n")
    finally:
        numba.set_num_threads(keep)
    m = s.model
    zst = m.rigid_engine._zstep
    assert zst.nset > 0 and zst.plastic
    zs = m.store("zones")
    return (zs["stress"].copy(), zs["state"].copy(), m.vertices["disp"].copy(), m.vertices["velocity"].copy(),
            np.array([m.rigid_engine.kinetic, m.rigid_engine.criteria()["unbalanced-maximum"]]))


def test_model_runs_give_the_same_bits_with_either_kernel_and_thread_count(tmp_path, monkeypatch):
    """A whole Mohr-Coulomb run (40 steps, large strain, tetrahedra and hexahedral sets, zones
    yielding): the zone step in one chunk, and in one chunk per thread on 1 and 2 threads, give the
    same stresses, plastic states, displacements, velocities, kinetic energy and unbalanced force."""
    ref = _model_run(tmp_path, monkeypatch, 1, False)
    assert (ref[1] & mz.ZSTATE_SHEAR_PAST).sum() > 0 and np.abs(ref[2]).max() > 1e-7
    for nt in (1, 2):
        got = _model_run(tmp_path, monkeypatch, nt, True)
        for a, b in zip(ref, got):
            assert np.array_equal(a, b), nt


def _trials(rng, n, gap):
    """n trial stresses (6,) about yield, principal values spread at random; with ``gap``, σ2 within
    gap × spread of σ1 or of σ3 (0: exactly repeated in exact arithmetic), random axes."""
    out = []
    for _ in range(n):
        lam = np.sort(rng.normal(size=3)) * rng.uniform(1e3, 1e5)
        if gap is not None:
            sp = lam[2] - lam[0]
            lam[1] = lam[0] + gap * sp * rng.random() if rng.random() < 0.5 else lam[2] - gap * sp * rng.random()
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        t = q @ np.diag(lam + rng.uniform(-1e5, 2e4)) @ q.T
        out.append(np.array([t[0, 0], t[1, 1], t[2, 2], t[0, 1], t[0, 2], t[1, 2]]))
    return out


@pytest.mark.parametrize("gap", [None, 2e-2, 1e-6, 0.0])
def test_mohr_pair_is_mohr_plastic(gap):
    """``zone_mohr_pair.mohr_pair`` (what the scalar path leaves: Itasca's plane with one other,
    nearly repeated values) gives ``mohr_plastic``'s code and, for values well apart, its bits;
    with σ2 near σ1 or σ3 (Jacobi in ``mohr_plastic``), its stress and dsp to 1e-12 of the stress
    scale; the slow twin's stress (tests/test_zone_mohr_kernels.py) to 1e-9; and settles most such
    zones (the rest: -1, the stress untouched)."""
    from dec3d.kernels.zone_mohr_pair import mohr_pair
    from tests.test_zone_mohr_kernels import twin_mohr

    rng = np.random.default_rng(11)
    K, G = 6.7e9, 4e9
    work = zm.mohr_work()
    general = settled = 0
    for coh, phi, ten, psi in ((1e4, 30, 5e3, 0), (2e4, 39, 1e3, 11), (1e3, 17, 1e4, 17)):
        tf, td = math.tan(math.radians(phi)), math.tan(math.radians(psi))
        cst = zm.mohr_constants(K, G, coh, tf, ten, td)
        for tr in _trials(rng, 400, gap):
            if zm.mohr_scalar(*tr, coh, *cst)[0] >= 0:
                continue
            general += 1
            s = tr.copy()
            code, dsp = zm.mohr_plastic(s, K, G, coh, tf, ten, td, work)
            got = mohr_pair(*tr, coh, *cst)
            if got[0] < 0:
                assert np.array_equal(np.array(got[1:7]), tr) and got[7] == 0.0
                continue
            settled += 1
            assert got[0] == code
            t6 = np.array(got[1:7])
            s_t, _, dsp_t, *_ = twin_mohr(tr, np.zeros(6), K, G, coh, tf, ten, td)
            assert np.abs(t6 - s_t).max() <= 1e-9 * (np.abs(tr).max() + coh) and abs(got[7] - dsp_t) <= 1e-9 * coh
            lam = np.linalg.eigvalsh(np.array([[tr[0], tr[3], tr[4]], [tr[3], tr[1], tr[5]], [tr[4], tr[5], tr[2]]]))
            if min(lam[1] - lam[0], lam[2] - lam[1]) > 0.021 * (lam[2] - lam[0]):
                assert np.array_equal(t6, s) and got[7] == dsp
            else:
                scale = np.abs(tr).sum() + coh
                assert np.abs(t6 - s).max() <= 1e-12 * scale and abs(got[7] - dsp) <= 1e-12 * scale
    assert settled >= 0.6 * general and general >= 300, (settled, general)


def _single_plane_twin(p1, p2, p3, coh, npf, csn, ft, nps, a1, a2, sp, ap, den):
    """Itasca's single-plane return (zone_mohr's module text) in plain Python, operation for
    operation as written there: (code, n1, n2, n3, admissible)."""
    tol = 1e-10 * (abs(p1) + abs(p3) + abs(p2) + coh + abs(ft))
    fs = p3 * npf - p1 - csn
    ften = p3 - ft
    if fs <= tol and ften <= tol:
        return 0, p1, p2, p3, True
    if fs > tol and (p3 - ft + ap * (p1 - sp) <= 0.0 or ften <= tol):
        lam_s = fs / den
        n = (p1 + lam_s * (a1 - a2 * nps), p2 + lam_s * a2 * (1.0 - nps), p3 + lam_s * (a2 - a1 * nps))
        code = 1
    else:
        lam_t = ften / a1
        n = (p1 - lam_t * a2, p2 - lam_t * a2, ft)
        code = 2
    lo, hi = min(n), max(n)
    return (code, *n, hi * npf - lo - csn <= tol and hi - ft <= tol)


def test_plane_return_is_the_single_plane_return():
    """``zone_mohr.plane_return`` (the one copy of the single-plane return that ``_fast_return``,
    ``mohr_plastic`` and ``mohr_pair`` share) gives the bits of the module text's formulas, for
    elastic, shear, tension and inadmissible (corner / edge) trials."""
    rng = np.random.default_rng(23)
    seen = {}
    for _ in range(3000):
        coh = rng.uniform(1e3, 2e6)
        tf, td = math.tan(math.radians(rng.uniform(5, 45))), math.tan(math.radians(rng.uniform(0, 20)))
        ten = rng.uniform(0, 1.0) * coh / tf
        cst = zm.mohr_constants(rng.uniform(1e8, 1e10), rng.uniform(1e8, 1e10), coh, tf, ten, td)
        p = np.sort(rng.uniform(-3, 1) * coh * 5 + rng.normal(size=3) * coh * 10 ** rng.uniform(-1, 1))
        got = zm.plane_return(p[0], p[1], p[2], coh, *cst)
        want = _single_plane_twin(float(p[0]), float(p[1]), float(p[2]), coh, *cst)
        assert got[0] == want[0] and got[1:4] == want[1:4] and got[4] == want[4]
        seen[(want[0], want[4])] = seen.get((want[0], want[4]), 0) + 1
    assert all(seen.get(k, 0) >= 30 for k in ((0, True), (1, True), (2, True), (1, False), (2, False))), seen
