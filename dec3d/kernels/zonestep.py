"""The deformable-block step besides the zone forces (``kernels/zone_step.py``): gridpoint masses
and stiffness, and the gridpoint equations of motion with damping.

Sources: the 3DEC theory text (/work/shared/seeds/000_b8ba745952e0c537.txt), sections
"Deformable Block Motion" (Eqs. 53-59, ERRATA: Δε_v has three terms), "Accurate Modeling of
Plastic Collapse" (mixed discretization, Eqs. 60-63 and the two overlays), "Mechanical
Damping" (local damping Eqs. 78-79, combined damping Eq. 83), "Numerical Stability" (Eqs. 84-86)
and "Mass (Density) Scaling".

``zone_mass_stiffness``
    Lumped mass of a 4-node tetrahedron: ρV/4 to each corner (its centroid rule; the text's
    "one-third" in Eq. 56 is the triangle rule of the 2-D code). A 10-node tetrahedron lumps by
    diagonal scaling of its consistent mass (corners ∫N² = V/70, mid-edge nodes 8V/105, scaled to
    sum to ρV: 1/36 and 4/27 of the zone mass). A zone of a mixed (hexahedral) set counts half:
    its two overlays cover the same volume. Node stiffness of Eq. (86),
    k = (8/3)(K + 4G/3) b_max² / h_min, b_max the longest edge and h_min the smallest height
    (3V / largest face area), added to each node of the zone (halved for an overlay zone; for a
    10-node zone four times the corner-tetrahedron value, dec3d's conservative choice, since its
    nodes are twice as close).

``gp_externals``  gravity (real mass), applied and face forces per row, then linked rows summed
    onto their master.

``gp_motion``  for each master gridpoint: Eq. (78) with the damping force of Eq. (79) (local)
    or Eq. (83) (combined, sign as ``motion._ldamp``), velocity components held at ``vapp``
    (``apply_fix`` bits) or at their value (``fixity`` bits), displacement += v Δt, position +=
    v Δt in large strain; then the motion of each master is copied to its linked rows.
"""
from __future__ import annotations

import math

from numba import njit, prange

from .motion import _sgn


@njit(cache=True)
def _area_vec(pos, i1, i2, i3, iopp):
    """Area vector of triangle (i1 i2 i3), pointing away from point iopp."""
    ux = pos[i2, 0] - pos[i1, 0]; uy = pos[i2, 1] - pos[i1, 1]; uz = pos[i2, 2] - pos[i1, 2]
    wx = pos[i3, 0] - pos[i1, 0]; wy = pos[i3, 1] - pos[i1, 1]; wz = pos[i3, 2] - pos[i1, 2]
    nx = 0.5 * (uy * wz - uz * wy)
    ny = 0.5 * (uz * wx - ux * wz)
    nz = 0.5 * (ux * wy - uy * wx)
    d = (pos[iopp, 0] - pos[i1, 0]) * nx + (pos[iopp, 1] - pos[i1, 1]) * ny + (pos[iopp, 2] - pos[i1, 2]) * nz
    if d > 0.0:
        return -nx, -ny, -nz
    return nx, ny, nz


@njit(cache=True)
def _tet_volume(pos, a, b, c, d):
    x1 = pos[b, 0] - pos[a, 0]; y1 = pos[b, 1] - pos[a, 1]; z1 = pos[b, 2] - pos[a, 2]
    x2 = pos[c, 0] - pos[a, 0]; y2 = pos[c, 1] - pos[a, 1]; z2 = pos[c, 2] - pos[a, 2]
    x3 = pos[d, 0] - pos[a, 0]; y3 = pos[d, 1] - pos[a, 1]; z3 = pos[d, 2] - pos[a, 2]
    return abs(x1 * (y2 * z3 - z2 * y3) - y1 * (x2 * z3 - z2 * x3) + z1 * (x2 * y3 - y2 * x3)) / 6.0


@njit(cache=True)
def zone_mass_stiffness(pos, gp, nnode, overlay, rows, bulk, shear, density, mass, stiff):
    """Add the lumped mass and Eq. (86) stiffness of each zone in ``rows`` to its nodes
    (``mass``, ``stiff`` indexed by vertex row; bulk/shear/density indexed by zone row)."""
    for k in range(rows.shape[0]):
        z = rows[k]
        a = gp[z, 0]; b = gp[z, 1]; c = gp[z, 2]; d = gp[z, 3]
        vol = _tet_volume(pos, a, b, c, d)
        if vol <= 0.0:
            continue
        w = 0.5 if overlay[z] >= 0 else 1.0
        # longest edge and largest face
        bmax2 = 0.0
        for i in range(4):
            for j in range(i + 1, 4):
                p = gp[z, i]; q = gp[z, j]
                e2 = ((pos[p, 0] - pos[q, 0]) ** 2 + (pos[p, 1] - pos[q, 1]) ** 2
                      + (pos[p, 2] - pos[q, 2]) ** 2)
                if e2 > bmax2:
                    bmax2 = e2
        amax = 0.0
        for n in range(4):
            ax, ay, az = _area_vec(pos, gp[z, (n + 1) % 4], gp[z, (n + 2) % 4], gp[z, (n + 3) % 4], gp[z, n])
            ar = math.sqrt(ax * ax + ay * ay + az * az)
            if ar > amax:
                amax = ar
        hmin = 3.0 * vol / amax
        kz = 8.0 / 3.0 * (bulk[z] + 4.0 * shear[z] / 3.0) * bmax2 / hmin * w
        mz = density[z] * vol * w
        if nnode[z] == 10:
            for n in range(4):
                mass[gp[z, n]] += mz / 36.0
                stiff[gp[z, n]] += 4.0 * kz
            for n in range(4, 10):
                mass[gp[z, n]] += mz * 4.0 / 27.0
                stiff[gp[z, n]] += 4.0 * kz
        else:
            for n in range(4):
                mass[gp[z, n]] += 0.25 * mz
                stiff[gp[z, n]] += kz


@njit(cache=True, parallel=True)
def gp_externals(rows, link, mass, gravity, fapp, fface, force, fmag):
    """Add gravity m g (real mass), applied and face forces to each gridpoint row of ``rows``
    (their magnitudes to ``fmag``), then sum each linked row's force and fmag onto its master
    (rows in parallel, the sums onto masters in row order: the same bits for any thread count)."""
    for k in prange(rows.shape[0]):
        r = rows[k]
        tot = 0.0
        for i in range(3):
            fg = mass[r] * gravity[i]
            force[r, i] += fg + fapp[r, i] + fface[r, i]
        tot = (math.sqrt((mass[r] * gravity[0]) ** 2 + (mass[r] * gravity[1]) ** 2 + (mass[r] * gravity[2]) ** 2)
               + math.sqrt(fapp[r, 0] ** 2 + fapp[r, 1] ** 2 + fapp[r, 2] ** 2)
               + math.sqrt(fface[r, 0] ** 2 + fface[r, 1] ** 2 + fface[r, 2] ** 2))
        fmag[r] += tot
    for k in range(rows.shape[0]):
        r = rows[k]
        m = link[r]
        if m >= 0:
            for i in range(3):
                force[m, i] += force[r, i]
            fmag[m] += fmag[r]


@njit(cache=True)
def gp_motion(masters, linked, link, force, fprev, mass, imass, held, vapp, vel, disp, pos, dt, mode, alpha,
              large, vmax, out):
    """Move the master gridpoints ``masters`` one step (see the module text), then copy the
    motion to the ``linked`` rows. ``force`` (total force per master) is left as the unbalanced
    force (held components zeroed) and copied to ``fprev`` (the previous step's unbalanced force
    for combined damping, read before). ``held`` (uint8): bits 0-2 held at vapp, bits 3-5 held
    at the present velocity. out: [0] largest unbalanced force, [1] Σ unbalanced force,
    [2] kinetic energy (real masses), [3] first row that became unstable (−1: none).
    Returns the number of master rows whose velocity exceeded ``vmax`` or is not finite."""
    umax = 0.0
    usum = 0.0
    ke = 0.0
    bad = -1
    for k in range(masters.shape[0]):
        r = masters[k]
        m = imass[r]
        u2 = 0.0
        for i in range(3):
            f = force[r, i]
            if held[r] & (1 << i):
                vel[r, i] = vapp[r, i]
                f = 0.0
            elif held[r] & (8 << i) or m <= 0.0:
                f = 0.0
            else:
                fd = 0.0
                if mode == 1 or mode == 3:
                    fd = alpha * abs(f) * _sgn(vel[r, i])
                elif mode == 2:
                    fd = alpha * abs(f) * (_sgn(vel[r, i]) - _sgn(f - fprev[r, i])) * 0.5
                if mode == 4:       # Rayleigh, mass term: viscous α = alpha [1/s], central form of Eq. 49
                    h = 0.5 * alpha * dt
                    vel[r, i] = ((1.0 - h) * vel[r, i] + f * dt / m) / (1.0 + h)
                else:
                    vel[r, i] += (f - fd) * dt / m
            force[r, i] = f
            fprev[r, i] = f
            u2 += f * f
            d = vel[r, i] * dt
            disp[r, i] += d
            if large:
                pos[r, i] += d
            ke += 0.5 * mass[r] * vel[r, i] * vel[r, i]
        u = math.sqrt(u2)
        usum += u
        if u > umax:
            umax = u
        sp = vel[r, 0] * vel[r, 0] + vel[r, 1] * vel[r, 1] + vel[r, 2] * vel[r, 2]
        if bad < 0 and not (sp <= vmax * vmax):
            bad = r
    for k in range(linked.shape[0]):
        r = linked[k]
        mr = link[r]
        for i in range(3):
            vel[r, i] = vel[mr, i]
            disp[r, i] = disp[mr, i]
            force[r, i] = force[mr, i]
            fprev[r, i] = fprev[mr, i]
            if large:
                pos[r, i] = pos[mr, i]
    out[0] = umax
    out[1] = usum
    out[2] = ke
    out[3] = bad
    return bad


@njit(cache=True, parallel=True)
def gp_motion_ws(masters, linked, link, force, fprev, mass, imass, held, vapp, vel, disp, pos, dt, mode, alpha,
                 large, vmax, out, work):
    """``gp_motion`` (same arguments, same bits) with the masters moved in parallel: each
    master's unbalanced force magnitude, kinetic-energy terms and speed test go to ``work``
    (len(masters), 5), then out[0..3] are reduced from it in master order, as ``gp_motion``
    accumulates them. Returns the first unstable master row or -1."""
    nm = masters.shape[0]
    for k in prange(nm):
        r = masters[k]
        m = imass[r]
        u2 = 0.0
        for i in range(3):
            f = force[r, i]
            if held[r] & (1 << i):
                vel[r, i] = vapp[r, i]
                f = 0.0
            elif held[r] & (8 << i) or m <= 0.0:
                f = 0.0
            else:
                fd = 0.0
                if mode == 1 or mode == 3:
                    fd = alpha * abs(f) * _sgn(vel[r, i])
                elif mode == 2:
                    fd = alpha * abs(f) * (_sgn(vel[r, i]) - _sgn(f - fprev[r, i])) * 0.5
                vel[r, i] += (f - fd) * dt / m
            force[r, i] = f
            fprev[r, i] = f
            u2 += f * f
            d = vel[r, i] * dt
            disp[r, i] += d
            if large:
                pos[r, i] += d
            work[k, 1 + i] = 0.5 * mass[r] * vel[r, i] * vel[r, i]
        work[k, 0] = math.sqrt(u2)
        sp = vel[r, 0] * vel[r, 0] + vel[r, 1] * vel[r, 1] + vel[r, 2] * vel[r, 2]
        work[k, 4] = 0.0 if sp <= vmax * vmax else 1.0
    umax = 0.0
    usum = 0.0
    ke = 0.0
    bad = -1
    for k in range(nm):
        ke += work[k, 1]
        ke += work[k, 2]
        ke += work[k, 3]
        u = work[k, 0]
        usum += u
        if u > umax:
            umax = u
        if bad < 0 and work[k, 4] != 0.0:
            bad = masters[k]
    for k in prange(linked.shape[0]):
        r = linked[k]
        mr = link[r]
        for i in range(3):
            vel[r, i] = vel[mr, i]
            disp[r, i] = disp[mr, i]
            force[r, i] = force[mr, i]
            fprev[r, i] = fprev[mr, i]
            if large:
                pos[r, i] = pos[mr, i]
    out[0] = umax
    out[1] = usum
    out[2] = ke
    out[3] = bad
    return bad
