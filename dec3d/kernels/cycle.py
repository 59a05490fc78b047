"""Many mechanical steps in one call (3DEC theory, Fig. 13: the calculation cycle).

Per step, with the contacts and sub-contacts fixed between two detection passes:
  1. sub-contact relative velocities → displacement increments → joint law → forces
     (``jointlaw.update_one``, in parallel over contacts, each doing its own sub-contacts:
     ``_contact_pass``);
  2. the forces and moments on every block summed in a fixed order (``jointlaw.block_sum``), then
     the motion of every group of joined blocks (a lone block is a group of one), Eqs. (44)-(52)
     with damping and Euler's equations as chosen (``motion.rigid_motion_groups``, in parallel
     over groups, the sums of a group's members inside its own iteration);
  3. the contact reference points and the sub-contact points move with the mean
     displacement of the two blocks at that point, Eq. (11) (rotation included) — done at the
     start of the next step's loop over contacts (the same numbers: nothing moves in between),
     and once more at the end of the call.
So a step wakes the threads twice (each parallel loop costs a fork and a join, and every pass
over the sub-contact arrays streams them from memory: on a large model the step is bound by
memory traffic, not arithmetic).
The host (``dec3d.physics.rigid``) calls this between detection passes, histories and
solve checks, so Python runs once per batch, not once per step.

Threads: every parallel loop writes only its own items' rows and every sum is taken in a fixed
order (never an atomic or a shared accumulator), so the results are bit-identical whatever the
number of threads (``dec3d.config.set_threads``), and equal to those of one serial loop.
"""
from __future__ import annotations

import math

import numpy as np
from numba import get_num_threads, literally, njit, prange
from numba.core.cpu import ParallelOptions

from dec3d.config import threading_layer

from .bundles import Fused
from .joints import cycle_mask
from .jointlaw import block_lists, block_sum, update_one
from .motion import rigid_motion_groups
from .rayleigh import contact_stiffness_damping
from .water import any_pressure, pore_forces


#: a model with less work per step than this (sub-contacts + 4 × bodies) runs the serial twin of
#: the kernel (``_run_steps_1``); None: the threshold of the threading layer in use
#: (``SERIAL_BY_LAYER``, ``serial_below``)
SERIAL_BELOW = None
#: each parallel loop costs a start of the other threads. Measured on the 2-core VM of
#: bench/README.md: with numba's workqueue (idle workers sleep and are woken for every loop) the two
#: loops of a step cost about 0.28 ms more than the serial twin: the 10-layer cube stack (34 000
#: units, 0.69 ms a step serial) ran 0.64 ms a step on two threads in the kernel alone and slower in
#: a run; the 20-layer one (287 000) 1.9 times faster. With GNU OpenMP (idle workers spin a moment)
#: two threads already win at 4 × 4 × 4 cubes (1 000 units: 0.030 against 0.042 ms a step), tie at
#: 3 × 3 × 3 (400 units) and lose at 2 × 2 × 2; the 10-layer stack runs 0.48 against 0.79 ms a step
SERIAL_BY_LAYER = {"omp": 1000, "workqueue": 60000}


def serial_below() -> int:
    """``SERIAL_BELOW``, or when None the threshold of numba's threading layer (started here if no
    parallel kernel has run yet; a layer not in ``SERIAL_BY_LAYER`` takes the workqueue's)."""
    if SERIAL_BELOW is not None:
        return SERIAL_BELOW
    layer = threading_layer()
    if layer == "not started yet":          # (an empty parallel loop starts it; with numba's JIT off
        none = np.zeros(0, np.int64)        # nothing does, and the workqueue's threshold is taken)
        _move_points(0.0, none, none, none, np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3)),
                     np.zeros((0, 3)))
        layer = threading_layer()
    return SERIAL_BY_LAYER.get(layer, SERIAL_BY_LAYER["workqueue"])


@njit(cache=True, inline="always")
def _move_point(dt, a, b, pts, i, centroid, vel, spin):
    """Eq. (11) for point pts[i] between blocks a and b, in place."""
    d0 = 0.0
    d1 = 0.0
    d2 = 0.0
    for side in range(2):
        x = a if side == 0 else b
        r0 = pts[i, 0] - centroid[x, 0] + vel[x, 0] * dt
        r1 = pts[i, 1] - centroid[x, 1] + vel[x, 1] * dt
        r2 = pts[i, 2] - centroid[x, 2] + vel[x, 2] * dt
        w0 = spin[x, 0] * dt
        w1 = spin[x, 1] * dt
        w2 = spin[x, 2] * dt
        d0 += vel[x, 0] * dt + w1 * r2 - w2 * r1
        d1 += vel[x, 1] * dt + w2 * r0 - w0 * r2
        d2 += vel[x, 2] * dt + w0 * r1 - w1 * r0
    pts[i, 0] += 0.5 * d0
    pts[i, 1] += 0.5 * d1
    pts[i, 2] += 0.5 * d2


@njit(cache=True, parallel=True)
def _move_points(dt, ca, cb, owner, pts, centroid, vel, spin):
    """Eq. (11) for points pts (k, 3) of contacts owner (k,), in place, without scratch
    (in parallel: each point is its own)."""
    for i in prange(pts.shape[0]):
        c = owner[i]
        _move_point(dt, ca[c], cb[c], pts, i, centroid, vel, spin)


@njit(cache=True, parallel=True)
def _contact_pass(models, move, dt, centroid, vel, spin, ca, cb, cn, cc, cmodel, cprop, cstart,
                  sc_pos, sc_area, sc_fn, sc_fs, sc_un, sc_udil, sc_us, sc_state, sc_hist, sg):
    """One parallel loop over the contacts: when ``move``, first Eq. (11) for the contact point and
    the sub-contact points (the motion of the step before), then the joint law of each sub-contact
    (``jointlaw.update_one``; force on B to sg). The sub-contacts of contact c are rows
    cstart[c]:cstart[c + 1] (``contact_ranges``). Each contact writes only its own rows. ``models``:
    the mask of the joint models (a literal: ``_run_steps``)."""
    literally(models)
    for c in prange(ca.shape[0]):
        a = ca[c]
        b = cb[c]
        if move:
            _move_point(dt, a, b, cc, c, centroid, vel, spin)
        for s in range(cstart[c], cstart[c + 1]):
            if move:
                _move_point(dt, a, b, sc_pos, s, centroid, vel, spin)
            update_one(models, s, c, a, b, dt, centroid, vel, spin, cn, cmodel, cprop,
                       sc_pos, sc_area, sc_fn, sc_fs, sc_un, sc_udil, sc_us, sc_state, sc_hist, sg)


@njit(cache=True)
def contact_ranges(nc, sc_contact):
    """cstart (nc + 1,) int64 with the sub-contacts of contact c at rows cstart[c]:cstart[c + 1],
    for sub-contact rows grouped by contact in contact order (as detection installs them);
    raises ValueError if they are not."""
    cstart = np.zeros(nc + 1, dtype=np.int64)
    last = 0
    for s in range(sc_contact.shape[0]):
        c = sc_contact[s]
        if c < last or c >= nc:
            raise ValueError("sub-contact rows are not grouped by contact in contact order")
        last = c
        cstart[c + 1] += 1
    for c in range(nc):
        cstart[c + 1] += cstart[c]
    return cstart


@njit(cache=True)
def _run_steps(models, nsteps, dt, gravity, full_inertia, beta, damping, groups, bodies, contacts, subs, bounds, vmax, out,
               bstart, bent, cstart, orphans, sg, step):
    """Take up to ``nsteps`` steps of Δt = dt [s]. Bundles (``kernels.bundles``): damping, groups,
    bodies as ``rigid_motion_groups`` takes them; contacts (``Contacts``: pos (nc, 3) the contact
    reference points, own (nc,) = arange(nc)) and subs (``SubContacts``) as
    ``jointlaw.subcontact_update`` reads them; bounds (``Bounds``) the detection trigger.
    bstart, bent: the sub-contacts of every block (``jointlaw.block_lists``); cstart: those of
    every contact (``contact_ranges``); orphans: rows of blocks with sub-contacts that are in no
    group (their forces are summed too); sg (ns, 3), step (nb,): scratch, overwritten (kept by the
    host from call to call: fresh arrays of this size are new pages to the kernel at every call).

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

    Per step two parallel loops: over contacts (Eq. 11 for the points of the step before, then
    the joint law, ``_contact_pass``) and over groups (block sums, motion, clearing the forces,
    step motion: ``rigid_motion_groups`` with ``Fused``); the points of the last step move
    before returning.

    ``models``: the mask of the joint models among the contacts (``joints.cycle_mask``), a
    compile-time constant (numba's ``literally``): a deck compiles the cycle for the joint laws it
    uses, once (cached), not for every law in the folder (``run_steps`` reaches it through
    ``_stepper``).
    """
    literally(models)
    gstart, gmember = groups.start, groups.member
    centroid, vel, spin, force, moment = bodies.centroid, bodies.vel, bodies.spin, bodies.force, bodies.moment
    ca, cb, cn, cc, cown, cmodel, cprop = contacts
    sc_contact, sc_pos, sc_area, sc_fn, sc_fs, sc_un, sc_udil, sc_us, sc_state, sc_hist, sc_ppf = subs
    radius, acc, trigger, motion = bounds
    wet = any_pressure(sc_ppf)   # pore pressures (fixed between detections): their force on top of the law's
    done = 0
    bad = -1
    motion[1] = 0.0
    fused = Fused(bstart, bent, sc_pos, sg, radius, step)
    pending = False             # the points still have to move with the last step's motion
    for _ in range(nsteps):
        _contact_pass(models, pending, dt, centroid, vel, spin, ca, cb, cn, cc, cmodel, cprop, cstart,
                      sc_pos, sc_area, sc_fn, sc_fs, sc_un, sc_udil, sc_us, sc_state, sc_hist, sg)
        pending = False
        if wet:
            pore_forces(cn, sc_contact, sc_ppf, sg)
        if beta > 0.0:
            contact_stiffness_damping(beta, centroid, vel, spin, ca, cb, cn, cmodel, cprop, sc_contact, sc_pos, sc_area,
                                      sc_fn, sc_state, sc_hist, sg)
        for k in range(orphans.shape[0]):
            block_sum(orphans[k], centroid, force, moment, sc_pos, sg, bstart, bent)
        g = rigid_motion_groups(dt, gravity, full_inertia, damping, groups, bodies, vmax, out, fused)
        done += 1
        if g >= 0 or not math.isfinite(out[0]):
            bad = gmember[gstart[g]] if g >= 0 else (gmember[0] if gmember.shape[0] else 0)
            break
        pending = True
        hit = False
        for k in range(gmember.shape[0]):
            b = gmember[k]
            d = step[b]
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
    if pending:
        _move_points(dt, ca, cb, cown, cc, centroid, vel, spin)
        _move_points(dt, ca, cb, sc_contact, sc_pos, centroid, vel, spin)
    return done, bad


def cycle_lists(nb, contacts, subs, gmember):
    """What ``_run_steps`` needs besides the bundles, made once per detection (the host keeps it
    while the contacts stay): (bstart, bent) the sub-contacts of every block, cstart those of
    every contact, orphans the rows of blocks with sub-contacts in no group, and the kernel's
    scratch sg (ns, 3), step (nb,)."""
    bstart, bent = block_lists(nb, contacts.a, contacts.b, subs.contact)
    cstart = contact_ranges(contacts.a.shape[0], subs.contact)
    grouped = np.zeros(nb, dtype=bool)
    grouped[gmember] = True
    orphans = np.flatnonzero((np.diff(bstart) > 0) & ~grouped).astype(np.int64)
    return bstart, bent, cstart, orphans, np.empty((subs.contact.shape[0], 3)), np.zeros(nb)


def run_steps(nsteps, dt, gravity, full_inertia, damping, groups, bodies, contacts, subs, bounds, vmax, out,
              beta=0.0, lists=None, models=None):
    """``_run_steps`` (the kernel, documented there); a small model (``SERIAL_BELOW``), or any
    model on one thread, runs its serial twin ``_run_steps_1`` (the same numbers: every sum has a
    fixed order). ``lists``: ``cycle_lists`` of these contacts (made here when None); ``models``:
    the mask of their joint models (``joints.cycle_mask``; worked out here when None)."""
    if lists is None:
        lists = cycle_lists(bodies.centroid.shape[0], contacts, subs, groups.member)
    if models is None:
        models = cycle_mask(contacts.jmodel)
    args = (nsteps, dt, gravity, bool(full_inertia), float(beta), damping, groups, bodies, contacts, subs,
            bounds, vmax, out) + tuple(lists)
    par = get_num_threads() > 1 and subs.contact.shape[0] + 4 * groups.member.shape[0] >= serial_below()
    return _stepper(int(models), par)(*args)


_STEPPERS: dict = {}


def _stepper(models: int, parallel: bool):
    """``_run_steps`` (or its serial twin) with the joint-model mask fixed. Called from Python with
    the mask as a plain integer, the kernel would be typed with an integer first at every call and
    only then with the literal it asks for (about a second a call); this small jitted function
    passes the mask as a constant and reaches the literal specialization at once. One per mask
    and process; cached on disk like the kernel (numba keys a closure's cache entry on the values
    it closes over: each mask has its own)."""
    f = _STEPPERS.get((models, parallel))
    if f is None:
        f = _STEPPERS[(models, parallel)] = (_parallel_stepper if parallel else _serial_stepper)(int(models))
    return f


def _parallel_stepper(mask):
    @njit(cache=True)
    def step_parallel(nsteps, dt, gravity, full_inertia, beta, damping, groups, bodies, contacts, subs, bounds, vmax,
                      out, bstart, bent, cstart, orphans, sg, step):
        return _run_steps(mask, nsteps, dt, gravity, full_inertia, beta, damping, groups, bodies, contacts, subs,
                          bounds, vmax, out, bstart, bent, cstart, orphans, sg, step)
    return step_parallel


def _serial_stepper(mask):
    @njit(cache=True)
    def step_serial(nsteps, dt, gravity, full_inertia, beta, damping, groups, bodies, contacts, subs, bounds, vmax,
                    out, bstart, bent, cstart, orphans, sg, step):
        return _run_steps_1(mask, nsteps, dt, gravity, full_inertia, beta, damping, groups, bodies, contacts, subs,
                            bounds, vmax, out, bstart, bent, cstart, orphans, sg, step)
    return step_serial


#: numba's parallel pipeline with every transformation off: ``prange`` runs as ``range`` and
#: nothing is handed to the threading layer, but the loop bodies are simplified as in a parallel
#: kernel. Compiled plainly (``njit`` without ``parallel``), the helpers inlined into a loop
#: (``inline="always"``) keep reference counting of their array arguments inside the loop: the
#: serial sub-contact pass ran 7x slower (4.7 vs 0.65 ms for 52 632 sub-contacts)
#: (an options object, not a dict: numba empties an options dict as it reads it, at every compile)
_SERIAL = ParallelOptions(dict(comprehension=False, reduction=False, inplace_binop=False, setitem=False,
                               numpy=False, stencil=False, fusion=False, prange=False))
# (numba's warning that such a kernel has nothing parallel is left out: ``config.init_threads``)


def _serial_twin(kernel, name, **swap):
    """The same kernel compiled without parallel loops (``_SERIAL``: its ``prange`` loops run as
    ``range``), under its own name (so numba caches it in its own file); ``swap`` replaces globals
    it calls."""
    f = getattr(kernel, "py_func", kernel)         # (a plain function when the JIT is disabled)
    glb = dict(f.__globals__, **swap) if swap else f.__globals__
    g = type(f)(f.__code__, glb, name, f.__defaults__, f.__closure__)      # (a FunctionType)
    g.__qualname__ = name
    g.__module__ = f.__module__
    g.__doc__ = f"``{f.__name__}`` on one thread, without parallel loops."
    return njit(cache=True, parallel=_SERIAL)(g)


# a small model's steps: no parallel loop at all. Waking the other threads costs more than such a
# step (on a busy machine up to a scheduler time slice per loop; even a one-thread parallel loop
# hands its work to a worker thread of numba's workqueue)
_run_steps_1 = _serial_twin(
    _run_steps, "_run_steps_1",
    _contact_pass=_serial_twin(_contact_pass, "_contact_pass_1"),
    rigid_motion_groups=_serial_twin(rigid_motion_groups, "_rigid_motion_groups_1"),
    _move_points=_serial_twin(_move_points, "_move_points_1"),
    contact_stiffness_damping=_serial_twin(contact_stiffness_damping, "_contact_stiffness_damping_1"))
