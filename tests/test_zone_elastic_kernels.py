"""The 4-node zone step (``kernels/zone_step.py``) on elastic zones: against a numpy twin written
from the text's formulas (shape-function gradients, not the kernel's face vectors), bit for bit
against the serial twin in passes (``tests/zone_plastic_twin.py``) for any number of parts and
threads and through either of its paths (two sweeps, or the plastic three), and the scatter
bookkeeping of ``kernels/zone_elastic.py``."""
import itertools

import numba
import numpy as np
import pytest

from dec3d.kernels import zone_elastic as ze
from dec3d.model import zones as mz
from tests import zone_plastic_twin as zp
from tests.zone_step_run import Stepper

K, G = 5e9, 3e9


def _lattice(n, rng, jitter=0.15):
    """n³ unit cubes, each split into the 6 tetrahedra around its main diagonal (conforming),
    gridpoints jittered; returns pos (nv, 3), gp (nz, 10) with -1 past the 4 corners."""
    idx = np.arange((n + 1) ** 3).reshape(n + 1, n + 1, n + 1)
    pos = np.stack(np.meshgrid(*[np.arange(n + 1.0)] * 3, indexing="ij"), -1).reshape(-1, 3)
    pos = pos + rng.uniform(-jitter, jitter, pos.shape)
    tets = []
    for i, j, k in itertools.product(range(n), repeat=3):
        corner = lambda b: idx[i + (b & 1), j + ((b >> 1) & 1), k + ((b >> 2) & 1)]
        for perm in itertools.permutations((1, 2, 4)):
            tets.append([corner(0), corner(perm[0]), corner(perm[0] | perm[1]), corner(7)])
    gp = np.full((len(tets), 10), -1, np.int64)
    gp[:, :4] = tets
    return pos, gp


def _tensor(s):
    return np.array([[s[0], s[3], s[4]], [s[3], s[1], s[5]], [s[4], s[5], s[2]]])


def _vec6(t):
    return np.array([t[0, 0], t[1, 1], t[2, 2], t[0, 1], t[0, 2], t[1, 2]])


def twin_elastic_step(pos, vel, gp, rows, zset, weight, node, bulk, shear, dt, large, nmd, stress, force, fmag):
    """Elastic step from shape-function gradients: Δε = sym(L) Δt, L = Σ v_n ⊗ ∇N_n; volumetric
    part averaged over each hexahedral set (volume-weighted) or, with NMD, the mean over the
    zone's nodes of the volume-weighted nodal averages; Jaumann turn by skw(L) Δt (large);
    Hooke; nodal force f_n = −w V σ ∇N_n."""
    kin = []
    for z in rows:
        x, v = pos[gp[z, :4]], vel[gp[z, :4]]
        m = np.hstack([np.ones((4, 1)), x])
        dn = np.linalg.inv(m)[1:, :].T
        L = v.T @ dn * dt
        kin.append((0.5 * (L + L.T), 0.5 * (L - L.T), abs(np.linalg.det(m)) / 6.0, dn))
    ev = np.array([np.trace(k[0]) for k in kin])
    vol = np.array([k[2] for k in kin])
    bar = ev.copy()
    for h in set(zset[zset >= 0].tolist()):
        on = zset == h
        bar[on] = (ev[on] * vol[on]).sum() / vol[on].sum()
    if nmd:
        acc, wt = {}, {}
        for k, z in enumerate(rows):
            if zset[k] < 0:
                for g in gp[z, :4]:
                    acc[node[g]] = acc.get(node[g], 0.0) + ev[k] * vol[k]
                    wt[node[g]] = wt.get(node[g], 0.0) + vol[k]
        for k, z in enumerate(rows):
            if zset[k] < 0:
                bar[k] = np.mean([acc[node[g]] / wt[node[g]] for g in gp[z, :4]])
    for k, z in enumerate(rows):
        e = kin[k][0] + (bar[k] - ev[k]) / 3.0 * np.eye(3)
        S = _tensor(stress[z])
        if large:
            W = kin[k][1]
            S = S + W @ S - S @ W
        S = S + (bulk[z] - 2 * shear[z] / 3) * np.trace(e) * np.eye(3) + 2 * shear[z] * e
        stress[z] = _vec6(S)
        for n in range(4):
            f = -weight[k] * vol[k] * S @ kin[k][3][n]
            force[gp[z, n]] += f
            fmag[gp[z, n]] += np.linalg.norm(f)


def _case(seed, n=3, plain=False):
    """A jittered lattice: ``plain`` steps every zone, no sets, unit weights, no links (the
    plan then passes rows, zset and weight empty); otherwise a subset of the zones, two
    hexahedral sets with half weights and one linked gridpoint."""
    rng = np.random.default_rng(seed)
    pos, gp = _lattice(n, rng)
    nz, nv = len(gp), len(pos)
    vel = rng.normal(size=(nv, 3)) * 1e-3
    node = np.arange(nv, dtype=np.int64)
    if plain:
        rows = np.arange(nz, dtype=np.int64)
        zset = np.full(nz, -1, np.int64)
    else:
        rows = np.sort(rng.choice(nz, nz - 7, replace=False)).astype(np.int64)    # not every zone
        zset = np.full(len(rows), -1, np.int64)
        zset[:12] = np.repeat(np.arange(2), 6)            # two cubes' tetrahedra as mixed sets
        node[gp[rows[40], 1]] = gp[rows[40], 0]           # one linked gridpoint (averages at its master)
    weight = np.where(zset >= 0, 0.5, 1.0)
    prop = np.zeros((nz, mz.NZPROP))
    prop[:, mz.ZP_BULK] = K * rng.uniform(0.5, 1.5, nz)
    prop[:, mz.ZP_SHEAR] = G * rng.uniform(0.5, 1.5, nz)
    stress = rng.normal(size=(nz, 6)) * 1e5
    return pos, vel, gp, rows, zset, weight, node, prop, stress


def _run(case, large, nmd, nparts, identity_node=False, plastic=False):
    pos, vel, gp, rows, zset, weight, node, prop, stress = case
    nv = len(pos)
    if identity_node:
        node = np.arange(nv, dtype=np.int64)
    zs = Stepper(gp, rows, zset, weight, node, nv, np.full(len(gp), mz.ZMODEL_ELASTIC, np.int8), prop, nparts)
    if plastic:                           # the three-sweep path, its correction zero on elastic zones
        from dec3d.physics.zone_setup import zone_bundles
        zs.plastic = True
        zs.mesh, zs.zplan, zs.scr = zone_bundles(zs.plan, int(zset.max()) + 1, True)
    st, f, fm = stress.copy(), np.ones((nv, 3)), np.full(nv, 0.5)
    zs.step(pos, vel, st, np.zeros(len(gp), np.int32), f, fm, 0.7, large, nmd)
    return st, f, fm


@pytest.mark.parametrize("large, nmd", [(False, True), (True, True), (False, False), (True, False)])
def test_elastic_step_matches_twin(large, nmd):
    case = _case(5)
    pos, vel, gp, rows, zset, weight, node, prop, stress = case
    st, f, fm = _run(case, large, nmd, 3)
    ts, tf, tm = stress.copy(), np.ones((len(pos), 3)), np.full(len(pos), 0.5)
    twin_elastic_step(pos, vel, gp, rows, zset, weight, node, prop[:, mz.ZP_BULK], prop[:, mz.ZP_SHEAR], 0.7, large,
                      nmd, ts, tf, tm)
    assert np.abs(st - ts).max() <= 1e-9 * np.abs(ts).max()
    assert np.abs(f - tf).max() <= 1e-9 * np.abs(tf).max()
    assert np.abs(fm - tm).max() <= 1e-9 * np.abs(tm).max()
    left = np.setdiff1d(np.arange(len(gp)), rows)
    np.testing.assert_array_equal(st[left], stress[left])                      # zones not stepped
    assert np.abs(st[rows] - stress[rows]).min() > 0.0


@pytest.mark.parametrize("large, nmd, plain", [(False, True, False), (True, True, False), (True, False, False),
                                               (False, True, True), (True, True, True)])
def test_elastic_step_gives_the_plastic_steps_bits_for_any_parts_and_threads(large, nmd, plain):
    case = _case(11, plain=plain)
    pos, vel, gp, rows, zset, weight, node, prop, stress = case
    plan = ze.ElasticPlan(gp, rows, node, zset, weight, len(pos), 2)
    assert (len(plan.rows), len(plan.zset), len(plan.weight)) == ((0, 0, 0) if plain else (len(rows),) * 3)
    assert (plan.n4 is plan.g4) == plain
    nv = len(pos)
    ref = [stress.copy(), np.zeros(len(gp), np.int32), np.ones((nv, 3)), np.full(nv, 0.5)]
    zp.zone_forces_plastic(pos, vel, gp, rows, zset, weight, int(zset.max()) + 1, node, np.ones(len(gp), np.int8),
                           prop, 0.7, large, nmd, *ref)
    keep = numba.get_num_threads()
    try:
        for nt in (1, 2):
            numba.set_num_threads(min(nt, numba.config.NUMBA_NUM_THREADS))
            for parts in (1, 2, 3, 5, 16):
                for plastic in (False, True):
                    st, f, fm = _run(case, large, nmd, parts, plastic=plastic)
                    for a, b in zip((ref[0], ref[2], ref[3]), (st, f, fm)):
                        assert np.array_equal(a, b), (nt, parts, plastic)
    finally:
        numba.set_num_threads(keep)


def test_partition_and_scatter_plan():
    rng = np.random.default_rng(2)
    pos, gp = _lattice(4, rng)
    g4 = gp[:, :4].astype(np.int32)
    nr, nv = len(g4), len(pos)
    for parts in (1, 3, 7):
        pstart, pk = ze.partition_entries(g4, nv, parts)
        assert np.array_equal(np.sort(pk), np.arange(nr))                        # every entry once
        sizes = np.diff(pstart)
        assert len(sizes) == parts and sizes.max() - sizes.min() <= 0.5 * nr / parts + 40
        part = np.empty(nr, int)
        for p in range(parts):
            seg = pk[pstart[p]:pstart[p + 1]]
            assert np.all(np.diff(seg) > 0)                                      # ascending in a part
            part[seg] = p
        sel = rng.uniform(size=nr) < 0.8
        bits, sbase, tstart, ptgt, pslot = ze.scatter_plan(g4, nv, pstart, pk, sel)
        # independent: per target, the entries in ascending order; the leading run in the first
        # entry's part is direct, the rest foreign
        foreign = {}
        for t in range(nv):
            ent = [(k, a) for k in range(nr) if sel[k] for a in range(4) if g4[k, a] == t]
            run = 0
            while run < len(ent) and part[ent[run][0]] == part[ent[0][0]]:
                run += 1
            for k, a in ent[run:]:
                foreign[(k, a)] = t
        got = {(k, a) for k in range(nr) for a in range(4) if bits[k] >> a & 1}
        assert got == set(foreign)
        if parts == 1:
            assert not got
        else:
            assert 0 < len(got) < 0.5 * sel.sum() * 4
        # slots: part p's foreign entries in its (ascending) order; targets list theirs ascending
        slot = {}
        for p in range(parts):
            s = sbase[p]
            for k in pk[pstart[p]:pstart[p + 1]]:
                for a in range(4):
                    if bits[k] >> a & 1:
                        slot[(k, a)] = s
                        s += 1
            assert s == sbase[p + 1]
        for i, t in enumerate(ptgt):
            want = sorted(e for e, tt in foreign.items() if tt == t)
            assert list(pslot[tstart[i]:tstart[i + 1]]) == [slot[e] for e in want]
        assert sorted(ptgt.tolist()) == sorted(set(foreign.values()))


@pytest.mark.parametrize("mode, large", [(0, False), (1, True), (2, False), (3, True)])
def test_threaded_motion_gives_the_serial_motions_bits(mode, large):
    """``zonestep.gp_motion_ws`` (masters on threads, reductions in master order) against
    ``gp_motion`` (twin-tested in tests/deformable/test_zone_step_kernels.py): every array and
    out[0..3] the same bits, 1 and 2 threads; the first runaway master in master order is named."""
    from dec3d.kernels.zonestep import gp_motion, gp_motion_ws
    rng = np.random.default_rng(40 + mode)
    n = 3000
    link = np.full(n, -1, np.int64)
    linked = np.sort(rng.choice(n, 300, replace=False))
    masters = np.setdiff1d(np.arange(n), linked)
    link[linked] = rng.choice(masters, len(linked))
    force, fprev = rng.normal(size=(n, 3)) * 1e3, rng.normal(size=(n, 3)) * 1e3
    mtot, imass = rng.uniform(1, 2, n), rng.uniform(1, 2, n)
    imass[masters[::97]] = 0.0
    held = rng.choice(np.array([0, 0, 0, 1, 5, 7, 8, 40], np.uint8), n)
    vapp, vel = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    vel[masters[::50], 1] = 0.0
    force[masters[700], 0] = 1e12                       # two runaways: the first in master order counts
    force[masters[1900], 2] = np.nan
    held[masters[[700, 1900]]] = 0
    imass[masters[[700, 1900]]] = 1.0
    keep = numba.get_num_threads()
    try:
        for vmax in (1e6, 1e30):
            base = [force, fprev, vel, rng.normal(size=(n, 3)), rng.normal(size=(n, 3))]
            ref = [a.copy() for a in base]
            out_ref = np.zeros(4)
            bad_ref = gp_motion(masters, linked, link, ref[0], ref[1], mtot, imass, held, vapp, ref[2], ref[3], ref[4],
                                0.3, mode, 0.8, large, vmax, out_ref)
            assert bad_ref == (masters[700] if vmax == 1e6 else masters[1900])
            for nt in (1, 2):
                numba.set_num_threads(min(nt, numba.config.NUMBA_NUM_THREADS))
                got = [a.copy() for a in base]
                out = np.zeros(4)
                bad = gp_motion_ws(masters, linked, link, got[0], got[1], mtot, imass, held, vapp, got[2], got[3],
                                   got[4], 0.3, mode, 0.8, large, vmax, out, np.full((len(masters), 5), np.nan))
                assert bad == bad_ref
                np.testing.assert_array_equal(out, out_ref)
                for a, b in zip(ref, got):
                    np.testing.assert_array_equal(a, b)
    finally:
        numba.set_num_threads(keep)


#: two zoned blocks apart: 4-node tetrahedra and hexahedral (mixed-discretization) zones, large
#: strain, gravity, a held base, a side load
_DECK = """model new
block create brick 0 1 0 1 0 1
block create brick 2 3 0 1 0 1
block zone generate edgelength 0.3 range position-x 0 1
block zone generate hexahedra divisions 3 2 3 range position-x 2 3
block zone cmodel assign elastic
block zone property bulk 5e8 shear 3e8 density 2000
block gridpoint apply velocity 0 0 0 range position-z 0
block gridpoint apply force-x 2e5 range position-z 1
model gravity 0 0 -10
model large-strain on
"""


def _model_run(tmp_path, monkeypatch, threads, chunked, nmd="on", steps=60):
    import io

    import dec3d
    import dec3d.physics.zones as pz

    if chunked:
        monkeypatch.setattr(pz, "PARALLEL_MIN_ZONES", 0)      # one chunk per thread on this small model
    keep = numba.get_num_threads()
    numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
    try:
        s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
        s.command(_DECK + f"block zone nodal-mixed-discretization {nmd}\nmodel cycle {steps}\n")
    finally:
        numba.set_num_threads(keep)
    m = s.model
    zst = m.rigid_engine._zstep
    assert zst.nset > 0 and (len(zst.fast.pstart) > 2) == (chunked and threads > 1)
    return (m.store("zones")["stress"].copy(), m.vertices["disp"].copy(), m.vertices["velocity"].copy(),
            np.array([m.rigid_engine.kinetic, m.rigid_engine.criteria()["unbalanced-maximum"]]))


@pytest.mark.parametrize("nmd", ["on", "off"])
def test_model_runs_give_the_same_bits_with_either_kernel_and_thread_count(tmp_path, monkeypatch, nmd):
    """A whole run (60 steps, large strain, tetrahedra and hexahedral sets): the zone step in one
    chunk and in one chunk per thread on 1 and 2 threads gives the same stresses, displacements,
    velocities, kinetic energy and unbalanced force, bit for bit."""
    ref = _model_run(tmp_path, monkeypatch, 1, False, nmd)
    assert np.abs(ref[1]).max() > 1e-7                             # it moved
    for threads in (1, 2):
        got = _model_run(tmp_path, monkeypatch, threads, True, nmd)
        for a, b in zip(ref, got):
            np.testing.assert_array_equal(a, b)
