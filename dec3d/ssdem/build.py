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


def from_slope(slope: Slope, mesh: dict, surface: dict | None, settings: Settings, title: str = "",
               max_blocks: float = np.inf) -> Problem:
    """Mesh the slope and set up every array the solver needs (mesh.MeshTooLarge past max_blocks)."""
    base_pairs = None
    if surface is not None:
        verts, offsets, fixed, base_pairs = surface_mesh(slope, surface, mesh["slices"], mesh.get("rows"), max_blocks)
        bottom = None
    else:
        verts, offsets, fix = grid_mesh(slope, mesh["size"], mesh["bottom"], max_blocks)
        fixed = fix.all(axis=1)
        bottom = mesh["bottom"]
    blocks = make_blocks(verts, offsets, fixed, fix=None if surface is not None else fix)
    blocks.force = block_loads(blocks, slope)
    itf, _ = find_interfaces(blocks)
    on = np.zeros(itf.m, bool)
    if base_pairs is not None:
        pair_key = set(map(tuple, base_pairs.tolist()))
        on = np.array([(a, b) in pair_key or (b, a) in pair_key for a, b in zip(itf.a, itf.b)], bool)
    itf.on_surface = on
    assign_properties(itf, slope)
    return Problem(title=title, blocks=blocks, interfaces=itf, settings=settings,
                   profile=slope.profile, surface=surface, bottom=bottom, slope=slope)


def from_polygons(polygons, fixed, *, kn, ks, c=0.0, phi=0.0, c_res=None, phi_res=None, delta_res=np.inf,
                  tensile=0.0, cutoff=False, gamma=0.0, force=None, n_steps=1, tol=1e-6, max_iter=500,
                  ru=0.0, ru_mode="standard", interfaces="linear", title="polygons") -> Problem:
    """A problem from explicit polygons with one set of interface properties (SI units).

    For scripts and tests: polygons is a list of (k, 2) counter-clockwise vertex arrays,
    fixed a list of bools (or (n, 3) DOF fixity), force an optional (n, 3) array added to
    the self-weight gamma * area.  Scalars apply to every interface.
    """
    verts = np.concatenate([np.asarray(p, float) for p in polygons])
    offsets = np.concatenate([[0], np.cumsum([len(p) for p in polygons])])
    fix = np.asarray(fixed, bool)
    if fix.ndim == 1:
        fix = np.repeat(fix[:, None], 3, axis=1)
    blocks = make_blocks(verts, offsets, fix.all(axis=1), fix=fix)
    blocks.force = self_weight(blocks, np.full(blocks.n, float(gamma)))
    if force is not None:
        blocks.force = blocks.force + np.asarray(force, float)
    itf, _ = find_interfaces(blocks)
    m = itf.m
    full = lambda v: np.full(m, float(v))    # noqa: E731
    itf.kn, itf.ks = full(kn), full(ks)
    itf.c_p, itf.tan_p = full(c), full(np.tan(np.radians(phi)))
    itf.c_r = full(c if c_res is None else c_res)
    itf.tan_r = full(np.tan(np.radians(phi if phi_res is None else phi_res)))
    itf.del_res, itf.tensile = full(delta_res), full(tensile)
    itf.cutoff = np.full(m, bool(cutoff))
    itf.u_pore, itf.on_surface = np.zeros(m), np.zeros(m, bool)
    settings = Settings(n_steps=n_steps, tol=tol, max_iter=max_iter, ru=ru, ru_mode=ru_mode, interfaces=interfaces)
    return Problem(title=title, blocks=blocks, interfaces=itf, settings=settings, fmt="polygons")
