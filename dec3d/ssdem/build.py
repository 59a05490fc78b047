"""From a slope description to a `Problem`: mesh, interface properties, loads, water.

Rules (documented in docs/ssdem.md):
  * a block's unit weight is that of the layer holding its centroid;
  * an interface takes the properties of the layer holding its midpoint (on a
    layer boundary: the layer below), so a slip surface along a weak layer's top
    gets the weak layer's strength;
  * pore pressure is evaluated at the interface midpoint;
  * a surcharge q (pressure on the horizontal projection) loads the top edges
    of the blocks it covers, as a force at the middle of the covered part;
  * a pseudo-static coefficient kh adds kh*W to every block, towards the face.
"""
from __future__ import annotations

import numpy as np

from .mesh import grid_mesh, surface_mesh
from .model import Interfaces, Problem, Settings, find_interfaces, make_blocks, self_weight
from .soil import Slope


def assign_properties(itf: Interfaces, slope: Slope) -> None:
    lay = slope.layer_at(itf.mid[:, 0], itf.mid[:, 1])
    m = itf.m
    itf.kn = slope.prop("kn", lay).astype(float)
    itf.ks = slope.prop("ks", lay).astype(float)
    itf.c_p = slope.prop("c", lay).astype(float)
    itf.tan_p = np.tan(np.radians(slope.prop("phi", lay).astype(float)))
    itf.c_r = slope.prop("c_res", lay).astype(float)
    itf.tan_r = np.tan(np.radians(slope.prop("phi_res", lay).astype(float)))
    itf.del_res = slope.prop("delta_res", lay).astype(float)
    itf.tensile = slope.prop("tensile", lay).astype(float)
    itf.cutoff = slope.prop("cutoff", lay).astype(bool)
    itf.u_pore = slope.pore_pressure(itf.mid[:, 0], itf.mid[:, 1])
    if itf.on_surface is None:
        itf.on_surface = np.zeros(m, bool)


def block_loads(blocks, slope: Slope) -> np.ndarray:
    """Self-weight, surcharges on top edges and pseudo-static force, (n, 3)."""
    lay = slope.layer_at(blocks.ref[:, 0], blocks.ref[:, 1])
    blocks.layer = lay
    gamma = slope.prop("gamma", lay).astype(float)
    f = self_weight(blocks, gamma)
    if slope.kh:
        sign = -1.0 if slope.faces_left() else 1.0
        # acts at the centroid, which is the reference point of generated blocks
        f[:, 0] += sign * slope.kh * gamma * blocks.area
    if slope.surcharges:
        from .geometry import edges
        owner, _, p, q = edges(blocks.verts, blocks.offsets)
        span = max(float(np.ptp(blocks.verts[:, 0])), 1.0)
        on_top = (np.abs(p[:, 1] - slope.ground(p[:, 0])) < 1e-9 * span) & \
                 (np.abs(q[:, 1] - slope.ground(q[:, 0])) < 1e-9 * span) & \
                 (np.abs(q[:, 0] - p[:, 0]) > 0)
        force, xbar = slope.surcharge_on(p[:, 0], q[:, 0])
        force = np.where(on_top, force, 0.0)
        f[:, 1] -= np.bincount(owner, force, minlength=blocks.n)
        # a downward force at x_bar: moment about the reference point = -(x_bar - x_ref) * force
        arm = xbar - blocks.ref[owner, 0]
        f[:, 2] -= np.bincount(owner, force * arm, minlength=blocks.n)
    return f


def from_slope(slope: Slope, mesh: dict, surface: dict | None, settings: Settings, title: str = "") -> Problem:
    """Mesh the slope and set up every array the solver needs."""
    base_pairs = None
    if surface is not None:
        verts, offsets, fixed, base_pairs = surface_mesh(slope, surface, mesh["slices"], mesh.get("rows"))
        bottom = None
    else:
        verts, offsets, fixed = grid_mesh(slope, mesh["size"], mesh["bottom"])
        bottom = mesh["bottom"]
    blocks = make_blocks(verts, offsets, fixed)
    blocks.force = block_loads(blocks, slope)
    itf, _ = find_interfaces(blocks)
    on = np.zeros(itf.m, bool)
    if base_pairs is not None:
        pair_key = set(map(tuple, base_pairs.tolist()))
        on = np.array([(a, b) in pair_key or (b, a) in pair_key for a, b in zip(itf.a, itf.b)], bool)
    itf.on_surface = on
    assign_properties(itf, slope)
    return Problem(title=title, blocks=blocks, interfaces=itf, settings=settings,
                   profile=slope.profile, layers=slope.layers, water=dict(ru=slope.ru, ru_mode=slope.ru_mode),
                   surface=surface, bottom=bottom, slope=slope)
