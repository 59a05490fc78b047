"""Flow in the joints on a network of knots and pipes (3DEC theory, "Joint Fluid Flow": the cubic law),
explicit transient step. The network is given as arrays: ``dec3d.physics.flowgeom`` builds it from the contacts,
``dec3d.physics.flownet`` runs it in the cycle, ``dec3d.physics.jointflow`` has the steady solve.

Knot i: pressure p[i] [Pa], volume vol[i] [m³] (aperture × its share of the joint area), fixed[i] (a
pressure boundary: p is held), inflow q_in[i] [m³/s] (a discharge boundary). Pipe k between knots
pa[k] and pb[k]: conductance c[k] = a³ w / (12 μ L) [m³/(s·Pa)] (hydraulic aperture a, width w, length L,
viscosity μ), so the flow from pa to pb is
    Q_k = c_k (p_a − p_b)
and an unfixed knot's pressure changes by  Δp_i = K_w Δt / vol_i (q_in_i + Σ inflow)  (fluid bulk modulus K_w).
Stable for Δt ≤ min_i vol_i / (K_w Σ_{k at i} c_k) (the diagonal bound of the explicit diffusion step,
taken with the factor 0.5 of ``stable_dt``).
"""
from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def stable_dt(pa, pb, c, vol, kw, fixed):
    """The largest stable Δt [s]: 0.5 min_i vol_i / (K_w Σ_{k at i} c_k) over the unfixed knots with a volume
    (inf when none has a pipe; a knot without volume is not stepped)."""
    s = np.zeros(vol.shape[0])
    for k in range(c.shape[0]):
        s[pa[k]] += c[k]
        s[pb[k]] += c[k]
    dt = np.inf
    for i in range(vol.shape[0]):
        if not fixed[i] and s[i] > 0.0 and vol[i] > 0.0:
            t = 0.5 * vol[i] / (kw * s[i])
            if t < dt:
                dt = t
    return dt


def flow_steps(nsteps, dt, pa, pb, c, vol, kw, fixed, q_in, p, flow):
    """``nsteps`` explicit steps of Δt [s] (reduced to ``stable_dt`` if larger: never blown up); p (nk,)
    updated in place, flow (npipe,) the last step's pipe flows [m³/s]. Returns the Δt used.
    ``network_steps`` without gravity (dg = 0)."""
    return network_steps(nsteps, dt, pa, pb, c, np.zeros(c.shape[0]), vol, kw, fixed, q_in, p, flow)


# ------------------------------------------------------------------ the network built from the contacts
@njit(cache=True)
def zone_update(zsub, zw, zcontact, un, a0, amin, amax, zk, zarea, zcot, zpipe, mu, zap, c, vol):
    """Apertures, pipe conductances and knot volumes of the network built from the contacts
    (``physics.flowgeom``). Zone t of contact zcontact[t]: hydraulic aperture
        a_t = clamp(a0 + Σ_j zw[t, j] un[zsub[t, j]], amin, amax)
    (3DEC's aperture at zero normal stress, residual and maximum apertures, per contact; un the sub-contacts'
    normal displacement, opening positive) → zap[t]. Pipe conductance c[p] = Σ_t a_t³ / (12 μ) zcot[t, j] over
    the zone edges j that are pipe p (zpipe[t, j]), negative sums taken as 0. Knot volume vol[i] = Σ a_t area_t / 3
    over the zones at knot i."""
    for p in range(c.shape[0]):
        c[p] = 0.0
    for i in range(vol.shape[0]):
        vol[i] = 0.0
    for t in range(zk.shape[0]):
        ct = zcontact[t]
        u = 0.0
        for j in range(3):
            u += zw[t, j] * un[zsub[t, j]]
        a = a0[ct] + u
        if a < amin[ct]:
            a = amin[ct]
        if a > amax[ct]:
            a = amax[ct]
        zap[t] = a
        tr = a * a * a / (12.0 * mu)
        for j in range(3):
            pj = zpipe[t, j]
            if pj >= 0:
                c[pj] += tr * zcot[t, j]
            vol[zk[t, j]] += a * zarea[t] / 3.0
    for p in range(c.shape[0]):
        if c[p] < 0.0:
            c[p] = 0.0


@njit(cache=True)
def network_steps(nsteps, dt, pa, pb, c, dg, vol, kw, fixed, q_in, p, flow):
    """``nsteps`` explicit steps of Δt [s] on the network with gravity: the pipe flow from pa to pb is
        Q_k = c_k (p_a − p_b + dg_k),   dg_k = −ρ_w g·(x_a − x_b)
    (the difference of p − ρ_w g·x: no flow in a column of water at rest). Δt is reduced to ``stable_dt``
    when larger; knots without volume keep their pressure. p updated in place, flow (npipe,) the last step's
    flows [m³/s]. Returns the Δt used."""
    h = stable_dt(pa, pb, c, vol, kw, fixed)
    if dt > h:
        dt = h
    nk = p.shape[0]
    net = np.empty(nk)
    for _ in range(nsteps):
        for i in range(nk):
            net[i] = q_in[i]
        for k in range(c.shape[0]):
            q = c[k] * (p[pa[k]] - p[pb[k]] + dg[k])
            flow[k] = q
            net[pa[k]] -= q
            net[pb[k]] += q
        for i in range(nk):
            if not fixed[i] and vol[i] > 0.0:
                p[i] += kw * dt / vol[i] * net[i]
    return dt


@njit(cache=True)
def sub_pressures(sknot, srep, scount, scontact, p, pp_apply, parea, zk, zsub, zw, zarea, pp, ppf):
    """The sub-contacts' pore pressures and their forces on the faces from the knots (``physics.flownet``).

    pp[s] = p[sknot[s]] + pp_apply[contact] (the pressure at its point; sub-contacts without a knot keep theirs).
    The force: each flow zone t pushes with F_t = A_t (p_a + p_b + p_c)/3 (the exact integral of the pressure,
    linear over the zone) at its centroid, handed to the sub-contacts of the coarse triangle that holds the
    centroid by its barycentric weights zw (so the resultant and its moment about any point in the plane are
    kept), each point's share split equally among the sub-contacts at that place (srep: the first of them,
    scount: how many); plus pp_apply A′ (parea). So a pressure that varies inside a contact (a drain under a
    dam) reaches the blocks, where the corner values alone would not show it. Without a knot:
    ppf[s] = pp[s] parea[s]."""
    ns = sknot.shape[0]
    acc = np.zeros(ns)
    for t in range(zk.shape[0]):
        f = zarea[t] * (p[zk[t, 0]] + p[zk[t, 1]] + p[zk[t, 2]]) / 3.0
        for j in range(3):
            acc[zsub[t, j]] += f * zw[t, j]
    for s in range(ns):
        k = sknot[s]
        if k >= 0:
            a = pp_apply[scontact[s]]
            pp[s] = p[k] + a
            r = srep[s]
            ppf[s] = acc[r] / scount[r] + a * parea[s]
        else:
            ppf[s] = pp[s] * parea[s]
