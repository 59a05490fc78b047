"""Unbalanced force and applied force magnitude of every moving body (for the equilibrium
measures of ``model solve``; definitions in ``dec3d.physics.rigid.RigidEngine.criteria``).

Per sub-contact s of contact c (blocks A = ca[c], B = cb[c], normal n = cn[c]) the force on B
is Fⁿ n + Fˢ and on A its negative (as ``jointlaw.subcontact_forces`` applies it). Per body g
(the blocks gmember[gstart[g]:gstart[g+1]]):
  unbalanced  |Σ (contact forces + m g + F_app)| with the components held (bits 0-2 of held[g]) left out,
  applied     Σ |each sub-contact force| + |m g| + |F_app| over its blocks.
"""
from __future__ import annotations

import math

from numba import njit


@njit(cache=True)
def body_balance(gravity, gstart, gmember, mass, fapp, held, ca, cb, cn, sc_contact, sc_fn, sc_fs,
                 fc, mag, unbal, applied):
    """fc (nb, 3) and mag (nb,) are scratch (zeroed here); unbal, applied (ng,) are filled [N]."""
    for b in range(fc.shape[0]):
        fc[b, 0] = 0.0
        fc[b, 1] = 0.0
        fc[b, 2] = 0.0
        mag[b] = 0.0
    for s in range(sc_contact.shape[0]):
        c = sc_contact[s]
        a = ca[c]
        b = cb[c]
        f0 = sc_fn[s] * cn[c, 0] + sc_fs[s, 0]
        f1 = sc_fn[s] * cn[c, 1] + sc_fs[s, 1]
        f2 = sc_fn[s] * cn[c, 2] + sc_fs[s, 2]
        fc[b, 0] += f0
        fc[b, 1] += f1
        fc[b, 2] += f2
        fc[a, 0] -= f0
        fc[a, 1] -= f1
        fc[a, 2] -= f2
        size = math.sqrt(f0 * f0 + f1 * f1 + f2 * f2)
        mag[a] += size
        mag[b] += size
    g0 = gravity[0]
    g1 = gravity[1]
    g2 = gravity[2]
    for g in range(gstart.shape[0] - 1):
        t0 = 0.0
        t1 = 0.0
        t2 = 0.0
        ap = 0.0
        for j in range(gstart[g], gstart[g + 1]):
            b = gmember[j]
            w0 = mass[b] * g0
            w1 = mass[b] * g1
            w2 = mass[b] * g2
            t0 += fc[b, 0] + w0 + fapp[b, 0]
            t1 += fc[b, 1] + w1 + fapp[b, 1]
            t2 += fc[b, 2] + w2 + fapp[b, 2]
            ap += (mag[b] + math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
                   + math.sqrt(fapp[b, 0] ** 2 + fapp[b, 1] ** 2 + fapp[b, 2] ** 2))
        h = held[g]
        if h & 1:
            t0 = 0.0
        if (h >> 1) & 1:
            t1 = 0.0
        if (h >> 2) & 1:
            t2 = 0.0
        unbal[g] = math.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
        applied[g] = ap
