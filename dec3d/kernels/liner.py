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

from .beam import VMAX, _sgn, move_nodes

#: ``cpl`` columns
C_KN, C_KS, C_TY, C_COH, C_COHR, C_TAN = range(6)
#: ``VMAX`` (``kernels.beam``): a liner node faster is unstable (a force of 1e200 N on a node pushed it to
#: 1e190 m/s, finite, and the equilibrium ratio to NaN)


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
    the number of non-finite or runaway node components (``kernels.beam.move_nodes``)."""
    n = pos.shape[0]
    for i in range(n):
        for k in range(3):
            last[i, k] = force[i, k]
            last[i, 3 + k] = moment[i, k]
            force[i, k] = 0.0
            moment[i, k] = 0.0
    coupling(dt, vel, host, hz, hvel, hpos, nrm, cpl, un, fn, fs, cstate, force, hforce, hmoment, bvel, bspin, bcen)
    element_forces(kg, conn, disp, rot, force, moment)
    return move_nodes(dt, g, alpha, damp, safety, pos, vel, disp, rot, avel, mass, inert, rt, rr, fix, fapp, mapp,
                     force, moment, imass, iinert, last)
