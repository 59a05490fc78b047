"""`fish automatic-create|list`: FISH settings and listing (`fish define` is read by the prepass)."""
from __future__ import annotations

from .registry import command
from .values import ONOFF, P, Text


@command("fish automatic-create", positional=[P("mode", ONOFF, "off: every FISH name must be declared "
                                                "`global` or `local` before use", required=True)],
         doc="Switch whether FISH creates variables on first use (on, the default) or requires declarations.",
         details="Applies to functions defined after the command: with it off, a `fish define` that uses a "
                 "name that is not a parameter, a `local`, a `global` declared in the function, an existing "
                 "global variable or function stops the deck with the name's position in the body.",
         examples=["fish automatic-create off"])
def fish_automatic_create(session, call):
    session.fish_rt.auto_create = bool(call.args["mode"])


@command("fish list", positional=[P("name", Text(), "a variable or function; omitted lists all", default="")],
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
            from ..errors import CommandError
            raise CommandError(f"`{name}` is neither a FISH variable nor a function", call.location)
        return
    for n in sorted(rt.functions):
        fn = rt.functions[n]
        session.write(f"{fn.name}({', '.join(fn.params)})  (function)")
    for n in sorted(variables):
        session.write(f"{n} = {to_string(variables[n])}")
