"""`block gridpoint apply` and `block gridpoint apply-remove`: conditions on the gridpoints of zoned blocks."""
from __future__ import annotations

import numpy as np

from ..errors import BindError, CommandError
from ..model.zones import zone_stores
from ..physics.dynamic import add_timefn, load_time, remove_timefns, timefn_factor
from .block_apply import _TIMEFN, check_timefn, timefn_source, where_text
from .registry import command
from .values import FLAG, Num, Nums, P

_AX = ("x", "y", "z")
_QUIET = ("quiet", "quiet_x", "quiet_y", "quiet_z")


def _gridpoints(session, call, what: str) -> np.ndarray:
    """Rows of zoned-block gridpoints in range; a warning naming file:line when there are none."""
    m = session.model
    zone_stores(m)
    sel = session.range_mask(call, "gridpoint")
    rows = np.flatnonzero(sel & m.vertices["zoned"])
    if not len(rows) and (sel.any() or call.range is None):      # (an empty range has warned already)
        why = (" (the range holds only vertices of rigid blocks, which are not gridpoints)" if sel.any()
               else "")
        session.write(f"warning: {call.location}: `{what}` selected no gridpoint{why}")
    return rows


@command("block gridpoint apply",
         keywords=[P("velocity", Nums(3, 3), "vx vy vz: all three components held", units="m/s"),
                   *[P(f"velocity-{a}", Num(), f"the {a} component held", units="m/s") for a in _AX],
                   P("force", Nums(3, 3), "fx fy fz applied force", units="N"),
                   *[P(f"force-{a}", Num(), f"the {a} component of the applied force", units="N") for a in _AX],
                   P("quiet", FLAG, "a quiet (viscous, Lysmer–Kuhlemeyer) boundary in all three directions",
                     bare=True),
                   *[P(f"quiet-{a}", FLAG, f"a quiet boundary acting along {a} only", bare=True) for a in _AX],
                   P("table", _TIMEFN, "time function: the value is multiplied by table <id> at the current time"),
                   P("fish", _TIMEFN, "time function: the value is multiplied by FISH function <s> at the current "
                     "time")],
         range="gridpoint", check=check_timefn,
         doc="Hold velocity components, or apply a force, at the gridpoints of zoned blocks in range.",
         details="A velocity condition holds the component at the value every step; a force is added to "
                 "the gridpoint's unbalanced force every step (a new value replaces the old one). Vertices "
                 "of rigid blocks are not gridpoints (use `block fix` / `block apply` for them). With `table <id>` "
                 "or `fish <name>` the value is multiplied at every step by the table at the current time (linear "
                 "interpolation) or the FISH function's value (as `block apply`: the dynamic time in dynamic "
                 "mode, else the model's time; a velocity at the middle of the step, a force at its start; such a "
                 "force adds to the constant one). `quiet` (or `quiet-x|-y|-z`, one direction) makes the "
                 "gridpoints a viscous boundary (Lysmer and Kuhlemeyer, as `block face apply quiet`): every "
                 "boundary face whose gridpoints are all quiet takes normal and shear dashpots ρC_p and ρC_s of "
                 "its zone (C_p = ((K + 4G/3)/ρ)^½, C_s = (G/ρ)^½) per unit area, shared to its gridpoints as an "
                 "applied stress is; a gridpoint quiet along some axes only keeps the dashpot forces along "
                 "them from the velocity along them. `quiet` takes no value, table or fish and no other keyword.",
         examples=["block gridpoint apply velocity-z 0 range position-z 0",
                   "block gridpoint apply quiet range position-z 0",
                   "block gridpoint apply quiet-x range position-x 0",
                   "block gridpoint apply velocity 0 0 0 range position-x 0",
                   "block gridpoint apply force 0 0 -1e3 range position 0 0 1",
                   "block gridpoint apply velocity-y 1 table 1 range position-z 0"])
def block_gridpoint_apply(session, call):
    a = call.args
    given = [k for k in ("velocity", "velocity_x", "velocity_y", "velocity_z", "force", "force_x", "force_y",
                         "force_z") if a[k] is not None]
    quiet = [k for k in _QUIET if a[k]]
    if quiet:
        return _apply_quiet(session, call, quiet, given)
    if not given:
        raise BindError("`block gridpoint apply` needs velocity[-x|-y|-z], force[-x|-y|-z] or quiet[-x|-y|-z]",
                        call.location)
    for k in given:
        if not np.isfinite(np.asarray(a[k], float)).all():
            raise BindError(f"`{k.replace('_', '-')}` must be finite", call.locations.get(k, call.location))
    table, fish = timefn_source(session, call)
    rows = _gridpoints(session, call, "block gridpoint apply")
    m = session.model
    v = m.vertices
    if table is not None or fish is not None:
        from .fish_cmds import attach_fish

        attach_fish(session)
        where = where_text(call)
        for k in given:
            kind = k.split("_")[0]
            val = np.asarray(a[k], float).reshape(-1)
            comps = range(3) if "_" not in k else ("xyz".index(k[-1]),)
            for j, i in enumerate(comps):
                x = float(val[j] if len(val) == 3 else val[0])
                add_timefn(m, "gridpoint", kind, i, x, rows, table=table, fish=fish, where=where)
                if kind == "velocity":
                    e = m.settings.mechanical["timefns"][-1]
                    v["vapp"][rows, i] = x * timefn_factor(m, e, load_time(m))
                    v["apply_fix"][rows] |= np.uint8(1 << i)
        return
    for i, ax in enumerate(_AX):
        if a["velocity"] is not None or a[f"velocity_{ax}"] is not None:
            remove_timefns(m, "gridpoint", rows, {("velocity", i)})
        if a["force"] is not None or a[f"force_{ax}"] is not None:
            remove_timefns(m, "gridpoint", rows, {("force", i)})
    if a["velocity"] is not None:
        v["vapp"][rows] = np.asarray(a["velocity"], float)
        v["apply_fix"][rows] |= np.uint8(7)
    for i, ax in enumerate(_AX):
        if a[f"velocity_{ax}"] is not None:
            v["vapp"][rows, i] = a[f"velocity_{ax}"]
            v["apply_fix"][rows] |= np.uint8(1 << i)
    if a["force"] is not None:
        v["fapp"][rows] = np.asarray(a["force"], float)
    for i, ax in enumerate(_AX):
        if a[f"force_{ax}"] is not None:
            v["fapp"][rows, i] = a[f"force_{ax}"]


def _apply_quiet(session, call, keys, given) -> None:
    """`block gridpoint apply quiet[-x|-y|-z]` (``dec3d.model.quiet``): the gridpoints in range become
    quiet in those directions, checked to make quiet some boundary face (with those quiet before) whose
    zone has an impedance."""
    from ..model.face_loads import _triangle_nodes
    from ..model.quiet import face_impedances, quiet_bits, quiet_gridpoint_faces

    other = list(given) + [k for k in ("table", "fish") if call.args[k] is not None]
    if other:
        k = other[0]
        raise BindError(f"`quiet` cannot be combined with `{k.replace('_', '-')}` in one `block gridpoint apply`",
                        call.locations.get(k, call.location))
    m = session.model
    rows = _gridpoints(session, call, "block gridpoint apply quiet")
    if not len(rows):
        return
    bits = quiet_bits(m)
    flag = bits != 0
    flag[rows] = True
    faces = quiet_gridpoint_faces(m, flag)
    if len(faces):
        mine = np.zeros(len(flag), bool)
        mine[rows] = True
        faces = faces[mine[_triangle_nodes(m, faces)].any(axis=1)]
    if not len(faces):
        raise CommandError("`block gridpoint apply quiet`: the gridpoints in range make no boundary face of a zoned "
                           "or FE block quiet (a face is quiet when its three gridpoints are: select whole faces, "
                           "e.g. `range position-z 0` for a base)", call.location)
    _, problems = face_impedances(m, faces)
    if problems:
        raise CommandError("`block gridpoint apply quiet`: " + "; ".join(problems), call.location)
    bits[rows] |= np.uint8(7 if "quiet" in keys else sum(1 << "xyz".index(k[-1]) for k in keys))


@command("block gridpoint apply-remove",
         keywords=[P("velocity", FLAG, "all velocity conditions", bare=True),
                   *[P(f"velocity-{a}", FLAG, f"the {a} velocity condition", bare=True) for a in _AX],
                   P("force", FLAG, "the applied force", bare=True),
                   *[P(f"force-{a}", FLAG, f"the {a} component of the applied force", bare=True) for a in _AX],
                   P("quiet", FLAG, "the quiet boundary in all directions", bare=True),
                   *[P(f"quiet-{a}", FLAG, f"the quiet boundary along {a}", bare=True) for a in _AX]],
         range="gridpoint",
         doc="Remove gridpoint conditions (all of them when no keyword is given) in range.",
         examples=["block gridpoint apply-remove", "block gridpoint apply-remove velocity-z range position-z 0",
                   "block gridpoint apply-remove quiet range position-z 0"])
def block_gridpoint_apply_remove(session, call):
    a = call.args
    keys = [k for k in ("velocity", "velocity_x", "velocity_y", "velocity_z", "force", "force_x", "force_y",
                        "force_z", *_QUIET) if a[k]]
    everything = not keys
    rows = _gridpoints(session, call, "block gridpoint apply-remove")
    v = session.model.vertices
    quiet = [k for k in _QUIET if a[k]]
    if everything or quiet:
        from ..model.quiet import quiet_bits
        drop = 7 if everything or "quiet" in quiet else sum(1 << "xyz".index(k[-1]) for k in quiet)
        quiet_bits(session.model)[rows] &= np.uint8(~drop & 0xFF)
    for i, ax in enumerate(_AX):
        if everything or a["velocity"] or a[f"velocity_{ax}"]:
            remove_timefns(session.model, "gridpoint", rows, {("velocity", i)})
            v["apply_fix"][rows] &= np.uint8(~(1 << i) & 0xFF)
            v["vapp"][rows, i] = 0.0
        if everything or a["force"] or a[f"force_{ax}"]:
            remove_timefns(session.model, "gridpoint", rows, {("force", i)})
            v["fapp"][rows, i] = 0.0


@command("block gridpoint initialize",
         keywords=[P("displacement", Nums(3, 3), "dx dy dz", units="m"),
                   *[P(f"displacement-{a}", Num(), f"the {a} component", units="m") for a in _AX],
                   P("velocity", Nums(3, 3), "vx vy vz", units="m/s"),
                   *[P(f"velocity-{a}", Num(), f"the {a} component", units="m/s") for a in _AX]],
         range="gridpoint",
         doc="Set the displacement or velocity of the gridpoints of zoned blocks in range.",
         details="Displacement is the accumulated record (positions do not move), as decks use it to "
                 "zero displacements after an initial equilibrium.",
         examples=["block gridpoint initialize displacement 0 0 0", "block gridpoint initialize velocity-x 0.1"])
def block_gridpoint_initialize(session, call):
    a = call.args
    pairs = [("displacement", "disp"), ("velocity", "velocity")]
    given = [k for base, _ in pairs for k in (base, *(f"{base}_{ax}" for ax in _AX)) if a[k] is not None]
    if not given:
        raise BindError("`block gridpoint initialize` needs displacement[-x|-y|-z] or velocity[-x|-y|-z]",
                        call.location)
    for k in given:
        if not np.isfinite(np.asarray(a[k], float)).all():
            raise BindError(f"`{k.replace('_', '-')}` must be finite", call.locations.get(k, call.location))
    rows = _gridpoints(session, call, "block gridpoint initialize")
    v = session.model.vertices
    for base, field in pairs:
        if a[base] is not None:
            v[field][rows] = np.asarray(a[base], float)
        for i, ax in enumerate(_AX):
            if a[f"{base}_{ax}"] is not None:
                v[field][rows, i] = a[f"{base}_{ax}"]


def _conditions(v, r) -> str:
    """Applied conditions of gridpoint row ``r`` in words: held velocity components and applied forces."""
    out = []
    bits = int(v["apply_fix"][r])
    for i, ax in enumerate(_AX):
        if bits & (1 << i):
            out.append(f"v{ax}={v['vapp'][r, i]:.4g}")
    for i, ax in enumerate(_AX):
        if v["fapp"][r, i] != 0.0:
            out.append(f"f{ax}={v['fapp'][r, i]:.4g}")
    if np.any(v["fface"][r] != 0.0):
        out.append("face-stress")
    q = int(v["gquiet"][r]) if "gquiet" in v else 0
    if q:
        out.append("quiet" if q == 7 else "quiet-" + "".join(ax for i, ax in enumerate(_AX) if q & (1 << i)))
    if v["link"][r] >= 0:
        out.append(f"linked-to={int(v['link'][r]) + 1}")
    return " ".join(out)


@command("block gridpoint list", range="gridpoint",
         doc="List the gridpoints of zoned blocks in range: id, block, position, displacement, velocity, conditions.",
         details="The id of a gridpoint is its vertex row + 1 (what `block.zone.gp` gives). Conditions: held "
                 "velocity components (`vz=0`), applied forces (`fx=…`), `face-stress` when an applied face "
                 "stress loads it, and `linked-to=<id>` for a gridpoint shared with a joined block (a copy of "
                 "that one).",
         examples=["block gridpoint list", "block gridpoint list range position-z 0"])
def block_gridpoint_list(session, call):
    m = session.model
    rows = _gridpoints(session, call, "block gridpoint list")
    if not len(rows):
        return
    v, b = m.vertices, m.blocks
    owner = v["block"][rows]
    session.write(f"{'id':>7} {'block':>6} {'x':>11} {'y':>11} {'z':>11} {'disp-x':>11} {'disp-y':>11} "
                  f"{'disp-z':>11} {'vel-x':>11} {'vel-y':>11} {'vel-z':>11}  conditions")
    for k, r in enumerate(rows):
        p, d, u = v["pos"][r], v["disp"][r], v["velocity"][r]
        nums = " ".join(f"{x:>11.5g}" for x in (*p, *d, *u))
        session.write(f"{r + 1:>7} {b['id'][owner[k]]:>6} {nums}  {_conditions(v, r)}")
