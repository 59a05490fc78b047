"""`model cycle|solve|update-interval`: run the rigid-block engine (dec3d.physics.rigid).

The equilibrium measures of `model solve` (`ratio`, `ratio-average`, `ratio-local`,
`ratio-maximum`, `unbalanced-maximum`) are Itasca's, applied to rigid bodies: see
``RigidEngine.criteria`` (source: the FLAC3D/3DEC manual page "Reaching Equilibrium", section
"Out-of-Balance Force and Ratio Calculation", and the `zone ratio` command page,
docs.itascacg.com).
"""
from __future__ import annotations

import time as _time

from ..errors import CommandError, _resolved
from ..physics.rigid import RunError, engine
from ..units import suffix
from .registry import command
from .values import FLAG, Num, P

_TIMING = P("timing", FLAG, "print how long each phase of the cycle took (dec3d)", bare=True)

#: the steps a `model solve` takes at most when it is given neither `cycles` nor `time` (or
#: `time` with `and`, which cannot end a solve whose ratio is never met)
#: (dec3d's choice: a limit so that a model that cannot settle ends with "not converged"
#: instead of running for hours; `cycles n` raises it)
SOLVE_CYCLE_CAP = 200_000
#: the ratio a `model solve` without any limit aims at (Itasca's default, "Reaching Equilibrium")
DEFAULT_RATIO = 1e-5
#: criterion keyword (call.args key) -> (printed name, key of RigidEngine.criteria())
CRITERIA = {"ratio": ("ratio", "ratio"), "ratio_average": ("ratio-average", "ratio-average"),
            "ratio_local": ("ratio-local", "ratio-local"), "ratio_maximum": ("ratio-maximum", "ratio-maximum"),
            "unbalanced_maximum": ("unbalanced-maximum", "unbalanced-maximum")}


def _run(session, call, n, stop=None, max_time=None):
    e = engine(session.model)
    if call.args.get("timing"):
        for k in e.timings:
            e.timings[k] = 0.0
    try:
        done = e.cycle(n, stop, max_time=max_time, warn=lambda msg: session.write(f"warning: {msg}"))
    except RunError as exc:
        raise CommandError(exc.message, call.location)
    if call.args.get("timing"):
        session.write(f"{done} steps, Δt = {e.dt:.4g}{suffix(session, 'time')}\n{e.timing_report()}\n")
    return done


@command("model cycle", positional=[P("n", Num(integer=True, lo=0), "number of steps", required=True)],
         keywords=[_TIMING],
         doc="Take n mechanical steps (contact detection every `model update-interval` steps).",
         details="`timing` prints the time spent in each phase: detection (of which neighbour search and "
                 "sub-contacts), the cycle kernel, and history sampling. A run that becomes unstable stops "
                 "with the step and block named and the model put back to its state before the command; "
                 "Ctrl-C stops at the end of the current batch of steps (the model consistent). A warning is "
                 "printed first when contacts in use have zero normal or shear stiffness.",
         examples=["model cycle 1000", "model cycle 1000 timing"])
def model_cycle(session, call):
    e = engine(session.model)
    time0 = e.time
    done = _run(session, call, int(call.args["n"]))
    rt = getattr(session, "fish_rt", None)
    if done and session.model.blocks.n and (rt is None or rt.depth == 0):
        # the compact report of `model solve` (not for the short cycles FISH functions take in loops)
        t = suffix(session, "time")
        session.write(f"model cycle: {done} steps (to step {e.step}), model time {e.time - time0:.6g}{t} "
                      f"(total {e.time:.6g}{t})")
        session.write(f"  {_fmt_criteria(e.criteria(), suffix(session, 'force'))}")


def _fmt_criteria(values: dict, force_unit: str = "") -> str:
    return ", ".join(f"{name} {values[key]:.4g}" + (force_unit if key == "unbalanced-maximum" else "")
                     for name, key in CRITERIA.values())


@command("model solve",
         keywords=[P("ratio", Num(lo=0, lo_open=True), "stop when the mechanical ratio (the average ratio) falls "
                                                        "below"),
                   P("ratio-average", Num(lo=0, lo_open=True), "stop when the mean unbalanced force over the mean "
                                                                "applied force magnitude falls below"),
                   P("ratio-local", Num(lo=0, lo_open=True), "stop when 0.1 × the largest body ratio (unbalanced "
                                                              "over applied force) falls below"),
                   P("ratio-maximum", Num(lo=0, lo_open=True), "stop when 0.1 × the largest unbalanced force over "
                                                                "the mean applied force magnitude falls below"),
                   P("unbalanced-maximum", Num(lo=0, lo_open=True), "stop when the largest unbalanced force falls "
                                                                     "below", units="N"),
                   P("time", Num(lo=0, lo_open=True), "stop after this much model time", units="s"),
                   P("cycles", Num(integer=True, lo=1), "stop after this many steps"),
                   P("clock", Num(lo=0, lo_open=True), "stop after this much wall-clock time", units="min"),
                   P("and", FLAG, "every given limit must be met", bare=True),
                   P("or", FLAG, "any given limit is enough (default)", bare=True),
                   P("implicit", FLAG, "elastic zoned and FE blocks: reach the static answer by a sparse solve "
                                       "first, then cycle on as usual (dec3d keyword)", bare=True), _TIMING],
         doc=f"Cycle until the limits are met (default: ratio {DEFAULT_RATIO:g}; at most {SOLVE_CYCLE_CAP} steps "
             "unless `cycles`, or `time` without `and`, is given).",
         details="The ratios are Itasca's (FLAC3D/3DEC manual, \"Reaching Equilibrium\", section \"Out-of-Balance "
                 "Force and Ratio Calculation\"; `zone ratio` command page), with each moving body (a block or a "
                 "group of joined blocks) in the place of a gridpoint. A body's unbalanced force is |ΣF| of the "
                 "contact forces, weight and applied force on it (fixed components left out); its applied force "
                 "magnitude is Σ|F| of the same forces one by one (each sub-contact force, the weight, the "
                 "applied force). `ratio` and `ratio-average`: mean unbalanced force / mean applied force "
                 "magnitude; `ratio-local`: 0.1 × the largest ratio of a body's unbalanced force to its own "
                 "applied magnitude; `ratio-maximum`: 0.1 × the largest unbalanced force / the mean applied "
                 "magnitude (the 0.1 makes them mean about the same as the average, as Itasca scales them); "
                 "`unbalanced-maximum`: the largest unbalanced force [N]. Bodies fixed in all three directions "
                 "take no part.\n\n"
                 f"Without `cycles`, or `time` without `and`, a solve stops after {SOLVE_CYCLE_CAP} steps (dec3d's "
                 "cap; Itasca's pages name no default cycle limit that we could find). At the end "
                 "it prints the steps taken, the model time, every criterion value and which limit stopped it; a "
                 "solve with a ratio or unbalanced-force limit that stops on its step, time or clock limit says "
                 "\"not converged\", and `dec3d run` repeats that as a warning at the end of the run (the exit "
                 "status stays 0). A warning is printed first when contacts in use have zero normal or shear "
                 "stiffness. When the output is not a terminal, a progress line is printed every 10 s.\n\n"
                 "`implicit` (dec3d's own keyword, not Itasca's) is for linear elastic zoned and FE blocks in "
                 "small strain: before cycling, the static equilibrium of the explicit scheme's own "
                 "discretisation (the same zone and element kernels: nodal mixed discretization, Gauss rules, "
                 "hourglass control; gravity, applied and face forces) is found by a sparse solve: sparse LU "
                 "of the stiffness probed from the element kernels for FE blocks and 10-node zones, conjugate "
                 "gradients of the zone step itself preconditioned by that LU with 4-node zones. Stresses and "
                 "displacements are set to it and velocities to zero (dec3d.physics.implicit). The solve then "
                 "cycles as usual, so the limits, the printed ratios, histories and FISH see the state the "
                 "explicit steps find: at rest, a solve stops after its first batch of steps (at most "
                 "`model update-interval` steps; the model time moves on only by these). A model it cannot "
                 "take (rigid blocks, contacts on deformable blocks, zone models other than elastic, large "
                 "strain, dynamic mode, time functions, quiet boundaries, energy tracking, FISH callbacks, a "
                 "held gridpoint moving, a block not held against rigid motion) is solved by cycling alone, "
                 "with a line saying why.",
         examples=["model solve", "model solve ratio 1e-6", "model solve ratio 1e-6 implicit",
                   "model solve ratio-local 1e-6 time 0.02",
                   "model solve time 0.5 cycles 20000 or", "model solve unbalanced-maximum 1 clock 5"])
def model_solve(session, call):
    a = call.args
    e = engine(session.model)
    crit = {k: float(a[k]) for k in CRITERIA if a.get(k) is not None}
    if not crit and a["time"] is None and a["cycles"] is None and a["clock"] is None:
        crit = {"ratio": DEFAULT_RATIO}
    t_end = e.time + a["time"] if a["time"] is not None else None
    both = bool(a["and"])
    # the cap holds unless the solve has its own end: `cycles`, or `time` alone (with `and` a
    # time limit does not end a solve whose ratio is never met)
    capped = a["cycles"] is None and (a["time"] is None or both)
    n = int(a["cycles"]) if a["cycles"] is not None else SOLVE_CYCLE_CAP if capped else 2**62
    wall_end = _time.monotonic() + 60.0 * a["clock"] if a["clock"] is not None else None
    why: dict = {}

    def met_criteria(en) -> list[bool]:
        values = en.criteria()
        return [values[CRITERIA[k][1]] <= v for k, v in crit.items()]

    def stop(en) -> bool:
        ok = met_criteria(en)
        if t_end is not None:
            ok.append(en.time >= t_end - 1e-9 * max(en.dt, 1e-300))
            if ok[-1]:
                why.setdefault("time", True)
        if wall_end is not None:
            ok.append(_time.monotonic() >= wall_end)
            if ok[-1]:
                why.setdefault("clock", True)
        return all(ok) if both else any(ok)

    if a.get("implicit"):
        _implicit(session, call, e)
    time0 = e.time
    done = _run(session, call, n, stop, max_time=t_end if (t_end is not None and not both) else None)
    if e.model.blocks.n == 0:
        session.write("model solve: there are no blocks: nothing to solve")
        return
    values = e.criteria()
    met = met_criteria(e)
    converged = bool(crit) and (all(met) if both else any(met))
    if done >= n:
        limit = f"the step limit ({n} steps{', dec3d’s default cap' if capped else ''})"
    elif t_end is not None and e.time >= t_end - 1e-9 * max(e.dt, 1e-300):
        limit = f"the time limit ({a['time']:g} s)"
    elif why.get("clock"):
        limit = f"the clock limit ({a['clock']:g} min)"
    else:
        limit = None
    if converged:
        names = [f"{CRITERIA[k][0]} {values[CRITERIA[k][1]]:.4g} ≤ {v:g}" for k, v in crit.items()
                 if values[CRITERIA[k][1]] <= v]
        head = "converged: " + ", ".join(names)
    elif crit:
        want = ", ".join(f"{CRITERIA[k][0]} ≤ {v:g}" for k, v in crit.items())
        head = f"not converged ({want} not met): stopped by {limit or 'a limit'}"
    else:
        head = f"stopped by {limit or 'a limit'}"
    t, f = suffix(session, "time"), suffix(session, "force")
    session.write(f"model solve: {head}; {done} steps (to step {e.step}), model time {e.time - time0:.6g}{t} "
                  f"(total {e.time:.6g}{t})")
    session.write(f"  {_fmt_criteria(values, f)}")
    if crit and not converged:
        where = _resolved(call.location)
        at = f"{where.file}:{where.line}: " if where is not None else ""
        warnings = getattr(session, "warnings", None)
        if warnings is not None:
            warnings.append(f"{at}model solve did not converge ({want}): stopped by {limit or 'a limit'} at step "
                            f"{e.step}; {_fmt_criteria(values, f)}")


def _implicit(session, call, e) -> None:
    """The sparse direct solve of ``model solve … implicit`` (``physics.implicit``), or a line saying
    why the model is solved by cycling alone."""
    from ..physics.implicit import Refusal, implicit_static

    try:
        r = implicit_static(e, warn=lambda msg: session.write(f"warning: {msg}"))
    except Refusal as exc:
        session.write(f"model solve implicit: {exc}: solving by cycling alone")
        return
    except RunError as exc:
        raise CommandError(exc.message, call.location)
    f = suffix(session, "force")
    how = (f"by conjugate gradients ({r['iterations']} iterations)" if r["iterations"] else "directly")
    session.write(f"model solve implicit: {r['unknowns']} unknowns solved {how} in {r['seconds']:.3g} CPU s "
                  f"(largest unbalanced force {r['first']:.4g}{f} before, {r['left']:.3g}{f} after"
                  f"{', ' + str(r['refines']) + ' refinement(s)' if r['refines'] else ''}); cycling on")


@command("model update-interval", positional=[P("n", Num(integer=True, lo=1), "steps between contact detections",
                                                  required=True)],
         doc="Set how often contacts and sub-contacts are detected again (3DEC default 10).",
         examples=["model update-interval 10"])
def model_update_interval(session, call):
    session.model.settings.update_interval = int(call.args["n"])
