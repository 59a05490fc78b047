"""`block face group`, `block face list`, `block face triangulate`, `block face apply` (stresses, table-driven stresses,
quiet boundaries) and `block face apply-remove`."""
from __future__ import annotations

import numpy as np

from ..errors import BindError, CommandError, NotSupportedError
from ..geometry.triangulate import triangulate_blocks
from ..lang.abbrev import matches
from ..model.blocks import group_faces
from .values import TableId
from .registry import command
from .values import FLAG, Num, Nums, P, Text, ValueType


@command("block face group", positional=[P("name", Text(), "group name", required=True)],
         keywords=[P("slot", Text(), "group slot (default 'Default')"),
                   P("remove", FLAG, "take the faces out of the group instead", bare=True)],
         range="face",
         doc="Put the block faces in range in a group (faces are located by their area centroid).",
         examples=["block face group 'base' range position-z 0", "block face group 'east' slot 'bc' range pos-x 10"])
def block_face_group(session, call):
    a = call.args
    group_faces(session.model, session.range_mask(call, "face"), a["name"], a["slot"], remove=bool(a["remove"]))


@command("block face list", range="face",
         doc="List the block faces in range: block id, area centroid, outward normal, area and groups.",
         details="Faces of zoned blocks are the boundary triangles of their zones.",
         examples=["block face list range group 'wall'", "block face list range position-z 0"])
def block_face_list(session, call):
    m = session.model
    f = m.faces
    rows = np.flatnonzero(session.range_mask(call, "face") & (f["block"][: f.n] >= 0))
    slots = m.groups.slot_names("faces")
    session.write(f"{'face':>7} {'block':>7} {'x':>10} {'y':>10} {'z':>10} {'nx':>7} {'ny':>7} {'nz':>7} "
                  f"{'area':>10}  groups")
    ids = m.blocks["id"]
    for r in rows:
        c, n = f["centroid"][r], f["normal"][r]
        names = [m.groups.name(int(g)) + ("" if s == "Default" else f"({s})")
                 for g, s in zip(f["group"][r], slots) if g >= 0]
        session.write(f"{r + 1:>7} {ids[f['block'][r]]:>7} {c[0]:>10.4g} {c[1]:>10.4g} {c[2]:>10.4g} {n[0]:>7.3f} "
                      f"{n[1]:>7.3f} {n[2]:>7.3f} {f['area'][r]:>10.4g}  {' '.join(names)}")
    session.write(f"{len(rows)} face(s)")


@command("block face triangulate",
         keywords=[P("radial", FLAG, "a fan of triangles around each face's centroid", bare=True),
                   P("radial-8", FLAG, "as radial, with the edge mid-points (8 triangles on a quadrilateral)", bare=True),
                   P("edge-max", Num(lo=0, lo_open=True), "radial, then halved until no edge is longer",
                     units="m")],
         range="block",
         doc="Split the faces of the blocks in range into triangles (more sub-contacts on rigid blocks).",
         details="Give one of `radial`, `radial-8` or `edge-max <f>`. Mid-points are shared by the faces "
                 "on an edge, so the surface stays closed. The shape, volume and mass properties do not "
                 "change; triangles keep the groups of their face.",
         examples=["block face triangulate radial-8", "block face triangulate radial range group 'arch'",
                   "block face triangulate edge-max 0.5"])
def block_face_triangulate(session, call):
    a = call.args
    modes = [m for m, on in (("radial", a["radial"]), ("radial-8", a["radial_8"]),
                             ("edge-max", a["edge_max"] is not None)) if on]
    if len(modes) != 1:
        raise BindError("`block face triangulate` takes exactly one of radial, radial-8, edge-max <f>",
                        call.location)
    rows = np.flatnonzero(session.range_mask(call, "block"))
    triangulate_blocks(session.model, rows, modes[0], a["edge_max"])


_STRESS_KEYS = ("stress-xx", "stress-yy", "stress-zz", "stress-xy", "stress-xz", "stress-yz")


class _History(ValueType):
    """3DEC's `history table <id>` (or `history fish @f`): what multiplies the applied stress in time."""

    label = "table <id> | fish <f>"
    fits_types = ("WORD",)

    def take(self, toks, i, binder):
        tok = toks[i]
        kind = matches(str(tok).lower(), ["table", "fish"])
        if len(kind) != 1:
            raise BindError("`history` takes `table <id>` (or `fish @f`)", binder.where(tok))
        if i + 1 >= len(toks):
            raise BindError(f"`history {kind[0]}` needs a {'table id' if kind[0] == 'table' else 'FISH function'}",
                            binder.where(tok))
        nt = toks[i + 1]
        if kind[0] == "fish":
            return ("fish", str(nt)), i + 2
        if nt.type not in ("NUMBER", "STRING", "WORD"):
            raise BindError("a table id is an integer or a name", binder.where(nt))
        return ("table", TableId().literal(nt)), i + 2


def _no_fish_history(call):
    h = call.args.get("history")
    if h is not None and h[0] == "fish":
        raise NotSupportedError("`block face apply … history fish` is not supported yet: give the time function as "
                                "a table (`history table <id>` or `table <id>`)", call.locations.get("history",
                                                                                                   call.location))
    if h is not None and call.args.get("table") is not None:
        raise BindError("give the table once: `table <id>` or `history table <id>`", call.location)


@command("block face apply",
         keywords=[P("stress", Nums(6, 6), "sxx syy szz sxy sxz syz", units="Pa"),
                   *[P(k, Num(), f"the {k[-2:]} component alone", units="Pa") for k in _STRESS_KEYS],
                   P("stress-normal", Num(), "normal stress (tension positive)", units="Pa"),
                   P("quiet", FLAG, "a quiet (viscous, Lysmer–Kuhlemeyer) boundary on the faces", bare=True),
                   P("table", TableId(), "multiply the stress by this table of time (model time, linear)"),
                   P("history", _History(), "3DEC's spelling of the same: `history table <id>`")],
         range="face", check=_no_fish_history,
         doc="Apply a stress, or a quiet boundary, to the boundary triangles of zoned blocks in range "
             "(located by centroid).",
         details="The traction t = σ·n on each triangle, times its area, goes a third to each of its "
                 "gridpoints every step; the two triangles of a hexahedral zone's face are loaded as the "
                 "quadrilateral (the mean of its two diagonal splits: a quarter to each corner of a "
                 "parallelogram) and the faces of 10-node zones as 6-node triangles. Loads add to what is there; only faces on the outside of a "
                 "joined continuum take them. `block face apply-remove` clears them.\n\n"
                 "`table <id>` (or 3DEC's `history table <id>`) multiplies the stress by the table's value at "
                 "the model time of each step (linear interpolation, end values held outside; the table's "
                 "points as they are when the command runs). A face carries one such table.\n\n"
                 "`quiet` puts the viscous boundary of Lysmer and Kuhlemeyer on the faces: dashpots with "
                 "tractions −ρC_p v_n (normal) and −ρC_s v_s (shear), C_p = ((K + 4G/3)/ρ)^½ and C_s = (G/ρ)^½ "
                 "of the zone each face belongs to (FE blocks: of their elements) when the command runs, shared among the "
                 "gridpoints like an applied stress. The time step and, in static runs, the scaled masses allow for the "
                 "dashpots. A wave comes in through a quiet base as a stress 2ρC_s v (shear) or 2ρC_p v (normal) "
                 "for the incident velocity v, e.g. `stress-xz` with a table (on a base whose outward normal is "
                 "−z, `stress-xz −2ρC_s v` pushes +x). Faces of rigid blocks take neither. (3DEC 7 lists no `quiet` "
                 "for `block face apply` and sets viscous boundaries on gridpoints, `block gridpoint apply quiet`, "
                 "which dec3d has too; `quiet` here is FLAC3D's `zone face apply quiet`.)",
         examples=["block face apply stress-normal -1e6 range position-z 1",
                   "block face apply stress -1e6 -2e6 -1e6 0 0 0 range group 'hole'",
                   "block face apply quiet range position-z 0",
                   "block face apply stress-xz -4e5 history table 1 range position-z 0",
                   "block face apply stress-xz -4e5 table 'pulse' range position-z 0"])
def block_face_apply(session, call):
    from ..model.face_loads import apply_face_stress
    a = call.args
    s = np.zeros(6)
    given = 0
    if a["stress"] is not None:
        s += np.asarray(a["stress"], float)
        given += 1
    for i, k in enumerate(_STRESS_KEYS):
        if a[k.replace("-", "_")] is not None:
            s[i] += a[k.replace("-", "_")]
            given += 1
    if a["stress_normal"] is not None:
        s[:3] += a["stress_normal"]
        given += 1
    tid = a["table"] if a["table"] is not None else (a["history"][1] if a["history"] is not None else None)
    if not given and not a["quiet"]:
        raise BindError("`block face apply` needs stress <6 values>, stress-xx … or stress-normal <f>, or quiet",
                        call.location)
    if tid is not None and not given:
        raise BindError("`table` multiplies a stress: give stress-xx … or stress <6 values> with it", call.location)
    if not np.isfinite(s).all():
        raise BindError("`block face apply`: the stress must be finite", call.location)
    mask = session.range_mask(call, "face")
    if a["quiet"]:
        _apply_quiet(session, call, mask)
    if tid is not None:
        _apply_table_stress(session, call, mask, s, tid)
    elif given:
        n = apply_face_stress(session.model, mask, s)
        if n == 0:
            session.write(f"warning: {call.location}: `block face apply` selected no boundary face of a zoned "
                          "block (faces of rigid blocks take no applied stress)")


def _apply_quiet(session, call, mask) -> None:
    from ..model.quiet import face_impedances, quiet_candidates, set_quiet
    m = session.model
    rows = quiet_candidates(m, mask)
    if not len(rows):
        raise CommandError("`block face apply quiet` selected no boundary face of a zoned or FE block (rigid "
                           "blocks take no quiet boundary in dec3d)", call.location)
    imp, problems = face_impedances(m, rows)
    if problems:
        raise CommandError("`block face apply quiet`: " + "; ".join(problems), call.location)
    set_quiet(m, rows, imp)


def _apply_table_stress(session, call, mask, s, tid) -> None:
    from ..fish.table_intrinsics import table_key
    from ..model.face_loads import loadable_faces
    from ..model.quiet import add_dynamic_stress, dynamic_conflicts, table_index
    m = session.model
    where = call.locations.get("table", call.locations.get("history", call.location))
    tab = session.fish_rt.tables.get(table_key(tid)) if hasattr(session.fish_rt, "tables") else None
    if tab is None or not tab.xs:
        raise CommandError(f"there is no table {tid}" + (" with points" if tab is not None else ""), where,
                           hint="make it first: `table <id> add (t,v) …` or `table <id> import '<file>'`")
    rows = np.flatnonzero(mask & loadable_faces(m))
    if not len(rows):
        session.write(f"warning: {call.location}: `block face apply` selected no boundary face of a zoned "
                      "block (faces of rigid blocks take no applied stress)")
        return
    before = list(m.settings.mechanical.get("face_tables", []))
    j = table_index(m, tid, tab.xs, tab.ys)
    clash = dynamic_conflicts(m, rows, j)
    if len(clash):
        m.settings.mechanical["face_tables"] = before
        raise CommandError(f"{len(clash)} faces in range carry a stress of another table already: a face takes "
                           "one table (`block face apply-remove stress` first)", call.location)
    add_dynamic_stress(m, rows, s, j)


@command("block face apply-remove", range="face",
         keywords=[P("stress", FLAG, "the applied stresses only (fixed and table-driven)", bare=True),
                   P("quiet", FLAG, "the quiet boundaries only", bare=True)],
         doc="Remove the stresses and quiet boundaries applied to the faces in range (`block face apply`).",
         details="With neither keyword both go.",
         examples=["block face apply-remove", "block face apply-remove stress range position-z 1",
                   "block face apply-remove quiet range position-z 0"])
def block_face_apply_remove(session, call):
    from ..model.face_loads import remove_face_stress
    from ..model.quiet import remove_dynamic_stress, remove_quiet
    a = call.args
    both = not a["stress"] and not a["quiet"]
    mask = session.range_mask(call, "face")
    if a["stress"] or both:
        remove_face_stress(session.model, mask)
        remove_dynamic_stress(session.model, mask)
    if a["quiet"] or both:
        remove_quiet(session.model, mask)
