"""The stores of beam structural elements (``structure beam …``; physics ``dec3d.physics.beams``,
kernel ``dec3d.kernels.beam``).

``beam_nodes``   one row per beam node (ids shared with the cable nodes: one `structure node` space)
    id (), beam ()        int64
    pos, pos0 (3,)        m      position now and as created
    vel, disp (3,)        m/s, m
    rot, avel (3,)        rad, rad/s  rotation (small, total) and rotational velocity
    mass, inert ()        kg, kg·m²  real mass and rotary inertia (from the elements' density)
    imass, iinert ()      the inertial ones of the last step (density-scaled in static runs)
    host ()               int64  block the node is linked to (-1: free)
    hz ()                 int8   0: a rigid host; else the node follows an element of a deformable host
                          (``model.hosts``: 4-node or 10-node zone, FE brick): hzone () its row, hgp (NHOST,)
                          its node rows, hw (NHOST,) the node's weights (shape functions) in it
    hpos (3,)             m      host point
    lf, lm (3,)           N, N·m link force and moment on the node
    fix ()                uint8  bits 0-2 velocity, 3-5 rotational velocity held (``structure node fix``)
    fapp, mapp (3,)       applied force and moment (``structure node apply``)
    force, moment (3,)    unbalanced force and moment of the last step
    hforce, hmoment (3,)  force of the link on the host block and its moment about the centroid
    group (1,)
``beam_elements`` one row per element
    id (), beam (), na (), nb ()  int64
    l0 ()                 m      length
    prop (7,)             young, poisson, cross-sectional-area, moi-y, moi-z, moi-polar, density
    ydir (3,)             the element's y axis as given (``direction-y``; 0: chosen)
    axes (3, 3)           rows: the element's x (a → b), y, z axes
    fl (12,)              end forces on the element in its axes: F, M at end a, F, M at end b
    pos (3,)              midpoint as created; group (1,)
"""
from __future__ import annotations

import numpy as np

from dec3d.kernels.beam import NBPROP

from .cables import place_nodes
from .hosts import NHOST, next_id, remap_node_hosts, widen
from .groups import group_field
from .model import Model
from .store import Field, Store

BNODES = "beam_nodes"
BELEMS = "beam_elements"
BPROPS = ("young", "poisson", "cross-sectional-area", "moi-y", "moi-z", "moi-polar", "density")
assert len(BPROPS) == NBPROP


def _node_fields():
    v3 = Field((3,), np.float64, 0.0)
    f = {k: v3 for k in ("pos", "pos0", "vel", "disp", "rot", "avel", "hpos", "lf", "lm", "fapp", "mapp", "force",
                         "moment", "hforce", "hmoment")}
    f.update({"id": Field((), np.int64, 0), "beam": Field((), np.int64, 0), "host": Field((), np.int64, -1),
              "fix": Field((), np.uint8, 0), "group": group_field(), "hz": Field((), np.int8, 0),
              "hzone": Field((), np.int64, -1), "hgp": Field((NHOST,), np.int64, -1),
              "hw": Field((NHOST,), np.float64, 0.0)})
    f.update({k: Field((), np.float64, 0.0) for k in ("mass", "inert", "imass", "iinert")})
    return f


def _elem_fields():
    return {"id": Field((), np.int64, 0), "beam": Field((), np.int64, 0), "na": Field((), np.int64, -1),
            "nb": Field((), np.int64, -1), "l0": Field((), np.float64, 0.0),
            "prop": Field((NBPROP,), np.float64, 0.0), "ydir": Field((3,), np.float64, 0.0),
            "axes": Field((3, 3), np.float64, 0.0), "fl": Field((12,), np.float64, 0.0),
            "pos": Field((3,), np.float64, 0.0), "group": group_field()}


def beam_stores(model: Model) -> tuple[Store, Store]:
    st = model.stores
    if BNODES not in st:
        model.add_store(Store(BNODES, _node_fields()))
    if BELEMS not in st:
        model.add_store(Store(BELEMS, _elem_fields()))
    widen(model.stores[BNODES])
    return model.stores[BNODES], model.stores[BELEMS]


def has_beams(model: Model) -> bool:
    return BELEMS in model.stores and model.stores[BELEMS].n > 0


def next_node_id(model: Model) -> int:
    """The next structural node id (cable, beam and liner nodes share one id space)."""
    top = 0
    for name in ("cable_nodes", BNODES, "liner_nodes"):
        if name in model.stores and model.stores[name].n:
            top = max(top, int(model.stores[name]["id"].max()))
    return top + 1


def element_axes(x: np.ndarray, ydir) -> np.ndarray:
    """Rows x, y, z of an element along unit ``x``: y is ``ydir`` made normal to x, or (when not
    given or along x) the global z × x — horizontal — or global y for a vertical element."""
    y = np.asarray(ydir, float) - np.dot(ydir, x) * x if ydir is not None else np.zeros(3)
    if np.linalg.norm(y) < 1e-9:
        y = np.cross([0.0, 0.0, 1.0], x)
        if np.linalg.norm(y) < 1e-9:
            y = np.array([0.0, 1.0, 0.0])
    y = y / np.linalg.norm(y)
    return np.array([x, y, np.cross(x, y)])


def add_beam(model: Model, p1, p2, segments: int, beam_id, group, tol: float) -> tuple[int, np.ndarray]:
    """Append a straight beam of equal elements; returns (beam id, host rows of its nodes: -1 free,
    -3 in a deformable block none of whose zones or FE elements holds it)."""
    nodes, els = beam_stores(model)
    p1, p2 = np.asarray(p1, float), np.asarray(p2, float)
    bid = int(beam_id) if beam_id is not None else next_id("beam", nodes["beam"], els["beam"])
    eid0 = int(els["id"].max(initial=0)) + 1
    rn, pts, hosts = place_nodes(model, nodes, p1, p2, segments, tol)
    nodes["beam"][rn] = bid
    nodes["pos0"][rn] = pts
    sl = els.append(segments)
    rs = np.arange(sl.start, sl.stop)
    els["id"][rs] = np.arange(eid0, eid0 + segments)
    els["beam"][rs] = bid
    els["na"][rs] = rn[:-1]
    els["nb"][rs] = rn[1:]
    els["l0"][rs] = float(np.linalg.norm(p2 - p1)) / segments
    els["pos"][rs] = 0.5 * (pts[:-1] + pts[1:])
    els["axes"][rs] = element_axes((p2 - p1) / np.linalg.norm(p2 - p1), None)
    if group:
        model.groups.assign(nodes, rn, group)
        model.groups.assign(els, rs, group)
    return bid, hosts


def update_beam_masses(model: Model) -> None:
    """Real node mass ρ A × half of each adjacent element, rotary inertia ρ (I_y + I_z) × half length
    + (ρ A half length) half length² / 3 (a rod of the tributary half length about its end)."""
    nodes, els = beam_stores(model)
    p = els["prop"]
    half = 0.5 * els["l0"]
    m = p[:, 6] * p[:, 2] * half
    ri = p[:, 6] * (p[:, 3] + p[:, 4]) * half + m * half ** 2 / 3.0
    mass, inert = np.zeros(nodes.n), np.zeros(nodes.n)
    for arr, v in ((mass, m), (inert, ri)):
        np.add.at(arr, els["na"], v)
        np.add.at(arr, els["nb"], v)
    nodes["mass"][:] = mass
    nodes["inert"][:] = inert


def remap_beam_hosts(model: Model, remap: np.ndarray) -> int:
    """After blocks are deleted: nodes whose block went are free (their link forces go with it)."""
    if BNODES not in model.stores or not model.stores[BNODES].n:
        return 0
    nodes = beam_stores(model)[0]
    lost = remap_node_hosts(model, nodes, remap)
    for k in ("lf", "lm", "hforce", "hmoment"):
        nodes[k][lost] = 0.0
    return int(lost.sum())
