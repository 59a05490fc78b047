"""Beam structural elements in the cycle (3DEC/FLAC3D "Beam Structural Elements": straight 2-node
elements of uniform section, 6 degrees of freedom per node, elastic; stores ``dec3d.model.beams``,
kernel ``dec3d.kernels.beam``).

Element: a 3-D Euler-Bernoulli beam in its own axes (x from node a to node b, y as
``direction-y`` made normal to x, or horizontal by default, z = x × y), linear and small-displacement:
the end forces are K d, d the total displacements and rotations of its nodes in its axes, with
    axial EA/L, torsion GJ/L (G = E / 2(1 + ν), J = ``moi-polar``),
    bending in x-y (v, θz): E I_z / L³ [12, 6L, −12, 6L; 6L, 4L², −6L, 2L²; …],
    bending in x-z (w, θy): E I_y / L³ [12, −6L, −12, −6L; −6L, 4L², 6L, 2L²; …] (θy = −dw/dx).
Large rotations of the beam are not followed (the axes stay those of creation): a beam is meant for
supports that deform little, as a liner or a pile.

Nodes: mass ρ A × tributary length, rotary inertia ρ (I_y + I_z) × tributary length + m l²/3
(``update_beam_masses``), moving with the blocks' central-difference scheme and damping (combined in
static mode, none in dynamic mode, as the cable nodes). In static runs (density scaling) each node's
inertial mass and rotary inertia are max(real, R (Δt / 2s)²), R the Gershgorin row sum of the
assembled stiffness over its translational / rotational rows (``row_sums``), so beams never cut the
blocks' Δt; with real masses they bound it (``beam_timestep``).

Links: a node created inside a visible rigid block is linked to it by springs from the node to the
block's material point there, translational k_l = ``LINK`` × max(EA/L, 12 E I/L³) and rotational
k_r = ``LINK`` × max(4 E I/L, GJ/L) over its elements (I the larger of I_y, I_z): a stiff, "rigid"
link that the explicit scheme can carry. The link forces (incremental) act on the block through its
``fapp``/``mapp`` (as a change from the last step, as the cables' grout) and enter its stiffness sums.
A node in a zoned block follows the 4-node zone that holds it: its host point is Σ wᵢ xᵢ over the
zone's gridpoints (barycentric weights fixed at creation), the translational link acts on the
relative velocity to Σ wᵢ vᵢ and its reaction goes to the gridpoints as wᵢ F (a zone has no rotation:
no rotational link there); wᵢ k_l enters the gridpoints' stiffness (``gridpoint_stiffness``). Nodes in
FE blocks or 10-node zones are refused at creation; `structure node fix` holds nodes (and rotations).
"""
from __future__ import annotations

import numpy as np

from dec3d.kernels.beam import B_A, B_E, B_IY, B_IZ, B_J, B_NU, VMAX, beam_step, local_stiffness
from dec3d.model.beams import beam_stores, has_beams, update_beam_masses
from dec3d.model.hosts import spread_stiffness

#: ω_max Δt ≤ 2 s for the beam nodes
SAFETY = 0.5
#: link stiffness over the stiffest element term at the node
LINK = 10.0
ALPHA_DEFAULT = 0.8


def check_beams(model) -> str | None:
    if not has_beams(model):
        return None
    _, els = beam_stores(model)
    p = els["prop"]
    bad = np.flatnonzero((p[:, B_E] <= 0) | (p[:, B_A] <= 0) | (p[:, B_IY] <= 0) | (p[:, B_IZ] <= 0)
                         | (p[:, B_J] <= 0))
    if bad.size:
        return (f"beam {int(els['beam'][bad[0]])} lacks `young`, `cross-sectional-area`, `moi-y`, `moi-z` or "
                f"`moi-polar`: set them with `structure beam property` before cycling")
    return None


def _global_k(els, e) -> np.ndarray:
    k = np.zeros((12, 12))
    p = els["prop"][e]
    local_stiffness(p[B_E], p[B_NU], p[B_A], p[B_IY], p[B_IZ], p[B_J], float(els["l0"][e]), k)
    t = np.zeros((12, 12))
    for blk in range(4):
        t[3 * blk:3 * blk + 3, 3 * blk:3 * blk + 3] = els["axes"][e]
    return t.T @ k @ t


def link_stiffness(model) -> tuple[np.ndarray, np.ndarray]:
    """Per beam node: (k_l, k_r) of its link to its host block (0 for free nodes)."""
    nodes, els = beam_stores(model)
    p = els["prop"]
    ln = els["l0"]
    imax = np.maximum(p[:, B_IY], p[:, B_IZ])
    g = p[:, B_E] / (2.0 * (1.0 + p[:, B_NU]))
    kt = np.maximum(p[:, B_E] * p[:, B_A] / ln, 12.0 * p[:, B_E] * imax / ln ** 3)
    kr = np.maximum(4.0 * p[:, B_E] * imax / ln, g * p[:, B_J] / ln)
    klt, klr = np.zeros(nodes.n), np.zeros(nodes.n)
    for arr, v in ((klt, kt), (klr, kr)):
        np.maximum.at(arr, els["na"], v)
        np.maximum.at(arr, els["nb"], v)
    free = nodes["host"] < 0
    klt[free] = 0.0
    klr[free] = 0.0
    klr[nodes["hz"] != 0] = 0.0          # (a zone has no rotation to link to)
    return LINK * klt, LINK * klr


def row_sums(model) -> tuple[np.ndarray, np.ndarray]:
    """Per beam node: the largest Gershgorin row sum of the assembled stiffness over its
    translational rows and over its rotational rows (links included)."""
    nodes, els = beam_stores(model)
    rows = np.zeros((nodes.n, 6))
    for e in range(els.n):
        kg = np.abs(_global_k(els, e)).sum(axis=1)
        rows[els["na"][e]] += kg[:6]
        rows[els["nb"][e]] += kg[6:]
    klt, klr = link_stiffness(model)
    return rows[:, :3].max(axis=1) + klt, rows[:, 3:].max(axis=1) + klr


def beam_timestep(model) -> float:
    """The beam nodes' critical step with their real masses, 2 s √(min(m / R_t, I / R_r)); inf
    without beams or densities."""
    if not has_beams(model):
        return np.inf
    update_beam_masses(model)
    nodes, _ = beam_stores(model)
    rt, rr = row_sums(model)
    out = np.inf
    for m, r in ((nodes["mass"], rt), (nodes["inert"], rr)):
        on = (m > 0) & (r > 0)
        if on.any():
            out = min(out, float(2.0 * SAFETY * np.sqrt(m[on] / r[on]).min()))
    return out


def block_stiffness(model) -> tuple[np.ndarray, np.ndarray]:
    """Per block row: Σ k_l of the beam links it hosts, and Σ (k_r + k_l |r|²)."""
    b = model.blocks
    kt, kr = np.zeros(b.n), np.zeros(b.n)
    if not has_beams(model):
        return kt, kr
    nodes, _ = beam_stores(model)
    klt, klr = link_stiffness(model)
    h = nodes["host"]
    on = (h >= 0) & (nodes["hz"] == 0)
    r2 = np.sum((nodes["hpos"][on] - b["centroid"][h[on]]) ** 2, axis=1)
    np.add.at(kt, h[on], klt[on])
    np.add.at(kr, h[on], klr[on] + klt[on] * r2)
    return kt, kr


def gridpoint_stiffness(model, n: int) -> np.ndarray:
    """Per vertex row: the Gershgorin sums of the links of beam nodes in deformable blocks
    (``model.hosts.spread_stiffness``)."""
    out = np.zeros(n)
    if not has_beams(model):
        return out
    nodes, _ = beam_stores(model)
    zn = np.flatnonzero((nodes["hz"] != 0) & (nodes["host"] >= 0))
    if zn.size:
        klt, _ = link_stiffness(model)
        spread_stiffness(out, nodes["hgp"][zn], nodes["hw"][zn], klt[zn])
    return out


class BeamStep:
    """A step of the cycle (next to ``physics.cables.CableStep``) when the model has beams."""
    timing = "cycle"

    def __init__(self, run):
        from .rigid import RunError

        self.run = run
        bad = check_beams(run.m)
        if bad:
            raise RunError(bad)
        update_beam_masses(run.m)
        self.g = np.asarray(run.m.settings.gravity, dtype=np.float64)
        self.scaled = bool(run.eng.mass_scaling())
        nodes, _ = beam_stores(run.m)
        if not self.scaled and ((nodes["mass"] <= 0) | (nodes["inert"] <= 0)).any():
            raise RunError("a beam has no density: without density scaling (dynamic mode, or damping none/rayleigh) "
                           "its nodes move with their real mass: set `structure beam property density <f>`")
        rt, rr = row_sums(run.m)
        # (the law of motion takes a row sum per degree of freedom: a beam node's three are equal)
        self.rt, self.rr = np.repeat(rt[:, None], 3, axis=1), np.repeat(rr[:, None], 3, axis=1)
        self.klt, self.klr = link_stiffness(run.m)
        self.last = np.zeros((nodes.n, 6))

    def prepare(self) -> None:
        pass

    def advance(self, n: int) -> int:
        from .cables import _damping, host_motion, pass_reactions
        from .rigid import RunError

        r = self.run
        m, b = r.m, r.m.blocks
        nodes, els = beam_stores(m)
        damp, a = _damping(r)
        old_f, old_m, zn, hvel = host_motion(m, nodes)
        hz = nodes["hz"]
        bad = beam_step(float(r.dt), self.g, a, damp, SAFETY if self.scaled else 0.0,
                        nodes["pos"], nodes["vel"], nodes["disp"], nodes["rot"], nodes["avel"], nodes["mass"],
                        nodes["inert"], self.rt, self.rr, nodes["host"], hz, hvel, nodes["hpos"], self.klt, self.klr,
                        nodes["lf"], nodes["lm"], nodes["fix"], nodes["fapp"], nodes["mapp"], nodes["force"],
                        nodes["moment"], nodes["hforce"], nodes["hmoment"], nodes["imass"], nodes["iinert"],
                        els["na"], els["nb"], els["l0"], els["prop"], els["axes"], els["fl"],
                        b["velocity"], b["spin"], b["centroid"], self.last)
        if bad:
            raise RunError(f"a beam node ran away (a speed over {VMAX:g} m/s, or off to infinity) at step {m.step + 1} (Δt {r.dt:.3g} s): check the "
                           f"beam properties")
        pass_reactions(m, nodes, old_f, old_m, zn)
        return min(n, 1)

    def __repr__(self) -> str:
        return "BeamStep"


def beam_balance(model) -> tuple[np.ndarray, np.ndarray]:
    """(unbalanced force, applied force magnitude) of each free beam node at the last step, counted as
    bodies in the equilibrium ratio (``rigid.RigidEngine.criteria``): |F| over the free translations,
    and |m g| + |F_app| + |link force| + Σ |end force| of its elements."""
    if not has_beams(model):
        return np.zeros(0), np.zeros(0)
    nodes, els = beam_stores(model)
    free = np.array([[not (int(f) >> k) & 1 for k in range(3)] for f in nodes["fix"]], bool).reshape(-1, 3)
    un = np.linalg.norm(np.where(free, nodes["force"], 0.0), axis=1)
    g = np.linalg.norm(np.asarray(model.settings.gravity, float))
    a = nodes["mass"] * g + np.linalg.norm(nodes["fapp"], axis=1) + np.linalg.norm(nodes["lf"], axis=1)
    np.add.at(a, els["na"], np.linalg.norm(els["fl"][:, 0:3], axis=1))
    np.add.at(a, els["nb"], np.linalg.norm(els["fl"][:, 6:9], axis=1))
    on = free.any(axis=1)
    return un[on], a[on]
