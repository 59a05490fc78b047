"""`model calm`, `model list`, `block contact list`: quick looks at and resets of the whole model."""
from __future__ import annotations

import numpy as np

from ..kernels.joints import ST_FAILED, ST_SLIP, ST_TENSION
from ..physics.jmodels import JOINT_MODELS
from ..physics.rigid import engine
from ..units import describe as describe_units, suffix
from .registry import command
from .values import Choice, P

_CT = {1: "vertex-vertex", 2: "vertex-edge", 3: "vertex-face", 4: "edge-edge", 5: "edge-face", 6: "face-face"}


@command("model calm",
         doc="Set every velocity to zero: blocks (translation and rotation), gridpoints of zoned and FE "
             "blocks, cable nodes.",
         details="Held velocities (`block fix`, `block apply velocity…`, `block gridpoint apply velocity…`) stay "
                 "held: the next step sets those components again. Displacements, forces, stresses and contact "
                 "forces are not touched.",
         examples=["model calm"])
def model_calm(session, call):
    m = session.model
    m.blocks["velocity"][:] = 0.0
    m.blocks["spin"][:] = 0.0
    m.vertices["velocity"][:] = 0.0
    if "cable_nodes" in m.stores:
        m.stores["cable_nodes"]["vel"][:] = 0.0


def _names() -> dict[int, str]:
    return {jm.code: name for name, jm in JOINT_MODELS.items()}


@command("model list",
         positional=[P("what", Choice(("information", "gravity", "title", "configure", "large-strain",
                                       "update-interval", "units")), "one setting only (default: all of them)")],
         doc="Print the model-wide settings and state: title, gravity, large strain, processes configured, "
             "time and step, time step, what the model holds, the units reports name (`model configure units`).",
         examples=["model list", "model list gravity"])
def model_list(session, call):
    m = session.model
    s = m.settings
    w = call.args["what"]
    eng = engine(m)
    rows = [("title", s.title or "(none)"),
            ("gravity", "{:g} {:g} {:g}".format(*s.gravity) + suffix(m, "acceleration")),
            ("large-strain", "on" if s.large_strain else "off"),
            ("configure", ", ".join(s.configure) or "(mechanical only)"),
            ("update-interval", f"{s.update_interval} steps"),
            ("units", describe_units(m)),
            ("information", None)]
    for key, text in rows:
        if w is not None and w != key:
            continue
        if key == "information":
            session.write(f"{'step':<16}: {m.step}")
            t = suffix(m, "time")
            session.write(f"{'time':<16}: {m.time:.6g}{t}")
            session.write(f"{'time step':<16}: " + (f"{eng.dt:.6g}{t} (last cycle)" if eng.dt else "not cycled yet"))
            counts = [f"{m.blocks.n} blocks", f"{eng.contacts.n} contacts"]
            for name, label in (("zones", "zones"), ("feblocks", "FE elements"), ("cable_segments",
                                                                                   "cable segments")):
                if name in m.stores and m.stores[name].n:
                    counts.append(f"{m.stores[name].n} {label}")
            session.write(f"{'holds':<16}: " + ", ".join(counts))
            continue
        session.write(f"{key:<16}: {text}")


def _state(bits: int) -> str:
    if bits & ST_TENSION:
        return "open"
    if bits & ST_SLIP:
        return "slip"
    if bits & ST_FAILED:
        return "slip-past"
    return "-"


@command("block contact list", positional=[P("what", Choice(("information",)), "summary instead of a table")],
         range="contact",
         doc="List the contacts in range (blocks, type, joint model, normal and shear force, state), as found "
             "at the last detection, or a summary with `information`.",
         details="The forces are the sums over each contact's sub-contacts (normal: compression positive, N; "
                 "shear: magnitude, N). State: `open` when a sub-contact is open (tension), `slip` when one is "
                 "slipping now, `slip-past` when one has slipped before. Contacts exist after the first cycle "
                 "(or `model cycle 0`).",
         examples=["block contact list", "block contact list information", "block contact list range group 'base'"])
def block_contact_list(session, call):
    m = session.model
    eng = engine(m)
    c, sc = eng.contacts, eng.subcontacts
    mask = session.range_mask(call, "contact")
    sel = np.flatnonzero(mask)
    if not c.n:
        session.write("no contacts yet (they are found at the first cycle: `model cycle 0` finds them)")
        return
    owner = sc["contact"]
    fn = np.bincount(owner, weights=sc["fn"], minlength=c.n)[: c.n] if sc.n else np.zeros(c.n)
    fs = np.zeros((c.n, 3))
    bits = np.zeros(c.n, np.int64)
    if sc.n:
        for k in range(3):
            fs[:, k] = np.bincount(owner, weights=sc["fs"][:, k], minlength=c.n)[: c.n]
        np.bitwise_or.at(bits, owner, sc["state"].astype(np.int64))
    names = _names()
    if call.args["what"] == "information":
        st = bits[sel]
        session.write(f"contacts {c.n} (in range {sel.size}), sub-contacts {sc.n}")
        session.write(f"open {int(np.count_nonzero(st & ST_TENSION))}, slipping "
                      f"{int(np.count_nonzero(((st & ST_SLIP) != 0) & ((st & ST_TENSION) == 0)))}, "
                      f"slipped before {int(np.count_nonzero(st & ST_FAILED))}")
        session.write(f"normal force in range: total {fn[sel].sum():.6g}{suffix(m, 'force')}")
        session.results.update({"contacts": float(c.n)})
        return
    session.write(f"{'contact':>8} {'block A':>8} {'block B':>8} {'type':>13} {'jmodel':>14} {'subs':>5} "
                  f"{'normal force':>13} {'shear force':>12}  state")
    for r in sel:
        session.write(f"{r + 1:>8} {c['ida'][r]:>8} {c['idb'][r]:>8} {_CT.get(int(c['type'][r]), '?'):>13} "
                      f"{names.get(int(c['jmodel'][r]), '?'):>14} {c['sub_count'][r]:>5} {fn[r]:>13.6g} "
                      f"{float(np.linalg.norm(fs[r])):>12.6g}  {_state(int(bits[r]))}")
