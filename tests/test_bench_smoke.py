"""bench/rigid_bench.py runs on a tiny stack and prints its figures (no timing asserted)."""
import os
import subprocess
import sys

import numpy as np
import pytest

from conftest import ROOT


def test_rigid_bench_runs_and_prints_the_figures():
    out = subprocess.run([sys.executable, str(ROOT / "bench" / "rigid_bench.py"), "--n", "2", "--steps", "5",
                          "--repeat", "1"], capture_output=True, text=True, timeout=120, cwd=ROOT,
                         env={**os.environ, "PYTHONPATH": os.pathsep.join(    # this checkout's dec3d
                             [str(ROOT)] + [p for p in [os.environ.get("PYTHONPATH")] if p])})
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    assert lines[0].startswith("machine: ")
    head = next(ln for ln in lines if ln.split()[:2] == ["n", "blocks"])
    for word in ("contacts", "subcont", "seconds", "blk-cyc/s", "subc-upd/s", "peak MiB"):
        assert word in head
    row = lines[-1].split()
    assert row[:2] == ["2", "8"]
    float(row[6])                      # seconds
    assert float(row[8]) > 0           # block-cycles/s


def test_fish_bench_runs_and_prints_its_rate():
    out = subprocess.run([sys.executable, str(ROOT / "bench" / "fish_bench.py"), "--n", "2000", "--runs", "1"],
                         capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert out.returncode == 0, out.stderr
    assert out.stdout.startswith("FISH loop: 2000 passes x 5 statements") and "statements/s" in out.stdout


def test_rigid_bench_equilibrium_check_on_one_cube():
    """One 1 m cube (2600 kg) on the base: the check says no before cycling and yes when the
    base carries m g = 25 506 N within 0.1 % and the cube is at rest; --threads is accepted."""
    sys.path.insert(0, str(ROOT / "bench"))
    try:
        import rigid_bench as rb
    finally:
        sys.path.pop(0)
    r = rb.equilibrium(1, cap=5000)
    assert r["reached"] and r["steps"] < 5000
    assert r["reaction_error"] <= 1e-3 and r["max_speed"] < 1e-5
    import io
    import tempfile

    import dec3d
    with tempfile.TemporaryDirectory() as d:
        s = dec3d.Session(out_dir=d, stdout=io.StringIO())
        s.command(rb.deck(1, "mohr"))
        assert not rb.at_equilibrium(s)[0]          # no contact yet: reaction 0
        s.command(f"model cycle {r['steps']}")
        assert abs(rb.base_reaction(s) - 2600 * 9.81) <= 1e-3 * 2600 * 9.81


def test_zone_bench_runs_and_prints_its_figures():
    """bench/zone_bench.py on two tiny cubes, one thread: the header and one row per size with a
    positive zone-cycle rate and memory per zone (no timing asserted)."""
    out = subprocess.run([sys.executable, str(ROOT / "bench" / "zone_bench.py"), "--zones", "150", "1500",
                          "--steps", "3", "--repeat", "1", "--threads", "1"], capture_output=True, text=True,
                         timeout=300, cwd=ROOT,
                         env={**os.environ, "PYTHONPATH": os.pathsep.join(
                             [str(ROOT)] + [p for p in [os.environ.get("PYTHONPATH")] if p])})
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    assert lines[0].startswith("machine: ") and lines[1].startswith("loadavg before: ")
    assert lines[-1].startswith("loadavg after: ")
    head = next(i for i, ln in enumerate(lines) if ln.split()[:2] == ["threads", "zones"])
    for word in ("zone-cyc/s", "zones B/z", "total B/z", "RSS B/z"):
        assert word in lines[head]
    rows = [ln.split() for ln in lines[head + 1:-1]]
    assert len(rows) == 2 and [r[0] for r in rows] == ["1", "1"]
    small, large = int(rows[0][1]), int(rows[1][1])
    assert 0 < small < large                      # more zones asked, more zones made
    for r in rows:
        assert float(r[6]) > 0                    # zone-cycles/s
        # the zones store alone is more than the 4 gridpoint indices and the stress tensor
        assert float(r[7]) >= 4 * 8 + 6 * 8
        # total = zones store + gridpoints + stepper, within the rounding of the printed columns
        assert abs(float(r[10]) - float(r[7]) - float(r[8]) - float(r[9])) <= 1.5


def test_zone_bench_edge_length_gives_about_the_zones_asked():
    """The edge length formula against the mesher itself: within 25 % of the asked count."""
    sys.path.insert(0, str(ROOT / "bench"))
    try:
        import zone_bench as zb
    finally:
        sys.path.pop(0)
    import numpy as np

    from dec3d.geometry.zoning import mesh_convex
    v = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], float)
    loops = np.array([[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]).ravel()
    _pts, tets, _tris, _src = mesh_convex(v, np.arange(0, 25, 4), loops, zb.edge_length(2e4))
    assert abs(len(tets) / 2e4 - 1) < 0.25


def test_zone_bench_jointed_case_prints_its_subcontact_figures():
    """bench/zone_bench.py --jointed on a coarse 64-block cube, one thread: sub-contacts on the joints
    between the zoned blocks, a positive sub-contact update rate and contact memory per zone."""
    out = subprocess.run([sys.executable, str(ROOT / "bench" / "zone_bench.py"), "--zones", "1000", "--steps", "3",
                          "--repeat", "1", "--threads", "1", "--jointed"], capture_output=True, text=True,
                         timeout=300, cwd=ROOT,
                         env={**os.environ, "PYTHONPATH": os.pathsep.join(
                             [str(ROOT)] + [p for p in [os.environ.get("PYTHONPATH")] if p])})
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    assert "64 jointed zoned blocks" in lines[2]
    head = next(i for i, ln in enumerate(lines) if ln.split()[:2] == ["threads", "zones"])
    assert lines[head].split()[-4:] == ["subcont", "sub-upd/s", "cont", "B/z"]
    row = lines[head + 1].split()
    # every one of the 64 blocks has at least 4 zones; the 144 face-face joints have sub-contacts
    assert int(row[1]) >= 64 * 4 and int(row[-3]) >= 144 * 3
    assert float(row[-2]) > 0 and float(row[-1]) > 0


def test_rigid_bench_quake_case_on_a_tiny_wall():
    """`rigid_bench.py --quake` on a 3-brick, 2-course wall, one thread: the scene line and one row
    whose simulated time is the timed steps times the step, with a positive rate."""
    out = subprocess.run([sys.executable, str(ROOT / "bench" / "rigid_bench.py"), "--quake", "--nx", "3", "--nz", "2",
                          "--steps", "10", "--repeat", "1", "--threads-list", "1"],
                         capture_output=True, text=True, timeout=300, cwd=ROOT,
                         env={**os.environ, "PYTHONPATH": os.pathsep.join(
                             [str(ROOT)] + [p for p in [os.environ.get("PYTHONPATH")] if p])})
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    assert lines[0].startswith("machine: ") and "masonry wall 3 bricks x 2 courses" in lines[1]
    import re

    row = re.match(r"threads 1: blocks (\d+) contacts (\d+) dt (\S+) s .* simulated (\S+) s; "
                   r"sim s per wall s (\S+); load average", lines[2])
    assert row, lines[2]
    # base + 3 bricks + (2 full + 2 half) bricks
    assert int(row.group(1)) == 1 + 3 + 4 and int(row.group(2)) > 0
    dt = float(row.group(3))
    assert dt > 0 and float(row.group(4)) == pytest.approx(10 * dt, rel=1e-3)
    assert float(row.group(5)) > 0


def test_quake_record_is_a_drift_free_band_limited_ground_motion():
    """The synthetic record: same seed, same record; the peak acceleration is the one asked for
    (to the base-line correction); the velocity is the trapezoid integral of the acceleration and
    ends at rest; almost all the energy lies in the 0.5..10 Hz band."""
    sys.path.insert(0, str(ROOT / "bench"))
    try:
        import quake_bench as qb
    finally:
        sys.path.pop(0)
    t, a, v = qb.record(seed=7, duration=4.0, dt=0.01, pga=3.0)
    t2, a2, v2 = qb.record(seed=7, duration=4.0, dt=0.01, pga=3.0)
    assert np.array_equal(a, a2) and np.array_equal(v, v2)
    assert not np.array_equal(a, qb.record(seed=8)[1])
    assert len(t) == 401 and t[-1] == pytest.approx(4.0)
    assert np.abs(a).max() == pytest.approx(3.0, rel=0.05)
    # integral checked independently: v(t_k) = sum of trapezoids up to t_k
    acc = 0.0
    for k in range(1, len(t)):
        acc += 0.5 * (a[k] + a[k - 1]) * (t[k] - t[k - 1])
        assert v[k] == pytest.approx(acc, abs=1e-12)
    assert abs(v[-1]) < 1e-12 and v[0] == 0.0
    spec = np.abs(np.fft.rfft(a)) ** 2
    f = np.fft.rfftfreq(len(a), 0.01)
    assert spec[(f >= 0.3) & (f <= 12.0)].sum() > 0.95 * spec.sum()


def test_quake_base_follows_the_velocity_record():
    """The base block of the quake scene moves with the record: its x velocity after the steps is
    the table's velocity at the middle of the last step (the time-function rule of `block apply`)."""
    sys.path.insert(0, str(ROOT / "bench"))
    try:
        import quake_bench as qb
    finally:
        sys.path.pop(0)
    r = qb.one(3, 2, 500, 1)
    t, _, v = qb.record()
    assert r["finite"] and r["simulated"] == pytest.approx(500 * r["dt"], rel=1e-9)
    expected = np.interp(r["dyn_time"] - r["dt"] / 2, t, v)
    assert abs(expected) > 1e-6
    assert r["base_vx"] == pytest.approx(expected, rel=1e-6)


def test_zone_bench_mohr_coulomb_case_runs_beside_the_elastic_one():
    """bench/zone_bench.py --cmodel elastic mohr-coulomb on a tiny cube: one row per model, the
    Mohr-Coulomb cube has zones that yielded (its in-situ stress is beyond its strength), the elastic one none,
    and the ratio line is the quotient of the two printed rates (to its rounding)."""
    out = subprocess.run([sys.executable, str(ROOT / "bench" / "zone_bench.py"), "--zones", "1500",
                          "--steps", "3", "--repeat", "1", "--threads", "1", "--cmodel", "elastic", "mohr-coulomb"],
                         capture_output=True, text=True, timeout=300, cwd=ROOT,
                         env={**os.environ, "PYTHONPATH": os.pathsep.join(
                             [str(ROOT)] + [p for p in [os.environ.get("PYTHONPATH")] if p])})
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    head = next(i for i, ln in enumerate(lines) if ln.split()[:2] == ["threads", "zones"])
    assert lines[head].split()[-2:] == ["cmodel", "yielded"]
    el, mc = lines[head + 1].split(), lines[head + 2].split()
    assert el[-2] == "elastic" and mc[-2] == "mohr-coulomb" and el[1] == mc[1]
    assert int(el[-1]) == 0 and int(mc[-1]) > 0
    ratio = lines[head + 3]
    assert ratio.startswith("MC / elastic zone-cycles/s:") and "target >= 0.5" in ratio
    got = float(ratio.split(":")[1].split()[0])
    assert got == pytest.approx(float(mc[6]) / float(el[6]), abs=0.01 + 1e-3 * got)


def test_static_scenes_bench_reaches_the_static_answer_of_a_small_scene():
    """bench/static_scenes.py on the 0.1 m cube on a 1 m cube, default and Eq. 87 scaling: both
    converge, and the small cube's centroid ends where the joints' elastic closure puts it
    (z = 1.05 m less the two contacts' closures, ρ g h / kn each: well under 0.1 mm)."""
    sys.path.insert(0, str(ROOT / "bench"))
    try:
        import static_scenes as ss
    finally:
        sys.path.pop(0)
    for setup in ("default", "eq87"):
        r = ss.run("mix", setup, 1e-5)
        assert r["converged"] and 0 < r["steps"] < 20000
        assert r["z"][1] == pytest.approx(1.05, abs=1e-4) and r["z"][0] == pytest.approx(0.5, abs=1e-4)


def test_joint_law_bench_runs_every_model_and_prints_its_cost():
    """bench/joint_law_bench.py on a few sub-contacts: one row per joint model, mohr's ratio 1."""
    from dec3d.physics.jmodels import JOINT_MODELS

    out = subprocess.run([sys.executable, str(ROOT / "bench" / "joint_law_bench.py"), "--n", "50", "--steps", "20",
                          "--repeat", "1"], capture_output=True, text=True, timeout=600, cwd=ROOT,
                         env={**os.environ, "PYTHONPATH": os.pathsep.join(
                             [str(ROOT)] + [p for p in [os.environ.get("PYTHONPATH")] if p])})
    assert out.returncode == 0, out.stderr
    rows = {ln.split()[0]: ln.split()[1:] for ln in out.stdout.splitlines()[1:]}
    assert set(rows) == set(JOINT_MODELS)
    assert float(rows["mohr"][1]) == 1.0 and all(float(r[0]) > 0 for r in rows.values())


def test_fe_static_bench_runs_and_agrees_with_calculix_when_present():
    """bench/fe_static_bench.py on a 1x1x4 cantilever (explicit capped at about a second): a row per run
    with the tip deflection; when CalculiX (`ccx`) is on PATH its row too, the implicit tip within
    1e-6 of it (the same C3D20 mesh and loads)."""
    import shutil

    out = subprocess.run([sys.executable, str(ROOT / "bench" / "fe_static_bench.py"), "--mesh", "1x1x4",
                          "--clock", "0.02"], capture_output=True, text=True, timeout=300, cwd=ROOT,
                         env={**os.environ, "PYTHONPATH": os.pathsep.join(
                             [str(ROOT)] + [p for p in [os.environ.get("PYTHONPATH")] if p])})
    assert out.returncode == 0, out.stderr
    rows = {" ".join(ln.split()[2:4]): ln.split() for ln in out.stdout.splitlines()
            if ln.strip().startswith("1x1x4")}
    assert {"dec3d implicit", "dec3d explicit"} <= set(rows)
    imp = float(rows["dec3d implicit"][7])
    assert 0.3 < imp < 0.45 and "converged;" in " ".join(rows["dec3d implicit"])
    if shutil.which("ccx"):
        assert abs(imp - float(rows["CalculiX C3D20"][5])) < 1e-6 * imp


def test_water_bench_runs_and_prints_its_figures():
    out = subprocess.run([sys.executable, str(ROOT / "bench" / "water_bench.py")], capture_output=True, text=True,
                         timeout=300, cwd=ROOT, env={**os.environ, "PYTHONPATH": os.pathsep.join(
                             [str(ROOT)] + [p for p in [os.environ.get("PYTHONPATH")] if p])})
    assert out.returncode == 0, out.stderr
    assert "channel-updates/s" in out.stdout and "steady solve: 10000 knots" in out.stdout


@pytest.mark.parametrize("nmd", [False, True])
def test_zone_roofline_kernels_do_the_engines_arithmetic(nmd):
    """bench/zone_roofline.py's minimal kernels are a fair roofline only if they compute what the
    engine's zone step computes: from zero stress, one step of the same random velocities gives
    the same stresses and nodal forces (1e-9 of the largest), with and without nodal mixed
    discretization."""
    sys.path.insert(0, str(ROOT / "bench"))
    try:
        import zone_roofline as zr
    finally:
        sys.path.remove(str(ROOT / "bench"))
    from zone_step_run import Stepper
    pos, gp, prop = zr._mesh(300)
    nz, nv = len(gp), len(pos)
    vel = np.random.default_rng(3).normal(size=(nv, 3))
    K, G = np.ascontiguousarray(prop[:, 0]), np.ascontiguousarray(prop[:, 1])
    s_min, f_min = np.zeros((nz, 6)), np.zeros((nv, 3))
    if nmd:
        zr.minimal_nmd_step(pos, vel, gp, K, G, 1e-3, s_min, f_min, np.zeros(nv), np.zeros(nv), np.zeros((nz, 10)))
    else:
        zr.minimal_step(pos, vel, gp, K, G, 1e-3, s_min, f_min)
    st = Stepper(gp, np.arange(nz, dtype=np.int64), np.full(nz, -1, np.int64), np.ones(nz),
                 np.arange(nv, dtype=np.int64), nv, np.ones(nz, np.int8), prop)
    s_eng, f_eng = np.zeros((nz, 6)), np.zeros((nv, 3))
    st.step(pos, vel, s_eng, np.zeros(nz, np.int32), f_eng, np.zeros(nv), 1e-3, False, nmd)
    assert nz > 100 and np.abs(s_eng).max() > 0
    np.testing.assert_allclose(s_min, s_eng, rtol=0, atol=1e-9 * np.abs(s_eng).max())
    np.testing.assert_allclose(f_min, f_eng, rtol=0, atol=1e-9 * np.abs(f_eng).max())


def test_cycle_setup_bench_runs_and_prints_its_figures():
    """bench/cycle_setup_bench.py on a tiny cube (no timing asserted): the overhead line, the kept
    bytes of the stepper cache and the phases of one profiled command."""
    out = subprocess.run([sys.executable, str(ROOT / "bench" / "cycle_setup_bench.py"), "--zones", "300", "--k", "2"],
                         capture_output=True, text=True, timeout=300, cwd=ROOT,
                         env={**os.environ, "PYTHONPATH": os.pathsep.join(
                             [str(ROOT)] + [p for p in [os.environ.get("PYTHONPATH")] if p])})
    assert out.returncode == 0, out.stderr
    text = out.stdout
    assert text.startswith("machine: ") and "stepper cache: on" in text
    assert "overhead per command" in text and "kept copies of the stepper cache" in text
    for phase in ("snapshot (rollback copy)", "zone stepper set-up", "command total"):
        assert phase in text
