"""`model cycle|solve|update-interval`: run the rigid-block engine (dec3d.physics.rigid)."""
from __future__ import annotations

from ..errors import CommandError
from ..physics.rigid import RunError, engine
from .registry import command
from .values import FLAG, Num, P


_TIMING = P("timing", FLAG, "print how long each phase of the cycle took (dec3d)", bare=True)


def _run(session, call, n, stop=None, max_time=None):
    e = engine(session.model)
    if call.args.get("timing"):
        for k in e.timings:
            e.timings[k] = 0.0
    try:
        done = e.cycle(n, stop, max_time=max_time)
    except RunError as exc:
        raise CommandError(str(exc), call.location)
    if call.args.get("timing"):
        session.write(f"{done} steps, Δt = {e.dt:.4g} s\n{e.timing_report()}\n")
    return done


@command("model cycle", positional=[P("n", Num(integer=True, lo=0), "number of steps", required=True)],
         keywords=[_TIMING],
         doc="Take n mechanical steps (contact detection every `model update-interval` steps).",
         details="`timing` prints the time spent in each phase: detection (of which neighbour search and "
                 "sub-contacts), the cycle kernel, and history sampling.",
         examples=["model cycle 1000", "model cycle 1000 timing"])
def model_cycle(session, call):
    _run(session, call, int(call.args["n"]))


@command("model solve",
         keywords=[P("ratio", Num(lo=0, lo_open=True), "stop when the mean unbalanced-force ratio falls below"),
                   P("ratio-local", Num(lo=0, lo_open=True), "stop when the unbalanced-force ratio falls below"),
                   P("ratio-average", Num(lo=0, lo_open=True), "same as ratio in dec3d"),
                   P("unbalanced-maximum", Num(lo=0, lo_open=True), "stop when the largest unbalanced force falls below",
                     units="N"),
                   P("time", Num(lo=0, lo_open=True), "stop at this total time", units="s"),
                   P("cycles", Num(integer=True, lo=1), "stop after this many steps"),
                   P("and", FLAG, "every given limit must be met", bare=True),
                   P("or", FLAG, "any given limit is enough (default)", bare=True), _TIMING],
         doc="Cycle until the limits are met (default: ratio 1e-5, at most 10^6 steps).",
         details="ratio is the largest unbalanced force over the mean of the gravity and contact forces "
                 "acting on the moving blocks.",
         examples=["model solve", "model solve ratio 1e-6", "model solve time 0.5 cycles 20000 or"])
def model_solve(session, call):
    a = call.args
    e = engine(session.model)
    limits = []
    for key in ("ratio", "ratio_local", "ratio_average"):
        if a[key] is not None:
            limits.append(lambda en, v=a[key]: en.ratio <= v)
    if a["unbalanced_maximum"] is not None:
        limits.append(lambda en, v=a["unbalanced_maximum"]: en.unbal <= v)
    t_end = e.time + a["time"] if a["time"] is not None else None
    if t_end is not None:
        limits.append(lambda en: en.time >= t_end - 1e-9 * max(en.dt, 1e-300))
    if not limits:
        limits.append(lambda en: en.ratio <= 1e-5)
    both = bool(a["and"])
    n = int(a["cycles"]) if a["cycles"] is not None else 10**6

    def stop(en):
        ok = [f(en) for f in limits]
        return all(ok) if both else any(ok)

    _run(session, call, n, stop, max_time=t_end if (t_end is not None and not both) else None)


@command("model update-interval", positional=[P("n", Num(integer=True, lo=1), "steps between contact detections",
                                                  required=True)],
         doc="Set how often contacts and sub-contacts are detected again (3DEC default 10).",
         examples=["model update-interval 10"])
def model_update_interval(session, call):
    session.model.settings.update_interval = int(call.args["n"])
