"""Histories of beam elements (``structure beam history``): the axial force (N, tension positive) or
the torsion / bending moments at end 1 (N·m, in the element's axes) of one element, found by its id."""
from __future__ import annotations

import numpy as np

from dec3d.errors import CommandError
from dec3d.model.beams import BELEMS

BEAM_QUANTITIES = ("force", "moment-x", "moment-y", "moment-z")
_COL = {"force": 6, "moment-x": 3, "moment-y": 4, "moment-z": 5}


def _row(model, ident: int) -> int:
    st = model.stores.get(BELEMS)
    rows = np.flatnonzero(st["id"] == ident) if st is not None and st.n else np.zeros(0, np.int64)
    if rows.size == 0:
        raise CommandError(f"there is no beam element with id {ident}")
    return int(rows[0])


def add_beam_history(hs, quantity: str, ident: int, name: str | None = None):
    model = hs.model
    if quantity not in BEAM_QUANTITIES:
        raise ValueError(f"unknown beam history quantity {quantity!r}")
    _row(model, ident)
    col = _COL[quantity]

    def value(eng) -> float:
        return float(model.stores[BELEMS]["fl"][_row(model, ident), col])
    return hs.add(f"beam element {ident} {quantity}", value, name, {"kind": "beam", "quantity": quantity,
                                                                     "id": int(ident)})
