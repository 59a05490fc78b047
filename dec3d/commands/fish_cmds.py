"""FISH commands: `fish automatic-create|list|history|callback`, and `table` (`fish define` is read by the
prepass).

`fish history` records a FISH global (or the value of a FISH function, called at each sample) as one of
the model's histories (dec3d.physics.history), so `history export`, `history rename` and save files treat
it like any other. `fish callback add` runs a FISH function during cycling: at a negative position from the
`FishBefore` step first in the step list (`RigidEngine.pre_steps`), before the step's forces; at a position
≥ 0 from a step hook of the rigid engine (`RigidEngine.step_hooks`), after its motion. The FISH run time reaches the model through `attach_fish` (the model
gets `fish_probe`, the engine the callback hook); `model restore` calls it again for the restored model.
"""
from __future__ import annotations

import math
import re
from functools import reduce

from ..errors import BindError, CommandError, Dec3dError, NotSupportedError
from ..fish import contact_intrinsics, intrinsics, zone_intrinsics
from ..lang.abbrev import matches
from .registry import command
from .values import FLAG, INT, NUMBERISH, ONOFF, InPath, Nums, P, TableId, Text, ValueType

_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")


@command("fish automatic-create", positional=[P("mode", ONOFF, "off: every FISH name must be declared "
                                                "`global` or `local` before use", required=True)],
         doc="Switch whether FISH creates variables on first use (on, the default) or requires declarations.",
         details="Applies to functions defined after the command: with it off, a `fish define` that uses a "
                 "name that is not a parameter, a `local`, a `global` declared in the function, an existing "
                 "global variable or function stops the deck with the name's position in the body.",
         examples=["fish automatic-create off"])
def fish_automatic_create(session, call):
    session.fish_rt.auto_create = bool(call.args["mode"])


class _ListName(ValueType):
    """The name `fish list` prints: `x`, `'x'`, `@x` or `[x]` all name the variable x (not its value)."""

    label = "<name>"
    fits_types = ("WORD", "STRING", "ATNAME", "EXPR")

    def take(self, toks, i, binder):
        tok = toks[i]
        text = str(tok)
        if tok.type in ("STRING", "EXPR"):
            text = text[1:-1].strip()
        elif tok.type == "ATNAME":
            text = text[1:]
        if not _NAME.match(text):
            raise BindError(f"`fish list` takes a FISH name, not `{text}`", binder.where(tok))
        return text, i + 1


@command("fish list", positional=[P("name", _ListName(), "a variable or function; omitted lists all", default="")],
         doc="Print FISH global variables and functions with their values.",
         details="Functions are listed with their parameters; `fish list [x]` (or `fish list x`) prints one name.",
         examples=["fish list", "fish list 'errsr'"])
def fish_list(session, call):
    from ..fish.values import to_string

    rt = session.fish_rt
    name = str(call.args["name"]).lower()
    variables = session.variables
    if name:
        if name in rt.functions:
            fn = rt.functions[name]
            session.write(f"{fn.name}({', '.join(fn.params)})  (function)")
        elif name in variables:
            session.write(f"{name} = {to_string(variables[name])}")
        else:
            raise CommandError(f"`{name}` is neither a FISH variable nor a function", call.location)
        return
    for n in sorted(rt.functions):
        fn = rt.functions[n]
        session.write(f"{fn.name}({', '.join(fn.params)})  (function)")
    for n in sorted(variables):
        session.write(f"{n} = {to_string(variables[n])}")


# ------------------------------------------------------------------ attaching the run time to a model

class FishCallbackHook:
    """Step hook of the rigid engine: runs the session's FISH callbacks at positions ≥ 0 after each step
    whose number their interval divides. ``interval`` (the gcd of those callbacks' intervals) makes the
    engine end a batch of steps at every step one is due, so it sees the model after exactly that step."""

    def __init__(self, rt):
        self.rt = rt

    @property
    def interval(self) -> int:
        ivs = [cb[2] for cb in self.rt.callbacks if cb[0] >= 0]
        return reduce(math.gcd, ivs) if ivs else 0

    def __call__(self, eng) -> None:
        if self.rt.callbacks:
            self.rt.run_callbacks(int(eng.step), before=False)


class FishBefore:
    """A step of the cycle, first in the step list (``RigidEngine.pre_steps``): the FISH callbacks at negative
    positions, called before anything of the step they are due at (step s = the model's step + 1: they see
    the model after step s − 1, and what they set — applied forces, velocities, face loads — acts in step
    s). The batch then ends before the next step one of them is due at."""
    timing = "hooks"

    def __init__(self, rt, run):
        self.rt, self.run = rt, run

    def prepare(self) -> None:
        pass

    def advance(self, n: int) -> int:
        ivs = [cb[2] for cb in self.rt.callbacks if cb[0] < 0]
        if not ivs:
            return n
        nxt = int(self.run.m.step) + 1
        if any(nxt % iv == 0 for iv in ivs):
            self.rt.run_callbacks(nxt, before=True)
        return max(1, min(n, min(iv - nxt % iv for iv in ivs)))

    def __repr__(self) -> str:
        return "FishBefore"


class _MakeFishBefore:
    """The factory ``RigidEngine.pre_steps`` holds: one ``FishBefore`` per run."""

    def __init__(self, rt):
        self.rt = rt

    def __call__(self, run) -> FishBefore:
        return FishBefore(self.rt, run)


def attach_fish(session, model=None) -> None:
    """Give ``model`` (default: the session's) the FISH run time: ``model.fish_probe`` for FISH histories,
    and, when there are callbacks, the callback hook first among the rigid engine's step hooks (before the
    histories, so a history sees what a callback set in the same step) and the ``FishBefore`` step first in
    its step list (callbacks at negative positions)."""
    model = session.model if model is None else model
    rt = session.fish_rt
    model.fish_probe = rt.probe
    model.fish_table = lambda tid: rt.tables.get(tid.lower() if type(tid) is str else tid)   # time functions
    if rt.callbacks:
        from ..physics.rigid import engine

        eng = engine(model)
        hooks = eng.step_hooks
        if not any(isinstance(h, FishCallbackHook) and h.rt is rt for h in hooks):
            hooks.insert(0, FishCallbackHook(rt))
        if not any(isinstance(f, _MakeFishBefore) and f.rt is rt for f in eng.pre_steps):
            eng.pre_steps.append(_MakeFishBefore(rt))


def _current_contacts(model):
    """The contact stores with the contacts up to date (detected when the blocks changed since the last
    detection), for FISH's block.contact.* intrinsics."""
    from ..physics.rigid import engine

    eng = engine(model)
    eng.ensure_contacts()
    return eng.contacts, eng.subcontacts


def _engine(model):
    from ..physics.rigid import engine

    return engine(model)


def _joint_model(code):
    from ..physics.jmodels import MODEL_BY_CODE

    return MODEL_BY_CODE.get(code)


def _zone_model(code):
    from ..physics.cmodels import MODEL_BY_CODE

    return MODEL_BY_CODE.get(code)


contact_intrinsics.CONTACTS[0] = _current_contacts
contact_intrinsics.JMODELS[0] = _joint_model
zone_intrinsics.ZMODELS[0] = _zone_model
intrinsics.ENGINE[0] = _engine


# ------------------------------------------------------------------ fish history


class FishHistoryArgs(ValueType):
    """`[name '<s>'] <var|@var>`: an optional history name, then the FISH name (not its value)."""

    label = "[name <s>] <var|@var>"
    fits_types = ("WORD", "ATNAME", "STRING")

    def take(self, toks, i, binder):
        hname = None
        tok = toks[i]
        if tok.type == "WORD" and matches(str(tok).lower(), ["name"]) == ["name"] and i + 2 < len(toks):
            nt = toks[i + 1]
            if nt.type not in ("STRING", "WORD", "NUMBER"):
                raise BindError("`name` needs a history name", binder.where(nt))
            hname = str(nt)[1:-1] if nt.type == "STRING" else str(nt)
            i += 2
            tok = toks[i]
        if tok.type not in self.fits_types:
            raise BindError("expected a FISH variable or function (`x` or `@x`)", binder.where(tok))
        text = str(tok)
        text = text[1:] if tok.type == "ATNAME" else (text[1:-1] if tok.type == "STRING" else text)
        if not _NAME.match(text):
            raise BindError(f"`{text}` is not a FISH name", binder.where(tok))
        return (hname, text), i + 1


@command("fish history", positional=[P("what", FishHistoryArgs(), "the FISH global or function to record",
                                       required=True)],
         doc="Record a FISH global variable, or the value of a FISH function, every `history interval` steps.",
         details="`fish history x` reads the global `x` at each sample; `fish history @f` (or `fish history f`) "
                 "of a function without arguments calls it at each sample and records its value. The value must "
                 "be a number (a boolean records 1 or 0). The history is named by the FISH name as written "
                 "(or `name '<s>'`); `history rename` renames it, `history export` writes it like any history. "
                 "An error inside the function stops the cycle with the function's line (the model goes back to "
                 "where the cycle command started).",
         examples=["fish history @shearforce", "fish history name 'ub' unbal_f", "fish history errd"])
def fish_history(session, call):
    from ..physics.history import histories

    hname, text = call.args["what"]
    var = text.lower()
    rt = session.fish_rt
    where = call.locations.get("what", call.location)
    fn = rt.functions.get(var)
    if fn is not None:
        if fn.nparams:
            raise CommandError(f"FISH function `{var}` takes {fn.nparams} argument(s): a history can only call "
                               "a function without arguments", where)
    elif var not in session.variables:
        raise CommandError(f"`{text}` is neither a FISH variable nor a FISH function", where,
                           hint="define or assign it before the `fish history` line")
    hs = histories(session.model)
    if hname is not None:
        if hs.find(hname) is not None:
            raise CommandError(f"a history named '{hname}' exists already", call.location)
    elif hs.find(text) is not None:
        hname = None            # the FISH name is taken: the history keeps its number as its name
    else:
        hname = text
    loc = where.resolve() if hasattr(where, "resolve") else where
    rt.history_sites[var] = loc
    attach_fish(session)
    hs.add_fish(var, hname)


# ------------------------------------------------------------------ fish callback

class _Position(ValueType):
    """A callback position: a number (3DEC cycle-sequence position)."""

    label = "<f>"
    fits_types = NUMBERISH

    def literal(self, tok):
        return float(str(tok))

    def convert(self, value, where):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise BindError(f"a callback position is a finite number, got {value!r}", where)
        return float(value)


class _FishFn(ValueType):
    """A FISH function by name (`f` or `@f`), not its value."""

    label = "<f|@f>"
    fits_types = ("WORD", "ATNAME", "STRING")

    def take(self, toks, i, binder):
        tok = toks[i]
        text = str(tok)
        text = text[1:] if tok.type == "ATNAME" else (text[1:-1] if tok.type == "STRING" else text)
        if not _NAME.match(text):
            raise BindError(f"`{text}` is not a FISH function name", binder.where(tok))
        return text.lower(), i + 1


_EVENT = P("event", Text(), "a named event (`event 'zone_delete'`)", supported=False)


@command("fish callback add", positional=[P("function", _FishFn(), "the FISH function (no arguments)", required=True),
                                          P("position", _Position(), "its position in the cycle sequence",
                                            required=True)],
         keywords=[P("interval", INT, "call it every n steps (default 1)", default=1), _EVENT],
         doc="Call a FISH function during cycling, at a position in the cycle sequence, every step (or every "
             "`interval` steps).",
         details="The position places the call in each step (`program list cycle-sequence` prints dec3d's "
                 "sequence): a negative position calls the function before anything of the step it is due at — "
                 "after contact detection, before time functions, contact forces and motion — so what it sets "
                 "(an applied force or velocity, a face load, a property) acts in that same step (3DEC's "
                 "`fish callback add srv_update -100.0`); it sees the model after the previous step "
                 "(`mech.cycle` = the step before). A position ≥ 0 calls it after the step's motion and clock, "
                 "with the step's state complete (positions, velocities, contact forces, `mech.cycle` and "
                 "`mech.time` of that step), before histories are sampled. Callbacks on the same side run in "
                 "increasing position (two at one position in the order added); due means the step's number is "
                 "a multiple of `interval`. dec3d's numbers are its own: 3DEC's cycle sequence has more points "
                 "(its positions between its calculations are all mapped to one side of dec3d's single step: "
                 "negative before it, others after). An error in the function stops the cycle with the "
                 "function's line and the callback command in the FISH stack; the model is put back as it was "
                 "before the cycle command (as for any error while cycling), FISH variables keep what the "
                 "callbacks set.",
         examples=["fish callback add joint_force 0.1 interval 1000", "fish callback add @srv_update -100.0"])
def fish_callback_add(session, call):
    name = call.args["function"]
    rt = session.fish_rt
    where = call.locations.get("function", call.location)
    fn = rt.functions.get(name)
    if fn is None:
        raise CommandError(f"`{name}` is not a FISH function", where, hint="define it with `fish define` first")
    if fn.nparams:
        raise CommandError(f"FISH function `{name}` takes {fn.nparams} argument(s): a callback is called "
                           "without arguments", where)
    interval = int(call.args["interval"])
    if interval < 1:
        raise CommandError(f"`interval` must be ≥ 1, got {interval}", call.locations.get("interval", call.location))
    loc = call.location.resolve() if hasattr(call.location, "resolve") else call.location
    rt.callbacks.append((call.args["position"], name, interval, loc))
    rt.callbacks.sort(key=lambda cb: cb[0])          # stable: equal positions keep the order added
    attach_fish(session)


@command("fish callback remove", positional=[P("function", _FishFn(), "the FISH function", required=True),
                                             P("position", _Position(), "only the callback at this position")],
         keywords=[_EVENT],
         doc="Stop calling a FISH function during cycling.",
         details="Without a position every callback of the function is removed; naming one that is not "
                 "registered is an error.",
         examples=["fish callback remove joint_force", "fish callback remove joint_force 0.1"])
def fish_callback_remove(session, call):
    name, pos = call.args["function"], call.args["position"]
    rt = session.fish_rt
    keep = [cb for cb in rt.callbacks if not (cb[1] == name and (pos is None or cb[0] == pos))]
    if len(keep) == len(rt.callbacks):
        at = "" if pos is None else f" at position {pos:g}"
        raise CommandError(f"`{name}` is not a FISH callback{at}", call.locations.get("function", call.location))
    rt.callbacks[:] = keep


@command("fish callback list", doc="Print the FISH callbacks in the order they are called.",
         examples=["fish callback list"])
def fish_callback_list(session, call):
    rt = session.fish_rt
    if not rt.callbacks:
        session.write("no FISH callbacks")
    for pos, name, interval, _site in rt.callbacks:
        when = "before the step's forces" if pos < 0 else "after the step's motion"
        session.write(f"{pos:g}  {name}  interval {interval}  ({when})")


#: dec3d's cycle sequence: (position, what runs there), for `program list cycle-sequence`
CYCLE_SEQUENCE = (
    ("", "contact detection, when due (every `model update-interval` steps, or a block moved CTOL/2)"),
    ("< 0", "FISH callbacks at negative positions, in increasing position (`FishBefore`)"),
    ("0", "the step: time functions (`block apply … table|fish`), energy record, contact forces, rigid-block "
          "motion, zone and FE-block forces and gridpoint motion, then the clock (step and time move on)"),
    ("≥ 0", "FISH callbacks at positions ≥ 0, in increasing position (step hook)"),
    ("", "histories, periodic VTK snapshots (step hooks)"),
)


def _check_program_list(call):
    what = call.args["what"]
    if what is None or (isinstance(what, str) and matches(what, ["cycle-sequence"]) != ["cycle-sequence"]):
        shown = "`program list`" + (f" `{what}`" if what is not None else " without a keyword")
        raise NotSupportedError(f"{shown} is not supported yet", call.locations.get("what", call.location),
                                hint="dec3d lists: cycle-sequence")


@command("program list", positional=[P("what", Text(), "what to list: `cycle-sequence` (the only one dec3d has)")],
         check=_check_program_list,
         doc="`program list cycle-sequence`: print dec3d's cycle sequence — where FISH callbacks run in a step — "
             "and the steps of the last run.",
         details="A callback at a negative position (`fish callback add f -100`) runs before the step's "
                 "calculations, one at a position ≥ 0 after its motion; the numbers are dec3d's own (one "
                 "calculation point, 0), not 3DEC's list. The last lines name the step objects of the last "
                 "`model cycle|solve` in order (`RigidEngine.steps`, or that nothing has cycled yet) and the "
                 "callbacks. Other `program list` keywords of 3DEC are not supported yet.",
         examples=["program list cycle-sequence"])
def program_list_cycle_sequence(session, call):
    session.write("position  what runs")
    for pos, what in CYCLE_SEQUENCE:
        session.write(f"{pos:>8}  {what}")
    eng = getattr(session.model, "rigid_engine", None)          # (listing makes no engine)
    steps = eng.steps if eng is not None else []
    session.write("last run's steps: " + (" -> ".join(repr(st) for st in steps) if steps else "none (not cycled yet)"))
    for pos, name, interval, _site in session.fish_rt.callbacks:
        session.write(f"callback {pos:g}  {name}  interval {interval}")


# ------------------------------------------------------------------ table

TABLE_FILE = InPath(exts=(".txt", ".tab", ".dat"))
#: largest table file read (bytes)
TABLE_MAX_BYTES = 64 * 2**20


@command("table", positional=[P("id", TableId(), "table id (integer) or name", required=True)],
         keywords=[P("add", Nums(2, 10**7, multiple_of=2), "points x y x y … (or (x,y) (x,y) …)", repeat=True),
                   P("insert", Nums(2, 10**7, multiple_of=2), "points x y …; the same as add (points are kept "
                     "in increasing x)", repeat=True),
                   P("import", TABLE_FILE, "read points from a text file beside the deck"),
                   P("label", Text(), "the table's label"),
                   P("delete", FLAG, "remove the table", bare=True),
                   P("list", FLAG, "print the table's points", bare=True)],
         doc="Make, fill, list or delete a table of (x, y) points (FISH `table(t, x)` interpolates it).",
         details="Points are kept in increasing x; adding a point at an x already there replaces its y. "
                 "`import` reads a text file looked for beside the deck, then in the output folder: lines of "
                 "two numbers separated by spaces, tabs or a comma; lines starting with `;` or `#` and blank "
                 "lines are skipped; a first line that is not two numbers is the table's label. `delete` "
                 "removes the table (a later `table.get` makes an empty one). FISH reads a table with "
                 "`table(t, x)` (linear interpolation, end values held outside), `table.size`, `table.x(t, i)`, "
                 "`table.y(t, i)`.",
         examples=["table 1 add (0,0) (1,2) (2,2)", "table 'pulse' import 'pulse.txt'", "table 1 list",
                   "table 1 delete"])
def table_cmd(session, call):
    from ..fish.table_intrinsics import Table, add_points, table_key

    rt = session.fish_rt
    tid = call.args["id"]
    key = table_key(tid)
    if call.args["delete"]:
        if key not in rt.tables:
            raise CommandError(f"there is no table {tid}", call.locations.get("id", call.location))
        del rt.tables[key]
        return
    points = []
    for kw in ("add", "insert"):
        for group in call.args[kw]:
            points.extend(zip(group[0::2], group[1::2]))
    imported = None
    if call.args["import"] is not None:
        where = call.locations.get("import", call.location)
        path = session.in_path(call.args["import"], where, TABLE_FILE.exts, "table file")
        imported = read_table_file(path, call.args["import"], where)
    tab = rt.tables.get(key)
    fresh = tab is None
    if fresh:
        tab = Table(tid)
    if imported is not None:
        label, pts = imported
        if label and not call.args["label"]:
            tab.label = label
        points = pts + points
    try:
        add_points(tab, points)
    except Dec3dError as exc:
        raise CommandError(exc.message, call.location) from None
    if call.args["label"] is not None:
        tab.label = str(call.args["label"])
    if fresh and call.args["list"] and not points and call.args["label"] is None:
        raise CommandError(f"there is no table {tid}", call.locations.get("id", call.location))
    if fresh:
        rt.tables[key] = tab
    if call.args["list"]:
        session.write(f"table {tid}" + (f" '{tab.label}'" if tab.label else "") + f": {len(tab.xs)} points")
        for x, y in zip(tab.xs, tab.ys):
            session.write(f"  {x:.10g}  {y:.10g}")


_SPLIT = re.compile(r"[ \t,]+")


def read_table_file(path, shown, where):
    """(label, [(x, y), …]) of a table file; bad content raises CommandError naming file and line."""
    try:
        size = path.stat().st_size
        if size > TABLE_MAX_BYTES:
            raise CommandError(f"table file '{shown}' is {size} bytes, more than a table file "
                               f"({TABLE_MAX_BYTES // 2**20} MiB at most)", where)
        text = path.read_bytes().decode("utf-8", errors="replace")
    except OSError as exc:
        from ..io.paths import os_error_text

        raise CommandError(f"cannot read table file '{shown}': {os_error_text(exc)}", where) from None
    label, points = "", []
    for n, raw in enumerate(text.splitlines(), 1):
        line = raw.strip()
        if not line or line[0] in ";#":
            continue
        parts = [p for p in _SPLIT.split(line) if p]
        xy = None
        if len(parts) == 2:
            try:
                xy = (float(parts[0]), float(parts[1]))
            except ValueError:
                xy = None
        if xy is None:
            if not points and not label:
                label = line[:200]
                continue
            raise CommandError(f"table file '{shown}', line {n}: expected two numbers x y", where)
        if not (math.isfinite(xy[0]) and math.isfinite(xy[1])):
            raise CommandError(f"table file '{shown}', line {n}: a value is not a finite number", where)
        points.append(xy)
    if not points:
        raise CommandError(f"table file '{shown}' holds no points", where)
    return label, points


# ------------------------------------------------------------------ save files

def fish_state(session, where) -> dict:
    """The session's FISH state for `model save` (``dec3d.fish.persist``)."""
    from ..fish.persist import FishStateError, to_state

    try:
        return to_state(session.fish_rt)
    except FishStateError as exc:
        raise CommandError(f"cannot save: {exc.message}", where) from None


def read_fish_state(session, data):
    """Check a saved FISH state and compile its functions (ValueError: nothing changed); returns a callable
    that puts it in place."""
    from ..errors import Dec3dError, SourceLocation
    from ..fish import compile_function
    from ..fish.persist import apply_state, read_state
    from ..lang.parser import ParsedDeck
    from ..lang.prepass import FishBlock

    snap = read_state(data)
    rt = session.fish_rt
    compiled = {}

    def compile_one(fdef, header):
        first = fdef.source.first_line
        lines = [""] * (first - 2) + [header] + list(fdef.source.lines)
        deck = ParsedDeck(fdef.source.filename, lines, [], [])
        loc = SourceLocation(fdef.source.filename, max(first - 1, 1), 1, header, max(1, len(header.rstrip())))
        try:
            bound = session.bind_fish_commands(fdef, deck, ())
            fn = compile_function(rt, fdef, bound, loc)
        except Dec3dError as exc:
            raise ValueError(f"saved FISH function `{fdef.name}`: {exc.message}") from None
        compiled[fdef.name] = FishBlock(fdef.name, fdef.params, "\n".join(fdef.source.lines), max(first - 1, 1),
                                        first + len(fdef.source.lines), frozenset(fdef.globals | fdef.assigned))
        return fn

    fns = [compile_one(fdef, header) for fdef, header in snap.fdefs]
    it = iter(fns)

    def put():
        apply_state(rt, snap, lambda fdef, header: next(it))
        rt.globals.update(session.parameters)      # `dec3d batch` values stay what the batch gave
        session.fish.clear()
        session.fish.update(compiled)
        for block in compiled.values():
            session.bind_context.define_fish(block)
    return put
