"""`model dynamic active|list|time-total` and `model history dynamic time-total`: dynamic mode
(dec3d.physics.dynamic says what it changes)."""
from __future__ import annotations

from ..errors import Dec3dError
from ..physics.dynamic import damping_text, dynamic_time, is_dynamic
from ..physics.history import histories
from ..physics.rigid import engine, mech
from ..units import suffix
from .histories import _name
from .registry import REGISTRY, command
from .values import ONOFF, Choice, Num, P

# 3DEC keywords of `model dynamic` that dec3d knows by name and does not implement
for _kw in ("follower", "slave", "substep", "timestep", "safety-factor"):
    REGISTRY.know(f"model dynamic {_kw}")


@command("model dynamic active",
         positional=[P("mode", ONOFF, "on (the default when omitted) or off", default=True)],
         doc="Switch dynamic mode on or off.",
         details="In dynamic mode the rigid blocks, zone gridpoints and FE nodes move with their real masses "
                 "and full inertia (no density scaling, unless `block mechanical mass-scale on` asks for it), "
                 "the time step is the one of the 3DEC theory text (Eqs. 84, 87, 88) without scaling, only "
                 "Rayleigh damping is applied (`block mechanical damping rayleigh …`; local, combined and "
                 "global damping stay set but are off while dynamic mode is on), and the dynamic time "
                 "(`model dynamic time-total`, FISH `dynamic.time.total`) runs on with every step. The time "
                 "functions of `block apply … table|fish` read the dynamic time in dynamic mode.",
         examples=["model dynamic active on", "model dynamic active off", "model dynamic active"])
def dynamic_active(session, call):
    mech(session.model)["dynamic"] = bool(call.args["mode"])


@command("model dynamic time-total",
         positional=[P("t", Num(lo=0), "the dynamic time", required=True, units="s")],
         doc="Set the dynamic time (it goes on from this value while dynamic mode is on).",
         examples=["model dynamic time-total 0"])
def dynamic_time_total(session, call):
    mech(session.model)["dyn_time"] = float(call.args["t"])


@command("model dynamic list",
         doc="Print the dynamic-mode settings: on or off, dynamic time, damping in effect, masses and time step.",
         examples=["model dynamic list"])
def dynamic_list(session, call):
    m = session.model
    eng = engine(m)
    on = is_dynamic(m)
    session.write(f"dynamic mode        : {'on' if on else 'off'}")
    t = suffix(m, "time")
    session.write(f"dynamic time-total  : {dynamic_time(m):.6g}{t}")
    session.write(f"damping             : {damping_text(m)}")
    kind = {"raised": "by body, masses only raised", "body": "by body", "eq87": "Eq. 87"}[eng.scaling()]
    session.write(f"density scaling     : {f'on ({kind})' if eng.mass_scaling() else 'off (real masses)'}")
    session.write(f"inertia             : {'full (Euler equations)' if eng.full_inertia() else 'scalar'}")
    if eng.dt:
        session.write(f"time step           : {eng.dt:.6g}{t} (last cycle)")
    elif not m.blocks.n:
        session.write("time step           : none (no blocks)")
    else:
        try:
            session.write(f"time step           : {eng.predict_timestep():.6g}{t} (the next cycle starts with it)")
        except Dec3dError as exc:
            session.write(f"time step           : not known yet ({exc.message})")


@command("model history dynamic",
         positional=[P("quantity", Choice(("time-total",)), "what to record", required=True)],
         doc="Record the dynamic time (the time since dynamic mode was turned on, or since "
             "`model dynamic time-total` set it).",
         details="A leading `name '<s>'` names the history (default: its number).",
         examples=["model history dynamic time-total", "model history name 'time' dynamic time-total"])
def model_history_dynamic(session, call):
    name = _name(session, call)
    histories(session.model).add_model("dynamic-time-total", name)
