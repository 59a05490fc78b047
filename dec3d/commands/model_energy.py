"""`model energy …`, `block mechanical energy` and `model history energy …`: energy tracking of the
rigid-block cycle (``dec3d.physics.energy``; 3DEC theory, "Energy Calculation")."""
from __future__ import annotations

from ..errors import CommandError
from ..physics.energy import QUANTITIES, energy_state, new_state, values
from ..physics.history import histories
from ..units import suffix
from .registry import command
from .values import ONOFF, Choice, P

_DOC = {"block-kinetic": "kinetic energy of the rigid blocks (½ m V² + ½ ωᵀ J ω, full inertia tensor) and gridpoints",
        "block-strain": "elastic strain energy of the zones, Σ V (p²/(2K) + s:s/(4G))",
        "contact-strain": "elastic energy of the contact springs, Σ Fn²/(2 kn A) + |Fs|²/(2 ks A)",
        "stored": "block-kinetic + block-strain + contact-strain",
        "block-plastic": "energy dissipated by plastic flow in the zones",
        "contact-slip": "energy dissipated in the contacts (Coulomb slip, tension cut-off)",
        "body": "work done by gravity",
        "boundary": "work of the applied forces and moments and of the reactions of fixed or applied velocities",
        "damping": "energy taken by the mechanical damping",
        "strain-change": "strain energy that appeared between steps without work (detections, commands)",
        "kinetic-change": "kinetic energy that appeared between steps without work (density scaling, commands)",
        "error": "the energy balance (0 when every joule is accounted for)",
        "error-relative": "|error| / (|body| + |boundary|)"}

_DETAILS = ("Running sums since tracking was switched on (or reset), worked out at every step as 3DEC does "
            "(3DEC theory, \"Energy Calculation\"). Works use the mid-step velocity (v(t−Δt/2) + v(t+Δt/2))/2; "
            "kinetic and contact strain energy are those at t + Δt/2, so that an undamped elastic model keeps "
            "kinetic + strain − work constant to round-off. Kinetic energy uses the masses the motion uses: the "
            "real ones unless density scaling is on (`block mechanical damping none` turns it off). "
            "Balance: (kinetic + strain now − at the start) + block-plastic + contact-slip + damping = body + "
            "boundary + strain-change + kinetic-change, up to `error`. Rigid blocks and zoned blocks of 4-node "
            "zones (also in contact with rigid blocks): a model with FE blocks or 10-node zones does not "
            "cycle while tracking is on. While tracking is on the cycle runs one step per kernel call "
            "(slower).")


def _switch(session, on: bool) -> None:
    e = energy_state(session.model)
    if on and not e["active"]:
        fresh = new_state(True)
        e.clear()
        e.update(fresh)
    else:
        e["active"] = bool(on)


@command("model energy active", positional=[P("on", ONOFF, "on: track energies from now; off: stop", required=True)],
         doc="Switch energy tracking on or off.",
         details="Switching it on (when it was off) starts every sum from zero. " + _DETAILS,
         examples=["model energy active on", "model energy active off"])
def model_energy_active(session, call):
    _switch(session, call.args["on"])


@command("block mechanical energy", positional=[P("on", ONOFF, "on: track energies from now; off: stop",
                                                  required=True)],
         doc="Switch energy tracking on or off (3DEC's block-level spelling of `model energy active`).",
         details="The same as `model energy active`. " + _DETAILS,
         examples=["block mechanical energy on"])
def block_mechanical_energy(session, call):
    _switch(session, call.args["on"])


@command("model energy reset", doc="Start every energy sum from zero again (tracking stays as it is).",
         details=_DETAILS, examples=["model energy reset"])
def model_energy_reset(session, call):
    e = energy_state(session.model)
    active = e["active"]
    e.clear()
    e.update(new_state(active))


@command("model energy list", doc="Print the energy components and put them into the results as `energy.<name>`.",
         details=_DETAILS, examples=["model energy list"])
def model_energy_list(session, call):
    e = energy_state(session.model)
    v = values(session.model)
    lines = [f"energy tracking {'on' if e['active'] else 'off'}" + ("" if e["started"] else " (no step tracked yet)")]
    for q in QUANTITIES:
        unit = "" if q == "error-relative" else suffix(session, "energy")
        lines.append(f"  {q:<16}{v[q]:>16.6g}{unit}")
        session.results[f"energy.{q}"] = v[q]
    session.write("\n".join(lines) + "\n")


@command("model history energy", positional=[P("quantity", Choice(QUANTITIES), "the energy component", required=True)],
         doc="Record an energy component (`model energy active on` must be on for it to change).",
         details="Components: " + "; ".join(f"`{q}` {d}" for q, d in _DOC.items()) + ". A leading `name '<s>'` "
                 "names the history. " + _DETAILS,
         examples=["model history energy block-kinetic", "model history name 'slip' energy contact-slip"])
def model_history_energy(session, call):
    name = call.args.get("name")
    hs = histories(session.model)
    if name is not None and hs.find(name) is not None:
        raise CommandError(f"a history named '{name}' exists already", call.location)
    hs.add_energy(call.args["quantity"], name)
