"""The step of 4-node zones, any constitutive model: strain increment, mixed discretization of
hexahedral sets, nodal mixed discretization (NMD) of the volumetric strain and of the plastic
mean-stress correction, stress rotation in large strain, the zone model's update
(``kernels/zmodels``), nodal forces. The one 4-node step of the engine; its serial twin in
passes is ``tests/zone_plastic_twin.py`` (elastic and Mohr-Coulomb), the models' own twins are
beside their tests.

Formulas: 3DEC theory text (deformable blocks, Eqs. 53-59; mixed discretization Eqs. 60-67;
NMD Eqs. 68-76, with the three-term Δε_v of ``shared/seeds/ERRATA.md``). The step is two sweeps
over the zones when no zone's model is plastic, three otherwise:

    sweep A (per zone): volume and strain increment; Σ Δε_v V and Σ V onto the averaging nodes
                        (zones outside hexahedral sets, when NMD is on) or the set sums; the
                        face area vectors and volume kept in the scratch ``geo`` for B and C
                        (reading 104 bytes a zone costs less than the four cross products);
    sweep B (per zone): strain again, averaged volumetric part, stress rotated (large strain),
                        the model's update; with no plastic model the nodal forces too; else the
                        plastic correction dsp kept per zone and Σ dsp V onto the averaging nodes;
    sweep C (plastic):  the stress corrected by dsp minus its average (set mean, Eqs. 64-67, or
                        the mean of the nodal averages, Eqs. 74-76), nodal forces.

Each averaging node's quotient is made once per node after its sums. Sums onto gridpoints and
averaging nodes follow the plans of ``zone_elastic.ElasticPlan`` (a target's terms in ascending
zone-entry order, foreign entries through slots), set sums serially between the sweeps: the
serial order, so one thread's bits for any thread count.
"""
import numpy as np
from numba import literally, njit, prange, types
from numba.extending import overload

from .zmodels import NWORK, Tables, merge_state, zone_update_for
from .zone_elastic import _add, _faces, _force, _strain
from .zone_mohr import mohr_work


@njit(cache=True, inline="always")
def _scatter_forces(force, fmag, fbits, k, i0, i1, i2, i3, s0, s1, s2, s3, s4, s5, a0x, a0y, a0z, a1x, a1y, a1z,
                    a2x, a2y, a2z, a3x, a3y, a3z, w, sb, j):
    b = fbits[k]
    fx, fy, fz, fm = _force(s0, s1, s2, s3, s4, s5, a0x, a0y, a0z, w)
    j = _add(force, fmag, i0, fx, fy, fz, fm, b & 1, sb, j)
    fx, fy, fz, fm = _force(s0, s1, s2, s3, s4, s5, a1x, a1y, a1z, w)
    j = _add(force, fmag, i1, fx, fy, fz, fm, b & 2, sb, j)
    fx, fy, fz, fm = _force(s0, s1, s2, s3, s4, s5, a2x, a2y, a2z, w)
    j = _add(force, fmag, i2, fx, fy, fz, fm, b & 4, sb, j)
    fx, fy, fz, fm = _force(s0, s1, s2, s3, s4, s5, a3x, a3y, a3z, w)
    j = _add(force, fmag, i3, fx, fy, fz, fm, b & 8, sb, j)
    return j


@njit(cache=True, inline="always")
def _keep(geo, k, a0x, a0y, a0z, a1x, a1y, a1z, a2x, a2y, a2z, a3x, a3y, a3z, vol):
    """Entry k's face area vectors and volume (``_faces``) into the step's scratch."""
    geo[k, 0] = a0x; geo[k, 1] = a0y; geo[k, 2] = a0z; geo[k, 3] = a1x; geo[k, 4] = a1y; geo[k, 5] = a1z
    geo[k, 6] = a2x; geo[k, 7] = a2y; geo[k, 8] = a2z; geo[k, 9] = a3x; geo[k, 10] = a3y; geo[k, 11] = a3z
    geo[k, 12] = vol


@njit(cache=True, inline="always")
def _kept(geo, k):
    """What ``_keep`` stored for entry k (the same bits ``_faces`` gives: positions do not move
    within a step)."""
    return (geo[k, 0], geo[k, 1], geo[k, 2], geo[k, 3], geo[k, 4], geo[k, 5], geo[k, 6], geo[k, 7], geo[k, 8],
            geo[k, 9], geo[k, 10], geo[k, 11], geo[k, 12])


@njit(cache=True, parallel=True)
def zone_step(pos, vel, mesh, mat, plan, scr, dt, large, nmd, models, force, fmag):
    """One step of the 4-node zones of ``mesh`` (``bundles.ZoneMesh``) with the materials
    ``mat`` (``bundles.ZoneMaterial``: stress, state and history updated), the plan ``plan``
    (``bundles.ZonePlan``) and scratch ``scr`` (``bundles.ZoneScratch``); pos, vel (nvert, 3)
    gridpoints; ``models``: the mask of the model codes among the zones, bit 0 set when some
    zone's model returns a mean-stress correction (three sweeps) (``zmodels.model_mask``); force
    (nvert, 3), fmag (nvert,) added to (Σ |zone force contributions| for the equilibrium ratio).

    ``models`` is a compile-time constant (numba's ``literally``): a deck compiles the step for the
    models it uses, once (cached), not every model's return nor an unused sweep."""
    literally(models)
    plastic = (models & 1) != 0
    g4 = mesh.g4; n4 = mesh.n4; rows = mesh.rows; zset = mesh.zset; weight = mesh.weight; nset = mesh.nset
    stress = mat.stress; state = mat.state; cmodel = mat.cmodel; bulk = mat.bulk; shear = mat.shear
    prop = mat.prop; hist = mat.hist
    # (parallel loops take arrays and scalars, not tuples: the tables go in as their arrays)
    tx = mat.tab.x; ty = mat.tab.y; tstart = mat.tab.start; tcount = mat.tab.count
    pstart = plan.pstart; pk = plan.pk; fbits = plan.fbits; fbase = plan.fbase
    nbits = plan.nbits; nbase = plan.nbase
    nodesum = scr.nodesum; nodevol = scr.nodevol; nodedsp = scr.nodedsp; sa = scr.sa; sb = scr.sb
    evs = scr.evs; vols = scr.vols; dsp = scr.dsp; geo = scr.geo
    nch = pstart.shape[0] - 1
    kept = nmd or nset > 0          # sweep A works the geometry out and keeps it for B (and C)
    if nmd:
        for t in prange(nodesum.shape[0]):
            nodesum[t] = 0.0
            nodevol[t] = 0.0
            if plastic:
                nodedsp[t] = 0.0
    # sweep A: volumetric strain increments onto the averaging nodes / set entries
    if nmd or nset > 0:
        for c in prange(nch):
            j = nbase[c]
            for q in range(pstart[c], pstart[c + 1]):
                k = pk[q]
                i0 = g4[k, 0]; i1 = g4[k, 1]; i2 = g4[k, 2]; i3 = g4[k, 3]
                a0x, a0y, a0z, a1x, a1y, a1z, a2x, a2y, a2z, a3x, a3y, a3z, vol = _faces(pos, i0, i1, i2, i3)
                _keep(geo, k, a0x, a0y, a0z, a1x, a1y, a1z, a2x, a2y, a2z, a3x, a3y, a3z, vol)
                d0, d1, d2, d3, d4, d5, w0, w1, w2 = _strain(vel, i0, i1, i2, i3, a0x, a0y, a0z, a1x, a1y, a1z,
                                                             a2x, a2y, a2z, a3x, a3y, a3z, vol, dt)
                e = d0 + d1 + d2
                if nset > 0 and zset[k] >= 0:
                    evs[k] = e
                    vols[k] = vol
                elif nmd:
                    x = e * vol
                    b = nbits[k]
                    for a in range(4):
                        if b & (1 << a):
                            sa[j, 0] = x
                            sa[j, 1] = vol
                            j += 1
                        else:
                            t = n4[k, a]
                            nodesum[t] += x
                            nodevol[t] += vol
        if nmd:
            npstart = plan.npstart; nptgt = plan.nptgt; npslot = plan.npslot
            for i in prange(nptgt.shape[0]):
                t = nptgt[i]
                for q in range(npstart[i], npstart[i + 1]):
                    nodesum[t] += sa[npslot[q], 0]
                    nodevol[t] += sa[npslot[q], 1]
            # each node's average once (the quotient its zones would each work out: same bits)
            for t in prange(nodesum.shape[0]):
                if nodevol[t] > 0.0:
                    nodesum[t] = nodesum[t] / nodevol[t]
    sv = np.zeros(nset)
    ss = np.zeros(nset)
    for k in range(zset.shape[0] if nset > 0 else 0):
        h = zset[k]
        if h >= 0:
            sv[h] += evs[k] * vols[k]
            ss[h] += vols[k]
    # sweep B: averaged strain, stress rotation, the model's update; forces (no plastic model)
    # or Σ dsp V onto the averaging nodes
    for c in prange(nch):
        j = fbase[c] if not plastic else nbase[c]
        mw = mohr_work()
        wf = np.full(NWORK, np.nan)
        tab = Tables(tx, ty, tstart, tcount)
        for q in range(pstart[c], pstart[c + 1]):
            k = pk[q]
            i0 = g4[k, 0]; i1 = g4[k, 1]; i2 = g4[k, 2]; i3 = g4[k, 3]
            if kept:
                a0x, a0y, a0z, a1x, a1y, a1z, a2x, a2y, a2z, a3x, a3y, a3z, vol = _kept(geo, k)
            else:
                a0x, a0y, a0z, a1x, a1y, a1z, a2x, a2y, a2z, a3x, a3y, a3z, vol = _faces(pos, i0, i1, i2, i3)
                if plastic:
                    _keep(geo, k, a0x, a0y, a0z, a1x, a1y, a1z, a2x, a2y, a2z, a3x, a3y, a3z, vol)
            d0, d1, d2, d3, d4, d5, w01, w02, w12 = _strain(vel, i0, i1, i2, i3, a0x, a0y, a0z, a1x, a1y, a1z,
                                                            a2x, a2y, a2z, a3x, a3y, a3z, vol, dt)
            e = d0 + d1 + d2
            bar = e
            h = zset[k] if nset > 0 else -1
            if h >= 0:
                if ss[h] > 0.0:
                    bar = sv[h] / ss[h]
            elif nmd:
                acc = 0.0
                acc += nodesum[n4[k, 0]]
                acc += nodesum[n4[k, 1]]
                acc += nodesum[n4[k, 2]]
                acc += nodesum[n4[k, 3]]
                bar = 0.25 * acc
            shift = (bar - e) / 3.0
            d0 += shift; d1 += shift; d2 += shift
            z = rows[k] if rows.shape[0] > 0 else k
            s0 = stress[z, 0]; s1 = stress[z, 1]; s2 = stress[z, 2]
            s3 = stress[z, 3]; s4 = stress[z, 4]; s5 = stress[z, 5]
            if large:
                # Jaumann rotation: σ += ωσ − σω
                r0 = s0 + 2.0 * (w01 * s3 + w02 * s4)
                r1 = s1 + 2.0 * (-w01 * s3 + w12 * s5)
                r2 = s2 + 2.0 * (-w02 * s4 - w12 * s5)
                r3 = s3 + w01 * (s1 - s0) + w02 * s5 + w12 * s4
                r4 = s4 + w02 * (s2 - s0) + w01 * s5 - w12 * s3
                r5 = s5 + w12 * (s2 - s1) - w01 * s4 - w02 * s3
                s0 = r0; s1 = r1; s2 = r2; s3 = r3; s4 = r4; s5 = r5
            code, s0, s1, s2, s3, s4, s5, dp = zone_update_for(models, cmodel[z], prop, hist, z, bulk[z],
                                                               shear[z], d0, d1, d2, d3, d4, d5, s0, s1, s2,
                                                               s3, s4, s5, tab, wf, mw)
            stress[z, 0] = s0; stress[z, 1] = s1; stress[z, 2] = s2
            stress[z, 3] = s3; stress[z, 4] = s4; stress[z, 5] = s5
            if not plastic:
                w = weight[k] / 3.0 if weight.shape[0] > 0 else 1.0 / 3.0
                j = _scatter_forces(force, fmag, fbits, k, i0, i1, i2, i3, s0, s1, s2, s3, s4, s5, a0x, a0y, a0z,
                                    a1x, a1y, a1z, a2x, a2y, a2z, a3x, a3y, a3z, w, sb, j)
                continue
            state[z] = merge_state(state[z], code)
            dsp[k] = dp
            if h < 0 and nmd:
                x = dp * vol
                b = nbits[k]
                for a in range(4):
                    if b & (1 << a):
                        sa[j, 0] = x
                        j += 1
                    else:
                        nodedsp[n4[k, a]] += x
    _correct(models, pos, mesh, mat, plan, scr, nmd, force, fmag)
    fpstart = plan.fpstart; fptgt = plan.fptgt; fpslot = plan.fpslot
    for i in prange(fptgt.shape[0]):
        t = fptgt[i]
        for q in range(fpstart[i], fpstart[i + 1]):
            sl = fpslot[q]
            force[t, 0] += sb[sl, 0]; force[t, 1] += sb[sl, 1]; force[t, 2] += sb[sl, 2]
            fmag[t] += sb[sl, 3]


def _correct(models, pos, mesh, mat, plan, scr, nmd, force, fmag):
    """Sweep C when bit 0 of ``models`` is set (a literal: the step of a deck without correcting
    models does not compile it)."""
    raise NotImplementedError("called from zone_step only")


@overload(_correct, jit_options={"cache": True})
def _correct_impl(models, pos, mesh, mat, plan, scr, nmd, force, fmag):
    if not isinstance(models, types.IntegerLiteral):
        return None             # (typed again once ``literally`` has made it a literal)
    if not models.literal_value & 1:
        def nothing(models, pos, mesh, mat, plan, scr, nmd, force, fmag):
            return None
        return nothing

    def sweep(models, pos, mesh, mat, plan, scr, nmd, force, fmag):
        _correction_sweep(pos, mesh, mat, plan, scr, nmd, force, fmag)
    return sweep


@njit(cache=True, parallel=True)
def _correction_sweep(pos, mesh, mat, plan, scr, nmd, force, fmag):
    """Sweep C of ``zone_step``: the averaged plastic corrections, then the nodal forces."""
    g4 = mesh.g4; n4 = mesh.n4; rows = mesh.rows; zset = mesh.zset; weight = mesh.weight; nset = mesh.nset
    stress = mat.stress
    pstart = plan.pstart; pk = plan.pk; fbits = plan.fbits; fbase = plan.fbase
    nodevol = scr.nodevol; nodedsp = scr.nodedsp; sa = scr.sa; sb = scr.sb
    vols = scr.vols; dsp = scr.dsp; geo = scr.geo
    nch = pstart.shape[0] - 1
    if nmd:
        npstart = plan.npstart; nptgt = plan.nptgt; npslot = plan.npslot
        for i in prange(nptgt.shape[0]):
            t = nptgt[i]
            for q in range(npstart[i], npstart[i + 1]):
                nodedsp[t] += sa[npslot[q], 0]
        for t in prange(nodedsp.shape[0]):
            if nodevol[t] > 0.0:
                nodedsp[t] = nodedsp[t] / nodevol[t]
    # the set sums in entry order (Eqs. 64-67)
    sd = np.zeros(nset)
    ss = np.zeros(nset)
    for k in range(zset.shape[0] if nset > 0 else 0):
        h = zset[k]
        if h >= 0:
            sd[h] += dsp[k] * vols[k]
            ss[h] += vols[k]
    for c in prange(nch):
        j = fbase[c]
        for q in range(pstart[c], pstart[c + 1]):
            k = pk[q]
            i0 = g4[k, 0]; i1 = g4[k, 1]; i2 = g4[k, 2]; i3 = g4[k, 3]
            a0x, a0y, a0z, a1x, a1y, a1z, a2x, a2y, a2z, a3x, a3y, a3z, vol = _kept(geo, k)
            z = rows[k] if rows.shape[0] > 0 else k
            s0 = stress[z, 0]; s1 = stress[z, 1]; s2 = stress[z, 2]
            s3 = stress[z, 3]; s4 = stress[z, 4]; s5 = stress[z, 5]
            h = zset[k] if nset > 0 else -1
            if h >= 0:
                if ss[h] > 0.0:
                    cc = dsp[k] - sd[h] / ss[h]
                    s0 += cc; s1 += cc; s2 += cc
            elif nmd:
                acc = 0.0
                acc += nodedsp[n4[k, 0]]
                acc += nodedsp[n4[k, 1]]
                acc += nodedsp[n4[k, 2]]
                acc += nodedsp[n4[k, 3]]
                cc = dsp[k] - 0.25 * acc
                s0 += cc; s1 += cc; s2 += cc
            stress[z, 0] = s0; stress[z, 1] = s1; stress[z, 2] = s2
            w = weight[k] / 3.0 if weight.shape[0] > 0 else 1.0 / 3.0
            j = _scatter_forces(force, fmag, fbits, k, i0, i1, i2, i3, s0, s1, s2, s3, s4, s5, a0x, a0y, a0z,
                                a1x, a1y, a1z, a2x, a2y, a2z, a3x, a3y, a3z, w, sb, j)


_STEPS: dict = {}


def zone_step_for(models: int):
    """``zone_step`` with ``models`` fixed: ``step(pos, vel, mesh, mat, plan, scr, dt, large, nmd,
    force, fmag)``. Called from Python with the mask as a plain integer, ``zone_step`` would type
    it as an integer first at every call and only then as the literal it asks for (about a
    second a call); a small jitted function that passes the mask as a constant reaches the
    literal specialization at once. One per mask and process, cached on disk like the step."""
    step = _STEPS.get(models)
    if step is None:
        mask = int(models)

        @njit(cache=True)      # (numba keys a closure's cache entry on the mask it closes over)
        def step(pos, vel, mesh, mat, plan, scr, dt, large, nmd, force, fmag):
            zone_step(pos, vel, mesh, mat, plan, scr, dt, large, nmd, mask, force, fmag)
        _STEPS[models] = step
    return step
