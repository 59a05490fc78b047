"""The stores of liner structural elements (``structure liner …``; physics ``dec3d.physics.liners``,
element ``dec3d.kernels.dkt``).

``liner_nodes``  one row per liner node (ids shared with the cable and beam nodes: one `structure node`
                 space)
    id (), liner ()       int64
    pos, pos0 (3,)        m      position now and as created
    vel, disp (3,)        m/s, m
    rot, avel (3,)        rad, rad/s  rotation (small, total) and rotational velocity
    mass, inert ()        kg, kg·m²  real mass and rotary inertia (``update_liner_masses``)
    imass, iinert ()      the inertial ones of the last step (density-scaled in static runs)
    host ()               int64  block the node is coupled to (-1: free)
    hz, hzone, hgp, hw    as the beam nodes' (``model.hosts``): 0 a rigid host, else the zone holding it
    hpos (3,)             m      host point
    nrm (3,)              unit normal of the liner at the node (area-weighted mean of its elements'
                          z axes, outward from the block it was made on)
    un ()                 m      normal displacement of the node from its host point (separation +)
    fn ()                 N      normal coupling force on the node along ``nrm`` (compression +)
    fs (3,)               N      shear coupling force on the node
    cstate ()             uint8  bit 0: the normal spring broke (tension gone), bit 1: the shear spring
                          slipped (cohesion now the residual one)
    fix ()                uint8  bits 0-2 velocity, 3-5 rotational velocity held (``structure node fix``)
    fapp, mapp (3,)       applied force and moment (``structure node apply``)
    force, moment (3,)    unbalanced force and moment of the last step
    hforce, hmoment (3,)  force of the coupling on the host block and its moment about the centroid
    group (1,)
    sx (3,)               surface-system x axis (``structure liner recover surface``; zero: none)
    nres (6,), nresok ()  recovered resultants M_x, M_y, M_xy, N_x, N_y, N_xy in the surface system, valid
                          (``model.liner_recover``)
``liner_elements`` one row per flat 3-node element
    id (), liner ()       int64
    nodes (3,)            int64  node rows, counter-clockwise seen from the element's +z side
    prop (10,)            ``LPROPS``: young, poisson, thickness, density and the coupling springs'
    axes (3, 3)           rows: the element's x (node 1 → 2), y, z (normal) axes, fixed at creation
    lxy (3,)              m      local corners (0, 0), (x2, 0), (x3, y3): x2, x3, y3
    area ()               m²
    pos (3,)              centroid as created; group (1,)
    eres (4, 8), eresok ()  recovered resultants at the centroid and nodes 1-3 (M_x, M_y, M_xy, N_x, N_y,
                          N_xy, Q_x, Q_y), valid (``model.liner_recover``)
"""
from __future__ import annotations

import numpy as np

from dec3d.errors import CommandError
from dec3d.kernels.dkt import element_frame

from .groups import group_field
from .hosts import NHOST, host_element, next_id, remap_node_hosts, widen
from .model import Model
from .store import Field, Store

LNODES = "liner_nodes"
LELEMS = "liner_elements"
#: ``prop`` columns (young and poisson are set together by `isotropic E ν`)
LPROPS = ("young", "poisson", "thickness", "density", "coupling-stiffness-normal", "coupling-stiffness-shear",
          "coupling-yield-normal", "coupling-cohesion-shear", "coupling-cohesion-shear-residual",
          "coupling-friction-shear")
L_E, L_NU, L_T, L_RHO, L_KN, L_KS, L_TY, L_C, L_CR, L_PHI = range(10)
NLPROP = len(LPROPS)


def _node_fields():
    v3 = Field((3,), np.float64, 0.0)
    f = {k: v3 for k in ("pos", "pos0", "vel", "disp", "rot", "avel", "hpos", "nrm", "fs", "fapp", "mapp", "force",
                         "moment", "hforce", "hmoment")}
    f.update({"id": Field((), np.int64, 0), "liner": Field((), np.int64, 0), "host": Field((), np.int64, -1),
              "fix": Field((), np.uint8, 0), "cstate": Field((), np.uint8, 0), "group": group_field(),
              "hz": Field((), np.int8, 0), "hzone": Field((), np.int64, -1), "hgp": Field((NHOST,), np.int64, -1),
              "hw": Field((NHOST,), np.float64, 0.0)})
    f.update({k: Field((), np.float64, 0.0) for k in ("mass", "inert", "imass", "iinert", "un", "fn")})
    f.update({"sx": v3, "nres": Field((6,), np.float64, 0.0), "nresok": Field((), np.uint8, 0)})
    return f


def _elem_fields():
    return {"id": Field((), np.int64, 0), "liner": Field((), np.int64, 0), "nodes": Field((3,), np.int64, -1),
            "prop": Field((NLPROP,), np.float64, 0.0), "axes": Field((3, 3), np.float64, 0.0),
            "lxy": Field((3,), np.float64, 0.0), "area": Field((), np.float64, 0.0),
            "pos": Field((3,), np.float64, 0.0), "group": group_field(),
            "eres": Field((4, 8), np.float64, 0.0), "eresok": Field((), np.uint8, 0)}


def liner_stores(model: Model) -> tuple[Store, Store]:
    st = model.stores
    if LNODES not in st:
        model.add_store(Store(LNODES, _node_fields()))
    if LELEMS not in st:
        model.add_store(Store(LELEMS, _elem_fields()))
    for name, fields in ((LNODES, _node_fields()), (LELEMS, _elem_fields())):
        store = model.stores[name]
        for key, spec in fields.items():          # (a store restored from a file of an older dec3d)
            if key not in store:
                store.add_field(key, spec)
    widen(model.stores[LNODES])
    return model.stores[LNODES], model.stores[LELEMS]


def has_liners(model: Model) -> bool:
    return LELEMS in model.stores and model.stores[LELEMS].n > 0


def add_liner(model: Model, tris: np.ndarray, hosts: np.ndarray, liner_id, group, slot, tol: float) -> int:
    """Append a liner of triangles ``tris (k, 3, 3)`` (corners counter-clockwise about the outward
    normal); ``hosts (k,)``: the block row each triangle was made on, or ``(k, 3)`` each corner's (-1:
    none). Corners within ``tol``
    are one node, coupled to the block of the first triangle that made it (a zoned block: the zone
    holding the point). Returns the liner id."""
    from .beams import next_node_id

    nodes, els = liner_stores(model)
    lid = int(liner_id) if liner_id is not None else next_id("liner", nodes["liner"], els["liner"])
    hosts = np.asarray(hosts, np.int64)
    edges = np.linalg.norm(tris - np.roll(tris, 1, axis=1), axis=2)
    keep = edges.min(axis=1) > 2.0 * tol                  # (a sliver under the tolerance is no element)
    if not keep.any():
        raise CommandError(f"every element has an edge shorter than twice the tolerance {tol:g} m: no liner made "
                           "(give a smaller `tolerance`)")
    tris, hosts = tris[keep], hosts[keep]
    pts = tris.reshape(-1, 3)
    first, inv = merge_points(pts, tol)
    order = np.arange(len(first))                         # nodes in order of first appearance
    rank = order
    nn = len(order)
    nid0 = next_node_id(model)
    sl = nodes.append(nn)
    rn = np.arange(sl.start, sl.stop)
    upts = pts[first[order]]
    nodes["id"][rn] = np.arange(nid0, nid0 + nn)
    nodes["liner"][rn] = lid
    nodes["pos"][rn] = upts
    nodes["pos0"][rn] = upts
    nodes["hpos"][rn] = upts
    conn = rn[rank[inv].reshape(-1, 3)]
    corner = hosts.reshape(-1) if hosts.ndim == 2 else np.repeat(hosts, 3)
    node_block = corner[first[order]]
    kinds = model.blocks["kind"]
    for k, h in enumerate(node_block):
        if h < 0:
            continue
        if kinds[h] != 0:
            z = host_element(model, int(h), upts[k], max(tol, 1e-9))
            if z is None:
                continue
            nodes["hz"][rn[k]], nodes["hzone"][rn[k]], nodes["hgp"][rn[k]], nodes["hw"][rn[k]] = z
        nodes["host"][rn[k]] = h
    eid0 = int(els["id"].max(initial=0)) + 1
    sl = els.append(len(tris))
    rs = np.arange(sl.start, sl.stop)
    els["id"][rs] = np.arange(eid0, eid0 + len(tris))
    els["liner"][rs] = lid
    els["nodes"][rs] = conn
    for r, t in zip(rs, tris):
        ax, x2, x3, y3 = element_frame(t[0], t[1], t[2])
        els["axes"][r] = ax
        els["lxy"][r] = (x2, x3, y3)
        els["area"][r] = 0.5 * x2 * y3
        els["pos"][r] = t.mean(axis=0)
    update_liner_normals(model)
    if group:
        model.groups.assign(nodes, rn, group, slot)
        model.groups.assign(els, rs, group, slot)
    return lid


def merge_points(pts: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Points within ``tol`` of each other (chains of them too) are one: (row in ``pts`` of each merged
    point's first member, in order of first appearance; merged point of each row of ``pts``)."""
    from scipy.spatial import cKDTree

    n = len(pts)
    parent = np.arange(n)

    def root(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    for a, b in sorted(cKDTree(pts).query_pairs(max(tol, 0.0))):
        ra, rb = root(a), root(b)
        if ra != rb:
            parent[max(ra, rb)] = min(ra, rb)            # the lowest row leads: deterministic
    roots = np.array([root(i) for i in range(n)])
    first, inv = np.unique(roots, return_inverse=True)   # roots are first members, ascending
    return first, inv.ravel()


def update_liner_normals(model: Model) -> None:
    nodes, els = liner_stores(model)
    acc = np.zeros((nodes.n, 3))
    for c in range(3):
        np.add.at(acc, els["nodes"][:, c], els["axes"][:, 2] * els["area"][:, None])
    nrm = np.linalg.norm(acc, axis=1)
    ok = nrm > 0
    nodes["nrm"][ok] = acc[ok] / nrm[ok, None]


def node_areas(model: Model) -> np.ndarray:
    """Tributary area of each liner node: a third of each of its elements'."""
    nodes, els = liner_stores(model)
    out = np.zeros(nodes.n)
    for c in range(3):
        np.add.at(out, els["nodes"][:, c], els["area"] / 3.0)
    return out


def update_liner_masses(model: Model) -> None:
    """Real node mass ρ t A/3 from each element; rotary inertia m (t²/12 + A/(6π)) per element third:
    the polar moment of a disc of its tributary area A/3 about its centre (and of the thickness)."""
    nodes, els = liner_stores(model)
    p = els["prop"]
    m = p[:, L_RHO] * p[:, L_T] * els["area"] / 3.0
    ri = m * (p[:, L_T] ** 2 / 12.0 + els["area"] / (6.0 * np.pi))
    mass, inert = np.zeros(nodes.n), np.zeros(nodes.n)
    for c in range(3):
        np.add.at(mass, els["nodes"][:, c], m)
        np.add.at(inert, els["nodes"][:, c], ri)
    nodes["mass"][:] = mass
    nodes["inert"][:] = inert


def remap_liner_hosts(model: Model, remap: np.ndarray) -> int:
    """After blocks are deleted: nodes whose block went are free (their coupling forces go with it)."""
    if LNODES not in model.stores or not model.stores[LNODES].n:
        return 0
    nodes = liner_stores(model)[0]
    lost = remap_node_hosts(model, nodes, remap)
    for k in ("fs", "hforce", "hmoment"):
        nodes[k][lost] = 0.0
    nodes["fn"][lost] = 0.0
    return int(lost.sum())
