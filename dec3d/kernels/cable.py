"""One explicit step of the grouted cables (``physics.cables``; equations in its docstring).

``cable_step`` makes one pass over the nodes (host-point motion, relative displacement), one over
the segments (axial force, grout force at both ends) and one over the nodes (law of motion), and
returns the forces the grout puts on the host blocks. The tests hold a plain-Python twin
(``tests/test_cables.py``) written from the formulas.

Arrays (n nodes, s segments):

- nodes: ``pos, vel, disp (n, 3)`` [m, m/s, m]; ``mass (n,)`` [kg, real]; ``host (n,)`` block row or
  -1; ``hpos (n, 3)`` the host point (the material point of the host block where the node sits);
  ``fix (n,)`` bits 0-2 held velocity components; ``fapp (n, 3)`` applied force [N]; ``conf (n,)``
  confining stress around the node [Pa, compression positive]; ``hz (n,)`` 1 where the host is a zoned
  block, whose host-point velocity ``hvel (n, 3)`` the caller gives (the kernel then leaves ``hpos`` and
  the moment alone). Out: ``force (n, 3)`` unbalanced
  force, ``hforce, hmoment (n, 3)`` force on the host block and its moment about the block's
  centroid, ``imass (n,)`` inertial mass used.
- segments: ``na, nb (s,)`` node rows; ``l0`` reference length; ``lcur`` length at the last step
  (updated); ``prop (s, NPROP)`` columns below; ``fa (s,)`` axial force (+ tension, updated);
  ``gf (s, 2)`` grout force at the a and b ends along the segment axis, on the cable (updated);
  ``state (s,)`` bits: 1 yield in tension now, 2 in compression now, 4 grout slipping now,
  8 yielded in the past, 16 grout slipped in the past, 32 ruptured (the element's axial strain
  (L − l0) / l0 went past ``prop[:, C_RUP]`` (> 0) once: from that step on it carries no axial and no
  grout force and adds no stiffness); ``tapp (s,)`` applied tension; ``tact (s,)``
  1 where it is active.
- blocks: ``bvel, bspin, bcen (nb, 3)``.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

#: property columns of a segment (``physics.cables.PROPS`` names them)
C_E, C_A, C_YT, C_YC, C_KG, C_CG, C_FG, C_PG, C_RHO, C_RUP = range(10)
NPROP = 10

#: ``state`` bits
S_YT, S_YC, S_SLIP, S_YPAST, S_SLIPPAST, S_RUPT = 1, 2, 4, 8, 16, 32


@njit(cache=True)
def _sgn(x):
    return 1.0 if x > 0.0 else (-1.0 if x < 0.0 else 0.0)


@njit(cache=True)
def cable_step(dt, g, alpha, damp, safety,
               pos, vel, disp, mass, host, hpos, fix, fapp, conf, force, hforce, hmoment, imass, hz, hvel,
               na, nb, l0, lcur, prop, fa, gf, state, tapp, tact,
               bvel, bspin, bcen, scratch):
    """One step; ``scratch (n, 13)``: work space (relative displacement, stiffness row sum, last force,
    host-point velocity, cable direction at the node);
    ``damp``: 0 none, 1 local, 2 combined damping with coefficient ``alpha``; ``safety`` > 0: inertial
    masses max(m, R (Δt / 2 safety)²) (density scaling), 0: the real masses.
    Returns the number of nodes that are not finite after the step (0: all well)."""
    n = pos.shape[0]
    s = na.shape[0]
    # --- pass 1, nodes: host point motion over the last step, relative displacement of the node
    for i in range(n):
        for k in range(3):
            scratch[i, 4 + k] = force[i, k]      # the last step's force (combined damping)
            force[i, k] = 0.0
            hforce[i, k] = 0.0
            scratch[i, k] = 0.0
        scratch[i, 3] = 0.0          # Gershgorin row sum of the stiffness at the node [N/m]
        for k in range(6):
            scratch[i, 7 + k] = 0.0  # host-point velocity, cable direction at the node (pass 2)
        h = host[i]
        if h >= 0 and hz[i] != 0:
            # a zoned host: the host point's velocity is given (from its zone's gridpoints)
            scratch[i, 0] = (vel[i, 0] - hvel[i, 0]) * dt
            scratch[i, 1] = (vel[i, 1] - hvel[i, 1]) * dt
            scratch[i, 2] = (vel[i, 2] - hvel[i, 2]) * dt
            for k in range(3):
                scratch[i, 7 + k] = hvel[i, k]
        elif h >= 0:
            # the block's centroid one step ago (the motion kernel moved it on by v dt since)
            r0 = hpos[i, 0] - bcen[h, 0] + bvel[h, 0] * dt
            r1 = hpos[i, 1] - bcen[h, 1] + bvel[h, 1] * dt
            r2 = hpos[i, 2] - bcen[h, 2] + bvel[h, 2] * dt
            w0, w1, w2 = bspin[h, 0], bspin[h, 1], bspin[h, 2]
            vh0 = bvel[h, 0] + w1 * r2 - w2 * r1
            vh1 = bvel[h, 1] + w2 * r0 - w0 * r2
            vh2 = bvel[h, 2] + w0 * r1 - w1 * r0
            hpos[i, 0] += vh0 * dt
            hpos[i, 1] += vh1 * dt
            hpos[i, 2] += vh2 * dt
            scratch[i, 0] = (vel[i, 0] - vh0) * dt
            scratch[i, 1] = (vel[i, 1] - vh1) * dt
            scratch[i, 2] = (vel[i, 2] - vh2) * dt
            scratch[i, 7] = vh0
            scratch[i, 8] = vh1
            scratch[i, 9] = vh2
    # --- pass 2, segments: axial force (elastic, perfectly plastic), grout at both ends
    for e in range(s):
        a = na[e]
        b = nb[e]
        d0 = pos[b, 0] - pos[a, 0]
        d1 = pos[b, 1] - pos[a, 1]
        d2 = pos[b, 2] - pos[a, 2]
        length = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        t0, t1, t2 = d0 / length, d1 / length, d2 / length
        ka = prop[e, C_E] * prop[e, C_A] / l0[e]
        st = state[e] & (S_YPAST | S_SLIPPAST | S_RUPT)
        # the cable's direction at its nodes (summed here, scaled in pass 3)
        scratch[a, 10] += t0
        scratch[a, 11] += t1
        scratch[a, 12] += t2
        scratch[b, 10] += t0
        scratch[b, 11] += t1
        scratch[b, 12] += t2
        dl = length - lcur[e]
        lcur[e] = length
        rup = prop[e, C_RUP]
        if (st & S_RUPT) != 0 or (rup > 0.0 and length - l0[e] > rup * l0[e]):
            # ruptured (now or before): the element is broken, it carries nothing from now on
            fa[e] = 0.0
            gf[e, 0] = 0.0
            gf[e, 1] = 0.0
            state[e] = st | S_RUPT
            continue
        if tact[e] != 0:
            fa[e] = tapp[e]
        else:
            fa[e] += ka * dl
            yt = prop[e, C_YT]
            yc = prop[e, C_YC]
            if yt > 0.0 and fa[e] > yt:
                fa[e] = yt
                st |= S_YT | S_YPAST
            elif yc > 0.0 and fa[e] < -yc:
                fa[e] = -yc
                st |= S_YC | S_YPAST
        f = fa[e]
        force[a, 0] += f * t0
        force[a, 1] += f * t1
        force[a, 2] += f * t2
        force[b, 0] -= f * t0
        force[b, 1] -= f * t1
        force[b, 2] -= f * t2
        kg = prop[e, C_KG]
        half = 0.5 * l0[e]
        scratch[a, 3] += 2.0 * ka
        scratch[b, 3] += 2.0 * ka
        for end in range(2):
            i = a if end == 0 else b
            if host[i] < 0 or kg <= 0.0:
                gf[e, end] = 0.0
                continue
            scratch[i, 3] += kg * half
            du = scratch[i, 0] * t0 + scratch[i, 1] * t1 + scratch[i, 2] * t2
            fg = gf[e, end] - kg * half * du
            cap = (prop[e, C_CG] + max(conf[i], 0.0) * math.tan(prop[e, C_FG]) * prop[e, C_PG]) * half
            if fg > cap:
                fg = cap
                st |= S_SLIP | S_SLIPPAST
            elif fg < -cap:
                fg = -cap
                st |= S_SLIP | S_SLIPPAST
            gf[e, end] = fg
            force[i, 0] += fg * t0
            force[i, 1] += fg * t1
            force[i, 2] += fg * t2
            hforce[i, 0] -= fg * t0
            hforce[i, 1] -= fg * t1
            hforce[i, 2] -= fg * t2
        state[e] = st
    # --- pass 3, nodes: law of motion (local damping when ``damp``), moment on the host
    bad = 0
    q = (dt / (2.0 * safety)) ** 2 if safety > 0.0 else 0.0
    for i in range(n):
        m = mass[i]
        mi = max(m, scratch[i, 3] * q) if safety > 0.0 else m
        if mi <= 0.0:
            mi = 1.0
        imass[i] = mi
        for k in range(3):
            force[i, k] += fapp[i, k] + m * g[k]
        h = host[i]
        tn = math.sqrt(scratch[i, 10] ** 2 + scratch[i, 11] ** 2 + scratch[i, 12] ** 2)
        if h >= 0 and fix[i] == 0 and tn > 0.0:
            # across the cable the node is linked rigidly to its host (only the axial direction has the
            # grout's spring): it moves with the host point there, and the host takes the force across
            _linked(i, dt, alpha, damp, mi, scratch[i, 10] / tn, scratch[i, 11] / tn, scratch[i, 12] / tn,
                    vel, force, hforce, scratch)
            for k in range(3):
                pos[i, k] += vel[i, k] * dt
                disp[i, k] += vel[i, k] * dt
                if not math.isfinite(pos[i, k]):
                    bad += 1
            _moment(i, h, hz, hpos, bcen, hforce, hmoment)
            continue
        for k in range(3):
            fk = force[i, k]
            if (fix[i] >> k) & 1:
                continue
            v = vel[i, k]
            if damp == 1:        # local damping (3DEC theory Eq. 79): −α |F| sgn(v)
                fk -= alpha * abs(fk) * _sgn(v)
            elif damp == 2:      # combined damping (Eq. 83): −α |F| (sgn(v) − sgn(ΔF)) / 2
                fk -= 0.5 * alpha * abs(fk) * (_sgn(v) - _sgn(fk - scratch[i, 4 + k]))
            v += fk / mi * dt
            vel[i, k] = v
        for k in range(3):
            pos[i, k] += vel[i, k] * dt
            disp[i, k] += vel[i, k] * dt
            if not math.isfinite(pos[i, k]):
                bad += 1
        _moment(i, h, hz, hpos, bcen, hforce, hmoment)
    return bad


@njit(cache=True)
def _linked(i, dt, alpha, damp, mi, t0, t1, t2, vel, force, hforce, scratch):
    """A node linked to its host across the cable (direction t): the force across goes to the host,
    the velocity across is the host point's, the velocity along follows the force along (damped as
    the free nodes are, on that component)."""
    fa = force[i, 0] * t0 + force[i, 1] * t1 + force[i, 2] * t2
    fprev = scratch[i, 4] * t0 + scratch[i, 5] * t1 + scratch[i, 6] * t2
    va = vel[i, 0] * t0 + vel[i, 1] * t1 + vel[i, 2] * t2
    vh0, vh1, vh2 = scratch[i, 7], scratch[i, 8], scratch[i, 9]
    vha = vh0 * t0 + vh1 * t1 + vh2 * t2
    f = fa
    if damp == 1:
        f -= alpha * abs(fa) * _sgn(va)
    elif damp == 2:
        f -= 0.5 * alpha * abs(fa) * (_sgn(va) - _sgn(fa - fprev))
    va += f / mi * dt
    for k in range(3):
        tk = t0 if k == 0 else (t1 if k == 1 else t2)
        vhk = vh0 if k == 0 else (vh1 if k == 1 else vh2)
        hforce[i, k] += force[i, k] - fa * tk        # the force across the cable, onto the host
        force[i, k] = fa * tk                        # the node's unbalanced force: along the cable
        vel[i, k] = va * tk + (vhk - vha * tk)


@njit(cache=True)
def _moment(i, h, hz, hpos, bcen, hforce, hmoment):
    """The moment about a rigid host's centroid of the force the node puts on it."""
    if h >= 0 and hz[i] == 0:
        r0 = hpos[i, 0] - bcen[h, 0]
        r1 = hpos[i, 1] - bcen[h, 1]
        r2 = hpos[i, 2] - bcen[h, 2]
        f0, f1, f2 = hforce[i, 0], hforce[i, 1], hforce[i, 2]
        hmoment[i, 0] = r1 * f2 - r2 * f1
        hmoment[i, 1] = r2 * f0 - r0 * f2
        hmoment[i, 2] = r0 * f1 - r1 * f0
    else:
        hmoment[i, 0] = 0.0
        hmoment[i, 1] = 0.0
        hmoment[i, 2] = 0.0


def empty_scratch(n: int) -> np.ndarray:
    return np.zeros((n, 13))
