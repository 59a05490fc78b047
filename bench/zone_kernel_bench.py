"""The 4-node zone step alone, per constitutive model: CPU ns per zone-step of the engine's zone
kernel on ``zone_bench.py``'s scene (unit cube of about N tetrahedra, in-situ stress beyond the
Mohr-Coulomb, Hoek-Brown and strain-softening strengths, gravity, base held), one thread.

    python bench/zone_kernel_bench.py [--zones 1e5] [--cmodel elastic mohr-coulomb hoek-brown strain-softening]
                                      [--warm 3] [--repeat 15] [--nmd on off]

The scene is built and cycled ``--warm`` steps through the public commands; then the zone kernel
is called ``--repeat`` times on the gridpoint velocities of that state, each call from the same
stresses, states and histories (put back outside the timed region), and the smallest process CPU
time of a call is printed per zone. CPU time, not wall time: on a shared machine another
process's load stretches the wall time of a run several-fold, much less its CPU time. The state
reached after ``--warm`` steps matters for the plastic models (after 40 steps about 15 % of the
Hoek-Brown zones are at a corner of shear and tension, which the model's general path returns).

Also runs on a checkout from before the one zone step (``zone_mohr_step.mohr_zone_step`` /
``zone_elastic.elastic_zone_step``, e.g. 1fd58a6), for A/B comparisons.
"""
from __future__ import annotations

import argparse
import io
import os
import sys
import tempfile
import time


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--zones", type=float, default=1e5)
    ap.add_argument("--cmodel", nargs="+", default=["elastic", "mohr-coulomb", "hoek-brown", "strain-softening"])
    ap.add_argument("--warm", type=int, default=3, help="steps cycled before the timed calls")
    ap.add_argument("--repeat", type=int, default=15)
    ap.add_argument("--nmd", nargs="+", default=["on"], choices=["on", "off"])
    args = ap.parse_args(argv)
    here = os.path.dirname(os.path.abspath(__file__))
    sys.path.insert(0, here)
    sys.path.insert(0, os.path.dirname(here))              # the checkout's dec3d
    import numba
    numba.set_num_threads(1)
    import dec3d
    from zone_bench import deck, edge_length
    print(f"{'cmodel':>18} {'nmd':>4} {'CPU ns/zone-step':>16} {'yielded':>8}")
    res = {}
    for cm in args.cmodel:
        s = dec3d.Session(out_dir=tempfile.mkdtemp(), stdout=io.StringIO())
        s.command(deck(edge_length(args.zones), cm))
        s.command(f"model cycle {args.warm}")
        zst = s.model.rigid_engine._zstep
        zs, v = s.model.store("zones"), s.model.vertices
        pos, vel, dt = v["pos"], v["velocity"], s.model.rigid_engine.dt
        saved = {k: zs[k].copy() for k in ("stress", "state", "hist") if k in zs.fields}
        for nmd in (a == "on" for a in args.nmd):
            if hasattr(zst, "fastmc"):                     # (before the one zone step)
                from dec3d.kernels.zone_elastic import elastic_zone_step
                from dec3d.kernels.zone_mohr_step import mohr_zone_step
                fast = zst.fast

                def call():
                    if zst.fastmc is not None:
                        mohr_zone_step(pos, vel, fast.g4, fast.n4, fast.rows, fast.zset, fast.weight, zst.nset,
                                       zs["cmodel"], zs["prop"], zst.bulk, zst.shear, dt, False, nmd, zs["stress"],
                                       zs["state"], zst.facc, zst.fmag, *fast.args(), *zst.fastmc)
                    else:
                        elastic_zone_step(pos, vel, fast.g4, fast.n4, fast.rows, fast.zset, fast.weight, zst.nset,
                                          zst.bulk, zst.shear, dt, False, nmd, zs["stress"], zst.facc, zst.fmag,
                                          *fast.args())
            else:
                from dec3d.kernels.zone_step import zone_step_for
                step = zone_step_for(zst.models)

                def call():
                    step(pos, vel, zst.zmesh, zst.material(), zst.zplan, zst.zscratch, dt, False, nmd, zst.facc,
                         zst.fmag)
            best = float("inf")
            for _ in range(args.repeat):
                for k, a in saved.items():
                    zs[k][:] = a
                zst.begin()
                c0 = time.process_time()
                call()
                best = min(best, time.process_time() - c0)
            ns = 1e9 * best / zs.n
            res[cm, nmd] = ns
            print(f"{cm:>18} {'on' if nmd else 'off':>4} {ns:>16.1f} {int((zs['state'][:zs.n] != 0).sum()):>8}",
                  flush=True)
    for cm in args.cmodel:
        if cm != "mohr-coulomb" and ("mohr-coulomb", True) in res and (cm, True) in res:
            print(f"{cm} / mohr-coulomb (NMD on): {res[cm, True] / res['mohr-coulomb', True]:.2f}")
    with open("/proc/loadavg", encoding="utf-8") as f:
        print(f"loadavg: {f.read().strip()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
