"""One explicit step of the beam structural elements (``physics.beams``; equations there).

Nodes carry 6 degrees of freedom (3 translations, 3 rotations). Each element is a straight 2-node
Euler-Bernoulli beam in its own axes (``axes (s, 3, 3)``: rows x along the element, y, z), linear,
small displacement: its end forces are K d with d the nodal displacements and rotations (total, from
creation) turned into the element's axes, K the 12 × 12 stiffness of an Euler-Bernoulli beam with
axial (EA/L), torsional (GJ/L) and bending stiffness about y (E I_y) and z (E I_z). Nodes inside a
rigid block are linked to it by a translational and a rotational spring (``klt, klr (n,)``,
incremental forces). The tests hold a plain-Python twin (``tests/test_beams.py``).

Arrays (n nodes, s elements):

- nodes: ``pos, vel, disp, rot, avel (n, 3)``; ``mass, inert (n,)`` real mass and rotary inertia;
  ``rt, rr (n, 3)`` Gershgorin row sums of the stiffness at the node (translational, rotational rows;
  a beam node's three are equal: ``move_nodes`` takes each degree of freedom's);
  ``host (n,)`` block row or -1; ``hz (n,)`` 1 where the host is a zoned block, whose host-point
  velocity ``hvel (n, 3)`` the caller gives (translational link only); ``hpos (n, 3)`` host point;
  ``klt, klr (n,)`` link stiffnesses;
  ``lf, lm (n, 3)`` link force and moment on the node (updated); ``fix (n,)`` bits 0-2 velocity,
  3-5 rotational velocity held; ``fapp, mapp (n, 3)``. Out: ``force, moment (n, 3)`` unbalanced,
  ``hforce, hmoment (n, 3)`` force on the host and its moment about the host's centroid,
  ``imass, iinert (n,)`` inertial mass and rotary inertia used.
- elements: ``na, nb (s,)``, ``l0 (s,)``, ``prop (s, 7)`` (young, poisson, area, moi-y, moi-z,
  moi-polar, density), ``axes (s, 3, 3)``; out ``fl (s, 12)``: end forces in the element's axes, on
  the element (N at end a, M at end a, N at end b, M at end b).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

#: a structural node faster than this [m/s] has run away (the limit blocks and gridpoints have, ``physics.steps``)
VMAX = 1e6

#: ``prop`` columns
B_E, B_NU, B_A, B_IY, B_IZ, B_J, B_RHO = range(7)
NBPROP = 7


@njit(cache=True)
def local_stiffness(e, nu, a, iy, iz, j, ln, k):
    """The 12 × 12 Euler-Bernoulli stiffness ``k`` (zeroed and filled) in the element's axes; DOF
    order u, v, w, θx, θy, θz at end a then end b."""
    for p in range(12):
        for q in range(12):
            k[p, q] = 0.0
    g = e / (2.0 * (1.0 + nu))
    ka = e * a / ln
    kt = g * j / ln
    k[0, 0] = ka
    k[6, 6] = ka
    k[0, 6] = -ka
    k[6, 0] = -ka
    k[3, 3] = kt
    k[9, 9] = kt
    k[3, 9] = -kt
    k[9, 3] = -kt
    l2 = ln * ln
    l3 = l2 * ln
    # bending in the x-y plane (v, θz): E I_z
    c = e * iz
    idx = (1, 5, 7, 11)
    m = ((12.0 / l3, 6.0 / l2, -12.0 / l3, 6.0 / l2), (6.0 / l2, 4.0 / ln, -6.0 / l2, 2.0 / ln),
         (-12.0 / l3, -6.0 / l2, 12.0 / l3, -6.0 / l2), (6.0 / l2, 2.0 / ln, -6.0 / l2, 4.0 / ln))
    for p in range(4):
        for q in range(4):
            k[idx[p], idx[q]] = c * m[p][q]
    # bending in the x-z plane (w, θy): E I_y (θy = −dw/dx)
    c = e * iy
    idx = (2, 4, 8, 10)
    m = ((12.0 / l3, -6.0 / l2, -12.0 / l3, -6.0 / l2), (-6.0 / l2, 4.0 / ln, 6.0 / l2, 2.0 / ln),
         (-12.0 / l3, 6.0 / l2, 12.0 / l3, 6.0 / l2), (-6.0 / l2, 2.0 / ln, 6.0 / l2, 4.0 / ln))
    for p in range(4):
        for q in range(4):
            k[idx[p], idx[q]] = c * m[p][q]


@njit(cache=True)
def _sgn(x):
    return 1.0 if x > 0.0 else (-1.0 if x < 0.0 else 0.0)


@njit(cache=True)
def beam_step(dt, g, alpha, damp, safety,
              pos, vel, disp, rot, avel, mass, inert, rt, rr, host, hz, hvel, hpos, klt, klr, lf, lm, fix, fapp, mapp,
              force, moment, hforce, hmoment, imass, iinert,
              na, nb, l0, prop, axes, fl, bvel, bspin, bcen, last):
    """One step; ``last (n, 6)``: the last step's force and moment (combined damping); ``damp`` 0
    none, 1 local, 2 combined with ``alpha``; ``safety`` > 0: inertial mass and rotary inertia
    max(real, R (Δt / 2 safety)²), 0: the real ones. Returns the number of non-finite nodes."""
    n = pos.shape[0]
    s = na.shape[0]
    # --- nodes: links to the host blocks
    for i in range(n):
        for k in range(3):
            last[i, k] = force[i, k]
            last[i, 3 + k] = moment[i, k]
            force[i, k] = 0.0
            moment[i, k] = 0.0
            hforce[i, k] = 0.0
            hmoment[i, k] = 0.0
        h = host[i]
        if h < 0:
            continue
        if hz[i] != 0:
            # a zoned host: the node's link follows the host point (its zone's gridpoints), translation only
            for k in range(3):
                lf[i, k] -= klt[i] * (vel[i, k] - hvel[i, k]) * dt
                force[i, k] += lf[i, k]
                hforce[i, k] = -lf[i, k]
            continue
        r0 = hpos[i, 0] - bcen[h, 0] + bvel[h, 0] * dt
        r1 = hpos[i, 1] - bcen[h, 1] + bvel[h, 1] * dt
        r2 = hpos[i, 2] - bcen[h, 2] + bvel[h, 2] * dt
        w0, w1, w2 = bspin[h, 0], bspin[h, 1], bspin[h, 2]
        vh = (bvel[h, 0] + w1 * r2 - w2 * r1, bvel[h, 1] + w2 * r0 - w0 * r2, bvel[h, 2] + w0 * r1 - w1 * r0)
        for k in range(3):
            hpos[i, k] += vh[k] * dt
            lf[i, k] -= klt[i] * (vel[i, k] - vh[k]) * dt
            lm[i, k] -= klr[i] * (avel[i, k] - bspin[h, k]) * dt
            force[i, k] += lf[i, k]
            moment[i, k] += lm[i, k]
            hforce[i, k] = -lf[i, k]
        r0 = hpos[i, 0] - bcen[h, 0]
        r1 = hpos[i, 1] - bcen[h, 1]
        r2 = hpos[i, 2] - bcen[h, 2]
        hmoment[i, 0] = r1 * hforce[i, 2] - r2 * hforce[i, 1] - lm[i, 0]
        hmoment[i, 1] = r2 * hforce[i, 0] - r0 * hforce[i, 2] - lm[i, 1]
        hmoment[i, 2] = r0 * hforce[i, 1] - r1 * hforce[i, 0] - lm[i, 2]
    # --- elements: end forces K d in the element's axes, back to the nodes
    kk = np.empty((12, 12))
    dg = np.empty(12)
    dl = np.empty(12)
    for e in range(s):
        a = na[e]
        b = nb[e]
        for k in range(3):
            dg[k] = disp[a, k]
            dg[3 + k] = rot[a, k]
            dg[6 + k] = disp[b, k]
            dg[9 + k] = rot[b, k]
        for blk in range(4):
            for p in range(3):
                acc = 0.0
                for q in range(3):
                    acc += axes[e, p, q] * dg[3 * blk + q]
                dl[3 * blk + p] = acc
        local_stiffness(prop[e, B_E], prop[e, B_NU], prop[e, B_A], prop[e, B_IY], prop[e, B_IZ], prop[e, B_J],
                        l0[e], kk)
        for p in range(12):
            acc = 0.0
            for q in range(12):
                acc += kk[p, q] * dl[q]
            fl[e, p] = acc
        for k in range(3):
            fa = 0.0
            ma = 0.0
            fb = 0.0
            mb = 0.0
            for p in range(3):
                fa += axes[e, p, k] * fl[e, p]
                ma += axes[e, p, k] * fl[e, 3 + p]
                fb += axes[e, p, k] * fl[e, 6 + p]
                mb += axes[e, p, k] * fl[e, 9 + p]
            force[a, k] -= fa
            moment[a, k] -= ma
            force[b, k] -= fb
            moment[b, k] -= mb
    return move_nodes(dt, g, alpha, damp, safety, pos, vel, disp, rot, avel, mass, inert, rt, rr, fix, fapp, mapp,
                      force, moment, imass, iinert, last)


@njit(cache=True)
def move_nodes(dt, g, alpha, damp, safety, pos, vel, disp, rot, avel, mass, inert, rt, rr, fix, fapp, mapp,
               force, moment, imass, iinert, last):
    """The law of motion of structural nodes with 6 degrees of freedom (beams', liners'): central
    differences, gravity and ``fapp``/``mapp`` added to ``force``/``moment`` (which hold the internal
    and link forces and are left holding the unbalanced ones), local or combined damping (``last (n,
    6)``: the last step's), density-scaled degree of freedom by degree of freedom: ``rt, rr (n, 3)`` the
    Gershgorin row sums of the stiffness over each global translation and rotation, inertia
    max(real, R (Δt / 2 safety)²) on each (stable: Gershgorin's bound on M⁻¹K; a beam's three rows are
    equal, a shell is far stiffer in its plane than across it and one mass per node would make its
    bending crawl). ``imass``/``iinert`` get the largest of the three. Returns the count of non-finite
    or runaway (speed over ``VMAX``, the blocks' and gridpoints' limit) node components."""
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
