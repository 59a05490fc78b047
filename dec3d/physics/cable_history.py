"""Histories of cables (``structure cable history``, ``structure node history``): the value of one
element or node, found by its id, sampled with the other histories (``physics.history.HistorySet``).

Quantities: elements ``force`` (axial force, N, tension positive) and ``stress`` (axial force over the
cross-sectional area, Pa); nodes ``displacement[-x|-y|-z]`` and ``velocity[-x|-y|-z]`` (the magnitude
without a component)."""
from __future__ import annotations

import numpy as np

from dec3d.errors import CommandError
from dec3d.model.cables import NODES, SEGMENTS

ELEMENT_QUANTITIES = ("force", "stress")
NODE_QUANTITIES = tuple(f"{q}{c}" for q in ("displacement", "velocity") for c in ("", "-x", "-y", "-z"))


def _row(model, store: str, ident: int, what: str) -> int:
    if store == NODES and what == "node":
        return _node(model, ident)[1]
    st = model.stores.get(store)
    rows = np.flatnonzero(st["id"] == ident) if st is not None and st.n else np.zeros(0, np.int64)
    if rows.size == 0:
        raise CommandError(f"there is no cable {what} with id {ident}")
    return int(rows[0])


def _node(model, ident: int):
    """(store, row) of structural node ``ident``: a cable, beam or liner node (one id space)."""
    for name in (NODES, "beam_nodes", "liner_nodes"):
        st = model.stores.get(name)
        if st is not None and st.n:
            rows = np.flatnonzero(st["id"] == ident)
            if rows.size:
                return st, int(rows[0])
    raise CommandError(f"there is no structural node with id {ident}")


def add_cable_history(hs, kind: str, quantity: str, ident: int, name: str | None = None):
    """Add to HistorySet ``hs`` a history of cable element (``kind`` "cable") or node ("cable-node")
    ``ident``; CommandError when there is none with that id."""
    model = hs.model
    if kind == "cable":
        if quantity not in ELEMENT_QUANTITIES:
            raise ValueError(f"unknown cable history quantity {quantity!r}")
        _row(model, SEGMENTS, ident, "element")

        def value(eng) -> float:
            st = model.stores[SEGMENTS]
            r = _row(model, SEGMENTS, ident, "element")
            f = float(st["fa"][r])
            if quantity == "force":
                return f
            a = float(st["prop"][r, 1])
            return f / a if a > 0 else 0.0
        label = f"cable element {ident} {quantity}"
    else:
        if quantity not in NODE_QUANTITIES:
            raise ValueError(f"unknown structure node history quantity {quantity!r}")
        _row(model, NODES, ident, "node")
        field = "disp" if quantity.startswith("displacement") else "vel"
        comp = "xyz".index(quantity[-1]) if quantity[-2] == "-" else None

        def value(eng) -> float:
            st, r = _node(model, ident)
            v = st[field][r]
            return float(np.linalg.norm(v)) if comp is None else float(v[comp])
        kind_name = {NODES: "cable", "liner_nodes": "liner"}.get(_node(model, ident)[0].name, "beam")
        label = f"{kind_name} node {ident} {quantity}"
    return hs.add(label, value, name, {"kind": kind, "quantity": quantity, "id": int(ident)})
