"""The state of an SSDEM analysis as plain arrays.

A `Problem` is what both readers produce and what the solver consumes: blocks
(polygons, reference points, fixity, loads), interfaces (geometry and spring /
strength parameters) and run settings.  SI units throughout: N, m, Pa, N/m^3,
Pa/m for spring constants; forces are per metre of slope (plane strain); angles
in the arrays are radians or tangents, degrees only at the input boundary.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import geometry


@dataclass
class Blocks:
    """n blocks.

    verts (nv, 2), offsets (n+1,): CSR polygons, counter-clockwise
    ref (n, 2): the point whose motion (u_x, u_y, omega) are the block's DOFs
        (the centroid unless an Appendix A file gives another point)
    area (n,), fixed (n,) bool: every DOF fixed (a boundary block of the thesis)
    fix (n, 3) bool: fixed DOFs (u_x, u_y, omega); a roller side block fixes u_x and omega
    layer (n,) int (-1: none)
    force (n, 3): load at full loading [F_x, F_y, M about ref], N and N*m per m
    """

    verts: np.ndarray
    offsets: np.ndarray
    ref: np.ndarray
    area: np.ndarray
    fixed: np.ndarray
    layer: np.ndarray
    force: np.ndarray
    fix: np.ndarray = None

    @property
    def n(self) -> int:
        return len(self.offsets) - 1

    def polygon(self, i: int) -> np.ndarray:
        return self.verts[self.offsets[i]:self.offsets[i + 1]]


@dataclass
class Interfaces:
    """m interfaces (block edges shared by two blocks, at least one free).

    a, b (m,): blocks; `normal` (m, 2) points from a to b
    p0, p1, mid (m, 2); length (m,)
    kn, ks (m,): initial spring constants, Pa/m
    c_p, tan_p, c_r, tan_r (m,): peak / residual cohesion (Pa) and tan(phi)
    del_res (m,): shear displacement at the onset of residual strength, m
    tensile (m,): tensile strength, Pa; cutoff (m,) bool: tension cut-off applies
    u_pore (m,): pore pressure at full load, Pa (standard definition, u = r_u*gamma*h
        or from a piezometric line); unused in the listing's r_u mode
    on_surface (m,) bool: lies on a prescribed failure surface
    side_a, side_b (m,): local side index in a and b (Appendix A side numbers)
    """

    a: np.ndarray
    b: np.ndarray
    p0: np.ndarray
    p1: np.ndarray
    mid: np.ndarray
    length: np.ndarray
    normal: np.ndarray
    side_a: np.ndarray
    side_b: np.ndarray
    kn: np.ndarray = None
    ks: np.ndarray = None
    c_p: np.ndarray = None
    tan_p: np.ndarray = None
    c_r: np.ndarray = None
    tan_r: np.ndarray = None
    del_res: np.ndarray = None
    tensile: np.ndarray = None
    cutoff: np.ndarray = None
    u_pore: np.ndarray = None
    on_surface: np.ndarray = None

    @property
    def m(self) -> int:
        return len(self.a)


@dataclass
class Settings:
    """How the analysis runs.

    n_steps: load increments to full load ("iterations" in the thesis)
    tol: convergence when max |k_s change| / k_s (the current secant) < tol in a step
    max_iter: secant iterations per load step before giving up on the step
    ru, ru_mode: pore pressure ratio and its meaning ("standard": u = r_u*gamma*h
        is in Interfaces.u_pore; "listing": sigma'_n = (1 - r_u)*sigma_n)
    pivot_tol: a pivot d_j with d_j / K_jj below this marks DOF j as unstable
    strength_reduction: also search the strength-reduction factor (reduction.py)
    interfaces: "linear" (springs carry tension, the thesis) or "no-tension" (contact.py)
    """

    n_steps: int = 10
    tol: float = 1e-3
    max_iter: int = 200
    ru: float = 0.0
    ru_mode: str = "standard"
    pivot_tol: float = 1e-9
    strength_reduction: bool = False
    interfaces: str = "linear"


@dataclass
class Problem:
    """Everything the solver needs, plus what the reports and Bishop need."""

    title: str
    blocks: Blocks
    interfaces: Interfaces
    settings: Settings
    source: str = ""
    fmt: str = ""
    units: str = "SI"
    # the slope description of a TOML input (Bishop and the figure need it); None for Appendix A
    slope: object = None          # soil.Slope
    profile: np.ndarray | None = None
    surface: dict | None = None   # prescribed slip surface, if any
    bottom: float | None = None   # base of a grid mesh
    notes: list = field(default_factory=list)


def make_blocks(verts, offsets, fixed, force=None, ref=None, layer=None, fix=None) -> Blocks:
    verts = np.asarray(verts, float)
    offsets = np.asarray(offsets, np.int64)
    area, cen = geometry.polygon_area_centroid(verts, offsets)
    n = len(offsets) - 1
    return Blocks(
        verts=verts, offsets=offsets,
        ref=cen if ref is None else np.asarray(ref, float),
        area=area, fixed=np.asarray(fixed, bool),
        layer=np.full(n, -1, np.int64) if layer is None else np.asarray(layer, np.int64),
        force=np.zeros((n, 3)) if force is None else np.asarray(force, float),
        fix=np.repeat(np.asarray(fixed, bool)[:, None], 3, axis=1) if fix is None else np.asarray(fix, bool),
    )


def find_interfaces(blocks: Blocks, tol: float | None = None) -> tuple[Interfaces, list]:
    """Interfaces between blocks (pairs of fixed blocks dropped) and same-side overlaps."""
    if tol is None:
        span = max(float(np.ptp(blocks.verts[:, 0])), float(np.ptp(blocks.verts[:, 1])), 1.0)
        tol = 1e-7 * span
    se = geometry.shared_edges(blocks.verts, blocks.offsets, tol)
    keep = ~(blocks.fixed[se.a] & blocks.fixed[se.b])
    a, b, p0, p1 = se.a[keep], se.b[keep], se.p0[keep], se.p1[keep]
    mid = 0.5 * (p0 + p1)
    t = p1 - p0
    length = np.hypot(t[:, 0], t[:, 1])
    normal = np.column_stack([t[:, 1], -t[:, 0]]) / np.maximum(length, 1e-300)[:, None]
    # orient from a to b: a's outward normal points away from a's reference area
    _, cen = geometry.polygon_area_centroid(blocks.verts, blocks.offsets)
    flip = np.einsum("ij,ij->i", normal, mid - cen[a]) < 0
    normal[flip] *= -1
    itf = Interfaces(a=a, b=b, p0=p0, p1=p1, mid=mid, length=length, normal=normal,
                     side_a=se.side_a[keep], side_b=se.side_b[keep])
    return itf, se.same_side


def self_weight(blocks: Blocks, gamma: np.ndarray) -> np.ndarray:
    """Block loads (n, 3) from unit weights gamma (n,) in N/m^3, acting at the centroid."""
    _, cen = geometry.polygon_area_centroid(blocks.verts, blocks.offsets)
    w = gamma * blocks.area
    f = np.zeros((blocks.n, 3))
    f[:, 1] = -w
    # the DOF reference point may differ from the centroid: carry the moment of the weight
    f[:, 2] = -(cen[:, 0] - blocks.ref[:, 0]) * w
    return f
