"""`structure liner group|delete|recover …`: grouping, deleting and stress-resultant recovery of liner
elements (stores ``dec3d.model.liners``; recovery ``dec3d.model.liner_recover``). Keywords are Itasca's
(``slot``, ``remove``; ``recover surface v``, ``recover resultants``)."""
from __future__ import annotations

import numpy as np

from ..errors import CommandError
from ..model.liners import LELEMS, has_liners, liner_stores, update_liner_masses, update_liner_normals
from .registry import command
from .values import FLAG, Nums, P, Text


def _need(session, call):
    if not has_liners(session.model):
        raise CommandError("there is no liner: make one first (`structure liner create …`)", call.location)


@command("structure liner group", positional=[P("name", Text(), "group name", required=True)],
         keywords=[P("slot", Text(), "group slot (default 'Default')"),
                   P("remove", FLAG, "take the elements out of the group instead", bare=True)],
         range=LELEMS,
         doc="Put the liner elements in range in a group (one group per slot; the old one is replaced).",
         details="`remove` takes them out of the group: in `slot` if given, else in every slot. Liner ranges "
                 "(`structure liner list`, `property`, `delete`, `recover`) can then select the group. (The form of "
                 "Itasca's `structure pile group` and `structure node group` pages; the liner page itself was not "
                 "among the pages found.)",
         examples=["structure liner group 'crown' range position-z 1.5 3", "structure liner group 'stage1' slot 'seq'",
                   "structure liner group 'crown' remove"])
def liner_group(session, call):
    _need(session, call)
    _, els = liner_stores(session.model)
    rows = np.flatnonzero(session.range_mask(call, LELEMS))
    a = call.args
    if a["remove"]:
        session.model.groups.remove(els, rows, a["name"], a["slot"])
    else:
        session.model.groups.assign(els, rows, a["name"], a["slot"])


def _histories_on(model, elem_ids, node_ids):
    from ..physics.history import histories

    for h in histories(model).items:
        kind, ident = h.spec.get("kind"), h.spec.get("id")
        if (kind == "liner" and ident in elem_ids) or (kind == "cable-node" and ident in node_ids):
            return h
    return None


@command("structure liner delete", range=LELEMS,
         doc="Delete the liner elements in range, and the liner nodes no other element uses.",
         details="A node left without an element goes with its coupling: the force its springs had put into "
                 "the block (or the zone's gridpoints) is taken back out, as `block excavate` does. Nodes still "
                 "used by a remaining element stay as they are (masses and normals are recomputed from the "
                 "remaining elements). Element and node ids of what remains do not change. A history that "
                 "records a deleted element or node is refused: `history delete` it first. (Itasca's `structure liner "
                 "delete` page was not among the documentation pages found; the form here, a range and no keyword, "
                 "is that of `block delete`.)",
         examples=["structure liner delete range group 'stage1'", "structure liner delete range id 2"])
def liner_delete(session, call):
    _need(session, call)
    m = session.model
    nodes, els = liner_stores(m)
    gone = session.range_mask(call, LELEMS)
    if not gone.any():
        session.write(f"warning: {call.location}: `structure liner delete` selected no element")
        return
    orphan = np.ones(nodes.n, bool)
    orphan[els["nodes"][~gone].ravel()] = False
    h = _histories_on(m, {int(i) for i in els["id"][gone]}, {int(i) for i in nodes["id"][orphan]})
    if h is not None:
        raise CommandError(f"history {h.id} ('{h.name}': {h.label}) records a liner element or node this would "
                           f"delete: `history delete {h.id}` first", call.location)
    # the orphans' couplings: the reactions they had put into their hosts' applied loads come back out
    b, v = m.blocks, m.vertices
    lost = np.flatnonzero(orphan & (nodes["host"] >= 0))
    rig, zn = lost[nodes["hz"][lost] == 0], lost[nodes["hz"][lost] != 0]
    np.add.at(b["fapp"], nodes["host"][rig], -nodes["hforce"][rig])
    np.add.at(b["mapp"], nodes["host"][rig], -nodes["hmoment"][rig])
    if zn.size:
        np.add.at(v["fapp"], nodes["hgp"][zn].ravel(),
                  -(nodes["hw"][zn][:, :, None] * nodes["hforce"][zn][:, None, :]).reshape(-1, 3))
    remap = nodes.compact(~orphan)
    els.compact(~gone)
    els["nodes"][:] = remap[els["nodes"]]
    if els.n:
        update_liner_normals(m)
        update_liner_masses(m)
    session.write(f"deleted {int(gone.sum())} liner element(s) and {int(orphan.sum())} node(s)")


@command("structure liner recover surface", positional=[P("v", Nums(3, 3), "the surface x direction (projected "
                                                           "onto each node's tangent plane)", required=True)],
         range=LELEMS,
         doc="Set the surface system of the nodes of the liner elements in range, for `recover resultants`.",
         details="At each node z is the liner's normal there (the area-weighted mean of its elements' z axes, "
                 "outward from the block) and x the projection of v onto the plane normal to z; y = z × x. A node "
                 "whose normal is parallel to v gets none (reported): give another v for it.",
         examples=["structure liner recover surface 1 0 0", "structure liner recover surface 0 1 0 range group 'wall'"])
def liner_recover_surface(session, call):
    from ..model.liner_recover import set_surface

    _need(session, call)
    rows = np.flatnonzero(session.range_mask(call, LELEMS))
    bad = set_surface(session.model, rows, [float(x) for x in call.args["v"]])
    if bad:
        session.write(f"warning: {call.location}: {bad} node(s) have a normal parallel to the vector: no surface "
                      "system there")


@command("structure liner recover resultants", range=LELEMS,
         doc="Recover the eight stress resultants of the liner elements in range, in the surface systems.",
         details="M_x, M_y, M_xy (bending and twisting moments per unit length, N·m/m), N_x, N_y, N_xy "
                 "(membrane forces per unit length, N/m, tension positive) and Q_x, Q_y (transverse shear per "
                 "unit length, N/m). The moments and membrane forces of each element (its corners' values) are "
                 "averaged at each node over the elements in range that share it, in the node's surface system "
                 "(`structure liner recover surface v` first): the range is the patch averaged over. Q_x = "
                 "∂M_x/∂x + ∂M_xy/∂y and Q_y = ∂M_xy/∂x + ∂M_y/∂y come from the averaged moments, linear over "
                 "each element (constant Q per element). Moments: M_x = −D (w,xx + ν w,yy), M_xy = −D (1 − ν) "
                 "w,xy in the surface axes (positive M_x makes +z concave). Read them with FISH "
                 "`struct.shell.resultant(id, iloc <, ires>)` (iloc 0 the centroid, 1-3 the nodes) and "
                 "`struct.node.resultant(node-id <, ires>)`. Values stay as recovered until the next recovery. Itasca's "
                 "`recover stress depth-factor f` (a stress tensor at a depth) is not built.",
         examples=["structure liner recover resultants", "structure liner recover resultants range group 'crown'"])
def liner_recover_resultants(session, call):
    from ..model.liner_recover import recover

    _need(session, call)
    rows = np.flatnonzero(session.range_mask(call, LELEMS))
    if not rows.size:
        session.write(f"warning: {call.location}: `structure liner recover resultants` selected no element")
        return
    missing = recover(session.model, rows)
    if missing:
        raise CommandError(f"{missing} node(s) of the elements in range have no surface system: "
                           "`structure liner recover surface v` first", call.location)
