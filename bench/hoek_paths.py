"""Which path of the Hoek-Brown update each zone takes, step by step, on ``zone_bench.py``'s scene
(unit cube of about N tetrahedra, in-situ stress beyond the strength, gravity, base held; one
thread). Not a timing: a count, to see where the model's time goes.

    python bench/hoek_paths.py [--zones 1e5] [--steps 53] [--at 4 10 20 30 40 50]

At each step of ``--at`` the trial stress of every zone is taken from one elastic step from the
same state (the zone step with the zones' model set to elastic, then stress, state and history
put back: the same strain increment, mixed discretization and NMD as the model's step sees), and
the model's scalar path (``hoek_brown.fast_update``) is asked for its code: 0 elastic, 1 shear,
2 tension, 3 both (settled in scalars), -1 the general path (``_general``: repeated Mohr-Coulomb
returns on arrays), -2/-3 ``_slow``'s edge and close-value returns, -4/-5 ``_slow``'s returns on
the envelope's line on Jacobi's axes (before 2026-11-29's line and edge returns, ``fast_update``
gave ``_fast``'s codes: then -1 also counts what ``update`` sent on to ``_slow``). Steps of
``--at`` from 2 on (the zone stepper exists after the first step).
"""
from __future__ import annotations

import argparse
import io
import os
import sys
import tempfile


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--zones", type=float, default=1e5)
    ap.add_argument("--steps", type=int, default=53)
    ap.add_argument("--at", type=int, nargs="+", default=[4, 10, 20, 30, 40, 50])
    args = ap.parse_args(argv)
    here = os.path.dirname(os.path.abspath(__file__))
    sys.path.insert(0, here)
    sys.path.insert(0, os.path.dirname(here))              # the checkout's dec3d
    import numba
    import numpy as np
    from numba import njit
    numba.set_num_threads(1)
    import dec3d
    from dec3d.kernels.zmodels import CODES, NWORK, model_mask
    from dec3d.kernels.zmodels import hoek_brown as hbk
    from dec3d.kernels.zone_mohr import mohr_work
    from dec3d.kernels.zone_step import zone_step_for
    from zone_bench import deck, edge_length

    @njit
    def codes(trial, prop, bulk, shear, n, out):
        wf = np.full(NWORK, np.nan)
        mw = mohr_work()
        h = np.zeros((1, 4))
        for z in range(n):
            t = trial[z]
            r = hbk.fast_update(prop, h, z, bulk[z], shear[z], 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, t[0], t[1], t[2],
                                t[3], t[4], t[5], h, wf, mw)
            out[r[0] + 5] += 1

    s = dec3d.Session(out_dir=tempfile.mkdtemp(), stdout=io.StringIO())
    s.command(deck(edge_length(args.zones), "hoek-brown"))
    zs, v = s.model.store("zones"), s.model.vertices
    n = zs.n
    elastic = zone_step_for(model_mask([CODES["elastic"]], True))
    names = ["-5", "-4", "-3", "-2", "-1", "0", "1", "2", "3"]
    print(f"{n} zones; codes of hoek_brown.fast_update per step (share of the zones, %)")
    print(f"{'step':>5} " + " ".join(f"{c:>6}" for c in names))
    for k in range(1, args.steps + 1):
        if k in args.at:
            zst = s.model.rigid_engine._zstep
            saved = {f: zs[f].copy() for f in ("stress", "state", "hist", "cmodel")}
            zs["cmodel"][:] = CODES["elastic"]
            zst.begin()
            elastic(v["pos"], v["velocity"], zst.zmesh, zst.material(), zst.zplan, zst.zscratch,
                    s.model.rigid_engine.dt, False, zst.nmd, zst.facc, zst.fmag)
            trial = zs["stress"][:n].copy()
            for f, a in saved.items():
                zs[f][:] = a
            out = np.zeros(9, np.int64)
            codes(trial, zs["prop"], zst.bulk, zst.shear, n, out)
            print(f"{k:>5} " + " ".join(f"{100.0 * c / n:>6.2f}" for c in out), flush=True)
        s.command("model cycle 1")
    return 0


if __name__ == "__main__":
    sys.exit(main())
