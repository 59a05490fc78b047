"""Rigid-block motion (3DEC theory Eqs. 44-52, ERRATA Eq. 49), mechanical damping (Eqs. 77-83),
the block time step (Eq. 87) and density scaling.

Sources: the 3DEC theory text (/work/shared/seeds/000_b8ba745952e0c537.txt, sections "Rigid Block
Motion", "Mechanical Damping", "Numerical Stability", "Mass (Density) Scaling") with its ERRATA
(D₁ = 1 − αΔt/2 in Eq. 49; frac = 0.1 in Eq. 87), and Itasca's PFC `rblock damping` command page
(https://docs.itascacg.com/pfc700/pfc/rblock/doc/manual/commands/cmd_rblock_damping.html:
combined damping is made of contributions from "changes in the sign of the velocity" and "changes
in the sign of the total force", with the local damping coefficient).

Central differences on velocities at half steps (one rigid body):

  F_u = F + F_applied + m g                       unbalanced force [N]
  local damping (Eq. 79 applied to rigid blocks): F_d,i = α_l |F_u,i| sgn(ẋ_i)
  ẋ(t+Δt/2) = [D₁ ẋ(t−Δt/2) + (F_u − F_d)/m_i Δt] D₂      (Eq. 49)
  D₁ = 1 − α_v Δt/2,  D₂ = 1/(1 + α_v Δt/2)  (α_v viscous damping constant, ERRATA)
  rotation with the scalar approximate inertia I (Eq. 46), same form with M and I.
  Δx = ẋ Δt,  Δθ = ω Δt   (Eq. 50);  centroid += Δx (Eq. 51)
  vertices (Eq. 52): x_v += Δx + Δθ × (r_mid), r = x_v − x_c, with r_mid taken as the mean of
  the old and new arms; solved exactly this is the Cayley rotation
      r_new = r + 2/(1 + a·a) [a × r + a × (a × r)],   a = Δθ/2,
  which keeps the block rigid to round-off (a plain explicit Eq. 52 lets it grow).

m_i is the inertial mass (mass-scaled or not), m the gravitational mass. Fixed velocity
components (fixity bits 0-2) and rotation components (bits 3-5) keep their velocity.
Forces and moments are reset to zero after the update.

``rigid_motion_groups`` (joined blocks, full inertia, four damping modes)
-------------------------------------------------------------------------
A group (CSR ``gstart``/``gmember``; a lone block is a group of one) moves as one rigid body:
"the motion calculations are only performed for the leader block, whose mass, moment of inertia,
and centroid position are modified to represent the group" (3DEC theory, after Eq. 52). The
composite properties come from ``dec3d.physics.bodies.group_properties`` (parallel-axis theorem). For a group with
centroid C, members b with centroids c_b and arms d_b = c_b − C:

  F = Σ_b (F_b + F_app,b + m_b g)
  M = Σ_b (M_b + M_app,b + d_b × (F_b + F_app,b + m_b g))

The group velocity V at C is recovered from the leader (first member): V = v_lead − ω × d_lead;
ω is the spin shared by all members. The leader's fixity bits apply to the group.

Translation: Eq. 49 with the group's inertial mass.
Rotation, ``full_inertia`` False: Eq. 46/49 with the scalar inertia ``giscalar`` (quasi-static,
as above; the gyroscopic term of Eq. 45 is dropped, so a torque-free body keeps ω).
Rotation, ``full_inertia`` True (Euler's equations, Eq. 45, for dynamic runs), written as
dL/dt = M for the world angular momentum L = J ω, J = R diag(I₁, I₂, I₃) Rᵀ, R = ``gaxes``:
  * L lives at half steps like ω. It is not stored: at the start of a step it is rebuilt from the
    stored ω(t−Δt/2) and the current axes R(t) by L = Pᵀ J(t) ω, where P is the half of the last
    Cayley rotation (P² = Q(a), a = ωΔt/2, P = Q(b) with b = a / (1 + sqrt(1 + a·a))).
  * L(t+Δt/2) = [D₁ L(t−Δt/2) + (M − M_d) Δt] D₂  (Eq. 49 form; M_d the damping moment).
  * ω(t+Δt/2) solves the implicit mid-point relation ω = J_mid⁻¹ L with J_mid = P J(t) Pᵀ, i.e.
    J(t) ω = Pᵀ(ω) L, by fixed-point iteration (contraction ≈ |ω|Δt; converged to round-off).
  * axes and vertices turn by the same Cayley rotation Q(ωΔt/2).
  The scheme is time-reversible and keeps L of a torque-free body exactly (to round-off): the L
  rebuilt at the next step is P J(t) ω = L. The principal moments used are ``gprin`` times the
  mass-scaling ratio gimass/gmass (1 when no scaling), so the engine passes unscaled ``gprin``.

Damping (``damp_mode``), with α = ``alpha`` for modes 1 and 2:
  0  none.
  1  local (Eq. 79): F_d,i = α |F_u,i| sgn(ẋ_i), same with M and ω; world components.
  2  combined (Eq. 83; 3DEC theory "Combined Damping", PFC rblock damping page):
         F_d,i = α |F_u,i| [sgn(ẋ_i) − sgn(Ḟ_u,i)] / 2        (subtracted from F_u as in Eq. 78)
     Eq. 83 is written for a damping force *added* to F: α|F|(sgn(Ḟ) − sgn(u̇))/2; this is the
     same force with the sign of Eq. 78. Ḟ_u,i is taken as F_u,i(t) − F_u,i(t−Δt) from the
     previous unbalanced force stored in ``damping.prev`` (see below); on the first step (no history)
     sgn(Ḟ) = 0, i.e. half the local damping. Same for the moment with ω.
  4  Rayleigh, mass-proportional term: viscous damping with the fixed coefficient α_v = ``alpha``
     [1/s] in D₁, D₂ of Eq. 49 (translation and rotation); the stiffness-proportional term acts on
     the contacts (``kernels.rayleigh``). See ``dec3d.physics.dynamic``.
  3  adaptive global (Cundall 1982; 3DEC theory Eq. 77, "damping auto"): viscous, mass
     proportional damping α_v (D₁, D₂ of Eq. 49) on translation and rotation, with α_v adjusted by a
     servo so that R = Σ P / Σ |Ė_k| tends to ``servo.ratio`` (0.5). P = α_v (m_i v² + ω·L)
     is the damping power of a group (evaluated as α_v (E_k(t−Δt/2) + E_k(t+Δt/2)), i.e. 2α_v E_k
     at mid step) and |Ė_k| the magnitude of the change of the group's (inertial) kinetic energy
     over the step. Eq. 77 sums the signed rates; their sum over a cycle of a freely decaying
     system is −Σ P, so R = −1 whatever α_v: the magnitude is the reading that makes the servo
     meaningful (for one oscillator of circular frequency w, R = π α_v / (2w), so R = 0.5 gives
     α_v = w/π, about 16 % of critical). Every ``servo.window`` steps the accumulated works
     are compared: α_v ← α_v·f if R < ratio, α_v ← α_v/f if R > ratio (f = ``servo.factor``),
     bounded to [1e-4/Δt, 1/Δt] (1/Δt keeps D₁ ≥ 1/2; the floor
     keeps the servo able to recover within ~70 windows when a settled model is loaded again). A servo that starts at 0 starts at
     0.02/Δt. The update rule (a multiplicative bang-bang servo) is this code's own: the texts
     give only the target ratio.

The damping state is the ``Damping`` bundle (``kernels.bundles``, fields named there): the
adaptive servo (``Servo``: α_v, the window's works, target ratio, window, factor, …; persists
across runs) and ``prev`` (ng, 6), each group's previous F_u (3) and M_u (3) for combined damping,
valid while ``servo.hist`` is 1 (set it to 0 when the groups change).

``out`` (4,): [0] max |F_u| over groups (fixed components left out) [N]; [1] Σ over members of
|m g_i| + |F_i| (contact force) [N]; [2] kinetic energy with the real masses and inertia
(½ m V² + ½ ωᵀ J ω, J from unscaled ``gprin``) [J]; [3] the viscous coefficient α_v used [1/s].
The groups move in parallel (numba ``prange``; each writes only its own rows) and the sums over
groups (out[1], out[2], the servo's works) are taken afterwards in group order, so the numbers do
not depend on the thread count. After the step every member has vel = V + ω × (c_b − C) (new arms) and spin = ω; member centroids
and vertices turn about C with the Cayley rotation and move by V Δt; disp accumulates each
member's centroid displacement; forces and moments of the members are reset to zero. A group
whose speed |V_x|+|V_y|+|V_z| reaches ``vmax`` or whose ω is not finite does not move; the first
such group index is returned (−1 if none), the others finish the step.

Density scaling (``dec3d.physics.bodies.inertial_masses``): Eq. 87 gives Δt_b = frac·2·sqrt(M/K). The inertial mass of
a group is raised to the smallest value that is stable at the step Δt with its stiffness sum K:
m_i = max(m, K (Δt / (2 frac))²); the scalar inertia is scaled by the same ratio m_i/m. Gravity
keeps the real mass (3DEC theory, "Mass (Density) Scaling": inertial density is irrelevant to
static systems "provided that gravity forces are correctly preserved").
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from .jointlaw import block_sum


@njit(cache=True)
def _sgn(x):
    if x > 0.0:
        return 1.0
    if x < 0.0:
        return -1.0
    return 0.0


@njit(cache=True)
def block_timestep(mass_min, k_max, frac):
    """Eq. (87): Δt_b = frac · 2 · sqrt(M_min / K_max) [s]; M_min kg, K_max N/m."""
    if k_max <= 0.0:
        return 0.0
    return frac * 2.0 * math.sqrt(mass_min / k_max)


# ----------------------------------------------------------------------------------------------
# groups of joined blocks, full inertia, damping modes
# ----------------------------------------------------------------------------------------------

#: damp_mode codes (4: Rayleigh, its mass-proportional term: viscous α_v = ``alpha``, fixed)
DAMP_NONE, DAMP_LOCAL, DAMP_COMBINED, DAMP_ADAPTIVE, DAMP_RAYLEIGH = 0, 1, 2, 3, 4


@njit(cache=True)
def _ldamp(mode, alpha, f, v, fprev, hist):
    """Damping force of modes 1 (local, Eq. 79) and 2 (combined, Eq. 83); subtracted from f."""
    if mode == 1:
        return alpha * abs(f) * _sgn(v)
    if mode == 2:
        fd = 0.0
        if hist:
            fd = _sgn(f - fprev)
        return alpha * abs(f) * (_sgn(v) - fd) * 0.5
    return 0.0


@njit(cache=True)
def _cay(a0, a1, a2, r0, r1, r2):
    """Cayley rotation of r by the Rodrigues vector a (angle 2 atan|a|)."""
    h = 2.0 / (1.0 + a0 * a0 + a1 * a1 + a2 * a2)
    s0 = r0 + (a1 * r2 - a2 * r1)
    s1 = r1 + (a2 * r0 - a0 * r2)
    s2 = r2 + (a0 * r1 - a1 * r0)
    return (r0 + h * (a1 * s2 - a2 * s1), r1 + h * (a2 * s0 - a0 * s2), r2 + h * (a0 * s1 - a1 * s0))


@njit(cache=True)
def _half(a0, a1, a2):
    """b with Q(b)² = Q(a): b = a / (1 + sqrt(1 + a·a))."""
    q = 1.0 / (1.0 + math.sqrt(1.0 + a0 * a0 + a1 * a1 + a2 * a2))
    return a0 * q, a1 * q, a2 * q


@njit(cache=True)
def _jmul(ax, p0, p1, p2, x0, x1, x2):
    """R diag(p) Rᵀ x with R = ax (principal axes as columns)."""
    y0 = (ax[0, 0] * x0 + ax[1, 0] * x1 + ax[2, 0] * x2) * p0
    y1 = (ax[0, 1] * x0 + ax[1, 1] * x1 + ax[2, 1] * x2) * p1
    y2 = (ax[0, 2] * x0 + ax[1, 2] * x1 + ax[2, 2] * x2) * p2
    return (ax[0, 0] * y0 + ax[0, 1] * y1 + ax[0, 2] * y2,
            ax[1, 0] * y0 + ax[1, 1] * y1 + ax[1, 2] * y2,
            ax[2, 0] * y0 + ax[2, 1] * y1 + ax[2, 2] * y2)


@njit(cache=True, parallel=True)
def rigid_motion_groups(dt, gravity, full_inertia, damping, groups, bodies, vmax, out, fused=None):
    """Advance every group of joined blocks by one step Δt [s] (see the module docstring).

    gravity (3,) m/s²; full_inertia bool (Euler's equations); damping a ``bundles.Damping``
    (mode 0 none / 1 local / 2 combined / 3 adaptive global / 4 Rayleigh; alpha the local
    coefficient of modes 1-2 or Rayleigh's mass term; the servo and ``prev`` updated);
    groups a ``bundles.Groups`` (axes and centroid updated); bodies a ``bundles.Bodies`` (every
    motion field and the vertices updated). vmax [m/s] the speed of a blow-up. out (4,) float64
    filled as documented.
    fused: None, or a ``bundles.Fused`` from the cycle kernel: then each group first adds the
    sub-contact forces to its members (``jointlaw.block_sum``, each member its own fixed-order
    list) and afterwards clears their forces and writes their step motion to fused.step, inside
    the one parallel loop (the same numbers as separate loops: every row is its own group's).
    Returns the first unstable group index or −1.
    """
    damp_mode, alpha, servo, prev = damping
    gstart, gmember, gmass, gimass, giscalar, gprin, gaxes, gcentroid = groups
    mass, fixity, force, moment, fapp, mapp, vel, spin, centroid, disp, vstart, vcount, vpos = bodies
    ng = gstart.shape[0] - 1
    hist = False
    if damp_mode == 2:
        if prev.shape[0] < ng:
            raise ValueError("combined damping needs the previous forces of every group (Damping.prev (ng, 6))")
        hist = servo.hist[0] != 0.0
    av = 0.0
    if damp_mode == 3:
        av = servo.alpha[0]
        if not av > 0.0:
            av = 0.02 / dt
        av = min(max(av, 1e-4 / dt), 1.0 / dt)
        servo.alpha[0] = av
    elif damp_mode == 4:
        av = alpha          # Rayleigh damping's mass-proportional term (dec3d.physics.dynamic)
    al = alpha if (damp_mode == 1 or damp_mode == 2) else 0.0
    d1 = 1.0 - av * dt * 0.5
    d2 = 1.0 / (1.0 + av * dt * 0.5)
    # every group in parallel (each writes only its own rows: its members, its ``prev`` row,
    # gaxes[g], gcentroid[g], and its terms below), then the sums in group order: the same
    # numbers whatever the thread count, and those of one serial loop over the groups
    fterm = np.zeros((gmember.shape[0], 3))
    gun = np.empty(ng)
    gke = np.empty(ng)
    gwork = np.empty(ng)
    gdek = np.empty(ng)
    gok = np.empty(ng, dtype=np.bool_)
    gon = np.empty(ng, dtype=np.bool_)
    if fused is not None:
        # (taken out of the bundle here: numba 0.68 drops writes to a namedtuple's array made
        # inside a prange loop)
        fstart, fent, fpos, fsg, frad, fstep = fused
    for g in prange(ng):
        j0 = gstart[g]
        j1 = gstart[g + 1]
        gon[g] = j1 > j0
        gok[g] = True
        if j1 > j0:
            if fused is not None:
                for j in range(j0, j1):
                    block_sum(gmember[j], centroid, force, moment, fpos, fsg, fstart, fent)
            lead = gmember[j0]
            fx = fixity[lead]
            C0 = gcentroid[g, 0]
            C1 = gcentroid[g, 1]
            C2 = gcentroid[g, 2]
            F0 = 0.0
            F1 = 0.0
            F2 = 0.0
            M0 = 0.0
            M1 = 0.0
            M2 = 0.0
            for j in range(j0, j1):
                b = gmember[j]
                f0 = force[b, 0] + fapp[b, 0] + mass[b] * gravity[0]
                f1 = force[b, 1] + fapp[b, 1] + mass[b] * gravity[1]
                f2 = force[b, 2] + fapp[b, 2] + mass[b] * gravity[2]
                e0 = centroid[b, 0] - C0
                e1 = centroid[b, 1] - C1
                e2 = centroid[b, 2] - C2
                M0 += (moment[b, 0] + mapp[b, 0]) + (e1 * f2 - e2 * f1)
                M1 += (moment[b, 1] + mapp[b, 1]) + (e2 * f0 - e0 * f2)
                M2 += (moment[b, 2] + mapp[b, 2]) + (e0 * f1 - e1 * f0)
                F0 += f0
                F1 += f1
                F2 += f2
                for i in range(3):
                    fterm[j, i] = abs(mass[b] * gravity[i]) + abs(force[b, i])
            # state at t − Δt/2: ω shared, V at C from the leader
            w0 = spin[lead, 0]
            w1 = spin[lead, 1]
            w2 = spin[lead, 2]
            e0 = centroid[lead, 0] - C0
            e1 = centroid[lead, 1] - C1
            e2 = centroid[lead, 2] - C2
            v0 = vel[lead, 0] - (w1 * e2 - w2 * e1)
            v1 = vel[lead, 1] - (w2 * e0 - w0 * e2)
            v2 = vel[lead, 2] - (w0 * e1 - w1 * e0)
            mi = gimass[g]
            ek0 = 0.5 * mi * (v0 * v0 + v1 * v1 + v2 * v2)
            # translation (Eq. 49)
            un2 = 0.0
            nv0 = v0
            nv1 = v1
            nv2 = v2
            for i in range(3):
                fu = F0 if i == 0 else (F1 if i == 1 else F2)
                v = v0 if i == 0 else (v1 if i == 1 else v2)
                fp = 0.0
                if damp_mode == 2:
                    fp = prev[g, i]
                    prev[g, i] = fu
                if (fx >> i) & 1:
                    fu = 0.0
                else:
                    fd = _ldamp(damp_mode, al, fu, v, fp, hist)
                    nv = (d1 * v + (fu - fd) / mi * dt) * d2
                    if i == 0:
                        nv0 = nv
                    elif i == 1:
                        nv1 = nv
                    else:
                        nv2 = nv
                un2 += fu * fu
            un = math.sqrt(un2)
            ek1 = 0.5 * mi * (nv0 * nv0 + nv1 * nv1 + nv2 * nv2)
            # rotation
            nw0 = w0
            nw1 = w1
            nw2 = w2
            if not full_inertia:
                isc = giscalar[g]
                ek0 += 0.5 * isc * (w0 * w0 + w1 * w1 + w2 * w2)
                for i in range(3):
                    mu = M0 if i == 0 else (M1 if i == 1 else M2)
                    w = w0 if i == 0 else (w1 if i == 1 else w2)
                    mp = 0.0
                    if damp_mode == 2:
                        mp = prev[g, 3 + i]
                        prev[g, 3 + i] = mu
                    if not (fx >> (3 + i)) & 1:
                        md = _ldamp(damp_mode, al, mu, w, mp, hist)
                        nw = (d1 * w + (mu - md) / isc * dt) * d2
                        if i == 0:
                            nw0 = nw
                        elif i == 1:
                            nw1 = nw
                        else:
                            nw2 = nw
                ek1 += 0.5 * isc * (nw0 * nw0 + nw1 * nw1 + nw2 * nw2)
            else:
                rs = gimass[g] / gmass[g]
                p0 = gprin[g, 0] * rs
                p1 = gprin[g, 1] * rs
                p2 = gprin[g, 2] * rs
                ax = gaxes[g]
                # L(t − Δt/2) = Pᵀ J(t) ω, P the half of the last rotation
                b0, b1, b2 = _half(0.5 * dt * w0, 0.5 * dt * w1, 0.5 * dt * w2)
                y0, y1, y2 = _jmul(ax, p0, p1, p2, w0, w1, w2)
                L0, L1, L2 = _cay(-b0, -b1, -b2, y0, y1, y2)
                ek0 += 0.5 * (w0 * L0 + w1 * L1 + w2 * L2)
                for i in range(3):
                    mu = M0 if i == 0 else (M1 if i == 1 else M2)
                    w = w0 if i == 0 else (w1 if i == 1 else w2)
                    mp = 0.0
                    if damp_mode == 2:
                        mp = prev[g, 3 + i]
                        prev[g, 3 + i] = mu
                    if not (fx >> (3 + i)) & 1:
                        md = _ldamp(damp_mode, al, mu, w, mp, hist)
                        if i == 0:
                            L0 = (d1 * L0 + (mu - md) * dt) * d2
                        elif i == 1:
                            L1 = (d1 * L1 + (mu - md) * dt) * d2
                        else:
                            L2 = (d1 * L2 + (mu - md) * dt) * d2
                # ω(t + Δt/2): J(t) ω = Pᵀ(ω) L by fixed-point iteration
                q0 = 1.0 / p0
                q1 = 1.0 / p1
                q2 = 1.0 / p2
                nw0, nw1, nw2 = _jmul(ax, q0, q1, q2, L0, L1, L2)
                for it in range(60):
                    b0, b1, b2 = _half(0.5 * dt * nw0, 0.5 * dt * nw1, 0.5 * dt * nw2)
                    x0, x1, x2 = _cay(-b0, -b1, -b2, L0, L1, L2)
                    u0, u1, u2 = _jmul(ax, q0, q1, q2, x0, x1, x2)
                    dw = abs(u0 - nw0) + abs(u1 - nw1) + abs(u2 - nw2)
                    nw0 = u0
                    nw1 = u1
                    nw2 = u2
                    if not dw > 1e-15 * (abs(u0) + abs(u1) + abs(u2)):
                        break
                if (fx >> 3) & 1:
                    nw0 = w0
                if (fx >> 4) & 1:
                    nw1 = w1
                if (fx >> 5) & 1:
                    nw2 = w2
                ek1 += 0.5 * (nw0 * L0 + nw1 * L1 + nw2 * L2)
            wterm = 0.0
            dterm = 0.0
            if damp_mode == 3:
                wterm = av * dt * (ek0 + ek1)
                dterm = abs(ek1 - ek0)
            # real kinetic energy at t + Δt/2
            y0, y1, y2 = _jmul(gaxes[g], gprin[g, 0], gprin[g, 1], gprin[g, 2], nw0, nw1, nw2)
            kterm = 0.5 * gmass[g] * (nv0 * nv0 + nv1 * nv1 + nv2 * nv2) + 0.5 * (nw0 * y0 + nw1 * y1 + nw2 * y2)
            sp = abs(nv0) + abs(nv1) + abs(nv2)
            ok = sp < vmax and math.isfinite(nw0 + nw1 + nw2)
            gun[g] = un
            gke[g] = kterm
            gwork[g] = wterm
            gdek[g] = dterm
            gok[g] = ok
            if not ok:
                for j in range(j0, j1):
                    b = gmember[j]
                    vel[b, 0] = nv0
                    vel[b, 1] = nv1
                    vel[b, 2] = nv2
                    spin[b, 0] = nw0
                    spin[b, 1] = nw1
                    spin[b, 2] = nw2
            else:
                dx0 = nv0 * dt
                dx1 = nv1 * dt
                dx2 = nv2 * dt
                a0 = 0.5 * nw0 * dt
                a1 = 0.5 * nw1 * dt
                a2 = 0.5 * nw2 * dt
                h = 2.0 / (1.0 + a0 * a0 + a1 * a1 + a2 * a2)
                for j in range(j0, j1):
                    b = gmember[j]
                    for v in range(vstart[b], vstart[b] + vcount[b]):
                        r0 = vpos[v, 0] - C0
                        r1 = vpos[v, 1] - C1
                        r2 = vpos[v, 2] - C2
                        s0 = r0 + (a1 * r2 - a2 * r1)
                        s1 = r1 + (a2 * r0 - a0 * r2)
                        s2 = r2 + (a0 * r1 - a1 * r0)
                        vpos[v, 0] = C0 + dx0 + r0 + h * (a1 * s2 - a2 * s1)
                        vpos[v, 1] = C1 + dx1 + r1 + h * (a2 * s0 - a0 * s2)
                        vpos[v, 2] = C2 + dx2 + r2 + h * (a0 * s1 - a1 * s0)
                    r0 = centroid[b, 0] - C0
                    r1 = centroid[b, 1] - C1
                    r2 = centroid[b, 2] - C2
                    s0 = r0 + (a1 * r2 - a2 * r1)
                    s1 = r1 + (a2 * r0 - a0 * r2)
                    s2 = r2 + (a0 * r1 - a1 * r0)
                    t0 = h * (a1 * s2 - a2 * s1)
                    t1 = h * (a2 * s0 - a0 * s2)
                    t2 = h * (a0 * s1 - a1 * s0)
                    centroid[b, 0] = C0 + dx0 + r0 + t0
                    centroid[b, 1] = C1 + dx1 + r1 + t1
                    centroid[b, 2] = C2 + dx2 + r2 + t2
                    disp[b, 0] += dx0 + t0
                    disp[b, 1] += dx1 + t1
                    disp[b, 2] += dx2 + t2
                    e0 = r0 + t0
                    e1 = r1 + t1
                    e2 = r2 + t2
                    vel[b, 0] = nv0 + (nw1 * e2 - nw2 * e1)
                    vel[b, 1] = nv1 + (nw2 * e0 - nw0 * e2)
                    vel[b, 2] = nv2 + (nw0 * e1 - nw1 * e0)
                    spin[b, 0] = nw0
                    spin[b, 1] = nw1
                    spin[b, 2] = nw2
                for k in range(3):
                    x0, x1, x2 = _cay(a0, a1, a2, gaxes[g, 0, k], gaxes[g, 1, k], gaxes[g, 2, k])
                    gaxes[g, 0, k] = x0
                    gaxes[g, 1, k] = x1
                    gaxes[g, 2, k] = x2
                gcentroid[g, 0] = C0 + dx0
                gcentroid[g, 1] = C1 + dx1
                gcentroid[g, 2] = C2 + dx2
            if fused is not None:
                for j in range(j0, j1):
                    b = gmember[j]
                    for i in range(3):
                        force[b, i] = 0.0
                        moment[b, i] = 0.0
                    fstep[b] = dt * (math.sqrt(vel[b, 0] ** 2 + vel[b, 1] ** 2 + vel[b, 2] ** 2)
                                     + frad[b] * math.sqrt(spin[b, 0] ** 2 + spin[b, 1] ** 2 + spin[b, 2] ** 2))
    fmax = 0.0
    fsum = 0.0
    ke = 0.0
    work = 0.0
    dek = 0.0
    bad = -1
    for g in range(ng):
        if not gon[g]:
            continue
        if gun[g] > fmax:
            fmax = gun[g]
        for j in range(gstart[g], gstart[g + 1]):
            for i in range(3):
                fsum += fterm[j, i]
        if damp_mode == 3:
            work += gwork[g]
            dek += gdek[g]
        ke += gke[g]
        if not gok[g] and bad < 0:
            bad = g
    if fused is None:
        for j in prange(gstart[0], gstart[ng]):
            b = gmember[j]
            for i in range(3):
                force[b, i] = 0.0
                moment[b, i] = 0.0
    if damp_mode == 2:
        servo.hist[0] = 1.0
    if damp_mode == 3:
        servo.work[0] += work
        servo.dek[0] += dek
        servo.nwin[0] += 1.0
        win = servo.window[0] if servo.window[0] >= 1.0 else 10.0
        if servo.nwin[0] >= win:
            ratio = servo.ratio[0] if servo.ratio[0] > 0.0 else 0.5
            fac = servo.factor[0] if servo.factor[0] > 1.0 else 1.1
            if servo.dek[0] > 0.0:
                r = servo.work[0] / servo.dek[0]
                servo.lastr[0] = r
                a = servo.alpha[0] * fac if r < ratio else servo.alpha[0] / fac
                servo.alpha[0] = min(max(a, 1e-4 / dt), 1.0 / dt)
            servo.work[0] = 0.0
            servo.dek[0] = 0.0
            servo.nwin[0] = 0.0
    servo.calls[0] += 1.0
    out[0] = fmax
    out[1] = fsum
    out[2] = ke
    out[3] = av
    return bad
