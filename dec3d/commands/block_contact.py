"""`block contact jmodel|property|material-table|tolerance`: joint models and properties."""
from __future__ import annotations

import numpy as np

from ..errors import CommandError
from ..physics.rigid import JOINT_MODELS, engine, props_vector
from .registry import command
from .values import FLAG, Num, P, Text

PROPS = JOINT_MODELS["mohr"][1]
_KW = [P(name, Num(), f"joint {name}", units="deg" if name in ("friction", "dilation", "friction-residual") else None)
       for name in PROPS]


def _given(call):
    out = {name: call.args[name.replace("-", "_")] for name in PROPS if call.args[name.replace("-", "_")] is not None}
    for k, v in call.extra.items():
        out[k] = float(v)
    return out


def _check(call, model_name, props):
    allowed = JOINT_MODELS[model_name][1]
    bad = [k for k in props if k not in allowed]
    if bad:
        raise CommandError(f"joint model '{model_name}' has no property '{bad[0]}' "
                           f"(it has: {', '.join(allowed)})", call.location)


#: 3DEC's other built-in joint models (Itasca joint-model reference), known by name
OTHER_3DEC_MODELS = ("softening-mohr", "bilinear-mohr", "cyjm", "nonlinear", "power", "ratestate")


def _check_model_name(name: str, where) -> None:
    """Built-in models bind; 3DEC's others and user models (`jmodel load`) are not supported yet."""
    if name is None or not isinstance(name, str) or name in JOINT_MODELS:
        return
    from ..errors import NotSupportedError
    from ..lang.abbrev import matches

    hits = matches(name, tuple(JOINT_MODELS) + OTHER_3DEC_MODELS)
    if len(hits) == 1 and hits[0] in OTHER_3DEC_MODELS:
        raise NotSupportedError(f"joint model `{hits[0]}` is not supported yet", where,
                                hint=f"implemented: {', '.join(JOINT_MODELS)}")
    if len(hits) != 1:
        raise NotSupportedError(f"joint model `{name}` is not a built-in model; user-defined joint models "
                                "(`block contact jmodel load`) are not supported yet", where,
                                hint=f"implemented: {', '.join(JOINT_MODELS)}")


def _model_arg(call, key):
    """The model name as bound, with a built-in abbreviation expanded (`el` = elastic)."""
    from ..lang.abbrev import matches

    name = call.args.get(key)
    if isinstance(name, str):
        hits = matches(name, tuple(JOINT_MODELS))
        if len(hits) == 1:
            call.args[key] = hits[0]
    return call.args.get(key)


def _check_assign(call):
    _check_model_name(_model_arg(call, "model"), call.locations.get("model", call.location))


def _check_default(call):
    _check_model_name(_model_arg(call, "jmodel"), call.locations.get("jmodel", call.location))


@command("block contact jmodel assign", positional=[P("model", Text(), "joint model: " + ", ".join(JOINT_MODELS),
                                                        required=True)], range="block", check=_check_assign,
         doc="Assign a joint model to the contacts (and to contacts created later).",
         examples=["block contact jmodel assign mohr", "block contact jmodel assign elastic"])
def jmodel_assign(session, call):
    e = engine(session.model)
    e.default_model = call.args["model"]
    code = JOINT_MODELS[e.default_model][0]
    e.cmodel[:] = code
    e.cname = [e.default_model] * len(e.cname)


@command("block contact property", keywords=_KW, open_keywords=True, range="block",
         doc="Set joint properties of the existing contacts (stiffness Pa/m, stress Pa, angles in degrees).",
         details="Names not declared here are accepted for user joint models; a name that the assigned "
                 "built-in model does not have is an error.",
         examples=["block contact property stiffness-normal 1e9 stiffness-shear 1e9 friction 30",
                   "block contact prop stiff-norm 10e6 stiff-shear 10e6 fric 20 coh 0 tension 0"])
def contact_property(session, call):
    e = engine(session.model)
    props = _given(call)
    _check(call, e.default_model, props)
    for c in range(len(e.cuser)):
        e.cuser[c].update(props)
        e.cprop[c] = props_vector(e.cuser[c])
    e.default_props.update(props)


@command("block contact material-table default",
         keywords=[P("jmodel", Text(), "joint model of contacts created from now on"),
                   P("property", FLAG, "3DEC's word before the properties", bare=True), *_KW],
         open_keywords=True, check=_check_default,
         doc="Joint properties given to contacts created from now on.",
         examples=["block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 friction 30"])
def material_default(session, call):
    e = engine(session.model)
    if call.args["jmodel"]:
        e.default_model = call.args["jmodel"]
    props = _given(call)
    props.pop("property", None)
    _check(call, e.default_model, props)
    e.default_props.update(props)


@command("block contact tolerance", positional=[P("ctol", Num(lo=0, lo_open=True), "contact tolerance CTOL",
                                                  required=True, units="m")],
         doc="Set CTOL: contacts are made when the gap is at most CTOL and deleted beyond it.",
         examples=["block contact tolerance 0.01"])
def contact_tolerance(session, call):
    engine(session.model).ctol = float(call.args["ctol"])


@command("block contact generate-subcontacts", range="block",
         doc="Detect the contacts and rebuild their sub-contacts now.",
         examples=["block contact generate-subcontacts"])
def generate_subcontacts(session, call):
    engine(session.model).detect()
