"""Energy bookkeeping of the rigid-block cycle, one step at a time (``dec3d.physics.energy``).

The cycle kernels are not touched: these kernels read what a step leaves behind (the state before
the step, copied by the host, and the state after it) and work out the energies of that step.

Time levels (leapfrog, 3DEC theory "Rigid Block Motion", Eqs. 44-52): forces Fⁿ are worked out at
tⁿ from the positions xⁿ; velocities live at half steps, v(n+1/2) = v(n−1/2) + (Fⁿ − damping) Δt / m.
Every work of a step is taken with the mid velocity v̄ⁿ = (v(n−1/2) + v(n+1/2)) / 2, because then

    ½ m v(n+1/2)² − ½ m v(n−1/2)² = (Fⁿ − damping)·v̄ⁿ Δt        exactly,

so the kinetic energy at the half step is what the works add up to.

Per sub-contact s of contact c (blocks A, B, normal n A → B; force on B = Fn n + Fs, on A the opposite,
as in ``jointlaw``): the relative displacement increment of the step is the joint law's own,
Δu = [v_B + ω_B × (x − c_B) − v_A − ω_A × (x − c_A)] Δt with the velocities before the step (3DEC theory
Eq. 15). The work done on the springs in the step is the trapezoid −½ (F_B(n−1) + F_B(n))·Δuⁿ (exactly the
change of ½F²/k while a spring stays elastic), and the elastic energy stored at tⁿ is

    Uⁿ = Σ Fn² / (2 kn A) + |Fs|² / (2 ks A)     (3DEC theory, "Energy Calculation": joint strain energy).

The strain energy reported at the half step (the time of the kinetic energy) is
U(n+1/2) = Uⁿ − ½ F_B(n)·Δu(n+1), Δu(n+1) the increment of the next step: for a linear spring this is
½ k uⁿ u(n+1), the leapfrog invariant's potential term, so an undamped elastic oscillation keeps
K + U constant to round-off.

A sub-contact made at a detection gets its force from its own gap at its first update, with no
displacement increment (``jointlaw``, ST_NEW): the strain energy it gains or loses in that step is
not slip; the host counts it with the energy made or lost at detections (``flag``).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .joints import joint_stiffness


@njit(cache=True)
def subcontact_increments(dt, bpos, bvel, bspin, ca, cb, sc_contact, sc_pos, du):
    """The relative displacement du (ns, 3) [m] of B against A at each sub-contact point over a step
    of Δt = dt with the block velocities as they are (Eq. 15: what the blocks do; the joint law leaves
    it out for a sub-contact's first update after a detection, see ``contact_strain``'s ``flag``)."""
    for s in range(sc_contact.shape[0]):
        c = sc_contact[s]
        a = ca[c]
        b = cb[c]
        for i in range(3):
            j = (i + 1) % 3
            k = (i + 2) % 3
            rbj = sc_pos[s, j] - bpos[b, j]
            rbk = sc_pos[s, k] - bpos[b, k]
            raj = sc_pos[s, j] - bpos[a, j]
            rak = sc_pos[s, k] - bpos[a, k]
            vb = bvel[b, i] + bspin[b, j] * rbk - bspin[b, k] * rbj
            va = bvel[a, i] + bspin[a, j] * rak - bspin[a, k] * raj
            du[s, i] = (vb - va) * dt


@njit(cache=True)
def contact_strain(cn, cmodel, cprop, sc_contact, sc_area, sc_fn, sc_fs, sc_hist, du_next, flag):
    """(Uⁿ, U(n+1/2), U of the flagged sub-contacts) [J]: the elastic energy of the sub-contact springs
    with the forces as they are, the same at the half step, Uⁿ − ½ F_B·du_next (module docstring), and
    the part of Uⁿ in the sub-contacts with flag (ns,) true (those made at the last detection: their
    first update sets the force from their gap, without a displacement increment). A spring of zero
    stiffness stores nothing. Stiffnesses: each joint model's current ones (``joints.joint_stiffness``;
    for a nonlinear joint F²/2k with its tangent k, the springs' energy if they were linear now)."""
    u = 0.0
    uf = 0.0
    corr = 0.0
    for s in range(sc_contact.shape[0]):
        c = sc_contact[s]
        kn, ks = joint_stiffness(cmodel[c], cprop, c, sc_hist, s)
        kn *= sc_area[s]
        ks *= sc_area[s]
        fn = sc_fn[s]
        f0 = sc_fs[s, 0]
        f1 = sc_fs[s, 1]
        f2 = sc_fs[s, 2]
        us = 0.0
        if kn > 0.0:
            us += 0.5 * fn * fn / kn
        if ks > 0.0:
            us += 0.5 * (f0 * f0 + f1 * f1 + f2 * f2) / ks
        u += us
        if flag[s]:
            uf += us
        g0 = fn * cn[c, 0] + f0
        g1 = fn * cn[c, 1] + f1
        g2 = fn * cn[c, 2] + f2
        corr += g0 * du_next[s, 0] + g1 * du_next[s, 1] + g2 * du_next[s, 2]
    return u, u - 0.5 * corr, uf


@njit(cache=True)
def spring_work(cn, sc_contact, fn0, fs0, fn1, fs1, du, flag):
    """(work, work of the flagged sub-contacts) [J] done on the sub-contact springs over one step:
    −½ (F_B before + F_B after)·du (the trapezoid)."""
    w = 0.0
    wf = 0.0
    for s in range(sc_contact.shape[0]):
        c = sc_contact[s]
        ws = 0.0
        for i in range(3):
            g = (fn0[s] + fn1[s]) * cn[c, i] + fs0[s, i] + fs1[s, i]
            ws -= 0.5 * g * du[s, i]
        w += ws
        if flag[s]:
            wf += ws
    return w, wf


@njit(cache=True)
def _kinetic(mi, isc, p0, p1, p2, full, ax, v0, v1, v2, w0, w1, w2):
    """½ m V² + ½ ω·J ω (J = ax diag(p) axᵀ, or isc I when not full)."""
    k = 0.5 * mi * (v0 * v0 + v1 * v1 + v2 * v2)
    if not full:
        return k + 0.5 * isc * (w0 * w0 + w1 * w1 + w2 * w2)
    # components of ω along the principal axes (the columns of ax)
    a0 = ax[0, 0] * w0 + ax[1, 0] * w1 + ax[2, 0] * w2
    a1 = ax[0, 1] * w0 + ax[1, 1] * w1 + ax[2, 1] * w2
    a2 = ax[0, 2] * w0 + ax[1, 2] * w1 + ax[2, 2] * w2
    return k + 0.5 * (p0 * a0 * a0 + p1 * a1 * a1 + p2 * a2 * a2)


@njit(cache=True)
def group_energy(dt, gravity, full, gstart, gmember, gmass, gimass, giscalar, gprin, fixity, mass, fapp, mapp,
                 cen0, gcen0, vel0, spin0, axes0, cen1, gcen1, vel1, spin1, axes1,
                 gid, ca, cb, cn, sc_contact, sc_pos0, sc_fn, sc_fs, out):
    """The works and kinetic energies of one step of the rigid groups (CSR gstart/gmember, leader
    first; ``rigid_motion_groups``' arguments), from the state before (…0: block centroids, group
    centroids, velocities, spins, group principal axes) and after it (…1), the sub-contact forces
    of the step (sc_fn, sc_fs) at the sub-contact points before it (sc_pos0), gid (nb,) the group of
    each block row (−1: none). Summed over the groups in order into out (7,):
    [0] work of gravity, [1] work of the applied forces and moments, [2] work of the reactions of
    fixed velocity/rotation components (−F_u·V̄ Δt on each fixed component), [3] work of the contact
    forces on the blocks, [4] kinetic energy before, [5] after (inertial masses; full inertia tensor
    R diag(I·m_i/m) Rᵀ or the scalar inertia), [6] work of every force on the free components minus
    the change of kinetic energy (what the damping took)."""
    ng = gstart.shape[0] - 1
    fc = np.zeros((ng, 6))
    for s in range(sc_contact.shape[0]):
        c = sc_contact[s]
        g0 = sc_fn[s] * cn[c, 0] + sc_fs[s, 0]
        g1 = sc_fn[s] * cn[c, 1] + sc_fs[s, 1]
        g2 = sc_fn[s] * cn[c, 2] + sc_fs[s, 2]
        for side in range(2):
            blk = cb[c] if side == 0 else ca[c]
            g = gid[blk]
            if g < 0:
                continue
            sg = 1.0 if side == 0 else -1.0
            r0 = sc_pos0[s, 0] - gcen0[g, 0]
            r1 = sc_pos0[s, 1] - gcen0[g, 1]
            r2 = sc_pos0[s, 2] - gcen0[g, 2]
            fc[g, 0] += sg * g0
            fc[g, 1] += sg * g1
            fc[g, 2] += sg * g2
            fc[g, 3] += sg * (r1 * g2 - r2 * g1)
            fc[g, 4] += sg * (r2 * g0 - r0 * g2)
            fc[g, 5] += sg * (r0 * g1 - r1 * g0)
    for i in range(7):
        out[i] = 0.0
    for g in range(ng):
        j0 = gstart[g]
        j1 = gstart[g + 1]
        if j1 == j0:
            continue
        lead = gmember[j0]
        fx = fixity[lead]
        fg = np.zeros(6)       # gravity
        fa = np.zeros(6)       # applied
        for j in range(j0, j1):
            b = gmember[j]
            e0 = cen0[b, 0] - gcen0[g, 0]
            e1 = cen0[b, 1] - gcen0[g, 1]
            e2 = cen0[b, 2] - gcen0[g, 2]
            w0 = mass[b] * gravity[0]
            w1 = mass[b] * gravity[1]
            w2 = mass[b] * gravity[2]
            fg[0] += w0
            fg[1] += w1
            fg[2] += w2
            fg[3] += e1 * w2 - e2 * w1
            fg[4] += e2 * w0 - e0 * w2
            fg[5] += e0 * w1 - e1 * w0
            a0 = fapp[b, 0]
            a1 = fapp[b, 1]
            a2 = fapp[b, 2]
            fa[0] += a0
            fa[1] += a1
            fa[2] += a2
            fa[3] += mapp[b, 0] + e1 * a2 - e2 * a1
            fa[4] += mapp[b, 1] + e2 * a0 - e0 * a2
            fa[5] += mapp[b, 2] + e0 * a1 - e1 * a0
        # group velocity at its centroid, before and after (V = v_lead − ω × (c_lead − C))
        q0 = np.empty(6)
        q1 = np.empty(6)
        for i in range(3):
            q0[3 + i] = spin0[lead, i]
            q1[3 + i] = spin1[lead, i]
        for i in range(3):
            j = (i + 1) % 3
            k = (i + 2) % 3
            q0[i] = vel0[lead, i] - (q0[3 + j] * (cen0[lead, k] - gcen0[g, k]) - q0[3 + k] * (cen0[lead, j] - gcen0[g, j]))
            q1[i] = vel1[lead, i] - (q1[3 + j] * (cen1[lead, k] - gcen1[g, k]) - q1[3 + k] * (cen1[lead, j] - gcen1[g, j]))
        rs = gimass[g] / gmass[g]
        k0 = _kinetic(gimass[g], giscalar[g], gprin[g, 0] * rs, gprin[g, 1] * rs, gprin[g, 2] * rs, full, axes0[g],
                      q0[0], q0[1], q0[2], q0[3], q0[4], q0[5])
        k1 = _kinetic(gimass[g], giscalar[g], gprin[g, 0] * rs, gprin[g, 1] * rs, gprin[g, 2] * rs, full, axes1[g],
                      q1[0], q1[1], q1[2], q1[3], q1[4], q1[5])
        wb = 0.0
        wa = 0.0
        wr = 0.0
        wc = 0.0
        for i in range(6):
            qm = 0.5 * (q0[i] + q1[i]) * dt
            wb += fg[i] * qm
            wa += fa[i] * qm
            wc += fc[g, i] * qm
            if (fx >> i) & 1:
                wr -= (fg[i] + fa[i] + fc[g, i]) * qm
        out[0] += wb
        out[1] += wa
        out[2] += wr
        out[3] += wc
        out[4] += k0
        out[5] += k1
        out[6] += (wb + wa + wr + wc) - (k1 - k0)
    return out


@njit(cache=True)
def group_kinetic(full, gstart, gmember, gmass, gimass, giscalar, gprin, cen, gcen, vel, spin, axes):
    """Kinetic energy [J] of the rigid groups as they are (inertial masses, as ``group_energy``)."""
    tot = 0.0
    for g in range(gstart.shape[0] - 1):
        if gstart[g + 1] == gstart[g]:
            continue
        lead = gmember[gstart[g]]
        w0 = spin[lead, 0]
        w1 = spin[lead, 1]
        w2 = spin[lead, 2]
        e0 = cen[lead, 0] - gcen[g, 0]
        e1 = cen[lead, 1] - gcen[g, 1]
        e2 = cen[lead, 2] - gcen[g, 2]
        v0 = vel[lead, 0] - (w1 * e2 - w2 * e1)
        v1 = vel[lead, 1] - (w2 * e0 - w0 * e2)
        v2 = vel[lead, 2] - (w0 * e1 - w1 * e0)
        rs = gimass[g] / gmass[g]
        tot += _kinetic(gimass[g], giscalar[g], gprin[g, 0] * rs, gprin[g, 1] * rs, gprin[g, 2] * rs, full, axes[g],
                        v0, v1, v2, w0, w1, w2)
    return tot


# ------------------------------------------------------------------ zoned blocks (4-node zones)
@njit(cache=True)
def _tet_gradients(pos, gp, z, grad):
    """Shape-function gradients grad (4, 3) of the linear tetrahedron z; returns its volume [m³]."""
    r0 = gp[z, 0]
    jm = np.empty((3, 3))
    for a in range(3):
        for i in range(3):
            jm[i, a] = pos[gp[z, a + 1], i] - pos[r0, i]
    det = (jm[0, 0] * (jm[1, 1] * jm[2, 2] - jm[1, 2] * jm[2, 1])
           - jm[0, 1] * (jm[1, 0] * jm[2, 2] - jm[1, 2] * jm[2, 0])
           + jm[0, 2] * (jm[1, 0] * jm[2, 1] - jm[1, 1] * jm[2, 0]))
    # rows of J⁻¹ are the gradients of the natural coordinates ξ₁ ξ₂ ξ₃ (= N₁ N₂ N₃)
    inv = np.empty((3, 3))
    inv[0, 0] = (jm[1, 1] * jm[2, 2] - jm[1, 2] * jm[2, 1]) / det
    inv[0, 1] = (jm[0, 2] * jm[2, 1] - jm[0, 1] * jm[2, 2]) / det
    inv[0, 2] = (jm[0, 1] * jm[1, 2] - jm[0, 2] * jm[1, 1]) / det
    inv[1, 0] = (jm[1, 2] * jm[2, 0] - jm[1, 0] * jm[2, 2]) / det
    inv[1, 1] = (jm[0, 0] * jm[2, 2] - jm[0, 2] * jm[2, 0]) / det
    inv[1, 2] = (jm[0, 2] * jm[1, 0] - jm[0, 0] * jm[1, 2]) / det
    inv[2, 0] = (jm[1, 0] * jm[2, 1] - jm[1, 1] * jm[2, 0]) / det
    inv[2, 1] = (jm[0, 1] * jm[2, 0] - jm[0, 0] * jm[2, 1]) / det
    inv[2, 2] = (jm[0, 0] * jm[1, 1] - jm[0, 1] * jm[1, 0]) / det
    for i in range(3):
        grad[0, i] = -(inv[0, i] + inv[1, i] + inv[2, i])
        for a in range(3):
            grad[a + 1, i] = inv[a, i]
    return abs(det) / 6.0


@njit(cache=True)
def zone_internal_forces(pos, gp, rows, weight, stress, force):
    """Add to force (nv, 3) the gridpoint forces of the 4-node zones ``rows`` (weights ``weight``, the
    overlay factor) from their stresses (xx yy zz xy xz yz, tension positive): f_n = −w V σ ∇N_n,
    the force the zone step applies for the stress it holds."""
    grad = np.empty((4, 3))
    for k in range(rows.shape[0]):
        z = rows[k]
        vol = _tet_gradients(pos, gp, z, grad) * weight[k]
        s = stress[z]
        for n in range(4):
            r = gp[z, n]
            force[r, 0] -= vol * (s[0] * grad[n, 0] + s[3] * grad[n, 1] + s[4] * grad[n, 2])
            force[r, 1] -= vol * (s[3] * grad[n, 0] + s[1] * grad[n, 1] + s[5] * grad[n, 2])
            force[r, 2] -= vol * (s[4] * grad[n, 0] + s[5] * grad[n, 1] + s[2] * grad[n, 2])


@njit(cache=True)
def zone_strain(pos, gp, rows, weight, stress, bulk, shear):
    """Elastic strain energy [J] of the 4-node zones ``rows``: Σ w V (p²/(2K) + s:s/(4G)), p the mean
    stress, s the deviator (σ : C⁻¹ : σ / 2 of isotropic elasticity; 3DEC theory, "Energy Calculation":
    stored strain energy)."""
    grad = np.empty((4, 3))
    u = 0.0
    for k in range(rows.shape[0]):
        z = rows[k]
        vol = _tet_gradients(pos, gp, z, grad) * weight[k]
        s = stress[z]
        p = (s[0] + s[1] + s[2]) / 3.0
        d0 = s[0] - p
        d1 = s[1] - p
        d2 = s[2] - p
        ss = d0 * d0 + d1 * d1 + d2 * d2 + 2.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5])
        e = 0.0
        if bulk[z] > 0.0:
            e += p * p / (2.0 * bulk[z])
        if shear[z] > 0.0:
            e += ss / (4.0 * shear[z])
        u += vol * e
    return u
