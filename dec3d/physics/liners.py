"""Liner structural elements in the cycle (3DEC/FLAC3D "Liner Structural Elements": flat 3-node shell
elements, 6 degrees of freedom per node, elastic and isotropic, coupled to the block surface they
were made on by normal and shear springs; stores ``dec3d.model.liners``, element ``kernels.dkt``
(DKT bending + CST membrane + a weak drilling spring), step ``kernels.liner``).

Elements are linear and small-displacement, their axes fixed at creation (as the beams'): the forces
are K d from the nodes' total displacements and rotations.

Coupling: per node, springs k_n A and k_s A (``coupling-stiffness-normal``/``-shear`` [Pa/m] times the
node's tributary area A, a third of each of its elements' areas), the normal one with tensile
strength ``coupling-yield-normal`` × A (then broken: compression only), the shear one a Coulomb
slider c A + f_n tan φ (``coupling-cohesion-shear``, falling to ``coupling-cohesion-shear-residual`` after
the first slip, ``coupling-friction-shear`` φ) — ``kernels.liner``. The host point is the block's
material point (rigid) or Σ wᵢ xᵢ of the zone holding the node (zoned: the node is at a gridpoint);
the reaction goes to the block's ``fapp``/``mapp`` or to the gridpoints (``cables.pass_reactions``).

Nodes: mass ρ t A/3 per element, rotary inertia ``model.liners.update_liner_masses``, moving with the
blocks' central-difference scheme and damping (``kernels.beam.move_nodes``, the beam nodes' law of
motion too); in static runs the inertia of each degree of freedom is max(real, R (Δt / 2s)²), R the
Gershgorin row sum of the assembled stiffness (coupling springs included) over that global
translation or rotation, so liners never cut the blocks' Δt (and their bending, much softer than their
membrane, is not slowed by it); with real masses they bound it (``liner_timestep``).
"""
from __future__ import annotations

import numpy as np

from dec3d.kernels.dkt import global_stiffness
from dec3d.kernels.liner import VMAX, liner_step
from dec3d.model.hosts import spread_stiffness
from dec3d.model.liners import (L_C, L_CR, L_E, L_KN, L_KS, L_NU, L_PHI, L_T, L_TY, has_liners, liner_stores,
                                node_areas, update_liner_masses)

#: ω_max Δt ≤ 2 s for the liner nodes
SAFETY = 0.5


def check_liners(model) -> str | None:
    if not has_liners(model):
        return None
    _, els = liner_stores(model)
    p = els["prop"]
    bad = np.flatnonzero((p[:, L_E] <= 0) | (p[:, L_T] <= 0))
    if bad.size:
        return (f"liner {int(els['liner'][bad[0]])} lacks `isotropic E ν` or `thickness`: set them with "
                f"`structure liner property` before cycling")
    return None


_KG_CACHE: dict = {}


def element_stiffness(model) -> np.ndarray:
    """(s, 18, 18) stiffness of each element in global axes (kept while the elements' geometry and
    properties stay as they are)."""
    _, els = liner_stores(model)
    sig = hash((els.n, els["prop"].tobytes(), els["lxy"].tobytes(), els["axes"].tobytes()))
    hit = _KG_CACHE.get(id(els))
    if hit is not None and hit[0] == sig:
        return hit[1]
    out = np.zeros((els.n, 18, 18))
    p = els["prop"]
    for e in range(els.n):
        x2, x3, y3 = els["lxy"][e]
        out[e] = global_stiffness(els["axes"][e], x2, x3, y3, p[e, L_E], p[e, L_NU], p[e, L_T])
    _KG_CACHE.clear()                 # (one model at a time: no stale matrices pile up)
    _KG_CACHE[id(els)] = (sig, out)
    return out


def coupling_table(model) -> np.ndarray:
    """(n, 6) per node: k_n A, k_s A, tensile yield force, cohesion force, residual cohesion force, tan φ
    (the sums over its elements' thirds; tan φ their area-weighted mean); zero for free nodes."""
    nodes, els = liner_stores(model)
    p = els["prop"]
    third = els["area"] / 3.0
    out = np.zeros((nodes.n, 6))
    w = np.zeros(nodes.n)
    cols = (L_KN, L_KS, L_TY, L_C, L_CR)
    for c in range(3):
        rows = els["nodes"][:, c]
        for j, col in enumerate(cols):
            np.add.at(out[:, j], rows, p[:, col] * third)
        np.add.at(out[:, 5], rows, np.tan(np.radians(p[:, L_PHI])) * third)
        np.add.at(w, rows, third)
    out[:, 5] = np.where(w > 0, out[:, 5] / np.where(w > 0, w, 1.0), 0.0)
    out[nodes["host"] < 0] = 0.0
    return out


def row_sums(model, kg=None, cpl=None) -> tuple[np.ndarray, np.ndarray]:
    """Per liner node (n, 3) each: the Gershgorin row sums of the assembled stiffness over its three
    translational rows and its three rotational rows (global axes; coupling springs included:
    k_n n nᵀ + k_s (I − n nᵀ) on the translations)."""
    nodes, els = liner_stores(model)
    kg = element_stiffness(model) if kg is None else kg
    cpl = coupling_table(model) if cpl is None else cpl
    rows = np.zeros((nodes.n, 6))
    for e in range(els.n):
        ks = np.abs(kg[e]).sum(axis=1)
        for c in range(3):
            rows[els["nodes"][e, c]] += ks[6 * c:6 * c + 6]
    n = nodes["nrm"]
    nn = n[:, :, None] * n[:, None, :]
    spring = cpl[:, 0, None, None] * nn + cpl[:, 1, None, None] * (np.eye(3)[None] - nn)
    return rows[:, :3] + np.abs(spring).sum(axis=2), rows[:, 3:].copy()


def liner_timestep(model) -> float:
    """The liner nodes' critical step with their real masses; inf without liners or densities."""
    if not has_liners(model) or check_liners(model):
        return np.inf
    update_liner_masses(model)
    nodes, _ = liner_stores(model)
    rt, rr = row_sums(model)
    out = np.inf
    for m, r in ((nodes["mass"], rt.max(axis=1)), (nodes["inert"], rr.max(axis=1))):
        on = (m > 0) & (r > 0)
        if on.any():
            out = min(out, float(2.0 * SAFETY * np.sqrt(m[on] / r[on]).min()))
    return out


def block_stiffness(model) -> tuple[np.ndarray, np.ndarray]:
    """Per block row: Σ max(k_n A, k_s A) of the liner couplings it hosts, and the same times |r|²."""
    b = model.blocks
    kt, kr = np.zeros(b.n), np.zeros(b.n)
    if not has_liners(model):
        return kt, kr
    nodes, _ = liner_stores(model)
    cpl = coupling_table(model)
    k = np.maximum(cpl[:, 0], cpl[:, 1])
    h = nodes["host"]
    on = (h >= 0) & (nodes["hz"] == 0)
    r2 = np.sum((nodes["hpos"][on] - b["centroid"][h[on]]) ** 2, axis=1)
    np.add.at(kt, h[on], k[on])
    np.add.at(kr, h[on], k[on] * r2)
    return kt, kr


def gridpoint_stiffness(model, n: int) -> np.ndarray:
    """Per vertex row: the Gershgorin sums of the couplings of liner nodes on zoned blocks."""
    out = np.zeros(n)
    if not has_liners(model):
        return out
    nodes, _ = liner_stores(model)
    zn = np.flatnonzero((nodes["hz"] != 0) & (nodes["host"] >= 0))
    if zn.size:
        cpl = coupling_table(model)
        spread_stiffness(out, nodes["hgp"][zn], nodes["hw"][zn], np.maximum(cpl[zn, 0], cpl[zn, 1]))
    return out


class LinerStep:
    """A step of the cycle (after ``physics.beams.BeamStep``) when the model has liners."""
    timing = "cycle"

    def __init__(self, run):
        from .rigid import RunError

        self.run = run
        bad = check_liners(run.m)
        if bad:
            raise RunError(bad)
        update_liner_masses(run.m)
        self.g = np.asarray(run.m.settings.gravity, dtype=np.float64)
        self.scaled = bool(run.eng.mass_scaling())
        nodes, els = liner_stores(run.m)
        if not self.scaled and ((nodes["mass"] <= 0) | (nodes["inert"] <= 0)).any():
            raise RunError("a liner has no density: without density scaling (dynamic mode, or damping "
                           "none/rayleigh) its nodes move with their real mass: set `structure liner property "
                           "density <f>`")
        self.kg = element_stiffness(run.m)
        self.cpl = coupling_table(run.m)
        self.rt, self.rr = row_sums(run.m, self.kg, self.cpl)
        self.conn = np.ascontiguousarray(els["nodes"])
        self.last = np.zeros((nodes.n, 6))

    def prepare(self) -> None:
        pass

    def advance(self, n: int) -> int:
        from .cables import _damping, host_motion, pass_reactions
        from .rigid import RunError

        r = self.run
        m, b = r.m, r.m.blocks
        nodes, _ = liner_stores(m)
        damp, a = _damping(r)
        old_f, old_m, zn, hvel = host_motion(m, nodes)
        hz = nodes["hz"]
        bad = liner_step(float(r.dt), self.g, a, damp, SAFETY if self.scaled else 0.0,
                         nodes["pos"], nodes["vel"], nodes["disp"], nodes["rot"], nodes["avel"], nodes["mass"],
                         nodes["inert"], self.rt, self.rr, nodes["host"], hz, hvel, nodes["hpos"], nodes["nrm"],
                         self.cpl, nodes["un"], nodes["fn"], nodes["fs"], nodes["cstate"], nodes["fix"],
                         nodes["fapp"], nodes["mapp"], nodes["force"], nodes["moment"], nodes["hforce"],
                         nodes["hmoment"], nodes["imass"], nodes["iinert"], self.kg, self.conn,
                         b["velocity"], b["spin"], b["centroid"], self.last)
        if bad:
            raise RunError(f"a liner node ran away (a speed over {VMAX:g} m/s, or off to infinity) at step "
                           f"{m.step + 1} (Δt {r.dt:.3g} s): check the liner properties and the loads on its nodes")
        pass_reactions(m, nodes, old_f, old_m, zn)
        return min(n, 1)

    def __repr__(self) -> str:
        return "LinerStep"


def liner_balance(model) -> tuple[np.ndarray, np.ndarray]:
    """(unbalanced force, applied force magnitude) of each free liner node at the last step, counted as
    bodies in the equilibrium ratio: |F| over the free translations, and |m g| + |F_app| + |coupling
    force| + Σ |K d| of its elements' translational rows."""
    if not has_liners(model):
        return np.zeros(0), np.zeros(0)
    nodes, els = liner_stores(model)
    free = ((nodes["fix"][:, None].astype(np.int64) >> np.arange(3)[None, :]) & 1) == 0
    un = np.linalg.norm(np.where(free, nodes["force"], 0.0), axis=1)
    g = np.linalg.norm(np.asarray(model.settings.gravity, float))
    a = nodes["mass"] * g + np.linalg.norm(nodes["fapp"], axis=1) + np.linalg.norm(nodes["hforce"], axis=1)
    kg = element_stiffness(model)
    d = np.concatenate([np.concatenate([nodes["disp"][els["nodes"][:, c]], nodes["rot"][els["nodes"][:, c]]], axis=1)
                        for c in range(3)], axis=1)
    f = np.einsum("epq,eq->ep", kg, d)
    for c in range(3):
        np.add.at(a, els["nodes"][:, c], np.linalg.norm(f[:, 6 * c:6 * c + 3], axis=1))
    on = free.any(axis=1)
    return un[on], a[on]
