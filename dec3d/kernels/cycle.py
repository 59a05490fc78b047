"""Many mechanical steps in one call (3DEC theory, Fig. 13: the calculation cycle).

Per step, with the contacts and sub-contacts fixed between two detection passes:
  1. sub-contact relative velocities → displacement increments → joint law → forces
     (``jointlaw.subcontact_update``, in parallel over sub-contacts), then the forces and
     moments on every block summed in a fixed order (``jointlaw.block_sums``, in parallel
     over blocks);
  2. motion of every group of joined blocks (a lone block is a group of one), Eqs. (44)-(52)
     with damping and Euler's equations as chosen (``motion.rigid_motion_groups``, in parallel
     over groups);
  3. the contact reference points and the sub-contact points move with the mean
     displacement of the two blocks at that point, Eq. (11) (rotation included).
The host (``dec3d.physics.rigid``) calls this between detection passes, histories and
solve checks, so Python runs once per batch, not once per step.

Threads: every parallel loop writes only its own items' rows and every sum is taken in a fixed
order (never an atomic or a shared accumulator), so the results are bit-identical whatever the
number of threads (``dec3d.config.set_threads``), and equal to those of one serial loop.
"""
from __future__ import annotations

import math

import numpy as np
from numba import get_num_threads, njit, prange

from .jointlaw import block_lists, block_sums, subcontact_update
from .motion import rigid_motion_groups
from .rayleigh import contact_stiffness_damping


#: a model with less work per step than this (sub-contacts + 4 × bodies) runs the serial twin of
#: the kernel (``_run_steps_1``): each parallel loop costs a wake-up of the other threads
#: (microseconds on a quiet machine, up to a scheduler time slice on a busy one), more than a
#: small model's whole step
SERIAL_BELOW = 4000


@njit(cache=True, parallel=True)
def _move_points(dt, ca, cb, owner, pts, centroid, vel, spin):
    """Eq. (11) for points pts (k, 3) of contacts owner (k,), in place, without scratch
    (in parallel: each point is its own)."""
    for i in prange(pts.shape[0]):
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
def _run_steps(nsteps, dt, gravity, full_inertia, beta, damping, groups, bodies, contacts, subs, bounds, vmax, out):
    """Take up to ``nsteps`` steps of Δt = dt [s]. Bundles (``kernels.bundles``): damping, groups,
    bodies as ``rigid_motion_groups`` takes them; contacts (``Contacts``: pos (nc, 3) the contact
    reference points, own (nc,) = arange(nc)) and subs (``SubContacts``) as
    ``jointlaw.subcontact_update`` reads them; bounds (``Bounds``) the detection trigger.

    out (4,): as ``rigid_motion_groups`` fills it, for the last step.
    Motion bound for contact detection: each block's step motion |v| Δt + |ω| Δt r (bounds.radius
    (nb,) m: largest centroid-to-vertex distance) is added to bounds.acc (nb,) [m]; the batch ends
    after the step in which some acc exceeds ``bounds.trigger`` [m] (the host then detects again).
    bounds.motion (2,): [0] the largest step motion of any block [m] (kept across calls: max),
    [1] 1.0 if the batch ended on the trigger, 2.0 if a block moved farther than its radius
    in one step (then returned as unstable: it can pass through other blocks unseen).
    beta [s]: the stiffness-proportional term of Rayleigh damping on the sub-contacts (0: none;
    ``rayleigh.contact_stiffness_damping``).
    Returns (steps done, first unstable block row or −1). An unstable step is not finished:
    the caller reports it and the arrays hold the state at that step.
    """
    gstart, gmember = groups.start, groups.member
    centroid, vel, spin, force, moment = bodies.centroid, bodies.vel, bodies.spin, bodies.force, bodies.moment
    ca, cb, cn, cc, cown, cmodel, cprop = contacts
    sc_contact, sc_pos, sc_area, sc_fn, sc_fs, sc_un, sc_udil, sc_us, sc_state = subs
    radius, acc, trigger, motion = bounds
    done = 0
    bad = -1
    motion[1] = 0.0
    # the sub-contacts of every block in a fixed order, for the forces' fixed-order sums
    bstart, bent = block_lists(centroid.shape[0], ca, cb, sc_contact)
    sg = np.empty((sc_contact.shape[0], 3))
    for _ in range(nsteps):
        subcontact_update(dt, centroid, vel, spin, ca, cb, cn, cmodel, cprop,
                          sc_contact, sc_pos, sc_area, sc_fn, sc_fs, sc_un, sc_udil, sc_us, sc_state, sg)
        if beta > 0.0:
            contact_stiffness_damping(beta, centroid, vel, spin, ca, cb, cn, cprop, sc_contact, sc_pos, sc_area,
                                      sc_fn, sc_state, sg)
        block_sums(centroid, force, moment, sc_pos, sg, bstart, bent)
        g = rigid_motion_groups(dt, gravity, full_inertia, damping, groups, bodies, vmax, out)
        done += 1
        if g >= 0 or not math.isfinite(out[0]):
            bad = gmember[gstart[g]] if g >= 0 else (gmember[0] if gmember.shape[0] else 0)
            break
        _move_points(dt, ca, cb, cown, cc, centroid, vel, spin)
        _move_points(dt, ca, cb, sc_contact, sc_pos, centroid, vel, spin)
        hit = False
        for k in range(gmember.shape[0]):
            b = gmember[k]
            d = dt * (math.sqrt(vel[b, 0] ** 2 + vel[b, 1] ** 2 + vel[b, 2] ** 2)
                      + radius[b] * math.sqrt(spin[b, 0] ** 2 + spin[b, 1] ** 2 + spin[b, 2] ** 2))
            if d > motion[0]:
                motion[0] = d
            if d > radius[b] and bad < 0:
                bad = b                 # farther than its own size in one step: contacts are lost
            acc[b] += d
            if acc[b] > trigger:
                hit = True
        if bad >= 0:
            motion[1] = 2.0
            break
        if hit:
            motion[1] = 1.0
            break
    return done, bad


def run_steps(nsteps, dt, gravity, full_inertia, damping, groups, bodies, contacts, subs, bounds, vmax, out,
              beta=0.0):
    """``_run_steps`` (the kernel, documented there); a small model (``SERIAL_BELOW``), or any
    model on one thread, runs its serial twin ``_run_steps_1`` (the same numbers: every sum has a
    fixed order)."""
    args = (nsteps, dt, gravity, bool(full_inertia), float(beta), damping, groups, bodies, contacts, subs,
            bounds, vmax, out)
    if subs.contact.shape[0] + 4 * groups.member.shape[0] >= SERIAL_BELOW and get_num_threads() > 1:
        return _run_steps(*args)
    return _run_steps_1(*args)


def _serial_twin(kernel, name, **swap):
    """The same kernel compiled without ``parallel`` (its ``prange`` loops run as ``range``), under
    its own name (so numba caches it in its own file); ``swap`` replaces globals it calls."""
    f = getattr(kernel, "py_func", kernel)         # (a plain function when the JIT is disabled)
    glb = dict(f.__globals__, **swap) if swap else f.__globals__
    g = type(f)(f.__code__, glb, name, f.__defaults__, f.__closure__)      # (a FunctionType)
    g.__qualname__ = name
    g.__module__ = f.__module__
    g.__doc__ = f"``{f.__name__}`` on one thread, without parallel loops."
    return njit(cache=True)(g)


# a small model's steps: no parallel loop at all. Waking the other threads costs more than such a
# step (on a busy machine up to a scheduler time slice per loop; even a one-thread parallel loop
# hands its work to a worker thread of numba's workqueue)
_run_steps_1 = _serial_twin(
    _run_steps, "_run_steps_1",
    subcontact_update=_serial_twin(subcontact_update, "_subcontact_update_1"),
    block_sums=_serial_twin(block_sums, "_block_sums_1"),
    rigid_motion_groups=_serial_twin(rigid_motion_groups, "_rigid_motion_groups_1"),
    _move_points=_serial_twin(_move_points, "_move_points_1"),
    contact_stiffness_damping=_serial_twin(contact_stiffness_damping, "_contact_stiffness_damping_1"))
