"""Flow in the joints on a network of knots and pipes (3DEC theory, "Joint Fluid Flow": the cubic law),
explicit transient step. Groundwork of issue 29 item 2: the network is given as arrays (not built from the
contacts yet; ``dec3d.physics.jointflow`` has the steady solve).

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
    """The largest stable Δt [s]: 0.5 min_i vol_i / (K_w Σ_{k at i} c_k) over the unfixed knots (inf when
    none has a pipe)."""
    s = np.zeros(vol.shape[0])
    for k in range(c.shape[0]):
        s[pa[k]] += c[k]
        s[pb[k]] += c[k]
    dt = np.inf
    for i in range(vol.shape[0]):
        if not fixed[i] and s[i] > 0.0:
            t = 0.5 * vol[i] / (kw * s[i])
            if t < dt:
                dt = t
    return dt


@njit(cache=True)
def flow_steps(nsteps, dt, pa, pb, c, vol, kw, fixed, q_in, p, flow):
    """``nsteps`` explicit steps of Δt [s] (reduced to ``stable_dt`` if larger: never blown up); p (nk,)
    updated in place, flow (npipe,) the last step's pipe flows [m³/s]. Returns the Δt used."""
    h = stable_dt(pa, pb, c, vol, kw, fixed)
    if dt > h:
        dt = h
    nk = p.shape[0]
    net = np.empty(nk)
    for _ in range(nsteps):
        for i in range(nk):
            net[i] = q_in[i]
        for k in range(c.shape[0]):
            q = c[k] * (p[pa[k]] - p[pb[k]])
            flow[k] = q
            net[pa[k]] -= q
            net[pb[k]] += q
        for i in range(nk):
            if not fixed[i]:
                p[i] += kw * dt / vol[i] * net[i]
    return dt
