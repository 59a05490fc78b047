"""Time to a static answer on a 20-node FE cantilever: dec3d's explicit `model solve` (capped),
dec3d's `model solve … implicit` and, when `ccx` is on PATH, CalculiX's direct solve of the same mesh.

    python bench/fe_static_bench.py [--mesh 2x2x20 4x4x40] [--nq 3] [--ratio 1e-6] [--clock 1] [--no-explicit]
    python bench/fe_static_bench.py --d3 [--ratio 1e-8]

The beam: 10 m long (x), 1 × 1 m section, E = 1 MPa, ν = 0.2, ρ = 2000 kg/m³ (no gravity), root
(x = 0) held in x, y, z; 100 N down at the tip shared equally by the master nodes of the top tip
edge (x = 10, z = 1: 2 ny + 1 nodes). Elements ny × nz × nx of (1/ny) × (1/nz) × (10/nx) m made by
`feblock generate` (an 80-element mesh is 2x2x20, a 640-element one 4x4x40). Integration 3 × 3 × 3
(`--nq 3`, CalculiX C3D20) or 2 × 2 × 2 with dec3d's hourglass control (`--nq 2`; CalculiX C3D20R has
no hourglass control, so the answers differ by more than rounding there). Beam theory WL³/(3EI) is
0.400 m (plus shear deflection, about 0.1 % here).

`--d3` times the zoned elastic-hole decks of verification/D3_elastic_hole_{tet,hex,ho} instead: each
deck's model lines, then its own `model cycle 2000`, an explicit `model solve ratio R` and `model solve
ratio R implicit` (fresh models), with the largest difference of the implicit gridpoint displacements
and zone stresses from the explicit solve's, relative to the largest value.

Each dec3d run is the `model solve` line of a fresh model in this process, after a warm-up solve of a
one-element beam (numba compilation is not counted); CPU s is ``time.process_time`` around that one
command (the model build is reported apart). The explicit solve is capped by `--clock` minutes
(`model solve ratio R clock C`). CalculiX runs one thread (OMP_NUM_THREADS=1); its CPU s is the child's
user + system time; the tip deflection is read from the .dat file (*NODE PRINT of U at the tip node).
"""
from __future__ import annotations

import argparse
import io
import os
import platform
import re
import resource
import shutil
import subprocess
import tempfile
import time

import numpy as np

from dec3d.session import Session

E, NU, RHO, L, LOAD = 1e6, 0.2, 2000.0, 10.0, 100.0
#: the sessions' output folder (removed at exit)
_OUT = tempfile.TemporaryDirectory(prefix="fe_static_")


def deck(nx, ny, nz, nq, how):
    dx, dy, dz = L / nx, 1.0 / ny, 1.0 / nz
    return (f"model new\nmodel configure feblock\nblock create brick 0 {L} 0 1 0 1\n"
            f"feblock generate {dx!r} {dy!r} {dz!r} integration {nq}\n"
            f"feblock change cmodel elastic young {E} poisson {NU} density {RHO}\n"
            "block gridpoint apply velocity 0 0 0 range position-x 0\n"
            f"block gridpoint apply force-z {-LOAD / (2 * ny + 1)!r} range position-x {L} position-z 1\n"
            "model large-strain off\n"), f"model solve {how}"


def tip(m):
    v = m.vertices
    r = np.flatnonzero(np.all(np.abs(v["pos"] - [L, 1.0, 1.0]) < 1e-9, axis=1))
    return -float(v["disp"][r[0], 2])


def dec3d_run(nx, ny, nz, nq, how):
    out = io.StringIO()
    s = Session(out_dir=_OUT.name, stdout=out)
    build, solve = deck(nx, ny, nz, nq, how)
    c0 = time.process_time()
    s.command(build)
    c1, w1 = time.process_time(), time.perf_counter()
    s.command(solve)
    c2, w2 = time.process_time(), time.perf_counter()
    text = out.getvalue()
    steps = int(re.search(r"; (\d+) steps", text).group(1))
    return {"build": c1 - c0, "cpu": c2 - c1, "wall": w2 - w1, "tip": tip(s.model), "steps": steps,
            "converged": "model solve: converged" in text, "model": s.model}


# CalculiX C3D20 node order (natural coordinates): corners of ζ = -1 then ζ = +1 counter-clockwise, the
# mid-edges of the bottom, of the top, then the vertical ones
_CORNERS = [(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1), (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)]
_EDGES = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)]
CCX_ORDER = _CORNERS + [tuple((np.add(_CORNERS[a], _CORNERS[b]) // 2).tolist()) for a, b in _EDGES]


def ccx_run(m, nq, ny, workdir):
    """Write the dec3d mesh of model ``m`` as a CalculiX deck, run ccx, return (cpu, tip)."""
    v, es = m.vertices, m.store("feblocks")
    pos = v["pos"]
    used = np.unique(es["nodes"][: es.n])
    num = {int(r): k + 1 for k, r in enumerate(used)}
    lines = ["*NODE"] + [f"{num[int(r)]}, " + ", ".join(repr(float(c)) for c in pos[r]) for r in used]
    lines.append(f"*ELEMENT, TYPE={'C3D20' if nq == 3 else 'C3D20R'}, ELSET=EALL")
    for e in range(es.n):
        nd = es["nodes"][e]
        x = pos[nd]
        c, h = 0.5 * (x.min(axis=0) + x.max(axis=0)), 0.5 * (x.max(axis=0) - x.min(axis=0))
        nat = {tuple(np.rint((x[a] - c) / h).astype(int).tolist()): int(nd[a]) for a in range(20)}
        ids = [num[nat[q]] for q in CCX_ORDER]
        # (continuation line after 15 entries, as the Abaqus format wants)
        lines.append(f"{e + 1}, " + ", ".join(map(str, ids[:15])) + ",")
        lines.append(", ".join(map(str, ids[15:])))
    root = [num[int(r)] for r in used if abs(pos[r, 0]) < 1e-9]
    edge = [num[int(r)] for r in used if abs(pos[r, 0] - L) < 1e-9 and abs(pos[r, 2] - 1.0) < 1e-9]
    assert len(edge) == 2 * ny + 1
    tipn = [num[int(r)] for r in used if np.all(np.abs(pos[r] - [L, 1.0, 1.0]) < 1e-9)][0]
    lines += ["*NSET, NSET=ROOT"] + [f"{k}," for k in root] + [f"*NSET, NSET=TIP\n{tipn},"]
    lines += ["*MATERIAL, NAME=M", "*ELASTIC", f"{E}, {NU}", "*SOLID SECTION, ELSET=EALL, MATERIAL=M",
              "*BOUNDARY", "ROOT, 1, 3", "*STEP", "*STATIC", "*CLOAD"]
    lines += [f"{k}, 3, {-LOAD / len(edge)!r}" for k in edge]
    lines += ["*NODE PRINT, NSET=TIP", "U", "*END STEP"]
    with open(os.path.join(workdir, "beam.inp"), "w") as f:
        f.write("\n".join(lines) + "\n")
    env = dict(os.environ, OMP_NUM_THREADS="1", CCX_NPROC_EQUATION_SOLVER="1")
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(["ccx", "-i", "beam"], cwd=workdir, env=env, check=True, stdout=subprocess.DEVNULL)
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    text = open(os.path.join(workdir, "beam.dat")).read()
    row = re.findall(rf"^\s*{tipn}\s+(\S+)\s+(\S+)\s+(\S+)\s*$", text, re.M)[-1]
    return cpu, -float(row[2])


def d3(ratio):
    from pathlib import Path

    root = Path(__file__).resolve().parent.parent / "verification"
    print(f"{'deck':>22} {'run':>34} {'CPU s':>8} {'steps':>7}  implicit vs explicit (disp, stress)")
    for name in ("D3_elastic_hole_tet", "D3_elastic_hole_hex", "D3_elastic_hole_ho"):
        src = (root / name / "deck.dat").read_text().replace("model cycle 2000", "")
        res = {}
        for how in ("model cycle 2000", f"model solve ratio {ratio}", f"model solve ratio {ratio} implicit"):
            out = io.StringIO()
            s = Session(out_dir=_OUT.name, stdout=out)
            s.command(src)
            c0 = time.process_time()
            s.command(how)
            cpu = time.process_time() - c0
            zs, v = s.model.store("zones"), s.model.vertices
            res[how] = (v["disp"][: v.n].copy(), zs["stress"][: zs.n].copy())
            cmp = ""
            if how.endswith("implicit"):
                ue, se = res[f"model solve ratio {ratio}"]
                cmp = (f"{np.abs(res[how][0] - ue).max() / np.abs(ue).max():.1e}, "
                       f"{np.abs(res[how][1] - se).max() / np.abs(se).max():.1e}")
            print(f"{name:>22} {how:>34} {cpu:8.3f} {s.model.step:7d}  {cmp}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--mesh", nargs="+", default=["2x2x20", "4x4x40"], help="ny x nz x nx elements")
    ap.add_argument("--nq", type=int, default=3, choices=(2, 3))
    ap.add_argument("--ratio", type=float, default=1e-6)
    ap.add_argument("--clock", type=float, default=1.0, help="cap of the explicit solve [min]")
    ap.add_argument("--no-explicit", action="store_true")
    ap.add_argument("--d3", action="store_true", help="the D3 zoned elastic-hole decks instead")
    a = ap.parse_args()
    print(f"# {platform.processor() or platform.machine()}, {os.cpu_count()} cores, load average "
          f"{os.getloadavg()[0]:.2f}; NUMBA_NUM_THREADS={os.environ.get('NUMBA_NUM_THREADS', 'default')}")
    if a.d3:
        d3(a.ratio)
        return
    dec3d_run(1, 1, 1, a.nq, f"ratio {a.ratio} implicit")              # warm-up (compilation)
    if not a.no_explicit:
        dec3d_run(1, 1, 1, a.nq, "cycles 20")
    ccx = shutil.which("ccx")
    print(f"{'mesh':>8} {'elements':>8} {'run':>18} {'CPU s':>8} {'wall s':>8} {'steps':>7} {'tip [m]':>10} "
          f"{'vs ccx':>8}  note")
    for spec in a.mesh:
        ny, nz, nx = (int(t) for t in spec.split("x"))
        ne = nx * ny * nz
        rows = []
        imp = dec3d_run(nx, ny, nz, a.nq, f"ratio {a.ratio} implicit")
        rows.append(("dec3d implicit", imp))
        if not a.no_explicit:
            rows.append(("dec3d explicit", dec3d_run(nx, ny, nz, a.nq, f"ratio {a.ratio} clock {a.clock}")))
        ref = None
        if ccx:
            with tempfile.TemporaryDirectory() as d:
                cpu, u = ccx_run(imp["model"], a.nq, ny, d)
            ref = (cpu, u)
        for name, r in rows:
            rel = f"{(r['tip'] - ref[1]) / ref[1]:+.1e}" if ref else "-"
            note = "converged" if r["converged"] else f"not converged (cap {a.clock:g} min)"
            print(f"{spec:>8} {ne:>8} {name:>18} {r['cpu']:8.3f} {r['wall']:8.3f} {r['steps']:7d} {r['tip']:10.6f} "
                  f"{rel:>8}  {note}; build {r['build']:.2f} CPU s")
        if ref:
            print(f"{spec:>8} {ne:>8} {'CalculiX ' + ('C3D20' if a.nq == 3 else 'C3D20R'):>18} {ref[0]:8.3f} "
                  f"{'':>8} {'':>7} {ref[1]:10.6f} {'':>8}  ccx, one thread")
            print(f"{'':>8} {'':>8} {'implicit / ccx CPU':>18} {imp['cpu'] / ref[0]:8.2f}")
        else:
            print("# ccx not on PATH: no CalculiX row (apt-get install calculix-ccx)")


if __name__ == "__main__":
    main()
