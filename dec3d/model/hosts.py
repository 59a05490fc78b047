"""Where a structural node (cable, beam) or a hybrid bolt's dowel point sits in a deformable block:
the element that holds it and the weights by which it follows the element's nodes.

A point in a deformable block follows one element of it (``host_element``):

* code 1, a 4-node zone: the point's barycentric weights over the zone's 4 gridpoints;
* code 2, a 10-node zone (``block zone generate high-order-tetra``): its 10 quadratic shape functions
  at the point (``kernels.hostpoint``);
* code 3, an FE block's 20-node brick (``feblock generate``): its 20 shape functions there.

The material point is Σ wᵢ xᵢ, its velocity Σ wᵢ vᵢ; a force F on it goes to the nodes as wᵢ F (the
consistent nodal forces of a point load: with quadratic elements some wᵢ are negative, Σ wᵢ = 1 still).
Stores keep ``hz`` (the code, 0 for a rigid host), ``hzone`` (zone row for codes 1 and 2, ``feblocks``
row for 3), ``hgp (NHOST,)`` node rows and ``hw (NHOST,)`` weights; the unused tail repeats the first
node with weight 0, so sums over all NHOST columns are right.
"""
from __future__ import annotations

import numpy as np

from dec3d.kernels.hostpoint import locate

#: node slots of a host element (the largest: a 20-node brick)
NHOST = 20

H_RIGID, H_TET4, H_TET10, H_FE = 0, 1, 2, 3

_I = np.int64


def _padded(gp, w):
    g = np.full(NHOST, int(gp[0]), _I)
    ww = np.zeros(NHOST)
    g[:len(gp)] = gp
    ww[:len(w)] = w
    return g, ww


def _tet4(model, block: int, p: np.ndarray, tol: float):
    zs = model.stores["zones"]
    rows = np.flatnonzero((zs["block"] == block) & (zs["nnode"] == 4))
    if not rows.size:
        return None
    gp = zs["gp"][rows, :4]
    x = model.vertices["pos"][gp]                      # (z, 4, 3)
    a = np.transpose(x[:, 1:, :] - x[:, :1, :], (0, 2, 1))   # columns x1-x0, x2-x0, x3-x0
    ok = np.abs(np.linalg.det(a)) > 0
    w = np.full((len(rows), 4), -np.inf)
    w[ok, 1:] = np.linalg.solve(a[ok], (p[None, :] - x[ok, 0, :])[:, :, None])[:, :, 0]
    w[ok, 0] = 1.0 - w[ok, 1:].sum(axis=1)
    inside = np.flatnonzero(w.min(axis=1) >= -tol)
    if not inside.size:
        return None
    k = int(inside[0])
    wk = np.clip(w[k], 0.0, None)
    return (H_TET4, int(rows[k])) + _padded(gp[k], wk / wk.sum())


def _quadratic(model, code, rows, conn, nn, p, tol):
    """The first of elements ``rows`` (node rows ``conn``) holding ``p`` within ``tol`` [m], by its box
    first, then by its natural coordinates (``kernels.hostpoint.locate``)."""
    if not rows.size:
        return None
    pos = model.vertices["pos"]
    x = pos[conn[rows, :nn]]                           # (e, nn, 3)
    lo, hi = x.min(axis=1), x.max(axis=1)
    near = rows[((p >= lo - tol) & (p <= hi + tol)).all(axis=1)]
    if not near.size:
        return None
    size = float(np.max(hi - lo))
    w = np.zeros(nn)
    k = locate(pos, conn, near.astype(_I), nn, np.asarray(p, np.float64), 1e-9 + tol / max(size, 1e-300), w)
    if k < 0:
        return None
    e = int(near[k])
    return (code, e) + _padded(conn[e, :nn], w)


def host_element(model, block: int, p: np.ndarray, tol: float):
    """(code, element row, node rows (NHOST,), weights (NHOST,)) of the element of deformable block row
    ``block`` that holds point ``p`` (on its boundary within ``tol`` [m] counts), or None."""
    p = np.asarray(p, np.float64)
    st = model.stores
    if "zones" in st and st["zones"].n:
        z = _tet4(model, block, p, tol)
        if z is not None:
            return z
        zs = st["zones"]
        rows = np.flatnonzero((zs["block"] == block) & (zs["nnode"] == 10))
        z = _quadratic(model, H_TET10, rows, zs["gp"], 10, p, tol)
        if z is not None:
            return z
    if "feblocks" in st and st["feblocks"].n:
        es = st["feblocks"]
        return _quadratic(model, H_FE, np.flatnonzero(es["block"] == block), es["nodes"], 20, p, tol)
    return None


def zone_hosted(model, host: np.ndarray, hz: np.ndarray) -> np.ndarray:
    """Rows of the structural nodes (block row ``host``, -1 none; element code ``hz``, 0 a rigid host)
    whose host element must be found (again): those on an element, whose rows move when blocks go or
    zones are made again, and those on a block made deformable since (a rigid block zoned after the
    node was made: it would stay coupled to the block's rigid motion, which a zoned block has not)."""
    rows = np.flatnonzero(host >= 0)
    return rows[(hz[rows] != 0) | (model.blocks["kind"][host[rows]] != 0)]


def remap_node_hosts(model, nodes, remap: np.ndarray) -> np.ndarray:
    """After blocks are deleted (old row -> new row, -1 gone): the structural ``nodes``' hosts renumbered,
    the zone-hosted ones of surviving blocks found again (the zones' and gridpoints' rows moved), ``hz`` 0
    where the host went or no element holds the node any more. Returns the mask of the nodes that lost
    their host (the caller drops the forces they carried)."""
    h = nodes["host"]
    ok = h >= 0
    h[ok] = remap[h[ok]]
    lost = ok & (h < 0)
    for i in zone_hosted(model, h, nodes["hz"]):
        z = host_element(model, int(h[i]), nodes["hpos"][i], 1e-9)
        if z is None:
            h[i] = -1
            lost[i] = True
        else:
            nodes["hz"][i], nodes["hzone"][i], nodes["hgp"][i], nodes["hw"][i] = z
    nodes["hz"][lost] = 0
    return lost


def next_id(what: str, *ids: np.ndarray) -> int:
    """The id after the largest of ``ids`` (a cable's, beam's or liner's: 1 when there are none); a
    CommandError when that is past 64 bits (an `id 9223372036854775807` given before: the next one
    wrapped round to a negative id)."""
    from dec3d.errors import CommandError

    top = max([0] + [int(a.max()) for a in ids if len(a)])
    if top >= 2 ** 63 - 1:
        raise CommandError(f"{what} ids are used up to {top}: give the new {what}'s `id`")
    return top + 1


def widen(store, hgp: str = "hgp", hw: str = "hw") -> None:
    """A store restored from a file written when hosts had 4 node slots: widen its ``hgp``/``hw`` to
    NHOST (trailing axis), the new slots repeating the first node with weight 0."""
    shape = store.fields[hgp].shape
    if shape[-1] == NHOST:
        return
    old = shape[-1]
    store.resize_field(hgp, shape[:-1] + (NHOST,))
    store.resize_field(hw, shape[:-1] + (NHOST,))
    g = store[hgp]
    g[..., old:] = g[..., :1]


def spread_stiffness(out: np.ndarray, hgp: np.ndarray, hw: np.ndarray, k: np.ndarray) -> None:
    """Add to ``out`` (per vertex row) the Gershgorin row sums of springs of stiffness ``k (…,)`` on host
    points Σ wᵢ xᵢ (``hgp``, ``hw`` (…, NHOST)): the spring adds k wᵢ wⱼ to the stiffness, row i sums to
    k |wᵢ| Σⱼ |wⱼ| (k wᵢ for the non-negative weights of a 4-node zone, which sum to 1)."""
    a = np.abs(hw)
    np.add.at(out, hgp.ravel(), (a * (a.sum(axis=-1) * k)[..., None]).ravel())


def host_stress(model, code: np.ndarray, row: np.ndarray) -> np.ndarray:
    """(k, 6) stresses (xx yy zz xy xz yz, tension positive) of host elements: a zone's (codes 1, 2) or
    an FE brick's (code 3; the volume-weighted mean of its Gauss points)."""
    out = np.zeros((len(code), 6))
    z = code != H_FE
    if z.any():
        out[z] = model.stores["zones"]["stress"][row[z]]
    if (~z).any():
        out[~z] = model.stores["feblocks"]["stress"][row[~z]]
    return out
