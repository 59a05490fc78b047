"""Groups of zones and gridpoints: `block zone group`, `block gridpoint group`.

Blocks, faces and contacts have their group commands beside their other commands. A zone or a
gridpoint is in a group when it was put in it here, or when its block is (so `range group
'foundation'` on gridpoints selects the gridpoints of the blocks of that group, as in 3DEC decks).
"""
from __future__ import annotations

import numpy as np

from ..model.zones import zone_stores
from .registry import command
from .values import FLAG, P, Text

_KEYS = [P("slot", Text(), "group slot (default 'Default')"),
         P("remove", FLAG, "take them out of the group instead", bare=True)]


def _group(session, call, store_name: str, rows: np.ndarray, what: str) -> None:
    m = session.model
    a = call.args
    store = m.store(store_name)
    if a["remove"]:
        m.groups.remove(store, rows, a["name"], a["slot"])
    else:
        m.groups.assign(store, rows, a["name"], a["slot"])
    if not len(rows):
        session.write(f"warning: {call.location}: `{call.command.name}` selected no {what}")


@command("block zone group", positional=[P("name", Text(), "group name", required=True)], keywords=_KEYS,
         range="zone",
         doc="Put the zones in range in a group (one group per slot; the old one is replaced), or take them out "
             "with `remove`.",
         details="A zone is also in the groups of its block: `range group` on zones selects both.",
         examples=["block zone group 'soft' range position-z 0 2", "block zone group 'layer2' slot 'geology'",
                   "block zone group 'soft' remove range position-z 0 1"])
def block_zone_group(session, call):
    zone_stores(session.model)
    rows = np.flatnonzero(session.range_mask(call, "zone"))
    _group(session, call, "zones", rows, "zone")


@command("block gridpoint group", positional=[P("name", Text(), "group name", required=True)], keywords=_KEYS,
         range="gridpoint",
         doc="Put the gridpoints (of zoned blocks) in range in a group, or take them out with `remove`.",
         details="A gridpoint is also in the groups of its block, so `block gridpoint apply … range group "
                 "'foundation'` acts on the gridpoints of the blocks in group 'foundation' without this command.",
         examples=["block gridpoint group 'base' range position-z 0", "block gridpoint group 'top' slot 'bc'"])
def block_gridpoint_group(session, call):
    m = session.model
    zone_stores(m)
    rows = np.flatnonzero(session.range_mask(call, "gridpoint") & m.vertices["zoned"])
    _group(session, call, "vertices", rows, "gridpoint")
