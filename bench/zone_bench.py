"""Benchmark of the elastic zone cycle: a unit cube zoned into about N 4-node tetrahedra under
gravity, base held, elastic zones (E = 10 GPa, nu = 0.25, rho = 2500), density scaling.

Figures per N (issue 10 targets on this machine: >= 2e7 zone-cycles/s with 2 threads at 1e6
zones; <= 1 kB per zone; zoning 1e6 zones <= 30 s):

- zone-cycles/s: zones x timed steps / wall time of `model cycle S` (after warm-up steps that
  also compile the kernels; the timed command builds its own zone stepper, as every `model
  cycle` does); "cpu s": the process's CPU time over the same command (all threads), which the
  other loads of a shared machine inflate less than the wall time;
- memory per zone: bytes of the live rows of the ``zones`` store, of the gridpoint store
  (``model.vertices``: positions, velocities, forces, masses of every gridpoint) and of the
  numpy arrays the engine's zone stepper holds, each divided by the zone count; and the growth
  of the process's resident set (VmRSS) from before the zoning to after the timed steps, per
  zone (this one also counts the mesher's temporaries that Python did not give back).

The scene is built through the public command API (``dec3d.Session().command``).  Each run is
a fresh process (``--child``); the median of ``--repeat`` runs is printed, with the machine and
/proc/loadavg before and after (the machine is shared: read the figures with the load).

    python bench/zone_bench.py [--zones 1e4 1e5 1e6] [--steps 50] [--repeat 3] [--threads 1 2] [--jointed]
                               [--cmodel elastic mohr-coulomb mohr-coulomb-strong hoek-brown strain-softening]

``--cmodel``: the constitutive models to time, one after the other for each thread count and size
(back to back, so the ratio is read at one load). ``mohr-coulomb`` gives the same elastic
constants and cohesion 10 kPa, friction 30°, dilation 0, tension 5 kPa. Both cubes (not the
jointed one) start from the in-situ stress σxx = -10, σyy = -40, σzz = -80 kPa, beyond that strength, so
every Mohr-Coulomb zone yields at the first step and the plastic return runs, not only the yield
test: the worst case for the Mohr-Coulomb cycle (the count of zones that have yielded is printed).
The Mohr-Coulomb rate is also printed as a ratio to the elastic one when both are asked for
(issue 11 target: MC at least half the elastic zone-cycles/s). ``mohr-coulomb-strong``: the same
with cohesion and tension 1 GPa, so no zone yields (the Mohr-Coulomb cycle of zones in their
elastic range: yield test, no return). ``hoek-brown`` (mb 1, s 0.001, a 0.5, σci 100 kPa) and
``strain-softening`` (the Mohr-Coulomb strength with the cohesion softening from 10 to 2 kPa over
κs = 0.01) yield under the same in-situ stress; their time per zone-cycle is printed as a ratio to
Mohr-Coulomb's (issue 26 target: at most 2).

``--jointed``: the cube cut by three orthogonal joint sets (spacing 0.25 m) into 64 blocks, each
zoned, Coulomb joints (kn = ks = 1e11 Pa/m, friction 30°) between them (contacts between
deformable blocks: a sub-contact at every surface gridpoint of both blocks on each joint), under
gravity and 1 MPa on the top face, rollers on the sides and base. Also printed: the sub-contacts
and sub-contact updates/s (sub-contacts × timed steps / wall time).

``--threads N`` calls numba.set_num_threads(N) in each run (dec3d has no `model configure
threads` command; numba's own count is the default).  The edge length for N zones is
(5.08 / N)^(1/3) m, from the mesher's measured density (bench/zone_mesh_bench.py: 0.037 m gives
about 1e5 zones, 0.0172 m about 1e6).
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time

WARMUP = 3
#: zones per m³ of a unit cube at edge length L is about ZONE_DENSITY / L³ (measured)
ZONE_DENSITY = 5.08


def edge_length(zones: float) -> float:
    """Edge length [m] giving about ``zones`` tetrahedra in a unit cube."""
    return (ZONE_DENSITY / zones) ** (1.0 / 3.0)


#: Mohr-Coulomb strength: with the in-situ stress below (σ3 = -10 kPa, σ2 = -40 kPa, σ1 = -80 kPa;
#: strength σ1 = σ3 Nφ + 2c √Nφ = 64.6 kPa) every zone starts beyond the yield surface and flows.
#: Three distinct principal stresses: the return is the single-plane (shear) one; with σ2 = σ3
#: (a triaxial compression edge) every zone would take the slower two-plane edge return instead
MOHR = "block zone property cohesion 1e4 friction 30 dilation 0 tension 5e3"
INSITU = "block insitu stress -1e4 -4e4 -8e4 0 0 0"
#: Mohr-Coulomb zones far from yield (``--cmodel mohr-coulomb-strong``): the yield test only
MOHR_STRONG = "block zone property cohesion 1e9 friction 30 dilation 0 tension 1e9"
#: Hoek-Brown zones that yield under the same in-situ stress (strength at σ3 = 10 kPa:
#: 10 kPa + σci (mb σ3/σci + s)^a = 41.8 kPa < 80 kPa), each return a few tangent iterations
HOEK = "block zone property constant-mb 1 constant-s 0.001 constant-a 0.5 constant-sci 1e5"
#: strain-softening zones: Mohr-Coulomb above with the cohesion softening along a table of κs
SOFT = "table 'zb-coh' add (0,1e4) (0.01,2e3)\n" + MOHR + " table-cohesion 'zb-coh'"
_STRENGTH = {"mohr-coulomb": MOHR, "mohr-coulomb-strong": MOHR_STRONG, "hoek-brown": HOEK,
             "strain-softening": SOFT}
#: the model each --cmodel choice assigns
_MODEL = {"elastic": "elastic", "mohr-coulomb": "mohr-coulomb", "mohr-coulomb-strong": "mohr-coulomb",
          "hoek-brown": "hoek-brown", "strain-softening": "strain-softening"}


def _cmodel_lines(cmodel: str) -> list:
    """The `cmodel assign` and strength lines of a --cmodel choice (elastic constants apart)."""
    return [f"block zone cmodel assign {_MODEL[cmodel]}"]


def deck(length: float, cmodel: str = "elastic") -> str:
    return "\n".join([
        "model new",
        "block create brick 0 1 0 1 0 1",
        f"block zone generate edgelength {length:.6g}",
        *_cmodel_lines(cmodel),
        "block zone property young 10e9 poisson 0.25 density 2500",
        *([_STRENGTH[cmodel]] if cmodel in _STRENGTH else []),
        INSITU,
        "model gravity 0 0 -10",
        "block gridpoint apply velocity 0 0 0 range position-z 0",
    ]) + "\n"


def deck_jointed(length: float, cmodel: str = "elastic") -> str:
    """The unit cube in 4 × 4 × 4 blocks (three joint sets), each zoned at ``length``, jointed."""
    return "\n".join([
        "model new",
        "block create brick 0 1 0 1 0 1",
        "block cut joint-set dip 90 dip-direction 90 origin 0.25 0 0 spacing 0.25 number 3",
        "block cut joint-set dip 90 dip-direction 0 origin 0 0.25 0 spacing 0.25 number 3",
        "block cut joint-set dip 0 dip-direction 0 origin 0 0 0.25 spacing 0.25 number 3",
        f"block zone generate edgelength {length:.6g}",
        *_cmodel_lines(cmodel),
        "block zone property young 10e9 poisson 0.25 density 2500",
        *([_STRENGTH[cmodel]] if cmodel in _STRENGTH else []),
        "block contact jmodel assign mohr",
        "block contact material-table default property stiffness-normal 1e11 stiffness-shear 1e11 friction 30",
        "model gravity 0 0 -10",
        "block gridpoint apply velocity-z 0 range position-z 0",
        "block gridpoint apply velocity-x 0 range position-x 0",
        "block gridpoint apply velocity-x 0 range position-x 1",
        "block gridpoint apply velocity-y 0 range position-y 0",
        "block gridpoint apply velocity-y 0 range position-y 1",
        "block face apply stress-zz -1e6 range position-z 1",
    ]) + "\n"


def _rss_bytes() -> int:
    with open("/proc/self/status", encoding="utf-8") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) * 1024
    return 0


def _store_bytes(store) -> int:
    """Bytes of the live rows of every field of a ``dec3d.model.store.Store``."""
    return int(sum(store.live(k).nbytes for k in store.fields))


def _stepper_bytes(model) -> int:
    """Bytes of the numpy arrays held by the engine's zone stepper (0 when there is none)."""
    import numpy as np

    eng = getattr(model, "rigid_engine", None)
    zst = getattr(eng, "_zstep", None) if eng is not None else None
    if zst is None:
        return 0
    seen: dict[int, int] = {}

    def walk(x, depth=0):
        if isinstance(x, np.ndarray):
            seen[id(x)] = x.nbytes          # (an array held twice counts once)
        elif isinstance(x, (tuple, list)):
            for y in x:
                walk(y, depth)
        elif depth == 0 and hasattr(x, "__dict__") and type(x).__module__.startswith("dec3d.kernels"):
            for y in vars(x).values():      # plans of the kernels the stepper holds (``ElasticPlan``)
                walk(y, 1)

    for v in vars(zst).values():
        walk(v)
    return int(sum(seen.values()))


def one(zones: float, steps: int, threads: int | None = None, jointed: bool = False,
        cmodel: str = "elastic") -> dict:
    """Build, warm up and time in this process."""
    import io
    import tempfile

    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    if os.path.isdir(os.path.join(root, "dec3d")) and root not in sys.path:
        sys.path.insert(0, root)       # the checkout's dec3d (also when it is not installed)
    import numba

    if threads:
        numba.set_num_threads(threads)
    import dec3d

    with tempfile.TemporaryDirectory() as d:
        # compile the kernels on a tiny cube first, so the RSS growth is the model's
        scene = deck_jointed if jointed else deck
        w = dec3d.Session(out_dir=d, stdout=io.StringIO())
        w.command(scene(0.5, cmodel))
        w.command(f"model cycle {WARMUP}")
        del w
        s = dec3d.Session(out_dir=d, stdout=io.StringIO())
        rss0 = _rss_bytes()
        t0 = time.perf_counter()
        s.command(scene(edge_length(zones), cmodel))
        t1 = time.perf_counter()
        s.command(f"model cycle {WARMUP}")
        t2 = time.perf_counter()
        c2 = time.process_time()
        s.command(f"model cycle {steps}")
        t3 = time.perf_counter()
        c3 = time.process_time()
        rss1 = _rss_bytes()
        m = s.model
        nz = m.store("zones").n
        yielded = int((m.store("zones")["state"][:nz] != 0).sum())
        out = dict(cmodel=cmodel, yielded=yielded, threads=numba.get_num_threads(), zones=nz, gridpoints=m.vertices.n,
                   zoning_s=t1 - t0, warmup_s=t2 - t1, seconds=t3 - t2, cpu_s=c3 - c2,
                   zones_b=_store_bytes(m.store("zones")), gp_b=_store_bytes(m.vertices),
                   stepper_b=_stepper_bytes(m), rss_growth_b=rss1 - rss0, blocks=m.blocks.n,
                   subcontacts=m.store("subcontacts").n if "subcontacts" in m.stores else 0,
                   contacts_b=sum(_store_bytes(m.store(k)) for k in ("contacts", "subcontacts") if k in m.stores))
    return out


def loadavg() -> str:
    try:
        with open("/proc/loadavg", encoding="utf-8") as f:
            return f.read().strip()
    except OSError:
        return "n/a"


def _row(args, th: int, n: float, cm: str, run_children) -> float:
    """Time one size, thread count and constitutive model in fresh processes; print its line and
    return its zone-cycles/s."""
    runs = run_children([sys.executable, os.path.abspath(__file__), "--child", str(n),
                         "--steps", str(args.steps), "--child-threads", str(th), "--cmodel", cm]
                        + (["--jointed"] if args.jointed else []),
                        args.repeat, f"zones = {n:g}, {cm}")
    sec = [r["seconds"] for r in runs]
    t = statistics.median(sec)
    r0 = runs[0]
    nz = r0["zones"]
    rate = nz * args.steps / t if t > 0 else float("inf")
    zb, gb, sb = r0["zones_b"] / nz, r0["gp_b"] / nz, r0["stepper_b"] / nz
    rss = statistics.median(r["rss_growth_b"] for r in runs) / nz
    print(f"{r0['threads']:>7} {nz:>8} {r0['gridpoints']:>8} "
          f"{statistics.median(r['zoning_s'] for r in runs):>8.2f} {t:>8.3f} "
          f"{min(sec):>7.3f}..{max(sec):<7.3f} {rate:>11.4g} {zb:>9.0f} {gb:>7.0f} {sb:>8.0f} "
          f"{zb + gb + sb:>9.0f} {rss:>8.0f} {statistics.median(r['cpu_s'] for r in runs):>7.3f} "
          f"{cm:>19} {r0['yielded']:>8}"
          + (f" {r0['subcontacts']:>8} {r0['subcontacts'] * args.steps / t:>10.4g} "
             f"{r0['contacts_b'] / nz:>8.0f}" if args.jointed else ""), flush=True)
    return rate


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--zones", type=float, nargs="+", default=[1e4, 1e5, 1e6], help="zone counts (about)")
    ap.add_argument("--steps", type=int, default=50, help="timed steps S")
    ap.add_argument("--repeat", type=int, default=3, help="runs per size (median printed)")
    ap.add_argument("--threads", type=int, nargs="+", default=[0],
                    help="numba thread counts to run (numba.set_num_threads); 0: numba's own")
    ap.add_argument("--jointed", action="store_true", help="the cube in 64 jointed zoned blocks")
    ap.add_argument("--cmodel", nargs="+", default=["elastic"],
                    choices=list(_MODEL),
                    help="constitutive models to time back to back (default elastic)")
    ap.add_argument("--child", type=float, help=argparse.SUPPRESS)
    ap.add_argument("--child-threads", type=int, default=0, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        print(json.dumps(one(args.child, args.steps, args.child_threads or None, args.jointed, args.cmodel[0])))
        return 0
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from rigid_bench import machine, run_children

    print(f"machine: {machine()}")
    print(f"loadavg before: {loadavg()}")
    what = ("unit cube in 64 jointed zoned blocks (Coulomb joints), gravity + 1 MPa on top, rollers"
            if args.jointed else "unit cube of 4-node tetrahedra under gravity, base held")
    print(f"scene: {what}; {WARMUP} warm-up + {args.steps} timed steps, median of {args.repeat}")
    print(f"{'threads':>7} {'zones':>8} {'gridpts':>8} {'zoning s':>8} {'seconds':>8} {'min..max':>15} "
          f"{'zone-cyc/s':>11} {'zones B/z':>9} {'gp B/z':>7} {'step B/z':>8} {'total B/z':>9} {'RSS B/z':>8} {'cpu s':>7}"
          + f" {'cmodel':>19} {'yielded':>8}"
          + (f" {'subcont':>8} {'sub-upd/s':>10} {'cont B/z':>8}" if args.jointed else ""))
    for th in args.threads:
        for n in args.zones:
            rates = {}
            for cm in args.cmodel:
                rates[cm] = _row(args, th, n, cm, run_children)
            for mc in ("mohr-coulomb", "mohr-coulomb-strong"):
                if "elastic" in rates and mc in rates:
                    print(f"MC / elastic zone-cycles/s: {rates[mc] / rates['elastic']:.2f} ({mc}; "
                          f"target >= 0.5); loadavg {loadavg()}", flush=True)
            for other in ("hoek-brown", "strain-softening"):
                if "mohr-coulomb" in rates and other in rates:
                    print(f"{other} / mohr-coulomb time per zone-cycle: {rates['mohr-coulomb'] / rates[other]:.2f} "
                          f"(target <= 2); loadavg {loadavg()}", flush=True)
    print(f"loadavg after: {loadavg()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
