"""Rigid-block motion (3DEC theory Eqs. 44-52, ERRATA Eq. 49) and the block time step (Eq. 87).

Central differences on velocities at half steps. For each moving block (a leader row):

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
"""
from __future__ import annotations

import math

from numba import njit


@njit(cache=True)
def _sgn(x):
    if x > 0.0:
        return 1.0
    if x < 0.0:
        return -1.0
    return 0.0


@njit(cache=True)
def rigid_motion(dt, gravity, alpha_local, alpha_visc, rows, mass, imass, iinert, fixity,
                 force, moment, fapp, mapp, vel, spin, centroid, disp,
                 vstart, vcount, vpos, vmax):
    """Advance blocks ``rows`` (int64 (k,)) by one step Δt [s].

    gravity (3,) m/s²; mass (nb,) kg gravitational; imass (nb,) kg inertial; iinert (nb,) kg·m²
    scalar inertia; fixity (nb,) uint8; force/moment/fapp/mapp/vel/spin/centroid/disp (nb, 3);
    vstart/vcount (nb,) vertex ranges; vpos (nv, 3) vertex positions, all updated in place.
    vmax: a speed [m/s] above which the run is declared unstable.
    Returns (bad row or −1, max |unbalanced force| [N], sum of |m g| + |F| over the rows [N]).
    """
    d1 = 1.0 - alpha_visc * dt * 0.5
    d2 = 1.0 / (1.0 + alpha_visc * dt * 0.5)
    fmax = 0.0
    fsum = 0.0
    bad = -1
    for k in range(rows.shape[0]):
        b = rows[k]
        fx = fixity[b]
        dx0 = 0.0
        dx1 = 0.0
        dx2 = 0.0
        un2 = 0.0
        for i in range(3):
            fu = force[b, i] + fapp[b, i] + mass[b] * gravity[i]
            if (fx >> i) & 1:
                fu = 0.0
            else:
                v = vel[b, i]
                fd = alpha_local * abs(fu) * _sgn(v)
                vel[b, i] = (d1 * v + (fu - fd) / imass[b] * dt) * d2
            un2 += fu * fu
            fsum += abs(mass[b] * gravity[i]) + abs(force[b, i])
        un = math.sqrt(un2)
        if un > fmax:
            fmax = un
        for i in range(3):
            if not (fx >> (3 + i)) & 1:
                mu = moment[b, i] + mapp[b, i]
                w = spin[b, i]
                md = alpha_local * abs(mu) * _sgn(w)
                spin[b, i] = (d1 * w + (mu - md) / iinert[b] * dt) * d2
        dx0 = vel[b, 0] * dt
        dx1 = vel[b, 1] * dt
        dx2 = vel[b, 2] * dt
        a0 = 0.5 * spin[b, 0] * dt
        a1 = 0.5 * spin[b, 1] * dt
        a2 = 0.5 * spin[b, 2] * dt
        sp = abs(vel[b, 0]) + abs(vel[b, 1]) + abs(vel[b, 2])
        if not (sp < vmax) or not math.isfinite(spin[b, 0] + spin[b, 1] + spin[b, 2]):
            if bad < 0:
                bad = b
            continue
        h = 2.0 / (1.0 + a0 * a0 + a1 * a1 + a2 * a2)
        c0 = centroid[b, 0]
        c1 = centroid[b, 1]
        c2 = centroid[b, 2]
        for v in range(vstart[b], vstart[b] + vcount[b]):
            r0 = vpos[v, 0] - c0
            r1 = vpos[v, 1] - c1
            r2 = vpos[v, 2] - c2
            t0 = a1 * r2 - a2 * r1
            t1 = a2 * r0 - a0 * r2
            t2 = a0 * r1 - a1 * r0
            s0 = r0 + t0
            s1 = r1 + t1
            s2 = r2 + t2
            vpos[v, 0] = c0 + dx0 + r0 + h * (a1 * s2 - a2 * s1)
            vpos[v, 1] = c1 + dx1 + r1 + h * (a2 * s0 - a0 * s2)
            vpos[v, 2] = c2 + dx2 + r2 + h * (a0 * s1 - a1 * s0)
        centroid[b, 0] = c0 + dx0
        centroid[b, 1] = c1 + dx1
        centroid[b, 2] = c2 + dx2
        disp[b, 0] += dx0
        disp[b, 1] += dx1
        disp[b, 2] += dx2
    for k in range(rows.shape[0]):
        b = rows[k]
        for i in range(3):
            force[b, i] = 0.0
            moment[b, i] = 0.0
    return bad, fmax, fsum


@njit(cache=True)
def block_timestep(mass_min, k_max, frac):
    """Eq. (87): Δt_b = frac · 2 · sqrt(M_min / K_max) [s]; M_min kg, K_max N/m."""
    if k_max <= 0.0:
        return 0.0
    return frac * 2.0 * math.sqrt(mass_min / k_max)
