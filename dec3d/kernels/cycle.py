"""Many mechanical steps in one call (3DEC theory, Fig. 13: the calculation cycle).

Per step, with the contacts and sub-contacts fixed between two detection passes:
  1. sub-contact relative velocities → displacement increments → joint law → forces and
     moments on the blocks (``jointlaw.subcontact_forces``);
  2. block motion, Eqs. (44)-(52) (``motion.rigid_motion``);
  3. the contact reference points and the sub-contact points move with the mean
     displacement of the two blocks at that point, Eq. (11) (rotation included).
The host (``dec3d.physics.rigid``) calls this between detection passes, histories and
solve checks, so Python runs once per batch, not once per step.
"""
from __future__ import annotations

import math

from numba import njit

from .jointlaw import subcontact_forces
from .motion import rigid_motion


@njit(cache=True)
def follow(dt, side, owner, pts, centroid, vel, spin, disp_out):
    """Displacement [m] over the last step of the point pts[i] carried by block side[owner[i]]:
    v Δt + ω Δt × (x − c_old), with c_old = c − v Δt (velocities at the half step).
    Adds half of it to disp_out (Eq. 11 takes the mean of the two blocks)."""
    for i in range(pts.shape[0]):
        b = side[owner[i]]
        r0 = pts[i, 0] - centroid[b, 0] + vel[b, 0] * dt
        r1 = pts[i, 1] - centroid[b, 1] + vel[b, 1] * dt
        r2 = pts[i, 2] - centroid[b, 2] + vel[b, 2] * dt
        w0 = spin[b, 0] * dt
        w1 = spin[b, 1] * dt
        w2 = spin[b, 2] * dt
        disp_out[i, 0] += 0.5 * (vel[b, 0] * dt + w1 * r2 - w2 * r1)
        disp_out[i, 1] += 0.5 * (vel[b, 1] * dt + w2 * r0 - w0 * r2)
        disp_out[i, 2] += 0.5 * (vel[b, 2] * dt + w0 * r1 - w1 * r0)


@njit(cache=True)
def _move_points(dt, ca, cb, owner, pts, centroid, vel, spin):
    """Eq. (11) for points pts (k, 3) of contacts owner (k,), in place, without scratch."""
    for i in range(pts.shape[0]):
        c = owner[i]
        d0 = 0.0
        d1 = 0.0
        d2 = 0.0
        for side in range(2):
            b = ca[c] if side == 0 else cb[c]
            r0 = pts[i, 0] - centroid[b, 0] + vel[b, 0] * dt
            r1 = pts[i, 1] - centroid[b, 1] + vel[b, 1] * dt
            r2 = pts[i, 2] - centroid[b, 2] + vel[b, 2] * dt
            w0 = spin[b, 0] * dt
            w1 = spin[b, 1] * dt
            w2 = spin[b, 2] * dt
            d0 += vel[b, 0] * dt + w1 * r2 - w2 * r1
            d1 += vel[b, 1] * dt + w2 * r0 - w0 * r2
            d2 += vel[b, 2] * dt + w0 * r1 - w1 * r0
        pts[i, 0] += 0.5 * d0
        pts[i, 1] += 0.5 * d1
        pts[i, 2] += 0.5 * d2


@njit(cache=True)
def run_steps(nsteps, dt, gravity, alpha_local, alpha_visc, rows, mass, imass, iinert, fixity,
              force, moment, fapp, mapp, vel, spin, centroid, disp, vstart, vcount, vpos,
              ca, cb, cn, cc, cown, cmodel, cprop,
              sc_contact, sc_pos, sc_area, sc_fn, sc_fs, sc_un, sc_udil, sc_us, sc_state,
              vmax, out):
    """Take up to ``nsteps`` steps of Δt = dt [s]; arrays as in ``subcontact_forces`` and
    ``rigid_motion`` (cc (nc, 3) contact reference points, cown (nc,) = arange(nc)).

    out (2,): the largest unbalanced force [N] and the sum of |m g| + |F| [N] of the last step.
    Returns (steps done, first unstable block row or −1). An unstable step is not finished:
    the caller reports it and the arrays hold the state at that step.
    """
    done = 0
    bad = -1
    for _ in range(nsteps):
        subcontact_forces(dt, centroid, vel, spin, force, moment, ca, cb, cn, cmodel, cprop,
                          sc_contact, sc_pos, sc_area, sc_fn, sc_fs, sc_un, sc_udil, sc_us, sc_state)
        bad, fmax, fsum = rigid_motion(dt, gravity, alpha_local, alpha_visc, rows, mass, imass, iinert,
                                       fixity, force, moment, fapp, mapp, vel, spin, centroid, disp,
                                       vstart, vcount, vpos, vmax)
        done += 1
        out[0] = fmax
        out[1] = fsum
        if bad >= 0 or not math.isfinite(fmax):
            if bad < 0:
                bad = rows[0] if rows.shape[0] else 0
            break
        _move_points(dt, ca, cb, cown, cc, centroid, vel, spin)
        _move_points(dt, ca, cb, sc_contact, sc_pos, centroid, vel, spin)
    return done, bad
