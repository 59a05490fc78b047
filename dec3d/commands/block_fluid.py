"""Flow in the joints (3DEC's words: `model fluid active`, `block fluid property`, `flowplane property`,
`flowknot apply|apply-remove|initialize`; dec3d's: `block fluid zone-size`, `block fluid solve-steady`,
`block fluid list`). Physics ``dec3d.physics.flownet``; needs `model configure fluid`."""
from __future__ import annotations

import numpy as np

from ..errors import BindError, CommandError
from ..fish import flow_intrinsics
from ..io.flowvalues import contact_values
from ..physics import flownet as F
from ..physics.rigid import engine
from .histories import _name
from .registry import REGISTRY, command
from .values import ONOFF, VEC3, Num, P, Text

flow_intrinsics.FLOW_VALUES[0] = contact_values


def _need_fluid(session, call):
    if not F.configured(session.model):
        raise CommandError(f"`{call.name}` needs `model configure fluid` first", call.location)
    F.settings(session.model)


def _network(session, call):
    """The engine with contacts detected and the network built from them."""
    m = session.model
    if m.blocks.n < 2:
        raise CommandError(f"`{call.name}`: there are no contacts, so no flow planes (fewer than two "
                           "blocks)", call.location)
    eng = engine(m)
    eng.ensure_contacts()
    F.rebuild(eng)
    return eng


@command("model fluid active", positional=[P("mode", ONOFF, "on (the default when omitted) or off", default=True)],
         doc="Switch flow in the joints on or off (after `model configure fluid`, on).",
         details="While on, every cycle takes flow steps in the joints' flow network over the time of each "
                 "mechanical step (the flow time step is the stable one or less, never larger), and the "
                 "sub-contacts' pore pressures are the flow knots' (plus `block contact apply pore-pressure`), "
                 "not the water table's; the hydraulic apertures follow the joints' normal displacements. "
                 "While blocks are free to move, flow and mechanics alternate every step. Off: the pore "
                 "pressures come from the water table again (`block water`).",
         examples=["model fluid active on", "model fluid active off"])
def fluid_active(session, call):
    _need_fluid(session, call)
    m = session.model
    F.settings(m)["active"] = bool(call.args["mode"])
    if m.blocks.n > 1 and "contacts" in m.stores:
        from ..physics.water import refresh

        eng = engine(m)
        eng.ensure_contacts()
        refresh(eng)


def _check_property(call):
    if all(call.args[k] is None for k in ("bulk", "density", "viscosity")):
        raise BindError("`block fluid property` needs bulk, density or viscosity", call.location)


@command("block fluid property",
         keywords=[P("bulk", Num(lo=0, lo_open=True), "fluid bulk modulus K_w (default 2e9)", units="Pa"),
                   P("density", Num(lo=0), "fluid density ρ_w (default 1000): the weight in the flow", units="kg/m³"),
                   P("viscosity", Num(lo=0, lo_open=True), "dynamic viscosity μ (default 1e-3)", units="Pa s")],
         check=_check_property,
         doc="Set the fluid properties of the flow in the joints.",
         details="The flow between two knots of a flow plane follows the cubic law with the hydraulic aperture "
                 "a: transmissivity a³/(12 μ); the driving difference is that of p − ρ_w g·x (water at rest "
                 "in a column does not flow). A knot's pressure changes by K_w Δt / V × its net inflow (V its "
                 "volume: aperture × its share of the plane). A viscosity ≤ 0 or a bulk modulus ≤ 0 is refused.",
         examples=["block fluid property bulk 2e9 density 1000 viscosity 1e-3"])
def fluid_property(session, call):
    _need_fluid(session, call)
    f = F.settings(session.model)
    for k in ("bulk", "density", "viscosity"):
        if call.args[k] is not None:
            f[k] = float(call.args[k])


@command("block fluid zone-size", positional=[P("size", Num(lo=0), "edge length of the flow zones; 0: the "
                                                                     "sub-contact points only", required=True,
                                               units="m")],
         doc="Set the size of the triangular flow zones the flow planes are cut into (dec3d's word).",
         details="0 (the default): each contact's flow plane is the Delaunay triangulation of its sub-contact "
                 "points. A size h > 0 adds a grid of points h apart inside each contact polygon and splits "
                 "its edges into equal parts no longer than h, so a transient front along a joint is resolved. "
                 "The network is built again at the next use.",
         examples=["block fluid zone-size 0.25", "block fluid zone-size 0"])
def fluid_zone_size(session, call):
    _need_fluid(session, call)
    f = F.settings(session.model)
    f["size"] = float(call.args["size"])
    f["sig"] = ""


@command("block fluid solve-steady",
         doc="Set the flow knots' pressures to the steady state now (a sparse direct solve; dec3d's word).",
         details="Every part of the network that holds a pressure boundary is solved: Σ Q = inflow at each "
                 "knot, with the conductances of the current apertures. Parts without a pressure boundary keep "
                 "their pressures (counted in the report). The sub-contacts take the pressures at once.",
         examples=["block fluid solve-steady"])
def fluid_solve_steady(session, call):
    _need_fluid(session, call)
    eng = _network(session, call)
    try:
        n, left = F.solve_steady(eng)
    except ValueError as exc:
        raise CommandError(f"`block fluid solve-steady`: {exc}", call.location) from None
    session.write(f"block fluid solve-steady: {n} knots solved" + (f", {left} parts without a pressure boundary "
                                                                     "left as they were" if left else ""))


@command("block fluid list", doc="Print the fluid settings, the size of the flow network and its stable time step.",
         examples=["block fluid list"])
def fluid_list(session, call):
    _need_fluid(session, call)
    m = session.model
    f = F.settings(m)
    nk = m.store("flowknots").n if "flowknots" in m.stores else 0
    npipe = m.store("flowpipes").n if "flowpipes" in m.stores else 0
    dt = F.stable_step(engine(m)) if nk else float("inf")
    session.write(f"fluid: {'active' if f['active'] else 'inactive'}, density {f['density']:g} kg/m³, viscosity "
                  f"{f['viscosity']:g} Pa s, bulk {f['bulk']:g} Pa, zone size {f['size']:g} m, apertures "
                  f"(initial, minimum, maximum) {f['aperture'][0]:g} {f['aperture'][1]:g} {f['aperture'][2]:g} m; "
                  f"{nk} knots, {npipe} pipes, stable flow step {dt:.4g} s (each mechanical step takes as many)")


def _check_aperture(call):
    if all(call.args[k] is None for k in ("aperture_initial", "aperture_minimum", "aperture_maximum")):
        raise BindError("`flowplane property` needs aperture-initial, aperture-minimum or aperture-maximum",
                        call.location)


@command("flowplane property",
         keywords=[P("aperture-initial", Num(lo=0), "hydraulic aperture at zero normal displacement a0", units="m"),
                   P("aperture-minimum", Num(lo=0), "residual (smallest) hydraulic aperture", units="m"),
                   P("aperture-maximum", Num(lo=0), "largest hydraulic aperture", units="m")],
         range="contact", check=_check_aperture,
         doc="Set the hydraulic apertures of the flow planes (the contacts) in range (3DEC's keywords).",
         details="The hydraulic aperture of a flow zone is a = a0 + un within [aperture-minimum, "
                 "aperture-maximum] (un the joint's normal displacement there, opening positive). Without a "
                 "range the values become the default of every plane, now and later (defaults 0, 0, 1 m); with "
                 "a range the contacts in range keep their own (carried through detections). A negative "
                 "aperture is refused, and so is a minimum above the maximum.",
         examples=["flowplane property aperture-initial 1e-4 aperture-minimum 1e-5 aperture-maximum 1e-3",
                   "flowplane property aperture-initial 2e-4 range group 'fault'"])
def flowplane_property(session, call):
    _need_fluid(session, call)
    m = session.model
    a = call.args
    new = [a["aperture_initial"], a["aperture_minimum"], a["aperture_maximum"]]
    f = F.settings(m)
    if call.range is None:
        vals = [float(v) if v is not None else f["aperture"][i] for i, v in enumerate(new)]
        if vals[1] > vals[2]:
            raise CommandError(f"aperture-minimum {vals[1]:g} is above aperture-maximum {vals[2]:g}", call.location)
        f["aperture"] = vals
        if "contacts" in m.stores:
            F.stores(m)
            m.store("contacts")["aperture"][...] = -1.0
        return
    eng = _network(session, call)
    mask = session.range_mask(call, "contact")
    ap = eng.contacts["aperture"]
    a0, amin, amax = F.apertures(m)
    cur = np.stack([a0, amin, amax], axis=1)[mask]
    for i, v in enumerate(new):
        if v is not None:
            cur[:, i] = float(v)
    if np.any(cur[:, 1] > cur[:, 2]):
        raise CommandError("aperture-minimum is above aperture-maximum on a plane in range", call.location)
    ap[mask] = cur


def _check_apply(call):
    a = call.args
    given = [k for k in ("pore_pressure", "discharge") if a[k] is not None]
    if len(given) != 1:
        raise BindError("`flowknot apply` needs one of pore-pressure <p> or discharge <q>", call.location)
    if a["gradient"] is not None and a["pore_pressure"] is None:
        raise BindError("`gradient` goes with `pore-pressure`", call.locations.get("gradient", call.location))


def _knots(session, call):
    eng = _network(session, call)
    kn = session.model.store("flowknots")
    if not kn.n:
        raise CommandError(f"`{call.name}`: the flow network has no knots (no contact with three "
                           "sub-contact points)", call.location)
    mask = session.range_mask(call, "flowknot")
    if not mask.any():
        raise CommandError(f"`{call.name}`: the range holds no flow knot (of {kn.n})",
                           call.range.elements[0].location if call.range is not None else call.location)
    return eng, kn, mask


@command("flowknot apply",
         keywords=[P("pore-pressure", Num(), "hold the pressure of the knots in range (a pressure boundary)",
                     units="Pa"),
                   P("gradient", Num(), "with pore-pressure: its change per metre of z (up is +z)", units="Pa/m"),
                   P("discharge", Num(), "add this inflow at each knot in range (negative: outflow)", units="m³/s")],
         range="flowknot", check=_check_apply,
         doc="Set boundary conditions on the flow knots in range (3DEC's keywords).",
         details="`pore-pressure p [gradient g]` holds each knot at p + g z; `discharge q` adds q to each knot's "
                 "inflow (cumulative, as in 3DEC). The knots are the corners of the flow zones; they are built "
                 "from the contacts now, and keep their conditions when the network is built again (a knot at "
                 "the same place takes them over). A range that holds no knot is an error. Knots are located by "
                 "their position (`position`, `position-x`, `plane`, `sphere`, ...).",
         examples=["flowknot apply pore-pressure 1e5 range position-x 0", "flowknot apply discharge 1e-6 range "
                   "sphere centre 5 0 0 radius 0.1", "flowknot apply pore-pressure 0 gradient -9810 range position-x 10"])
def flowknot_apply(session, call):
    _need_fluid(session, call)
    eng, kn, mask = _knots(session, call)
    a = call.args
    if a["pore_pressure"] is not None:
        g = float(a["gradient"]) if a["gradient"] is not None else 0.0
        kn["fixed"][mask] = 1
        kn["p_fixed"][mask] = float(a["pore_pressure"]) + g * kn["pos"][mask, 2]
        kn["pp"][mask] = kn["p_fixed"][mask]
    else:
        kn["q_in"][mask] += float(a["discharge"])
    F.to_subcontacts(eng)


@command("flowknot apply-remove", range="flowknot",
         doc="Remove the pressure boundaries and inflows of the knots in range.",
         examples=["flowknot apply-remove range position-x 0"])
def flowknot_apply_remove(session, call):
    _need_fluid(session, call)
    _eng, kn, mask = _knots(session, call)
    kn["fixed"][mask] = 0
    kn["q_in"][mask] = 0.0


@command("flowknot initialize",
         keywords=[P("pore-pressure", Num(), "the knots' pressure", units="Pa", required=True),
                   P("gradient", Num(), "its change per metre of z", units="Pa/m")],
         range="flowknot",
         doc="Set the pressure of the knots in range (a start value; boundaries keep theirs).",
         examples=["flowknot initialize pore-pressure 0", "flowknot initialize pore-pressure 1e5 gradient -9810"])
def flowknot_initialize(session, call):
    _need_fluid(session, call)
    eng, kn, mask = _knots(session, call)
    g = float(call.args["gradient"]) if call.args["gradient"] is not None else 0.0
    free = mask & (kn["fixed"] == 0)
    kn["pp"][free] = float(call.args["pore_pressure"]) + g * kn["pos"][free, 2]
    F.to_subcontacts(eng)


REGISTRY.node_keywords("flowknot history", [P("name", Text(), "history name")])


def _flowknot_history(quantity):
    def handler(session, call):
        from ..physics.history import histories

        _need_fluid(session, call)
        name = _name(session, call)
        label, value, spec = F.flowknot_history(session.model, quantity, call.args["position"])
        histories(session.model).add(label, value, name, spec)

    handler.__name__ = "flowknot_history_" + quantity.replace("-", "_")
    return handler


for _q in F.FLOWKNOT_QUANTITIES:
    command(f"flowknot history {_q}",
            keywords=[P("position", VEC3, "the knot nearest this point (at each sample)", units="m", required=True)],
            doc="Record the " + ("pressure [Pa]" if _q == "pore-pressure" else "discharge [m³/s]")
                + " of the flow knot nearest a point.",
            details="`discharge` is what the knot's boundary puts into the network: at a pressure boundary the net "
                    "flow out of it through the pipes, elsewhere the applied inflow. The knot is looked up at each "
                    "sample (the network is built again when the contacts change); NaN while there is none. A "
                    "leading `name '<s>'` names the history.",
            examples=[f"flowknot history {_q} position 5 1 0", f"flowknot history name 'h' {_q} position 0 1 0"],
            )(_flowknot_history(_q))
