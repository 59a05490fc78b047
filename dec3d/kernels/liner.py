"""One explicit step of the liner structural elements (``physics.liners``; element ``kernels.dkt``).

Nodes carry 6 degrees of freedom. Each element's end forces are K d, K its 18 × 18 stiffness in
global axes (``kg (s, 18, 18)``, from ``kernels.dkt`` with the element's axes fixed at creation),
d the total displacements and rotations of its three nodes; they act on the nodes as −K d, summed
element by element in order (deterministic).

Coupling (per node with a host, ``cpl (n, 6)``: k_n A, k_s A, tensile yield force, cohesion force,
residual cohesion force, tan φ; A the node's tributary area): the node's velocity relative to its host
point (a rigid block's material point, or Σ wᵢ vᵢ of the zone holding it, ``hvel``) is split along the
node's normal ``nrm`` and across it.
    normal:  u_n += Δu_n (separation +); f_n = −k_n A u_n (on the node along ``nrm``, compression +);
             tension −f_n beyond the yield force breaks the spring (``cstate`` bit 0): from then on
             f_n = max(−k_n A u_n, 0), compression only, as the liner comes back onto the surface;
    shear:   f_s −= k_s A Δu_s (incremental); |f_s| ≤ c A + max(f_n, 0) tan φ, c the cohesion until the
             first slip (``cstate`` bit 1), the residual one after.
The coupling force f_n n + f_s acts on the node; its reaction on the host (``hforce``, and ``hmoment``
about a rigid host's centroid). Rotations are not coupled (the liner's nodes rotate freely).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .beam import _sgn

#: ``cpl`` columns
C_KN, C_KS, C_TY, C_COH, C_COHR, C_TAN = range(6)
#: a node faster than this [m/s] is unstable (the limit blocks and gridpoints have, ``physics.steps``): a
#: force of 1e200 N on a node pushed it to 1e190 m/s, finite, and the equilibrium ratio to NaN
VMAX = 1e6


@njit(cache=True)
def coupling(dt, vel, host, hz, hvel, hpos, nrm, cpl, un, fn, fs, cstate, force, hforce, hmoment,
             bvel, bspin, bcen):
    """Coupling forces into ``force`` (added) and the reactions into ``hforce``/``hmoment`` (set)."""
    n = vel.shape[0]
    vh = np.empty(3)
    for i in range(n):
        for k in range(3):
            hforce[i, k] = 0.0
            hmoment[i, k] = 0.0
        h = host[i]
        if h < 0:
            continue
        if hz[i] != 0:
            for k in range(3):
                vh[k] = hvel[i, k]
        else:
            r0 = hpos[i, 0] - bcen[h, 0] + bvel[h, 0] * dt
            r1 = hpos[i, 1] - bcen[h, 1] + bvel[h, 1] * dt
            r2 = hpos[i, 2] - bcen[h, 2] + bvel[h, 2] * dt
            w0, w1, w2 = bspin[h, 0], bspin[h, 1], bspin[h, 2]
            vh[0] = bvel[h, 0] + w1 * r2 - w2 * r1
            vh[1] = bvel[h, 1] + w2 * r0 - w0 * r2
            vh[2] = bvel[h, 2] + w0 * r1 - w1 * r0
            for k in range(3):
                hpos[i, k] += vh[k] * dt
        dn = 0.0
        for k in range(3):
            dn += (vel[i, k] - vh[k]) * nrm[i, k]
        # normal spring (total)
        un[i] += dn * dt
        f = -cpl[i, C_KN] * un[i]
        if cstate[i] & 1:
            f = max(f, 0.0)
        elif -f > cpl[i, C_TY]:
            cstate[i] |= 1
            f = 0.0
        fn[i] = f
        # shear spring (incremental), in the plane normal to nrm
        for k in range(3):
            fs[i, k] -= cpl[i, C_KS] * (vel[i, k] - vh[k] - dn * nrm[i, k]) * dt
        along = fs[i, 0] * nrm[i, 0] + fs[i, 1] * nrm[i, 1] + fs[i, 2] * nrm[i, 2]
        for k in range(3):
            fs[i, k] -= along * nrm[i, k]
        mag = math.sqrt(fs[i, 0] ** 2 + fs[i, 1] ** 2 + fs[i, 2] ** 2)
        coh = cpl[i, C_COHR] if cstate[i] & 2 else cpl[i, C_COH]
        lim = coh + max(f, 0.0) * cpl[i, C_TAN]
        if mag > lim:
            cstate[i] |= 2
            sc = lim / mag
            for k in range(3):
                fs[i, k] *= sc
        for k in range(3):
            c = f * nrm[i, k] + fs[i, k]
            force[i, k] += c
            hforce[i, k] = -c
        if hz[i] == 0:
            r0 = hpos[i, 0] - bcen[h, 0]
            r1 = hpos[i, 1] - bcen[h, 1]
            r2 = hpos[i, 2] - bcen[h, 2]
            hmoment[i, 0] = r1 * hforce[i, 2] - r2 * hforce[i, 1]
            hmoment[i, 1] = r2 * hforce[i, 0] - r0 * hforce[i, 2]
            hmoment[i, 2] = r0 * hforce[i, 1] - r1 * hforce[i, 0]


@njit(cache=True)
def element_forces(kg, conn, disp, rot, force, moment):
    """Add −K d of every element to its nodes' ``force``/``moment`` (element by element, in order)."""
    d = np.empty(18)
    for e in range(kg.shape[0]):
        for c in range(3):
            i = conn[e, c]
            for k in range(3):
                d[6 * c + k] = disp[i, k]
                d[6 * c + 3 + k] = rot[i, k]
        for c in range(3):
            i = conn[e, c]
            for k in range(6):
                p = 6 * c + k
                acc = 0.0
                for q in range(18):
                    acc += kg[e, p, q] * d[q]
                if k < 3:
                    force[i, k] -= acc
                else:
                    moment[i, k - 3] -= acc


@njit(cache=True)
def liner_step(dt, g, alpha, damp, safety,
               pos, vel, disp, rot, avel, mass, inert, rt, rr, host, hz, hvel, hpos, nrm, cpl, un, fn, fs, cstate,
               fix, fapp, mapp, force, moment, hforce, hmoment, imass, iinert, kg, conn, bvel, bspin, bcen, last):
    """One step; arguments as ``kernels.beam.beam_step`` (motion) and the module docstring. Returns
    the number of non-finite or runaway node components (``move_dofs``)."""
    n = pos.shape[0]
    for i in range(n):
        for k in range(3):
            last[i, k] = force[i, k]
            last[i, 3 + k] = moment[i, k]
            force[i, k] = 0.0
            moment[i, k] = 0.0
    coupling(dt, vel, host, hz, hvel, hpos, nrm, cpl, un, fn, fs, cstate, force, hforce, hmoment, bvel, bspin, bcen)
    element_forces(kg, conn, disp, rot, force, moment)
    return move_dofs(dt, g, alpha, damp, safety, pos, vel, disp, rot, avel, mass, inert, rt, rr, fix, fapp, mapp,
                     force, moment, imass, iinert, last)


@njit(cache=True)
def move_dofs(dt, g, alpha, damp, safety, pos, vel, disp, rot, avel, mass, inert, rt, rr, fix, fapp, mapp,
              force, moment, imass, iinert, last):
    """The law of motion of the liner nodes: as ``kernels.beam.move_nodes`` (central differences,
    gravity and ``fapp``/``mapp`` added, local or combined damping) but density-scaled degree of freedom
    by degree of freedom: ``rt, rr (n, 3)`` the Gershgorin row sums of the stiffness over each global
    translation and rotation, inertia max(real, R (Δt / 2 safety)²) on each (stable: Gershgorin's bound
    on M⁻¹K). A shell is far stiffer in its plane than across it; one mass per node would make its
    bending crawl. ``imass``/``iinert`` get the largest of the three. Returns the count of
    non-finite or runaway (speed over ``VMAX``) node components."""
    n = pos.shape[0]
    bad = 0
    q = (dt / (2.0 * safety)) ** 2 if safety > 0.0 else 0.0
    for i in range(n):
        imass[i] = 0.0
        iinert[i] = 0.0
        for k in range(3):
            m = max(mass[i], rt[i, k] * q) if safety > 0.0 else mass[i]
            ri = max(inert[i], rr[i, k] * q) if safety > 0.0 else inert[i]
            if m <= 0.0:
                m = 1.0
            if ri <= 0.0:
                ri = 1.0
            imass[i] = max(imass[i], m)
            iinert[i] = max(iinert[i], ri)
            fk = force[i, k] + fapp[i, k] + mass[i] * g[k]
            force[i, k] = fk
            mk = moment[i, k] + mapp[i, k]
            moment[i, k] = mk
            if not (fix[i] >> k) & 1:
                v = vel[i, k]
                if damp == 1:
                    fk -= alpha * abs(fk) * _sgn(v)
                elif damp == 2:
                    fk -= 0.5 * alpha * abs(fk) * (_sgn(v) - _sgn(fk - last[i, k]))
                vel[i, k] = v + fk / m * dt
            if not (fix[i] >> (3 + k)) & 1:
                w = avel[i, k]
                if damp == 1:
                    mk -= alpha * abs(mk) * _sgn(w)
                elif damp == 2:
                    mk -= 0.5 * alpha * abs(mk) * (_sgn(w) - _sgn(mk - last[i, 3 + k]))
                avel[i, k] = w + mk / ri * dt
        for k in range(3):
            pos[i, k] += vel[i, k] * dt
            disp[i, k] += vel[i, k] * dt
            rot[i, k] += avel[i, k] * dt
            if not (math.isfinite(pos[i, k]) and math.isfinite(rot[i, k]) and abs(vel[i, k]) <= VMAX):
                bad += 1
    return bad
