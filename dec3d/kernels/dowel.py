"""One explicit step of the dowel shear springs of hybrid bolts (``physics.dowels``; equations there).

A dowel sits where a bolt crosses the contact between two blocks (side 0 = A, side 1 = B). Each step
it takes the relative velocity of B against A at its point, drops the part along the bolt's axis (the
cable carries that), and updates the shear force on B incrementally (F -= k_d Δu_s), held at the
yield force; once the accumulated shear displacement |u_s| reaches the rupture displacement the
dowel carries nothing from then on. Returns its force on B (A gets the opposite) and the moments of
both about their blocks' centroids. The tests hold a plain-Python twin (``tests/test_dowels.py``).

Arrays (d dowels): ``axis (d, 3)`` the bolt's unit axis (as created: the cable's nodes are free
across it, so its elements' present directions are no guide); ``blk (d, 2)`` block rows of the two
sides; ``hz (d, 2)`` 1 where a side is a zoned block, whose point velocity ``hvel (d, 2, 3)`` the
caller gives; ``pos (d, 3)`` the dowel point (moved on with the mean motion of its sides);
``prop (d, 3)`` stiffness [N/m], yield force [N, 0: no limit], rupture displacement [m, 0: none];
``fs (d, 3)`` shear force on B [N]; ``us (d, 3)`` accumulated relative shear displacement of B
against A [m]; ``state (d,)`` bits 1 yielding now, 2 yielded in the past, 4 ruptured.
Out: ``moment (d, 2, 3)`` moments of −F (on A) and F (on B) about the blocks' centroids (rigid
sides; 0 on zoned ones).
"""
from __future__ import annotations

import math

from numba import njit

#: ``prop`` columns
D_K, D_Y, D_R = 0, 1, 2
NDPROP = 3
#: ``state`` bits
DS_YIELD, DS_YPAST, DS_RUPT = 1, 2, 4


@njit(cache=True)
def _side_velocity(i, s, dt, blk, hz, hvel, pos, bvel, bspin, bcen):
    h = blk[i, s]
    if hz[i, s] != 0:
        return hvel[i, s, 0], hvel[i, s, 1], hvel[i, s, 2]
    # the block's centroid one step ago (the motion kernel moved it on by v dt since)
    r0 = pos[i, 0] - bcen[h, 0] + bvel[h, 0] * dt
    r1 = pos[i, 1] - bcen[h, 1] + bvel[h, 1] * dt
    r2 = pos[i, 2] - bcen[h, 2] + bvel[h, 2] * dt
    w0, w1, w2 = bspin[h, 0], bspin[h, 1], bspin[h, 2]
    return bvel[h, 0] + w1 * r2 - w2 * r1, bvel[h, 1] + w2 * r0 - w0 * r2, bvel[h, 2] + w0 * r1 - w1 * r0


@njit(cache=True)
def dowel_step(dt, axis, blk, hz, hvel, pos, prop, fs, us, state, moment, bvel, bspin, bcen):
    d = axis.shape[0]
    for i in range(d):
        t0, t1, t2 = axis[i, 0], axis[i, 1], axis[i, 2]
        # velocity of each side at the dowel point
        va0, va1, va2 = _side_velocity(i, 0, dt, blk, hz, hvel, pos, bvel, bspin, bcen)
        vb0, vb1, vb2 = _side_velocity(i, 1, dt, blk, hz, hvel, pos, bvel, bspin, bcen)
        pos[i, 0] += 0.5 * (va0 + vb0) * dt
        pos[i, 1] += 0.5 * (va1 + vb1) * dt
        pos[i, 2] += 0.5 * (va2 + vb2) * dt
        dv0 = vb0 - va0
        dv1 = vb1 - va1
        dv2 = vb2 - va2
        ax = dv0 * t0 + dv1 * t1 + dv2 * t2
        du0 = (dv0 - ax * t0) * dt
        du1 = (dv1 - ax * t1) * dt
        du2 = (dv2 - ax * t2) * dt
        us[i, 0] += du0
        us[i, 1] += du1
        us[i, 2] += du2
        st = state[i] & (DS_YPAST | DS_RUPT)
        if st & DS_RUPT:
            fs[i, 0] = 0.0
            fs[i, 1] = 0.0
            fs[i, 2] = 0.0
        else:
            kd = prop[i, D_K]
            f0 = fs[i, 0] - kd * du0
            f1 = fs[i, 1] - kd * du1
            f2 = fs[i, 2] - kd * du2
            fa = f0 * t0 + f1 * t1 + f2 * t2          # (keep the force across the present axis)
            f0 -= fa * t0
            f1 -= fa * t1
            f2 -= fa * t2
            fy = prop[i, D_Y]
            fm = math.sqrt(f0 * f0 + f1 * f1 + f2 * f2)
            if fy > 0.0 and fm > fy:
                c = fy / fm
                f0 *= c
                f1 *= c
                f2 *= c
                st |= DS_YIELD | DS_YPAST
            ur = prop[i, D_R]
            if ur > 0.0 and math.sqrt(us[i, 0] ** 2 + us[i, 1] ** 2 + us[i, 2] ** 2) >= ur:
                f0 = 0.0
                f1 = 0.0
                f2 = 0.0
                st = (st & DS_YPAST) | DS_RUPT
            fs[i, 0] = f0
            fs[i, 1] = f1
            fs[i, 2] = f2
        state[i] = st
        for s in range(2):
            h = blk[i, s]
            sg = -1.0 if s == 0 else 1.0
            if hz[i, s] != 0:
                moment[i, s, 0] = 0.0
                moment[i, s, 1] = 0.0
                moment[i, s, 2] = 0.0
                continue
            r0 = pos[i, 0] - bcen[h, 0]
            r1 = pos[i, 1] - bcen[h, 1]
            r2 = pos[i, 2] - bcen[h, 2]
            g0, g1, g2 = sg * fs[i, 0], sg * fs[i, 1], sg * fs[i, 2]
            moment[i, s, 0] = r1 * g2 - r2 * g1
            moment[i, s, 1] = r2 * g0 - r0 * g2
            moment[i, s, 2] = r0 * g1 - r1 * g0
