"""Sub-contact force update: kinematics of every sub-contact, its joint model's law, the sums on the
blocks (3DEC theory Eqs. 15-32, ERRATA).

Batched over sub-contacts; every array has the sub-contact as its first dimension.
Units: forces N, displacements m, stiffness Pa/m, stresses Pa, areas m², angles as tangents.

Per sub-contact s of contact c (blocks A = ca[c], B = cb[c], normal n = cn[c], A → B):
  V   = ẋ_B + ω_B × (x − B) − ẋ_A − ω_A × (x − A)              (Eq. 15)
  ΔU  = V Δt,  ΔUⁿ = ΔU·n,  ΔUˢ = ΔU − ΔUⁿ n                   (Eqs. 20-22)
  Fˢ := Fˢ − Fˢ × (n_old × n)                                 (Eq. 23)
  uⁿ := uⁿ + ΔUⁿ (total normal displacement, starting at the sub-contact's own gap when it is
        made; that gap already holds the last step's motion, so its first update (ST_NEW) adds
        no increment: counting it twice made impacts engage one step, v Δt, early)
  Fⁿ  = −Kn A (uⁿ − u_dil)  (Eq. 24 integrated: compression positive, zero while open)
  Fˢ := Fˢ − Ks A ΔUˢ                                          (Eqs. 25, 27)
  then the joint model's law (``joints``: one kernel file per model) gives Fⁿ, Fˢ and the state.
Force on B = Fⁿ n + Fˢ at x, on A the negative; moments (x − centroid) × force (ERRATA Eqs. 28-32).

prop columns: kn, ks for every model (``joints._common``), then the model's own (e.g. ``joints.mohr``).
"""
from __future__ import annotations

import numpy as np
from numba import literally, njit, prange

from .joints import ST_NEW, joint_law_for, joint_stiffness, joint_stiffness_bound


@njit(cache=True, inline="always")   # (inlined into each caller's loop: the call costs as much as the work)
def update_one(models, s, c, a, b, dt, bpos, bvel, bspin, cn, cmodel, cprop,
               sc_pos, sc_area, sc_fn, sc_fs, sc_un, sc_udil, sc_us, sc_state, sc_hist, sg):
    """The joint law of sub-contact s of contact c (blocks a = A, b = B): its rows of sc_* updated,
    the force on B to sg[s] [N] (``subcontact_update`` for one sub-contact). ``models``: the mask
    of the joint models that may come up (a literal, ``joints.joint_law_for``)."""
    n0 = cn[c, 0]
    n1 = cn[c, 1]
    n2 = cn[c, 2]
    x0 = sc_pos[s, 0]
    x1 = sc_pos[s, 1]
    x2 = sc_pos[s, 2]
    ra0 = x0 - bpos[a, 0]
    ra1 = x1 - bpos[a, 1]
    ra2 = x2 - bpos[a, 2]
    rb0 = x0 - bpos[b, 0]
    rb1 = x1 - bpos[b, 1]
    rb2 = x2 - bpos[b, 2]
    wa0 = bspin[a, 0]
    wa1 = bspin[a, 1]
    wa2 = bspin[a, 2]
    wb0 = bspin[b, 0]
    wb1 = bspin[b, 1]
    wb2 = bspin[b, 2]
    # Eq. (15)
    v0 = bvel[b, 0] + wb1 * rb2 - wb2 * rb1 - bvel[a, 0] - (wa1 * ra2 - wa2 * ra1)
    v1 = bvel[b, 1] + wb2 * rb0 - wb0 * rb2 - bvel[a, 1] - (wa2 * ra0 - wa0 * ra2)
    v2 = bvel[b, 2] + wb0 * rb1 - wb1 * rb0 - bvel[a, 2] - (wa0 * ra1 - wa1 * ra0)
    du0 = v0 * dt
    du1 = v1 * dt
    du2 = v2 * dt
    dun = du0 * n0 + du1 * n1 + du2 * n2
    st0 = sc_state[s]
    if st0 & ST_NEW:
        du0 = 0.0
        du1 = 0.0
        du2 = 0.0
        dun = 0.0
        st0 &= ~ST_NEW
    fn, f0, f1, f2, un, ud, u0, u1, u2, st = joint_law_for(
        models, cmodel[c], cprop, c, sc_hist, s, sc_area[s], dun, du0 - dun * n0, du1 - dun * n1, du2 - dun * n2, sc_un[s],
        sc_udil[s], sc_fs[s, 0], sc_fs[s, 1], sc_fs[s, 2], sc_us[s, 0], sc_us[s, 1], sc_us[s, 2], st0)
    sc_fn[s] = fn
    sc_fs[s, 0] = f0
    sc_fs[s, 1] = f1
    sc_fs[s, 2] = f2
    sc_un[s] = un
    sc_udil[s] = ud
    sc_us[s, 0] = u0
    sc_us[s, 1] = u1
    sc_us[s, 2] = u2
    sc_state[s] = st
    # force on B (ERRATA Eqs. 28-32)
    sg[s, 0] = fn * n0 + f0
    sg[s, 1] = fn * n1 + f1
    sg[s, 2] = fn * n2 + f2


@njit(cache=True, parallel=True)
def subcontact_update(models, dt, bpos, bvel, bspin, ca, cb, cn, cmodel, cprop,
                      sc_contact, sc_pos, sc_area, sc_fn, sc_fs, sc_un, sc_udil, sc_us, sc_state, sc_hist, sg):
    """The joint law of every sub-contact, in parallel (each writes only its own rows); the
    force on B of sub-contact s goes to sg (ns, 3) [N] for ``block_sums``. ``models``: the mask of
    the joint models among the contacts (a literal, ``joints.cycle_mask``: compiled for those laws only;
    with every law inlined the compile took two minutes)."""
    literally(models)
    for s in prange(sc_contact.shape[0]):
        c = sc_contact[s]
        update_one(models, s, c, ca[c], cb[c], dt, bpos, bvel, bspin, cn, cmodel, cprop,
                   sc_pos, sc_area, sc_fn, sc_fs, sc_un, sc_udil, sc_us, sc_state, sc_hist, sg)


@njit(cache=True)
def block_lists(nb, ca, cb, sc_contact):
    """Per block, the sub-contacts acting on it in a fixed order (CSR): the entries of block x
    are bent[bstart[x]:bstart[x + 1]], each 2 s (x is B of sub-contact s) or 2 s + 1 (x is A),
    ascending — the order in which a serial scatter over s, B before A, would add them.
    Returns (bstart (nb + 1,), bent (2 ns,)) int64."""
    ns = sc_contact.shape[0]
    bstart = np.zeros(nb + 1, dtype=np.int64)
    for s in range(ns):
        c = sc_contact[s]
        bstart[cb[c] + 1] += 1
        bstart[ca[c] + 1] += 1
    for x in range(nb):
        bstart[x + 1] += bstart[x]
    fill = bstart[:nb].copy()
    bent = np.empty(2 * ns, dtype=np.int64)
    for s in range(ns):
        c = sc_contact[s]
        b = cb[c]
        bent[fill[b]] = 2 * s
        fill[b] += 1
        a = ca[c]
        bent[fill[a]] = 2 * s + 1
        fill[a] += 1
    return bstart, bent


@njit(cache=True, inline="always")   # (a call with this many arrays costs more than the work)
def block_sum(x, bpos, bforce, bmoment, sc_pos, sg, bstart, bent):
    """``block_sums`` for block x."""
    e0 = bstart[x]
    e1 = bstart[x + 1]
    if e1 == e0:
        return
    p0 = bpos[x, 0]
    p1 = bpos[x, 1]
    p2 = bpos[x, 2]
    f0 = bforce[x, 0]
    f1 = bforce[x, 1]
    f2 = bforce[x, 2]
    m0 = bmoment[x, 0]
    m1 = bmoment[x, 1]
    m2 = bmoment[x, 2]
    for e in range(e0, e1):
        code = bent[e]
        s = code >> 1
        g0 = sg[s, 0]
        g1 = sg[s, 1]
        g2 = sg[s, 2]
        r0 = sc_pos[s, 0] - p0
        r1 = sc_pos[s, 1] - p1
        r2 = sc_pos[s, 2] - p2
        if code & 1:
            f0 -= g0
            f1 -= g1
            f2 -= g2
            m0 -= r1 * g2 - r2 * g1
            m1 -= r2 * g0 - r0 * g2
            m2 -= r0 * g1 - r1 * g0
        else:
            f0 += g0
            f1 += g1
            f2 += g2
            m0 += r1 * g2 - r2 * g1
            m1 += r2 * g0 - r0 * g2
            m2 += r0 * g1 - r1 * g0
    bforce[x, 0] = f0
    bforce[x, 1] = f1
    bforce[x, 2] = f2
    bmoment[x, 0] = m0
    bmoment[x, 1] = m1
    bmoment[x, 2] = m2


@njit(cache=True, parallel=True)
def block_sums(bpos, bforce, bmoment, sc_pos, sg, bstart, bent):
    """Add the sub-contact forces sg (ns, 3) (on B; −sg on A) and their moments about each
    centroid, (x − centroid) × force, to bforce/bmoment (nb, 3), in parallel over blocks: each
    block sums its own list (``block_lists``) in its fixed order, so the sums do not depend on
    the number of threads (and equal a serial scatter over s)."""
    for x in prange(bstart.shape[0] - 1):
        block_sum(x, bpos, bforce, bmoment, sc_pos, sg, bstart, bent)


@njit(cache=True)
def subcontact_forces(models, dt, bpos, bvel, bspin, bforce, bmoment,
                      ca, cb, cn, cmodel, cprop,
                      sc_contact, sc_pos, sc_area, sc_fn, sc_fs, sc_un, sc_udil, sc_us, sc_state, sc_hist):
    """One force update of every sub-contact; adds the forces and moments to the blocks. ``models``:
    the joint-model mask (a literal, as ``subcontact_update``).

    bpos/bvel/bspin (nb, 3): centroid [m], velocity [m/s], spin [rad/s] at t − Δt/2.
    bforce/bmoment (nb, 3): accumulated in place [N], [N·m].
    ca, cb (nc,) block rows; cn (nc, 3) unit normal A → B; cmodel (nc,); cprop (nc, NPROP).
    sc_* (ns, ...): contact row, position on the c-p (3), area, Fn, Fs (3), uⁿ, u_dil, uˢ (3), state, history (NJHIST).
    Two parallel passes with fixed-order sums (``subcontact_update``, ``block_sums``): the result
    is that of a serial loop over s adding the force on B, then on A, whatever the thread count.
    (``cycle.run_steps`` calls the passes itself, making ``block_lists`` once per call.)
    """
    literally(models)
    sg = np.empty((sc_contact.shape[0], 3))
    subcontact_update(models, dt, bpos, bvel, bspin, ca, cb, cn, cmodel, cprop,
                      sc_contact, sc_pos, sc_area, sc_fn, sc_fs, sc_un, sc_udil, sc_us, sc_state, sc_hist, sg)
    bstart, bent = block_lists(bpos.shape[0], ca, cb, sc_contact)
    block_sums(bpos, bforce, bmoment, sc_pos, sg, bstart, bent)


@njit(cache=True)
def subcontact_stiffness(cmodel, cprop, sc_contact, sc_hist, kn, ks):
    """Each sub-contact's current normal and shear stiffness [Pa/m] from its joint model
    (``joints.joint_stiffness``) into kn, ks (ns,)."""
    for s in range(sc_contact.shape[0]):
        c = sc_contact[s]
        kn[s], ks[s] = joint_stiffness(cmodel[c], cprop, c, sc_hist, s)


@njit(cache=True)
def raise_to_bound(cmodel, cprop, kn, ks):
    """Each contact's kn, ks (nc,) [Pa/m] raised, in place, to the largest stiffness its joint model
    can reach (``joints.joint_stiffness_bound``; columns 0, 1 for a model without the hook)."""
    for c in range(cmodel.shape[0]):
        bn, bs = joint_stiffness_bound(cmodel[c], cprop, c)
        if bn > kn[c]:
            kn[c] = bn
        if bs > ks[c]:
            ks[c] = bs
