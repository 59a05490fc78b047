"""`model factor-of-safety`: the factor of safety of the joints and zones by strength reduction
(dec3d.physics.fos; Itasca's procedure, FLAC3D/3DEC manual "Strength Reduction Procedure in
FLAC3D and 3DEC" and the `model factor-of-safety` command page, docs.itascacg.com)."""
from __future__ import annotations

import os
import time as _time

from ..errors import BindError, CommandError
from ..io.vtk import write_vtu
from ..io.state import StateFileError, save_state
from ..model.zones import has_zones
from ..physics.fos import (DEFAULT_RESOLUTION, DEFAULT_TRIAL_STEPS, STABLE_RATIO, FileTrials, StrengthTrials,
                           FosError, bracket_fos)
from ..physics.rigid import RunError, engine
from .registry import command
from .values import FLAG, Num, Nums, P

#: the failure mechanism (the first unstable trial) is written here, in the output folder
MECHANISM_FILE = "fos_mechanism.vtu"


def _check(call):
    br = call.args.get("bracket")
    if br is not None and all(isinstance(v, (int, float)) for v in br) and not br[0] < br[1]:
        raise BindError(f"bracket: the lower factor must be below the upper one (got {br[0]:g} {br[1]:g})",
                        call.locations.get("bracket", call.location))


@command("model factor-of-safety",
         keywords=[P("associated", FLAG, "the dilation angle follows the reduced friction angle", bare=True),
                   P("bracket", Nums(2, 2, item=Num(lo=0, lo_open=True)),
                     "a stable and an unstable factor to start from (default: from F = 1, doubling or halving)"),
                   P("resolution", Num(lo=0, lo_open=True), "stop when the bracket is at most this wide",
                     default=DEFAULT_RESOLUTION),
                   P("cycles", Num(integer=True, lo=1), "steps a trial may take to reach equilibrium (dec3d)",
                     default=DEFAULT_TRIAL_STEPS),
                   P("trials-per-round", Num(integer=True, lo=1, hi=16),
                     "factors tried in each narrowing round (dec3d; 1: bisection)", default=1),
                   P("workers", Num(integer=True, lo=1, hi=64),
                     "processes that run the trials of a round (dec3d; default: the trials per round, at most "
                     "the number of CPUs)")],
         range="contact", check=_check,
         doc="Find the factor of safety of the `mohr` joints and the zones by strength reduction (bisection on "
             "the factor).",
         details="Each trial factor F divides the cohesion, the tensile strength and tan φ of the `mohr` contacts "
                 "in range (peak and residual values; without a range the material-table defaults too, so that "
                 "contacts made during a trial are reduced as well): c/F, T/F, φ = atan(tan φ / F) (Itasca, "
                 "\"Strength Reduction Procedure\" and \"Computational Methods for Factor of Safety\", "
                 "docs.itascacg.com). Dilation as 3DEC's command page says: with `associated` the dilation angle "
                 "is the reduced friction angle; without it the dilation angle is kept but never above the reduced "
                 "friction angle.\n\n"
                 "The zones are reduced together with the joints, as in 3DEC and FLAC3D: every zone whose "
                 "constitutive model has a strength to reduce (`mohr-coulomb`: c/F, tan φ/F, σt/F, the dilation "
                 "angle kept at most the reduced friction angle; see each model's page) takes the reduced "
                 "strengths for the trial; `elastic` zones are left as they are. The range selects contacts "
                 "only: every zone with a reducible model is reduced.\n\n"
                 f"Every trial starts from the model as it is when the command is given (stresses, contacts, "
                 f"velocities, time). A trial is **stable** when the mechanical ratio of `model solve` falls to "
                 f"{STABLE_RATIO:g} (Itasca's equilibrium ratio) within `cycles` steps (default "
                 f"{DEFAULT_TRIAL_STEPS}), **unstable** otherwise. (Itasca finds a characteristic number of steps "
                 "N_r by perturbing a strong model; dec3d takes a fixed limit instead: raise `cycles` for models "
                 "that settle slowly.) With `bracket lo hi`, lo must be stable and hi unstable (else the command "
                 "stops with an error saying on which side the factor lies); without it F = 1 is tried, then "
                 "doubled or halved until the other state is met. The bracket is then halved (Dawson, Roth & "
                 "Drescher 1999) until it is at most `resolution` wide "
                 f"(default {DEFAULT_RESOLUTION:g}).\n\n"
                 "By default the trials run one after the other. With `trials-per-round k` (dec3d) each round tries "
                 "k factors evenly spaced inside the bracket at once (the bracket shrinks k + 1 times per round) "
                 "and runs them in parallel on `workers` processes, each trial on a copy of the model read from a "
                 "state file written once in the output folder (removed afterwards). The factors tried depend on "
                 "k only, so the result is the same for any number of workers.\n\n"
                 "The factor of safety is the stable end of the final bracket (the largest factor shown to hold); "
                 "it is printed with the trials, put in the results as `fos` (with `fos.unstable`, `fos.trials`) "
                 "and as `fos.<n>` for the n-th search of the run, and kept on the model. The first unstable trial's state at its end (vertex and block velocities: "
                 f"the failure mechanism) is written to `{MECHANISM_FILE}` in the output folder. Afterwards the "
                 "model is put back exactly to its state before the command (zone stresses, plastic states, histories "
                 "and properties, gridpoint positions and velocities included; dec3d's choice; `history` "
                 "records and periodic VTK snapshots are not sampled during the trials).",
         examples=["model factor-of-safety", "model factor-of-safety bracket 0.5 2 resolution 0.001",
                   "model factor-of-safety associated", "model factor-of-safety range group 'joints'"])
def model_factor_of_safety(session, call):
    a = call.args
    lo, hi = (a["bracket"] if a["bracket"] is not None else (None, None))
    _check(call)
    e = engine(session.model)
    if session.model.blocks.n == 0:
        raise CommandError("model factor-of-safety: there are no blocks", call.location)
    e.ensure_contacts()
    mask = session.range_mask(call, "contact") if call.range is not None else None
    vtk_path = session.out_path(MECHANISM_FILE, call.location)

    def mechanism(factor):
        write_vtu(session.model, vtk_path)
        session.write(f"  failure mechanism (F = {factor:.6g}) written to {MECHANISM_FILE}")

    trials = StrengthTrials(e, mask, associated=a["associated"], steps=int(a["cycles"]), on_unstable=mechanism)
    if trials.empty:
        trials.finish()
        raise CommandError("model factor-of-safety: nothing to reduce: no contact "
                           + ("in range " if mask is not None else "") + "has the `mohr` joint model"
                           + (" and no zone has a constitutive model with a strength (e.g. `block zone cmodel "
                              "assign mohr-coulomb`)" if has_zones(session.model) else ""), call.location)
    points = int(a["trials_per_round"])
    workers = int(a["workers"]) if a["workers"] is not None else min(points, os.cpu_count() or 1)
    t0 = _time.perf_counter()
    log = trials.log
    state = runner = None
    try:
        if points == 1:
            res = bracket_fos(trials, lo, hi, float(a["resolution"]))
        else:
            state = session.out_path(f".dec3d-fos-{os.getpid()}.zip", call.location)
            trials.finish()                       # the file holds the model as it was given
            save_state(session.model, state)
            runner = FileTrials(str(state), trials, workers)
            log = runner.log
            res = bracket_fos(None, lo, hi, float(a["resolution"]), points=points, run_many=runner)
            bad = next((f for f, ok, _, _ in log if not ok), None)
            if bad is not None:                   # the failure mechanism: the first unstable trial again, here
                trials = StrengthTrials(e, mask, associated=a["associated"], steps=int(a["cycles"]),
                                        on_unstable=mechanism)
                trials(bad)
    except FosError as exc:
        raise CommandError(f"model factor-of-safety: {exc}", call.location)
    except RunError as exc:
        raise CommandError(exc.message, call.location)
    except StateFileError as exc:
        raise CommandError(f"model factor-of-safety: {exc.message}", call.location)
    finally:
        trials.finish()
        if runner is not None:
            runner.close()
        if state is not None:
            try:
                os.unlink(state)
            except OSError:
                pass
    wall = _time.perf_counter() - t0
    for f, ok, steps, ratio in log:
        session.write(f"  F = {f:.6g}: {'stable' if ok else 'unstable'} ({steps} steps, ratio {ratio:.3g})")
    session.write(f"model factor-of-safety: FS = {res.fs:.6g} (stable at {res.stable:.6g}, unstable at "
                  f"{res.unstable:.6g}; {len(res.trials)} trials, {wall:.3g} s)")
    # `fos` is the last one; `fos.<n>` the n-th of the run (a deck may search several models)
    k = 1 + sum(1 for key in session.results if key.startswith("fos.") and key[4:].isdigit())
    for key in ("fos", f"fos.{k}"):
        session.results[key] = float(res.fs)
        session.results[key + ".unstable"] = float(res.unstable)
        session.results[key + ".trials"] = float(len(res.trials))
    session.model.factor_of_safety = float(res.fs)
