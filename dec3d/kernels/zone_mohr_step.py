"""The step of 4-node zones when some are Mohr-Coulomb: the numbers of
``zone_plastic.zone_forces_plastic`` bit for bit (strain increment, mixed discretization of
hexahedral sets, nodal mixed discretization of strain and of the plastic mean-stress correction,
stress rotation in large strain, Hooke or Mohr-Coulomb, nodal forces), laid out as the elastic
step ``zone_elastic.elastic_zone_step``: scalar locals, the same parts and scatter plans
(``ElasticPlan``), any thread count gives the same bits.

Formulas: 3DEC theory text (deformable blocks, Eqs. 53-59; mixed discretization Eqs. 60-67; NMD
Eqs. 68-76), as ``kernels/zone_plastic.py``; the constitutive update of a Mohr-Coulomb zone is
``zone_mohr.mohr_scalar`` (the yield test, and Itasca's single-plane return with the principal
axes in closed form), ``zone_mohr.mohr_plastic`` for the rest (corner and edge returns, nearly
repeated principal values). A step is three sweeps over the zones:

    sweep A (per zone): volume and strain increment; Σ Δε_v V and Σ V onto the averaging nodes
                        (zones outside hexahedral sets, when NMD is on) or the set sums;
    sweep B (per zone): strain again, averaged volumetric part, stress rotated (large strain),
                        Hooke or Mohr-Coulomb; the plastic mean-stress correction dsp kept per
                        zone and Σ dsp V onto the averaging nodes;
    sweep C (per zone): the stress corrected by dsp minus its average (set mean, Eqs. 64-67, or
                        the mean of the nodal averages, Eqs. 74-76), nodal forces scattered.

Each averaging node's quotient (Σ Δε_v V / Σ V, Σ dsp V / Σ V) is made once per node after its
sums rather than by each of its zones (the same quotient, so the same bits). Sums onto gridpoints
and averaging nodes follow the plans of ``ElasticPlan`` (a target's terms in
ascending zone-entry order, foreign entries through slots), hexahedral-set sums are made
serially between the sweeps: the serial order, so the serial kernel's bits for any thread count.
"""
import numpy as np
from numba import njit, prange

from .zone_elastic import _add, _faces, _force, _strain
from .zone_mohr import (ZMODEL_MOHR, ZP_COHESION, ZP_TANDIL, ZP_TANFRIC, ZP_TENSION, merge_state, mohr_constants,
                        mohr_plastic, mohr_scalar, mohr_work)


@njit(cache=True, parallel=True)
def mohr_zone_step(pos, vel, g4, n4, rows, zset, weight, nset, cmodel, prop, bulk, shear, dt, large, nmd, stress,
                   state, force, fmag, pstart, pk, fbits, fbase, fpstart, fptgt, fpslot, nbits, nbase, npstart,
                   nptgt, npslot, nodesum, nodevol, sa, sb, evs, vols, dsp, nodedsp):
    """One step of the 4-node zones ``rows`` (elastic and Mohr-Coulomb, by ``cmodel``): the
    numbers of ``zone_plastic.zone_forces_plastic`` for any thread count. Arguments as
    ``zone_elastic.elastic_zone_step`` (the plan of ``ElasticPlan``) plus cmodel, prop (zone
    rows: model codes and ``ZP_*`` properties), state (plastic bits, updated), and scratch dsp
    (nr,) and nodedsp (nvert,)."""
    nch = pstart.shape[0] - 1
    if nmd:
        for t in prange(nodesum.shape[0]):
            nodesum[t] = 0.0
            nodevol[t] = 0.0
            nodedsp[t] = 0.0
    # sweep A: volumetric strain increments onto the averaging nodes / set entries
    if nmd or nset > 0:
        for c in prange(nch):
            j = nbase[c]
            for q in range(pstart[c], pstart[c + 1]):
                k = pk[q]
                i0 = g4[k, 0]; i1 = g4[k, 1]; i2 = g4[k, 2]; i3 = g4[k, 3]
                a0x, a0y, a0z, a1x, a1y, a1z, a2x, a2y, a2z, a3x, a3y, a3z, vol = _faces(pos, i0, i1, i2, i3)
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
            for i in prange(nptgt.shape[0]):
                t = nptgt[i]
                for q in range(npstart[i], npstart[i + 1]):
                    nodesum[t] += sa[npslot[q], 0]
                    nodevol[t] += sa[npslot[q], 1]
            # each node's average once (the quotient the zones would each work out: same bits)
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
    # sweep B: averaged strain, stress, constitutive model; Σ dsp V onto the averaging nodes
    for c in prange(nch):
        j = nbase[c]
        work = mohr_work()
        # (the constants of the last Mohr-Coulomb zone's properties: neighbours mostly share them)
        kb = -1.0; kg = -1.0; kc = -1.0; kt = -1.0; kn = -1.0; kd = -1.0
        npf, csn, ft, nps, a1, a2, sp, ap, den = mohr_constants(1.0, 1.0, 1.0, 1.0, 1.0, 0.0)
        for q in range(pstart[c], pstart[c + 1]):
            k = pk[q]
            i0 = g4[k, 0]; i1 = g4[k, 1]; i2 = g4[k, 2]; i3 = g4[k, 3]
            a0x, a0y, a0z, a1x, a1y, a1z, a2x, a2y, a2z, a3x, a3y, a3z, vol = _faces(pos, i0, i1, i2, i3)
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
                # (zone_plastic.jaumann_rotate)
                r0 = s0 + 2.0 * (w01 * s3 + w02 * s4)
                r1 = s1 + 2.0 * (-w01 * s3 + w12 * s5)
                r2 = s2 + 2.0 * (-w02 * s4 - w12 * s5)
                r3 = s3 + w01 * (s1 - s0) + w02 * s5 + w12 * s4
                r4 = s4 + w02 * (s2 - s0) + w01 * s5 - w12 * s3
                r5 = s5 + w12 * (s2 - s1) - w01 * s4 - w02 * s3
                s0 = r0; s1 = r1; s2 = r2; s3 = r3; s4 = r4; s5 = r5
            # incremental Hooke (zones.hooke_increment): the elastic update or the trial
            K = bulk[z]; G = shear[z]
            ev = d0 + d1 + d2
            lam = K - 2.0 * G / 3.0
            s0 += lam * ev + 2.0 * G * d0
            s1 += lam * ev + 2.0 * G * d1
            s2 += lam * ev + 2.0 * G * d2
            s3 += 2.0 * G * d3
            s4 += 2.0 * G * d4
            s5 += 2.0 * G * d5
            dp = 0.0
            if cmodel[z] == ZMODEL_MOHR:
                coh = prop[z, ZP_COHESION]; tf = prop[z, ZP_TANFRIC]
                ten = prop[z, ZP_TENSION]; td = prop[z, ZP_TANDIL]
                if K != kb or G != kg or coh != kc or tf != kt or ten != kn or td != kd:
                    npf, csn, ft, nps, a1, a2, sp, ap, den = mohr_constants(K, G, coh, tf, ten, td)
                    kb = K; kg = G; kc = coh; kt = tf; kn = ten; kd = td
                code, s0, s1, s2, s3, s4, s5, dp = mohr_scalar(s0, s1, s2, s3, s4, s5, coh, npf, csn, ft, nps, a1, a2,
                                                               sp, ap, den)
                if code < 0:
                    stress[z, 0] = s0; stress[z, 1] = s1; stress[z, 2] = s2
                    stress[z, 3] = s3; stress[z, 4] = s4; stress[z, 5] = s5
                    code, dp = mohr_plastic(stress[z], K, G, coh, tf, ten, td, work)
                    s0 = stress[z, 0]; s1 = stress[z, 1]; s2 = stress[z, 2]
                    s3 = stress[z, 3]; s4 = stress[z, 4]; s5 = stress[z, 5]
                state[z] = merge_state(state[z], code)
            stress[z, 0] = s0; stress[z, 1] = s1; stress[z, 2] = s2
            stress[z, 3] = s3; stress[z, 4] = s4; stress[z, 5] = s5
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
    if nmd:
        for i in prange(nptgt.shape[0]):
            t = nptgt[i]
            for q in range(npstart[i], npstart[i + 1]):
                nodedsp[t] += sa[npslot[q], 0]
        for t in prange(nodedsp.shape[0]):
            if nodevol[t] > 0.0:
                nodedsp[t] = nodedsp[t] / nodevol[t]
    # (zone_plastic.md_stress_average: the set sums in entry order)
    sd = np.zeros(nset)
    for k in range(zset.shape[0] if nset > 0 else 0):
        h = zset[k]
        if h >= 0:
            sd[h] += dsp[k] * vols[k]
    # sweep C: stress averaging, nodal forces
    for c in prange(nch):
        j = fbase[c]
        for q in range(pstart[c], pstart[c + 1]):
            k = pk[q]
            i0 = g4[k, 0]; i1 = g4[k, 1]; i2 = g4[k, 2]; i3 = g4[k, 3]
            a0x, a0y, a0z, a1x, a1y, a1z, a2x, a2y, a2z, a3x, a3y, a3z, vol = _faces(pos, i0, i1, i2, i3)
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
            b = fbits[k]
            fx, fy, fz, fm = _force(s0, s1, s2, s3, s4, s5, a0x, a0y, a0z, w)
            j = _add(force, fmag, i0, fx, fy, fz, fm, b & 1, sb, j)
            fx, fy, fz, fm = _force(s0, s1, s2, s3, s4, s5, a1x, a1y, a1z, w)
            j = _add(force, fmag, i1, fx, fy, fz, fm, b & 2, sb, j)
            fx, fy, fz, fm = _force(s0, s1, s2, s3, s4, s5, a2x, a2y, a2z, w)
            j = _add(force, fmag, i2, fx, fy, fz, fm, b & 4, sb, j)
            fx, fy, fz, fm = _force(s0, s1, s2, s3, s4, s5, a3x, a3y, a3z, w)
            j = _add(force, fmag, i3, fx, fy, fz, fm, b & 8, sb, j)
    for i in prange(fptgt.shape[0]):
        t = fptgt[i]
        for q in range(fpstart[i], fpstart[i + 1]):
            sl = fpslot[q]
            force[t, 0] += sb[sl, 0]; force[t, 1] += sb[sl, 1]; force[t, 2] += sb[sl, 2]
            fmag[t] += sb[sl, 3]
