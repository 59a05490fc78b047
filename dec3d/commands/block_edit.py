"""`block delete|hide|group|join|property|list`: editing and inspecting blocks."""
from __future__ import annotations

import numpy as np

from ..model.blocks import (delete_blocks, group_blocks, hide_blocks, join_blocks, joined_groups,
                            set_density, summary)
from ..units import suffix
from .registry import command
from .values import DENSITY, FLAG, ONOFF, Choice, Num, P, Text


@command("block delete", keywords=[P("reaction", Num(lo=0.0, hi=1.0), "fraction of the deleted blocks' contact "
                                     "forces left on the rigid blocks that remain, as applied loads (dec3d)")],
         range="block",
         doc="Delete the blocks in range (all blocks without a range).",
         details="Block ids are not reused. Followers of a deleted leader follow the lowest remaining block "
                 "of their joined group. Zoned blocks of a joined group that remain keep sharing their gridpoints "
                 "(the links of shared gridpoints are made again, so a gridpoint whose master row was in a "
                 "deleted block is not split): deleting zoned blocks excavates. With `reaction f` (dec3d) the "
                 "sub-contact forces the deleted blocks exert on each remaining rigid block (normal and shear, "
                 "as they are now) are summed into a force and a moment about its centroid, and f times them "
                 "is added to its applied force and moment (`block apply`): an excavation whose face keeps a "
                 "fraction f of its reaction, as 3DEC decks do with `block face apply stress` of part of the "
                 "in-situ stress on zoned blocks. Remove the loads later with `block apply-remove force moment`.",
         examples=["block delete range cylinder end-1 0 0 0 end-2 0 1 0 radius 0 1",
                   "block delete range plane dip 0 dip-direction 0 below",
                   "block delete range pos-x 0.3230 0.4038",
                   "block delete reaction 0.5 range group 'exc'"])
def block_delete(session, call):
    from ..model.zone_mesh import relink

    mask = np.asarray(session.range_mask(call, "block"), bool)
    loads = None
    if call.args["reaction"] is not None:
        loads = reaction_loads(session.model, mask, call.location)
    from ..model.cables import nodes_hosted_by

    lost = nodes_hosted_by(session.model, mask)
    if delete_blocks(session.model, mask):
        relink(session.model)
    if lost:
        session.write(f"notice: {lost} cable node(s) lay in the deleted blocks: from now on they are free "
                      "(no grout force)")
    if loads is not None:
        ids, f, m = loads
        b = session.model.blocks
        row_of = {int(i): r for r, i in enumerate(b["id"])}
        rows = np.array([row_of[int(i)] for i in ids], np.int64)
        frac = float(call.args["reaction"])
        np.add.at(b["fapp"], rows, frac * f)
        np.add.at(b["mapp"], rows, frac * m)


def reaction_loads(model, mask, location):
    """(ids, forces, moments) of the remaining blocks: the sum of the sub-contact forces that the
    blocks of ``mask`` exert on each of them, and its moment about the block's centroid.
    The force on a contact's second block B is fn n + fs (n the unit normal A → B, fn compression
    positive, fs the shear force on B); A takes the opposite. Nothing is changed here."""
    from ..errors import CommandError
    from ..model.model import KIND_RIGID

    b = model.blocks
    ids = np.zeros(0, np.int64)
    if "contacts" not in model.stores or not mask.any():
        return ids, np.zeros((0, 3)), np.zeros((0, 3))
    cs, ss = model.store("contacts"), model.store("subcontacts")
    row_of = {int(i): r for r, i in enumerate(b["id"])}
    gone = set(int(i) for i in b["id"][mask])
    acc = {}
    for k in range(ss.n):
        c = int(ss["contact"][k])
        ia, ib = int(cs["ida"][c]), int(cs["idb"][c])
        if (ia in gone) == (ib in gone) or ia not in row_of or ib not in row_of:
            continue
        fb = ss["fn"][k] * cs["normal"][c] + ss["fs"][k]           # force on B
        keep, force = (ib, fb) if ia in gone else (ia, -fb)
        r = row_of[keep]
        if b["kind"][r] != KIND_RIGID or (b["leader"][r] >= 0 and b["leader"][r] != r):
            raise CommandError(f"`block delete reaction`: block {keep} next to the deleted blocks is "
                               f"{'joined to another' if b['kind'][r] == KIND_RIGID else 'not rigid'}; the "
                               "reaction is applied to rigid, unjoined blocks only; nothing was deleted", location)
        f, m = acc.setdefault(keep, (np.zeros(3), np.zeros(3)))
        f += force
        m += np.cross(ss["pos"][k] - b["centroid"][r], force)
    ids = np.array(sorted(acc), np.int64)
    f = np.array([acc[i][0] for i in ids]).reshape(-1, 3)
    m = np.array([acc[i][1] for i in ids]).reshape(-1, 3)
    if not (np.isfinite(f).all() and np.isfinite(m).all()):
        raise CommandError("`block delete reaction`: a contact force is not finite; nothing was deleted", location)
    return ids, f, m


@command("block hide", positional=[P("mode", ONOFF, "on hides, off shows again", default=True)], range="block",
         doc="Hide the blocks in range (hidden blocks are not cut), or show them again with `off`.",
         examples=["block hide range group 'brickUp' not", "block hide group \"foundation\"", "block hide off",
                   "block hide pos-x 0 0.32", "block hide"])
def block_hide(session, call):
    hide_blocks(session.model, session.range_mask(call, "block"), on=call.args["mode"])


@command("block group", positional=[P("name", Text(), "group name", required=True)],
         keywords=[P("slot", Text(), "group slot (default 'Default')"),
                   P("remove", FLAG, "take the blocks out of the group instead", bare=True)],
         range="block",
         doc="Put the blocks in range in a group (one group per slot; the old one is replaced).",
         examples=["block group 'Masonry' range group 'S' or 'T_B' not", "block group 'top' slot 'layer'",
                   "block group 'top' slot 'layer' remove range position-z 0 1"])
def block_group(session, call):
    a = call.args
    group_blocks(session.model, session.range_mask(call, "block"), a["name"], a["slot"], remove=bool(a["remove"]))


@command("block join", positional=[P("mode", ONOFF, "on joins, off releases", default=True)], range="block",
         doc="Join the blocks in range into one rigid body (leader/follower), or release them with `off`.",
         details="Joined blocks keep their convex pieces for contact detection and move as one body "
                 "(the leader carries the group's mass, centroid and inertia). Joining merges with any "
                 "joined group a selected block already belongs to.",
         examples=["block join on", "block join range group 'wall'", "block join off range id 3"])
def block_join(session, call):
    from ..model.zone_mesh import relink

    join_blocks(session.model, session.range_mask(call, "block"), on=call.args["mode"])
    relink(session.model)            # zoned and FE blocks of one joined set share their coincident gridpoints


@command("block property", keywords=[P("density", DENSITY, "mass density", required=True,
                                       units="kg/m³")],
         range="block",
         doc="Set the density of the blocks in range (mass and inertia follow).",
         examples=["block property density 2650", "block prop dens 1500 range group 'soft'"])
def block_property(session, call):
    set_density(session.model, session.range_mask(call, "block"), call.args["density"])
    density_warning(session, call, call.args["density"])


#: densities outside these bounds are not those of a rock, soil, masonry or concrete in SI units
PLAUSIBLE_DENSITY = (100.0, 30_000.0)


def density_warning(session, call, rho: float) -> None:
    """One warning for a density no rock, soil or masonry has in SI units (kg/m³): a deck in other
    units (tonnes, MN) is right to ignore it; a deck in SI has a typo."""
    lo, hi = PLAUSIBLE_DENSITY
    if lo <= rho <= hi:
        return
    text = (f"density {rho:g} is outside {lo:g}–{hi:g} kg/m³, the range of rock, soil and masonry in SI units "
            "(fine if the deck works in other units)")
    session.write(f"warning: {call.location}: {text}")
    session.warnings.append(f"{call.location}: {text}")


def _groups_of(model, row) -> str:
    names = []
    for col, slot in enumerate(model.groups.slot_names("blocks")):
        code = model.blocks["group"][row, col]
        if code >= 0:
            names.append(model.groups.name(code) if slot == "Default" else f"{model.groups.name(code)}({slot})")
    return " ".join(names)


@command("block list", positional=[P("what", Choice(("information",)), "summary instead of a block table")],
         range="block",
         doc="List the blocks in range (id, centroid, volume, density, groups), or a summary with `information`.",
         examples=["block list", "block list information", "block list range group 'rock'"])
def block_list(session, call):
    m = session.model
    mask = session.range_mask(call, "block")
    if call.args["what"] == "information":
        s = summary(m)
        sel = np.flatnonzero(mask)
        session.write(f"blocks {s['blocks']} (in range {sel.size}, hidden {s['hidden']}, "
                      f"joined {s['joined']} in {len(joined_groups(m))} groups)")
        session.write(f"vertices {s['vertices']}, faces {s['faces']}")
        L, V = suffix(m, "length"), suffix(m, "volume")
        session.write(f"total volume {s['volume']:.6g}{V}, mass {s['mass']:.6g}{suffix(m, 'mass')}")
        if sel.size:
            vol = m.blocks["volume"][sel]
            session.write(f"volume in range: total {vol.sum():.6g}, min {vol.min():.6g}, max {vol.max():.6g}{V}")
        if s["extent"]:
            lo, hi = s["extent"]
            session.write("extent x {:.6g} {:.6g}  y {:.6g} {:.6g}  z {:.6g} {:.6g}".format(
                lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]) + L)
        session.write(f"tolerance {s['tolerance']:g}{L}")
        session.results.update({"blocks": float(s["blocks"]), "volume": s["volume"]})
        return
    b = m.blocks
    session.write(f"{'id':>7} {'x':>11} {'y':>11} {'z':>11} {'volume':>11} {'density':>9}  groups")
    for r in np.flatnonzero(mask):
        c = b["centroid"][r]
        flag = " (hidden)" if b["hidden"][r] else ""
        session.write(f"{b['id'][r]:>7} {c[0]:>11.5g} {c[1]:>11.5g} {c[2]:>11.5g} {b['volume'][r]:>11.5g} "
                      f"{b['density'][r]:>9.5g}  {_groups_of(m, r)}{flag}")

