"""Histories of liner elements (``structure liner history``): the coupling springs at one node of one
element (found by its id and the node's place 1-3 in it), in Itasca's sense:

* ``coupling-displacement-normal`` [m]: the node's normal displacement from its host point, separation
  positive (``liner_nodes.un``);
* ``coupling-displacement-shear`` [m]: the magnitude of its displacement from its host point across the
  normal (host point: a rigid block's material point, ``hpos − pos0``, or Σ wᵢ uᵢ of its zone's
  gridpoints);
* ``coupling-stress-normal`` [Pa]: the normal spring's force over the node's tributary area, tension
  positive;
* ``coupling-stress-shear`` [Pa]: the shear spring's force magnitude over that area.
A free node gives 0."""
from __future__ import annotations

import numpy as np

from dec3d.errors import CommandError
from dec3d.model.liners import LELEMS, LNODES, node_areas

LINER_QUANTITIES = ("coupling-displacement-normal", "coupling-displacement-shear", "coupling-stress-normal",
                    "coupling-stress-shear")


def _node_row(model, ident: int, node: int) -> int:
    st = model.stores.get(LELEMS)
    rows = np.flatnonzero(st["id"] == ident) if st is not None and st.n else np.zeros(0, np.int64)
    if rows.size == 0:
        raise CommandError(f"there is no liner element with id {ident}")
    if node not in (1, 2, 3):
        raise CommandError(f"a liner element has nodes 1, 2 and 3 (not {node})")
    return int(st["nodes"][int(rows[0]), node - 1])


def coupling_value(model, quantity: str, i: int) -> float:
    """``quantity`` of liner node row ``i``."""
    nodes = model.stores[LNODES]
    if nodes["host"][i] < 0:
        return 0.0
    if quantity == "coupling-displacement-normal":
        return float(nodes["un"][i])
    if quantity == "coupling-stress-normal":
        return float(-nodes["fn"][i] / node_areas(model)[i])
    if quantity == "coupling-stress-shear":
        return float(np.linalg.norm(nodes["fs"][i]) / node_areas(model)[i])
    if nodes["hz"][i] == 0:
        dh = nodes["hpos"][i] - nodes["pos0"][i]
    else:
        dh = nodes["hw"][i] @ model.vertices["disp"][nodes["hgp"][i]]
    r = nodes["disp"][i] - dh
    n = nodes["nrm"][i]
    return float(np.linalg.norm(r - np.dot(r, n) * n))


def add_liner_history(hs, quantity: str, ident: int, node: int = 1, name: str | None = None):
    model = hs.model
    if quantity not in LINER_QUANTITIES:
        raise ValueError(f"unknown liner history quantity {quantity!r}")
    _node_row(model, ident, node)

    def value(eng) -> float:
        return coupling_value(model, quantity, _node_row(model, ident, node))
    return hs.add(f"liner element {ident} node {node} {quantity}", value, name,
                  {"kind": "liner", "quantity": quantity, "id": int(ident), "node": int(node)})
