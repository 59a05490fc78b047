"""`structure cable history` and `structure node history`: sampled values of one cable element or node
(3DEC's forms: `structure cable history [name 's'] force component-id 3`, `… position x y z`: the element
whose midpoint is nearest; `structure node history displacement-x component-id 1`). Sampled with the
other histories (`history interval`, `history export`; ``dec3d.physics.cable_history``)."""
from __future__ import annotations

import numpy as np

from ..errors import BindError, CommandError
from ..model.cables import NODES, SEGMENTS, has_cables
from ..physics.cable_history import ELEMENT_QUANTITIES, NODE_QUANTITIES, add_cable_history
from ..physics.history import histories
from .histories import _name
from .registry import REGISTRY, command
from .values import POINT, Num, P, Text

_WHICH = [P("component-id", Num(integer=True, lo=1), "id of the element (node)"),
          P("position", POINT, "the element (node) nearest this point", units="m")]
REGISTRY.node_keywords("structure cable history", [P("name", Text(), "history name")])
REGISTRY.node_keywords("structure node history", [P("name", Text(), "history name")])


def _check(call):
    if (call.args["component_id"] is None) == (call.args["position"] is None):
        raise BindError("give either `component-id <i>` or `position <x y z>`", call.location)


def _ident(session, call, store: str) -> int:
    from ..model.beams import has_beams
    from ..model.liners import has_liners
    if not has_cables(session.model) and not (store == NODES and (has_beams(session.model)
                                                                   or has_liners(session.model))):
        raise CommandError("there is no cable: make one first (`structure cable create by-line …`)", call.location)
    if call.args["component_id"] is not None:
        return int(call.args["component_id"])
    p = np.asarray([float(x) for x in call.args["position"]])
    names = (NODES, "beam_nodes", "liner_nodes") if store == NODES else (SEGMENTS,)
    best = None
    for st in (session.model.stores[n] for n in names if n in session.model.stores and session.model.stores[n].n):
        d = np.linalg.norm(st["pos"] - p, axis=1)
        k = int(np.argmin(d))
        if best is None or d[k] < best[0]:
            best = (float(d[k]), int(st["id"][k]))
    return best[1]


def _handler(kind, store, quantity):
    def handler(session, call):
        name = _name(session, call)
        ident = _ident(session, call, store)
        try:
            add_cable_history(histories(session.model), kind, quantity, ident, name)
        except CommandError as exc:
            raise exc.with_location(call.locations.get("component_id", call.location))
    return handler


_EDOC = {"force": "axial force (N, tension positive)", "stress": "axial stress (Pa): axial force / area"}
for _q in ELEMENT_QUANTITIES:
    command(f"structure cable history {_q}", keywords=_WHICH, check=_check,
            doc=f"Record the {_EDOC[_q]} of a cable element.",
            details="The element is named by `component-id <i>` (its id, as `structure cable list` shows) or by "
                    "`position x y z` (the element whose midpoint, as created, is nearest). A leading "
                    "`name '<s>'` names the history.",
            examples=[f"structure cable history {_q} component-id 1",
                      f"structure cable history name 'n1' {_q} position 0 0 -1"])(
        _handler("cable", SEGMENTS, _q))

for _q in NODE_QUANTITIES:
    _what = ("displacement" if _q.startswith("d") else "velocity") + (
        f" ({_q[-1]} component)" if _q[-2] == "-" else " (magnitude)")
    command(f"structure node history {_q}", keywords=_WHICH, check=_check,
            doc=f"Record the {_what} of a structural node (cable, beam or liner).",
            details="The node is named by `component-id <i>` (its id; cable, beam and liner nodes share one id "
                    "space) or "
                    "by `position x y z` (the nearest node).",
            examples=[f"structure node history {_q} component-id 1"])(_handler("cable-node", NODES, _q))
