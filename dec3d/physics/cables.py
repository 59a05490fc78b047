"""Grouted cable structural elements in the cycle (3DEC/FLAC3D "Cable Structural Elements" and
"Shear Behavior of Grout Annulus", Itasca manuals, docs.itascacg.com …/sel_manual/cables/cables.html).

Model (Itasca's, as those pages state it):

* A cable is a chain of straight elements between nodes. Each element is elastic, perfectly plastic in
  its axis and has no bending stiffness: the axial force follows, incrementally,
  ΔF = (E A / L) ΔL, and is held within  −F_c ≤ F ≤ F_t  (``yield-compression`` F_c, ``yield-tension``
  F_t; dec3d reads 0 as "no limit", see the command page).
* The grout annulus couples each node to the rock around it in the cable's axis: a spring of stiffness
  k_g per length (``grout-stiffness`` [N/m/m]) acting on the relative axial displacement u_c − u_m of
  cable and rock, elastic, perfectly plastic, with the strength per length
      F_s / L = c_g + σ_m · tan(φ_g) · p_g
  (``grout-cohesion`` c_g [N/m], ``grout-friction`` φ_g, ``grout-perimeter`` p_g [m], σ_m the
  confining stress around the node). The force on the node is that per-length force times the node's
  tributary length: each element gives half its length to each of its nodes (so a node inside a
  chain has L, an end node L/2). The equal and opposite force acts on the host at the host point.
* Rigid hosts: the host point moves with the block (v = v_c + ω × r), the reaction goes to the block
  as a force and a moment about its centroid (through the block's applied force and moment, as a
  change from the last step). A rigid block has no stress field, so σ_m = 0 there and only the
  cohesion bounds the grout.
* Deformable hosts: the node follows the element that holds it (``model.hosts``: a 4-node zone by
  its barycentric weights, a 10-node zone or an FE block's 20-node brick by its shape functions at
  the node, all fixed at creation): the host point is Σ wᵢ xᵢ over the element's nodes, its velocity
  Σ wᵢ vᵢ, and the reaction goes to the nodes' applied forces as wᵢ F (consistent nodal forces of a
  point load). σ_m is the mean of the element's normal stresses across the cable, −(tr σ − tᵀ σ t) / 2
  (``zone_host_state``; a 10-node zone's or a brick's mean stress), so friction and perimeter count
  there. The grout stiffness enters the nodes' stiffness sums (k_g × tributary length × |wᵢ| Σ|wⱼ|,
  ``gridpoint_grout_stiffness``, added in ``ZoneStepper._stiffness``), hence their scaled masses.

Across the cable a hosted node is linked rigidly to its host (Itasca's cable nodes: only the axial
direction of the link is deformable, through the grout): it takes the host point's velocity in the
two directions normal to the cable (the cable's direction at the node: the mean of its elements'
unit vectors), and the force on it across the cable (the axial forces of a bent chain, its weight,
an applied force) goes to the host with the grout reaction. So a block sliding across a cable carries
the cable's nodes with it (the cable turns and bends at the joint), and a cable in compression cannot
buckle sideways through the rock. A node with held components (`structure node fix`) is not linked.

Motion: the nodes carry mass and move explicitly with the blocks' central-difference scheme, as
Itasca's structural-element nodes do, with combined damping (3DEC theory Eq. 83, the form meant for
parts in steady motion, such as a cable being pulled out: local damping, Eq. 79, takes only the sign
of the velocity, which does not change in a steady pull, and left a pulled chain ringing 20 % over its
capacity) in static mode and none in dynamic mode (or with Rayleigh/no damping).
With density scaling on (static runs), a node's inertial mass is the larger of its real mass
(``density`` × area × tributary length) and the mass that keeps it stable at the run's Δt,
R (Δt / 2s)², with R the Gershgorin row sum of the stiffness at the node (2 E A / L per element +
k_g × tributary length) and s = ``SAFETY``: density scaling of the nodes (3DEC theory, "Mass (Density)
Scaling"), so a cable never shortens the blocks' static step. Without it (dynamic mode, damping none
or Rayleigh) the nodes keep their real masses (a density is then required) and bound Δt by
2 s √(m / R) (``cable_timestep``): a scaled node dragged along by its block adds its inertia to the
block's (SE2's bolted block slid 7 % slow with the scaled head node).
The grout stiffness enters the blocks' stiffness sums (density scaling, Eq. 87 and the
unscaled Δt: ``block_stiffness``), so a block held by cables has a stable step too.

The step (``CableStep``) runs first in each step of the cycle, which it cuts into single steps:
kernel ``kernels.cable.cable_step`` (forces at t, node velocities to t + Δt/2), then the change of
the grout reactions goes into the host blocks' ``fapp``/``mapp`` before the block step.
"""
from __future__ import annotations

import numpy as np

from dec3d.kernels.cable import C_A, C_E, C_KG, cable_step, empty_scratch
from dec3d.kernels.motion import DAMP_ADAPTIVE, DAMP_COMBINED, DAMP_LOCAL, block_timestep
from dec3d.model.cables import cable_stores, has_cables, update_masses
from dec3d.model.hosts import host_stress, spread_stiffness

from dec3d.model.beams import has_beams

from .beams import BeamStep, beam_timestep
from .beams import block_stiffness as beam_block_stiffness
from .beams import gridpoint_stiffness as beam_gridpoint_stiffness
from .dowels import advance_dowels
from .liners import LinerStep, liner_timestep
from .liners import block_stiffness as liner_block_stiffness
from .liners import gridpoint_stiffness as liner_gridpoint_stiffness
from dec3d.model.liners import has_liners
from .dowels import block_stiffness as dowel_block_stiffness
from .dowels import gridpoint_stiffness as dowel_gridpoint_stiffness

#: ω_max Δt ≤ 2 s for the cable nodes (s = 0.5: ω Δt ≤ 1, as the local damping likes it)
SAFETY = 0.5

#: damping coefficient of the cable nodes when the blocks use adaptive (global) damping
ALPHA_DEFAULT = 0.8


def check_cables(model) -> str | None:
    """Why the cables cannot be cycled (None: they can)."""
    if not has_cables(model):
        return None
    _, segs = cable_stores(model)
    p = segs["prop"]
    bad = np.flatnonzero((p[:, C_E] <= 0) | (p[:, C_A] <= 0))
    if bad.size:
        cid = int(segs["cable"][bad[0]])
        return (f"cable {cid} has no `young` or `cross-sectional-area`: set them with "
                f"`structure cable property young <f> cross-sectional-area <f>` before cycling")
    return None


def block_stiffness(model) -> tuple[np.ndarray, np.ndarray]:
    """Per block row: Σ k_g × tributary length of the grout springs it hosts [N/m], and the same
    weighted by |r|² (r: host point − block centroid) [N·m] (its rotational bound); with the dowels
    of hybrid bolts and the links of beams."""
    b = model.blocks
    kt, kr = beam_block_stiffness(model)          # beam links (``physics.beams``)
    if has_liners(model):                         # liner couplings (``physics.liners``)
        lt, lr = liner_block_stiffness(model)
        kt, kr = kt + lt, kr + lr
    if not has_cables(model):
        return kt, kr
    nodes, segs = cable_stores(model)
    kend = segs["prop"][:, C_KG] * 0.5 * segs["l0"]
    kn = np.zeros(nodes.n)
    np.add.at(kn, segs["na"], kend)
    np.add.at(kn, segs["nb"], kend)
    h = nodes["host"]
    on = (h >= 0) & (nodes["hz"] == 0)
    r2 = np.sum((nodes["hpos"][on] - b["centroid"][h[on]]) ** 2, axis=1)
    np.add.at(kt, h[on], kn[on])
    np.add.at(kr, h[on], kn[on] * r2)
    dkt, dkr = dowel_block_stiffness(model)      # dowels of hybrid bolts (``physics.dowels``)
    return kt + dkt, kr + dkr


def cable_timestep(model) -> float:
    """The cable nodes' critical step with their real masses, 2 s √(m / R) (R: the Gershgorin row sum
    of the stiffness at the node, s = ``SAFETY``); inf without cables or densities. The beams' too
    (``physics.beams.beam_timestep``)."""
    if not has_cables(model):
        return min(beam_timestep(model), liner_timestep(model))
    nodes, segs = cable_stores(model)
    p = segs["prop"]
    r = np.zeros(nodes.n)
    ka = 2.0 * p[:, C_E] * p[:, C_A] / segs["l0"]
    np.add.at(r, segs["na"], ka)
    np.add.at(r, segs["nb"], ka)
    kend = p[:, C_KG] * 0.5 * segs["l0"]
    np.add.at(r, segs["na"], np.where(nodes["host"][segs["na"]] >= 0, kend, 0.0))
    np.add.at(r, segs["nb"], np.where(nodes["host"][segs["nb"]] >= 0, kend, 0.0))
    m = nodes["mass"]
    on = (r > 0) & (m > 0)
    dt = float(2.0 * SAFETY * np.sqrt(m[on] / r[on]).min()) if on.any() else np.inf
    return min(dt, beam_timestep(model), liner_timestep(model))


def grouted_timestep(model, frac: float, moving=None) -> float:
    """Eq. (87) for each (moving) block hosting grout: its mass against its grout stiffness (inf: none)."""
    kt, _ = block_stiffness(model)
    m = model.blocks["mass"]
    on = (kt > 0) & (m > 0)
    if moving is not None:
        on &= moving
    if not on.any():
        return np.inf
    return float(min(block_timestep(float(mm), float(k), frac) for mm, k in zip(m[on], kt[on])))


class CableStep:
    """A step of the cycle (first in ``steps._Run.steps`` when the model has cables)."""
    timing = "cycle"

    def __init__(self, run):
        self.run = run
        bad = check_cables(run.m)
        if bad:
            raise _run_error(bad)
        update_masses(run.m)
        self.g = np.asarray(run.m.settings.gravity, dtype=np.float64)
        #: density scaling of the nodes: with the blocks' (static runs); else real masses, and the
        #: cable bounds Δt (``cable_timestep``, in ``RigidEngine.timestep``)
        self.scaled = bool(run.eng.mass_scaling())
        if not self.scaled:
            nodes, _ = cable_stores(run.m)
            if (nodes["mass"] <= 0).any():
                raise _run_error("a cable has no density: without density scaling (dynamic mode, or damping "
                                 "none/rayleigh) its nodes move with their real mass: set `structure cable "
                                 "property density <f>`")

    def prepare(self) -> None:
        pass

    def advance(self, n: int) -> int:
        r = self.run
        m, b = r.m, r.m.blocks
        nodes, segs = cable_stores(m)
        damp, a = _damping(r)
        old_f = nodes["hforce"].copy()
        old_m = nodes["hmoment"].copy()
        hz = nodes["hz"]
        zn = np.flatnonzero((hz != 0) & (nodes["host"] >= 0))
        conf = np.zeros(nodes.n)
        hvel = np.zeros((nodes.n, 3))
        if zn.size:
            conf[zn], hvel[zn] = zone_host_state(m, nodes, segs, zn)
        bad = cable_step(float(r.dt), self.g, a, damp, SAFETY if self.scaled else 0.0,
                         nodes["pos"], nodes["vel"], nodes["disp"], nodes["mass"], nodes["host"], nodes["hpos"],
                         nodes["fix"], nodes["fapp"], conf, nodes["force"], nodes["hforce"], nodes["hmoment"],
                         nodes["imass"], hz, hvel, segs["na"], segs["nb"], segs["l0"], segs["lcur"], segs["prop"],
                         segs["fa"], segs["gf"], segs["state"], segs["tapp"], segs["tact"],
                         b["velocity"], b["spin"], b["centroid"], empty_scratch(nodes.n))
        if bad:
            raise _run_error(f"a cable node moved off to infinity at step {m.step + 1} (Δt {r.dt:.3g} s): "
                             f"check the cable and grout properties")
        advance_dowels(m, r.dt)   # hybrid bolts' dowels
        pass_reactions(m, nodes, old_f, old_m, zn)
        # (segments clear their "now" bits at the next step: the kernel rebuilds them)
        return min(n, 1)

    def __repr__(self) -> str:
        return "CableStep"


def pass_reactions(m, nodes, old_f, old_m, zn) -> None:
    """The change since the last step of the structural nodes' reactions on their hosts (``hforce``,
    ``hmoment``; ``old_f``, ``old_m`` as they were) into the hosts' applied loads: a rigid block's
    ``fapp``/``mapp``, a zoned host's gridpoints' ``fapp`` by the node's weights (nodes ``zn``).
    Cables and beams (``physics.beams``) hand theirs on this way."""
    b = m.blocks
    h, hz = nodes["host"], nodes["hz"]
    on = (h >= 0) & (hz == 0)
    if on.any():
        np.add.at(b["fapp"], h[on], nodes["hforce"][on] - old_f[on])
        np.add.at(b["mapp"], h[on], nodes["hmoment"][on] - old_m[on])
    if zn.size:
        df = nodes["hforce"][zn] - old_f[zn]
        np.add.at(m.vertices["fapp"], nodes["hgp"][zn].ravel(),
                  (nodes["hw"][zn][:, :, None] * df[:, None, :]).reshape(-1, 3))


def host_motion(m, nodes) -> tuple:
    """Before a step of 6-degree-of-freedom structural nodes (beams, liners): (the reactions on the
    hosts as they are, ``hforce`` and ``hmoment`` copied for ``pass_reactions``; the rows ``zn`` of the
    nodes held by zones; each node's host velocity ``hvel`` (n, 3), Σ wᵢ vᵢ over its zone's gridpoints,
    zero for the others), with ``hpos`` of the nodes in zones brought to Σ wᵢ xᵢ."""
    old_f = nodes["hforce"].copy()
    old_m = nodes["hmoment"].copy()
    zn = np.flatnonzero((nodes["hz"] != 0) & (nodes["host"] >= 0))
    hvel = np.zeros((nodes.n, 3))
    if zn.size:
        v = m.vertices
        w, gp = nodes["hw"][zn], nodes["hgp"][zn]
        nodes["hpos"][zn] = np.einsum("kj,kjc->kc", w, v["pos"][gp])
        hvel[zn] = np.einsum("kj,kjc->kc", w, v["velocity"][gp])
    return old_f, old_m, zn, hvel


def _damping(r) -> tuple[int, float]:
    """(damping kind for the structural nodes: 0 none, 2 combined; its coefficient) of run ``r``."""
    mode, alpha = r.mode, r.alpha
    if r.dynamic or mode not in (DAMP_LOCAL, DAMP_COMBINED, DAMP_ADAPTIVE):
        return 0, 0.0
    return 2, (float(alpha) if mode in (DAMP_LOCAL, DAMP_COMBINED) else ALPHA_DEFAULT)


def zone_host_state(m, nodes, segs, zn):
    """For the zone-hosted nodes ``zn``: (confining stress [Pa, compression positive], host-point
    velocity (k, 3)), and their host points set from the gridpoints. The confinement is the mean of the
    zone's normal stresses across the cable, −(tr σ − tᵀ σ t) / 2 (t: the axis of an element at the
    node; 3DEC's stresses are tension positive)."""
    v = m.vertices
    w, gp = nodes["hw"][zn], nodes["hgp"][zn]
    nodes["hpos"][zn] = np.einsum("kj,kjc->kc", w, v["pos"][gp])
    hvel = np.einsum("kj,kjc->kc", w, v["velocity"][gp])
    # an element at each node (the one it starts, else the one it ends)
    seg = np.full(nodes.n, -1, np.int64)
    seg[segs["nb"]] = np.arange(segs.n)
    seg[segs["na"]] = np.arange(segs.n)
    e = seg[zn]
    d = nodes["pos"][segs["nb"][e]] - nodes["pos"][segs["na"][e]]
    t = d / np.linalg.norm(d, axis=1)[:, None]
    sx = host_stress(m, nodes["hz"][zn], nodes["hzone"][zn])      # xx yy zz xy xz yz
    tr = sx[:, 0] + sx[:, 1] + sx[:, 2]
    tst = (sx[:, 0] * t[:, 0] ** 2 + sx[:, 1] * t[:, 1] ** 2 + sx[:, 2] * t[:, 2] ** 2
           + 2.0 * (sx[:, 3] * t[:, 0] * t[:, 1] + sx[:, 4] * t[:, 0] * t[:, 2] + sx[:, 5] * t[:, 1] * t[:, 2]))
    return -(tr - tst) / 2.0, hvel


def gridpoint_grout_stiffness(m, n: int) -> np.ndarray:
    """Per vertex row (length n): Σ k_g × tributary length × weight of the grout springs on it [N/m]
    (a grout spring on a host point Σ wᵢ xᵢ adds wᵢ k to gridpoint i's Gershgorin row: Σ wⱼ = 1)."""
    out = beam_gridpoint_stiffness(m, n)          # links of beam nodes in zones (``physics.beams``)
    if has_liners(m):
        out += liner_gridpoint_stiffness(m, n)    # couplings of liner nodes on zoned blocks
    if not has_cables(m):
        return out
    out += dowel_gridpoint_stiffness(m, n)
    nodes, segs = cable_stores(m)
    zn = np.flatnonzero((nodes["hz"] != 0) & (nodes["host"] >= 0))
    if not zn.size:
        return out
    kend = segs["prop"][:, C_KG] * 0.5 * segs["l0"]
    kn = np.zeros(nodes.n)
    np.add.at(kn, segs["na"], kend)
    np.add.at(kn, segs["nb"], kend)
    spread_stiffness(out, nodes["hgp"][zn], nodes["hw"][zn], kn[zn])
    return out


def _run_error(msg: str):
    from .rigid import RunError
    return RunError(msg)


def cable_steps(run) -> list:
    """[CableStep] when the model has cables, [BeamStep] when it has beams (``physics.beams``), [LinerStep]
    when it has liners (``physics.liners``)."""
    return (([CableStep(run)] if has_cables(run.m) else []) + ([BeamStep(run)] if has_beams(run.m) else [])
            + ([LinerStep(run)] if has_liners(run.m) else []))
