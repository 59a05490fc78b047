"""Every run can be stopped (issue 35, item 3): `dec3d run --max-seconds` stops a FISH loop that never
ends and a cycle that would take hours; `dec3d batch --timeout` records such a run as `timeout`, runs
the others, and writes results.csv as runs finish. Importing dec3d changes no process-wide setting."""
import csv
import os
import subprocess
import sys
import time

from conftest import ROOT

LOOP = ("model new\nfish define f\n  local i = 0\n  loop while true\n    i = i + 1\n  endloop\nend\n"
        "[f]\n")
CYCLE = ("model new\nblock create brick 0 1 0 1 -1 0\nblock create brick 0 1 0 1 0 1\nblock property density 2000\n"
         "block contact property stiffness-normal 1e9 stiffness-shear 1e9\nblock fix range position-z -1 0\n"
         "model gravity 0 0 -10\nmodel cycle 1000000000\n")


def _env():
    return {**os.environ, "PYTHONPATH": str(ROOT)}


def _run(tmp_path, text, *flags):
    deck = tmp_path / "d.dat"
    deck.write_text(text)
    t0 = time.monotonic()
    r = subprocess.run([sys.executable, "-m", "dec3d", "run", str(deck), "-q", *flags], capture_output=True,
                       text=True, env=_env(), cwd=tmp_path, timeout=600)
    return r, time.monotonic() - t0


def test_max_seconds_stops_a_fish_loop_that_never_ends(tmp_path):
    r, took = _run(tmp_path, LOOP, "--max-seconds", "3")
    assert r.returncode == 124, r.stderr
    assert "stopped at step 0: the run reached --max-seconds 3" in r.stderr
    assert "Traceback" not in r.stderr
    assert took < 3 + 60                 # the interpreter's start and the loop's own check; not hours


def test_max_seconds_stops_cycling_at_the_end_of_a_batch(tmp_path):
    r, _ = _run(tmp_path, CYCLE + "model save 'never'\n", "--max-seconds", "8")
    assert r.returncode == 124, r.stderr
    line = [ln for ln in r.stderr.splitlines() if "--max-seconds" in ln][0]
    step = int(line.split("stopped at step ")[1].split(":")[0])
    assert 0 < step < 1_000_000_000     # it cycled, and stopped long before the end
    assert not (tmp_path / "never.sav").exists()


def test_bad_limits_are_refused(tmp_path):
    for bad in ("0", "-1", "nan", "soon"):
        r, _ = _run(tmp_path, "model new\n", "--max-seconds", bad)
        assert r.returncode == 2 and "--max-seconds" in r.stderr and "Traceback" not in r.stderr


def test_batch_timeout_records_the_run_and_runs_the_others(tmp_path):
    deck = tmp_path / "b.dat"
    # [k] = 1 loops for ever; [k] = 0 finishes at once
    deck.write_text("model new\n[k = 0]\nfish define f\n  local i = 0\n  loop while k > 0\n    i = i + 1\n"
                    "  endloop\n  f = i\nend\n[r = f]\n")
    out = tmp_path / "out"
    res = subprocess.run([sys.executable, "-m", "dec3d", "batch", str(deck), "--param", "k=0,1", "--out", str(out),
                          "--workers", "1", "--timeout", "4"], capture_output=True, text=True, env=_env(),
                         cwd=tmp_path, timeout=900)
    assert res.returncode == 1, res.stderr          # a run did not finish: reported as failed
    rows = list(csv.DictReader(open(out / "results.csv")))
    status = {r["k"]: (r["status"], r["error"]) for r in rows}
    assert status["0"] == ("ok", "")
    assert status["1"][0] == "timeout" and "after 4 s (--timeout)" in status["1"][1]
    assert "Traceback" not in res.stderr


def test_importing_dec3d_changes_no_process_wide_setting():
    probe = ("import sys; before = sys.getrecursionlimit(); import dec3d, dec3d.fish, dec3d.session, dec3d.cli; "
             "print(before == sys.getrecursionlimit())")
    r = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, env=_env(), timeout=300)
    assert r.stdout.strip() == "True", r.stderr
