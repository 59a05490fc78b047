"""``block create tunnel``: a square block of rock around a circular opening.

Itasca's form (used by the elastic-hole verification decks):
``block create tunnel dip δ dip-direction α radius R length l1 l2 blocks-axial na
blocks-radial nr blocks-tangential nt boundary b radius-ratio q``.

What dec3d builds (read from those decks, where ``boundary 9`` with ``radius 1`` puts the
loaded faces at x = 10 and z = 10, and the opening is removed afterwards with
``block delete range cylinder ... radius 0 1``):

* the axis is the dip vector of (δ, α): dip 0, dip-direction 0 runs along +y; the tunnel
  spans axial coordinates l1 .. l2 from the origin, cut into ``na`` equal slices;
* the cross-section is the square |u|, |v| ≤ R + b around the axis (u horizontal);
* rays at equal angles, ``nt`` per 45° octant (so the square's corners are nodes and
  every block is convex), run from the opening's polygon at radius R to the square;
* each ray is divided into ``nr`` rings whose widths grow by the factor ``q`` outwards;
* the opening itself is filled with triangular prisms (one per ray interval), so that
  it can be deleted or kept by a later range.

Every block is a prism checked by ``polyhedron.prism``.
"""
from __future__ import annotations

import math

import numpy as np

from .errors import GeometryError
from .planes import dip_vector
from .polyhedron import Poly, prism


def _section_points(radius: float, half: float, nr: int, nt: int, ratio: float):
    """Node coordinates (8·nt rays, nr+1 rings, 2) in the (u, v) plane, ray 0 along +u."""
    nray = 8 * nt
    theta = np.arange(nray) * (2.0 * math.pi / nray)
    c, s = np.cos(theta), np.sin(theta)
    c[np.abs(c) < 1e-15] = 0.0
    s[np.abs(s) < 1e-15] = 0.0
    m = np.maximum(np.abs(c), np.abs(s))
    outer = np.stack([c, s], axis=1) * (half / m)[:, None]
    # land exactly on the square's sides
    on_u = np.abs(c) >= np.abs(s)
    outer[on_u, 0] = np.sign(c[on_u]) * half
    outer[~on_u, 1] = np.sign(s[~on_u]) * half
    inner = np.stack([c, s], axis=1) * radius
    if abs(ratio - 1.0) < 1e-12:
        frac = np.arange(nr + 1) / nr
    else:
        with np.errstate(over="ignore", invalid="ignore"):
            frac = (ratio ** np.arange(nr + 1) - 1.0) / (ratio ** nr - 1.0)
    frac[-1] = 1.0
    if not (np.isfinite(frac).all() and (np.diff(frac) > 0).all()):
        raise GeometryError(f"tunnel: radius-ratio {ratio:g} over {nr} rings makes rings of zero width")
    return inner[:, None, :] + frac[None, :, None] * (outer - inner)[:, None, :]


def tunnel_block_count(blocks_axial: int, blocks_radial: int, blocks_tangential: int) -> int:
    """Blocks `tunnel` makes: per axial slice, 8·nt rays, each with one opening prism and nr rings."""
    return int(blocks_axial) * 8 * int(blocks_tangential) * (int(blocks_radial) + 1)


def tunnel(dip: float, dip_direction: float, radius: float, length: tuple[float, float],
           blocks_axial: int, blocks_radial: int, blocks_tangential: int, boundary: float,
           radius_ratio: float = 1.0, origin=(0.0, 0.0, 0.0), tol: float = 1e-6) -> list[Poly]:
    """The blocks of a tunnel model (angles in radians, lengths in m), opening included."""
    l1, l2 = float(length[0]), float(length[1])
    if not radius > 0:
        raise GeometryError(f"tunnel: radius must be positive, got {radius:g}")
    if not boundary > 0:
        raise GeometryError(f"tunnel: boundary must be positive, got {boundary:g}")
    if not l2 - l1 > tol:
        raise GeometryError(f"tunnel: length {l1:g} to {l2:g} is empty")
    for name, n in (("blocks-axial", blocks_axial), ("blocks-radial", blocks_radial),
                    ("blocks-tangential", blocks_tangential)):
        if int(n) < 1:
            raise GeometryError(f"tunnel: {name} must be at least 1, got {n}")
    if not radius_ratio > 0:
        raise GeometryError(f"tunnel: radius-ratio must be positive, got {radius_ratio:g}")
    axis = dip_vector(dip, dip_direction)
    e1 = np.cross(axis, [0.0, 0.0, 1.0])
    if np.linalg.norm(e1) < 1e-12:
        e1 = np.array([1.0, 0.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(e1, axis)
    e2[np.abs(e2) < 1e-15] = 0.0
    o = np.asarray(origin, dtype=np.float64)
    nodes = _section_points(radius, radius + boundary, int(blocks_radial),
                            int(blocks_tangential), radius_ratio)
    nray = nodes.shape[0]
    axial = l1 + (l2 - l1) * np.arange(int(blocks_axial) + 1) / int(blocks_axial)
    axial[-1] = l2

    def lift(uv: np.ndarray, a: float) -> np.ndarray:
        return o + uv[:, :1] * e1 + uv[:, 1:] * e2 + a * axis

    polys: list[Poly] = []
    for k in range(int(blocks_axial)):
        a0, a1 = axial[k], axial[k + 1]
        for r in range(nray):
            r2 = (r + 1) % nray
            core = np.array([[0.0, 0.0], nodes[r, 0], nodes[r2, 0]])
            polys.append(prism(lift(core, a0), lift(core, a1), tol))
            for i in range(int(blocks_radial)):
                quad = np.array([nodes[r, i], nodes[r, i + 1], nodes[r2, i + 1], nodes[r2, i]])
                polys.append(prism(lift(quad, a0), lift(quad, a1), tol))
    return polys
