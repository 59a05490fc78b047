"""`block contact jmodel|property|material-table|tolerance`: joint models and properties."""
from __future__ import annotations

import numpy as np

from ..errors import CommandError
from ..physics.jmodels import ALIASES, ALL_PROPS, JOINT_MODELS, MODEL_BY_CODE, REFUSED
from ..physics.contact_store import history_columns, property_columns
from ..physics.contacts import default_row
from ..kernels.joints import model_mask
from ..physics.rigid import engine, mech
from .registry import command
from .values import FLAG, Choice, Num, P, Text, ValueRangeError

PROPS = ALL_PROPS
_UNITS = {p.name: p.units for m in JOINT_MODELS.values() for p in m.props.values()}
_DOCS = {p.name: p.doc for m in JOINT_MODELS.values() for p in m.props.values()}


def _loosest(name):
    """(lo, lo_open, hi, hi_open) of keyword ``name`` at binding: the widest range any model gives it
    (each model's own range is checked when its contacts take the value, ``_check``)."""
    ps = [m.props[name] for m in JOINT_MODELS.values() if name in m.props]
    los = [p for p in ps if p.lo is not None]
    his = [p for p in ps if p.hi is not None]
    lo = min(p.lo for p in los) if len(los) == len(ps) else None
    hi = max(p.hi for p in his) if len(his) == len(ps) else None
    lo_open = lo is not None and all(p.lo_open for p in los if p.lo == lo)
    hi_open = hi is not None and all(p.hi_open for p in his if p.hi == hi)
    return lo, lo_open, hi, hi_open


_BOUNDS = {name: _loosest(name) for name in PROPS}
_KW = [P(name, Num(lo=_BOUNDS[name][0], lo_open=_BOUNDS[name][1], hi=_BOUNDS[name][2], hi_open=_BOUNDS[name][3]),
         _DOCS[name], units=_UNITS[name]) for name in PROPS]


def _given(call):
    out = {name: call.args[name.replace("-", "_")] for name in PROPS if call.args[name.replace("-", "_")] is not None}
    for k, v in call.extra.items():
        # a user joint-model property: any finite number (an `[expr]` may give a string or inf)
        try:
            out[k] = Num().convert(v, call.location)
        except ValueRangeError as exc:
            raise exc.named(k) from None
    return out


def _check(call, model_name, props):
    model = JOINT_MODELS[model_name]
    allowed = tuple(model.props)
    bad = [k for k in props if k not in allowed]
    if bad:
        raise CommandError(f"joint model '{model_name}' has no property '{bad[0]}' "
                           f"(it has: {', '.join(allowed)})", call.location)
    # a keyword several models share binds with the widest range (``_BOUNDS``): the model's own
    # range (``Prop.lo/hi/lo_open/hi_open``) is checked here, at the keyword's location
    for k, v in props.items():
        p = model.props[k]
        try:
            Num(lo=p.lo, hi=p.hi, lo_open=p.lo_open, hi_open=p.hi_open).convert(
                v, call.locations.get(k.replace("-", "_"), call.location))
        except ValueRangeError as exc:
            raise exc.named(k) from None


#: 3DEC's built-in joint models dec3d does not have (Itasca joint-model reference), known by name,
#: with what is missing to build them where it is known
OTHER_3DEC_MODELS = {
    "nonlinear": "",
    # (issue 27: the theory page "Power Law Creeping Joint Model In 3DEC" is held only up to its
    # Eq. 2, ΔFs = −Ks (ΔUs − U̇c) As, and the sentence introducing the two-component Norton law of
    # the creep rate U̇c; that law and the model's `block contact property` keywords are not there)
    "power": ": 3DEC's text of the power-law creep joint stops before its creep-rate law (a two-component "
             "Norton law of the shear force, the theory page's Eq. 3 on) and its property keywords",
    "ratestate": "",
}


def _known_names() -> tuple[str, ...]:
    return tuple(JOINT_MODELS) + tuple(ALIASES)


def _check_model_name(name: str, where) -> None:
    """Built-in models bind; 3DEC's others and user models (`jmodel load`) are not supported yet."""
    if name is None or not isinstance(name, str) or name in JOINT_MODELS:
        return
    from ..errors import NotSupportedError
    from ..lang.abbrev import matches

    if name in REFUSED:
        raise NotSupportedError(REFUSED[name], where, hint=f"implemented: {', '.join(JOINT_MODELS)}")
    hits = matches(name, _known_names() + tuple(OTHER_3DEC_MODELS))
    if len(hits) == 1 and hits[0] in OTHER_3DEC_MODELS:
        raise NotSupportedError(f"joint model `{hits[0]}` is not supported yet{OTHER_3DEC_MODELS[hits[0]]}", where,
                                hint=f"implemented: {', '.join(JOINT_MODELS)}")
    if len(hits) != 1:
        raise NotSupportedError(f"joint model `{name}` is not a built-in model; user-defined joint models "
                                "(`block contact jmodel load`) are not supported yet", where,
                                hint=f"implemented: {', '.join(JOINT_MODELS)}")


def _model_arg(call, key):
    """The model name as bound, with a built-in abbreviation (`el` = elastic) or alias expanded."""
    from ..lang.abbrev import matches

    name = call.args.get(key)
    if isinstance(name, str) and name not in REFUSED:
        hits = matches(name, _known_names())
        if len(hits) == 1:
            call.args[key] = ALIASES.get(hits[0], hits[0])
    return call.args.get(key)


def _contacts_in_range(session, call):
    """(engine, mask over the contacts in the call's range), the contacts detected first."""
    e = engine(session.model)
    e.ensure_contacts()
    return e, session.range_mask(call, "contact")


def _check_assign(call):
    _check_model_name(_model_arg(call, "model"), call.locations.get("model", call.location))


def _check_default(call):
    _check_model_name(_model_arg(call, "jmodel"), call.locations.get("jmodel", call.location))


@command("block contact jmodel assign", positional=[P("model", Text(), "joint model: " + ", ".join(JOINT_MODELS),
                                                        required=True)], range="contact", check=_check_assign,
         doc="Assign a joint model to the contacts in range; without a range also to contacts created later.",
         details="The contacts' properties go back to the material-table defaults and follow them until "
                 "`block contact property` sets them. A contact range tests the contact's reference "
                 "point, its own groups and the groups of its two blocks.",
         examples=["block contact jmodel assign mohr", "block contact jmodel assign elastic range group 'base'"])
def jmodel_assign(session, call):
    name = _model_arg(call, "model")
    _check_model_name(name, call.locations.get("model", call.location))    # an [expr] is known only now
    e, sel = _contacts_in_range(session, call)
    jm = JOINT_MODELS[name]
    c = e.contacts
    c["jmodel"][sel] = jm.code
    width = property_columns(c, model_mask(c["jmodel"]) | 1 << jm.code)
    c["prop"][sel] = default_row(mech(session.model), jm.code, width)
    c["own_props"][sel] = 0
    ss = e.subcontacts
    history_columns(ss, c["jmodel"])
    if ss.n:
        ss["hist"][sel[ss["contact"]]] = 0.0        # the model's history starts afresh
    if call.range is None:
        mech(session.model)["jmodel"] = name


def _plugin_name(raw: str) -> str:
    """The model a plugin file name stands for: its base name without directory and extension, and
    without 3DEC's ``jmodel`` file-name prefix (``jmodelmason.dll``, ``jmodel_mason_v8.dll`` → ``mason``,
    ``mason_v8``)."""
    import os
    import re

    base = os.path.basename(raw.replace("\\", "/"))
    base = re.sub(r"\.(dll|so|dylib)$", "", base, flags=re.IGNORECASE)
    for pre in ("jmodel_", "jmodel-", "jmodel"):
        if base.lower().startswith(pre) and len(base) > len(pre):
            base = base[len(pre):]
            break
    return base.lower()


@command("block contact jmodel load", positional=[P("name", Text(), "plugin file or model name", required=True)],
         doc="3DEC's loader of joint-model plugins (DLLs): accepted for the models dec3d has built in, "
             "refused for any other.",
         details="dec3d runs no compiled plugin: a deck or a file from someone else never runs foreign code. "
                 "When the plugin is one of dec3d's own models (by its name, an alias such as `mason_v8`, or a "
                 "file name such as `jmodelmason.dll`) the command does nothing and `jmodel assign` takes the "
                 "name; any other plugin stops the deck with the list of built-in models.",
         examples=["block contact jmodel load 'mason'"])
def jmodel_load(session, call):
    from ..errors import NotSupportedError

    raw = str(call.args["name"])
    where = call.locations.get("name", call.location)
    name = _plugin_name(raw)
    if name in JOINT_MODELS or name in ALIASES:
        return
    if name in REFUSED:
        raise NotSupportedError(REFUSED[name], where, hint=f"built in: {', '.join(JOINT_MODELS)}")
    raise NotSupportedError(f"joint-model plugin '{raw}' cannot be loaded: dec3d runs no compiled plugins, and "
                            f"'{name}' is not one of its built-in joint models", where,
                            hint=f"built in: {', '.join(JOINT_MODELS)}")


@command("block contact property", keywords=_KW, open_keywords=True, range="contact",
         doc="Set joint properties of the contacts in range (stiffness Pa/m, stress Pa, angles in degrees).",
         details="Without a range the values also become the defaults of contacts created later. Names not "
                 "declared here are accepted for user joint models; a name that the assigned built-in model "
                 "does not have is an error.",
         examples=["block contact property stiffness-normal 1e9 stiffness-shear 1e9 friction 30",
                   "block contact prop stiff-norm 10e6 stiff-shear 10e6 fric 20 coh 0 tension 0"])
def contact_property(session, call):
    e, mask = _contacts_in_range(session, call)
    s = mech(session.model)
    props = _given(call)
    c = e.contacts
    if call.range is not None and c.n == 0:
        text = ("no contacts exist yet, so the range reaches none: these properties are lost (without a range "
                "they become the defaults of the contacts made later)")
        session.write(f"warning: {call.location}: {text}")
        session.warnings.append(f"{call.location}: {text}")
    sel = np.flatnonzero(mask)
    codes = np.unique(c["jmodel"][sel]) if sel.size else np.array([JOINT_MODELS[s["jmodel"]].code])
    for code in codes:
        _check(call, MODEL_BY_CODE[int(code)].name, props)
    for code in codes:
        rows = sel[c["jmodel"][sel] == code]
        if rows.size:
            block = c["prop"][rows]
            MODEL_BY_CODE[int(code)].apply(block, props)
            c["prop"][rows] = block
            c["own_props"][rows] = 1
    if call.range is None:
        _check(call, s["jmodel"], props)
        s["props"].update(props)


@command("block contact material-table default",
         keywords=[P("jmodel", Text(), "joint model of contacts created from now on"),
                   P("property", FLAG, "3DEC's word before the properties", bare=True), *_KW],
         open_keywords=True, check=_check_default,
         doc="Joint properties of contacts created from now on, and of existing contacts whose properties "
             "were never set by `block contact property`.",
         examples=["block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 friction 30"])
def material_default(session, call):
    s = mech(session.model)
    name = _model_arg(call, "jmodel")
    _check_model_name(name, call.locations.get("jmodel", call.location))   # an [expr] is known only now
    props = _given(call)
    props.pop("property", None)
    _check(call, name or s["jmodel"], props)
    if name:
        s["jmodel"] = name
    s["props"].update(props)


def _table_rule(call):
    """The group pair [a, b] and slot of a range that is one `group-intersection` (kept for contacts
    made later), or None for any other range."""
    r = call.range
    if r is None or len(r.elements) != 1:
        return None
    rc = r.elements[0]
    if rc.element.name != "group-intersection" or rc.negate:
        return None
    a, b, slot = rc.args.get("first"), rc.args.get("second"), rc.args.get("slot")
    if not all(isinstance(x, str) for x in (a, b)) or not (slot is None or isinstance(slot, str)):
        return None
    return [a, b], slot


@command("block contact material-table add",
         keywords=[P("jmodel", Text(), "joint model of the entry (default: the current default model)"),
                   P("property", FLAG, "3DEC's word before the properties", bare=True), *_KW],
         open_keywords=True, range="contact", check=_check_default,
         doc="Add a material-table entry: a joint model and properties for the contacts in range, now and "
             "(for a `group-intersection` range) for contacts made later between those groups.",
         details="Entries are numbered from 1 in the order they are added. The contacts in range take the "
                 "entry's model and properties (properties not given take the model's own defaults, not "
                 "those of `material-table default`), and keep them through re-detection until `block contact "
                 "property` or `jmodel assign` changes them. When the range is one `group-intersection 'a' 'b' "
                 "[slot 's']`, a contact made later between a block of a and a block of b takes the entry too "
                 "(the last entry added wins where several match); any other range applies to the contacts "
                 "that exist when the command runs.",
         examples=["block contact material-table add jmodel mohr prop stiffness-normal 1e10 stiffness-shear 1e9 "
                   "friction 35 range group-intersection 'brickUp' 'brickDown' slot 'components'"])
def material_add(session, call):
    s = mech(session.model)
    name = _model_arg(call, "jmodel")
    _check_model_name(name, call.locations.get("jmodel", call.location))
    name = name or s["jmodel"]
    props = _given(call)
    props.pop("property", None)
    _check(call, name, props)
    jm = JOINT_MODELS[name]
    tables = s.setdefault("mtables", [])
    entry = {"id": len(tables) + 1, "jmodel": name, "props": dict(props), "groups": None, "slot": None}
    rule = _table_rule(call)
    if rule is not None:
        entry["groups"], entry["slot"] = rule
    e, sel = _contacts_in_range(session, call)
    c = e.contacts
    c["jmodel"][sel] = jm.code
    c["prop"][sel] = jm.row(props, property_columns(c, model_mask(c["jmodel"]) | 1 << jm.code))
    c["own_props"][sel] = 1
    ss = e.subcontacts
    history_columns(ss, c["jmodel"])
    if ss.n:
        ss["hist"][sel[ss["contact"]]] = 0.0
    if rule is not None or call.range is None:
        tables.append(entry)
    session.results["material-table.count"] = float(len(tables))


@command("block contact tolerance", positional=[P("ctol", Num(lo=0, lo_open=True), "contact tolerance CTOL",
                                                  required=True, units="m")],
         doc="Set CTOL: contacts are made when the gap is at most CTOL and deleted beyond it.",
         details="Default: 0.005 × the mean block size (cube root of the mean volume), dec3d's choice.",
         examples=["block contact tolerance 0.01"])
def contact_tolerance(session, call):
    mech(session.model)["ctol"] = float(call.args["ctol"])


@command("block contact generate-subcontacts", range="block",
         doc="Detect the contacts and rebuild their sub-contacts now (force history is kept).",
         examples=["block contact generate-subcontacts"])
def generate_subcontacts(session, call):
    engine(session.model).detect(force_search=True)


@command("block contact group", positional=[P("name", Text(), "group name", required=True)],
         keywords=[P("slot", Text(), "group slot"), P("remove", FLAG, "take the contacts out of the group", bare=True)],
         range="contact",
         doc="Put the contacts in range into a group (contact ranges can then select it).",
         examples=["block contact group 'Reaction' range pos-y -0.01 0.01",
                   "block contact group 'MidCrack' slot 'components' range group-intersection 'brickDown' 'brickUp'"])
def contact_group(session, call):
    e, sel = _contacts_in_range(session, call)
    a = call.args
    rows = np.flatnonzero(sel)
    if a["remove"]:
        session.model.groups.remove(e.contacts, rows, a["name"], a["slot"])
    else:
        session.model.groups.assign(e.contacts, rows, a["name"], a["slot"])


@command("block contact reset", positional=[P("what", Choice(("displacement", "state", "force", "overlap")),
                                                 "what to reset", required=True)],
         range="contact",
         doc="Reset the sub-contacts of the contacts in range: `displacement` zeroes the accumulated shear "
             "displacement and dilation (the normal displacement is kept, so forces do not jump), "
             "`state` clears the slip and failure flags, `force` zeroes the shear forces; `overlap` (dec3d) "
             "makes the sub-contacts whose blocks overlap just touching (normal displacement set to the "
             "dilation, normal and shear forces and shear displacement zero; gaps are kept), so a support "
             "built against rock that has moved starts unloaded and takes load only from later movement.",
         examples=["block contact reset displacement", "block contact reset state range group 'joint'",
                   "block contact reset overlap range group-intersection 'liner' 'rock'"])
def contact_reset(session, call):
    e, sel = _contacts_in_range(session, call)
    ss = e.subcontacts
    rows = sel[ss["contact"]] if ss.n else np.zeros(0, bool)
    what = call.args["what"]
    if what == "displacement":
        ss["us"][rows] = 0.0
        ss["un"][rows] -= ss["udil"][rows]
        ss["udil"][rows] = 0.0
    elif what == "state":
        ss["state"][rows] = 0
    elif what == "overlap":
        rows &= ss["un"] < ss["udil"]
        ss["un"][rows] = ss["udil"][rows]
        ss["fn"][rows] = 0.0
        ss["fs"][rows] = 0.0
        ss["us"][rows] = 0.0
    else:
        ss["fs"][rows] = 0.0
