"""bench/rigid_bench.py runs on a tiny stack and prints its figures (no timing asserted)."""
import os
import subprocess
import sys

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
