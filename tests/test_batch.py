"""`dec3d batch` / dec3d.batch.run: parameters, the wedge's sliding threshold, Dask, resuming, bad input."""
import math
import os
import signal
import socket

import pytest

from conftest import ROOT
from dec3d import batch
from dec3d.cli import main

WEDGE = ROOT / "examples" / "batch" / "wedge.dat"
PHI_CRIT = 33.357            # verification/R2_wedge/README.md: atan(1 / 1.5190)
ANGLES = [32.0, 32.5, 33.0, 33.5, 34.0, 34.5]
SLIDES = 0.1                 # m: a sliding wedge has moved decimetres to metres, a holding one millimetres
RESULTS = ("status", "error", "u.final", "v.final", "blocks_made")


def _rows(table):
    return table.to_dict("records") if hasattr(table, "to_dict") else table


def test_parameters_parse_and_combine():
    assert batch.parse_param("phi=30,30.5, 31") == ("phi", [30, 30.5, 31])
    assert batch.parse_param("Name='a',b") == ("name", ["a", "b"])
    assert batch.combinations({"a": [1, 2], "b": [3, 4]}) == [
        {"a": 1, "b": 3}, {"a": 1, "b": 4}, {"a": 2, "b": 3}, {"a": 2, "b": 4}]
    assert batch.combinations({"a": [1, 2], "b": [3, 4]}, "zip") == [{"a": 1, "b": 3}, {"a": 2, "b": 4}]
    with pytest.raises(batch.BatchError, match=r"--zip: every --param needs the same number of values \(a: 2, b: 1\)"):
        batch.combinations({"a": [1, 2], "b": [3]}, "zip")
    with pytest.raises(batch.BatchError, match="write name=value1,value2"):
        batch.parse_param("phi")
    with pytest.raises(batch.BatchError, match="`2x` is not a FISH variable name"):
        batch.parse_param("2x=1")
    assert batch.run_name(3, {"phi": 33.5, "s": "a/b"}) == "run-0003-phi=33.5-s=a_b"


def test_parameter_survives_model_new_and_overrides_the_decks_default(tmp_path):
    import io

    from dec3d.session import Session

    s = Session(out_dir=tmp_path, stdout=io.StringIO(), parameters={"phi": 31.5})
    s.run_items(s.load_text("[phi = 40.0]\nmodel new\n[x = phi * 2]\n"))
    assert s.variables["x"] == 63.0
    s2 = Session(out_dir=tmp_path, stdout=io.StringIO())
    s2.run_items(s2.load_text("[phi = 40.0]\n[x = phi * 2]\n"))
    assert s2.variables["x"] == 80.0


def _threshold(rows):
    slid = [r["phi"] for r in rows if r["u.final"] > SLIDES]
    held = [r["phi"] for r in rows if r["u.final"] <= SLIDES]
    assert slid and held and max(slid) < min(held), rows     # one threshold: below it every angle slides
    return 0.5 * (max(slid) + min(held))


@pytest.fixture(scope="module")
def pool_batch(tmp_path_factory):
    out = tmp_path_factory.mktemp("pool")
    warnings = []
    table = batch.run(WEDGE, {"phi": ANGLES + ["abc"]}, out, workers=2, progress=False, warn=warnings.append)
    return out, _rows(table), warnings


def test_wedge_threshold_within_half_a_degree(pool_batch):
    out, rows, warnings = pool_batch
    assert warnings == []
    good = [r for r in rows if r["status"] == "ok"]
    assert [r["phi"] for r in good] == ANGLES                      # run order, not finishing order
    assert abs(_threshold(good) - PHI_CRIT) <= 0.5
    for r in good:
        assert (out / r["run"] / "result.json").is_file() and (out / r["run"] / "output.txt").is_file()
        assert r["wall_s"] > 0 and r["error"] == ""
    # the table on disk says the same, bit for bit
    disk = batch.read_table(out / "results.csv")
    assert [d["u.final"] for d in disk] == [r["u.final"] for r in rows]


def test_a_value_that_does_not_bind_fails_only_its_run(pool_batch):
    out, rows, _ = pool_batch
    bad = rows[-1]
    assert bad["run"] == "run-0007-phi=abc" and bad["status"] == "error"
    assert bad["error"] == f"{WEDGE}:23:33: error: expected a number, got 'abc'"
    assert bad["u.final"] is None
    assert sum(r["status"] == "ok" for r in rows) == len(ANGLES)


def test_rerun_skips_finished_runs(pool_batch):
    out, rows, _ = pool_batch
    ran = []
    again = _rows(batch.run(WEDGE, {"phi": ANGLES + ["abc"]}, out, workers=2, progress=False,
                            on_result=ran.append))
    assert ran == [] and again == rows
    # one run's result removed: only that run is done again
    (out / rows[2]["run"] / "result.json").unlink()
    again = _rows(batch.run(WEDGE, {"phi": ANGLES + ["abc"]}, out, workers=2, progress=False,
                            on_result=ran.append))
    assert [r["run"] for r in ran] == [rows[2]["run"]]
    assert [r["u.final"] for r in again] == [r["u.final"] for r in rows]


def test_unused_parameter_is_a_warning(tmp_path, capsys):
    assert main(["batch", str(WEDGE), "--param", "phi=40", "--param", "spacing=1,2", "--zip",
                 "--out", str(tmp_path)]) == 2          # --zip with 1 and 2 values: refused before any run
    assert "every --param needs the same number of values (phi: 1, spacing: 2)" in capsys.readouterr().err
    assert not any(tmp_path.iterdir())
    assert batch.unused_parameters(WEDGE, ["phi", "ncycles", "spacing"]) == ["spacing"]


def test_unreachable_scheduler_is_an_error_before_any_run(tmp_path, capsys):
    pytest.importorskip("dask.distributed")
    with socket.socket() as s:           # a port nobody listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    code = main(["batch", str(WEDGE), "--param", "phi=33", "--scheduler", f"tcp://127.0.0.1:{port}",
                 "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2
    assert (f"error: cannot reach the Dask scheduler at tcp://127.0.0.1:{port} within 5 s (OSError); "
            "no run was started") in err
    assert not any(p.name.startswith("run-") for p in tmp_path.iterdir())


def test_dask_gives_the_same_table_and_survives_a_killed_worker(pool_batch, tmp_path):
    pytest.importorskip("dask.distributed")
    import logging

    from dask.distributed import Client, LocalCluster

    _, pool_rows, _ = pool_batch
    killed = []
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                      silence_logs=logging.CRITICAL) as cluster, Client(cluster) as client:
        pids = client.run(os.getpid)         # worker address -> its process id

        def kill_a_busy_worker(row):
            if killed:
                return
            busy = [w for w, keys in client.processing().items() if keys]
            if busy:                         # the process of a worker that is running a task dies
                os.kill(pids[busy[0]], signal.SIGKILL)
                killed.append(busy[0])

        rows = _rows(batch.run(WEDGE, {"phi": ANGLES + ["abc"]}, tmp_path, client=client, retries=3,
                               progress=False, on_result=kill_a_busy_worker))
    assert killed, "no worker was busy when the first run finished"
    assert [r["run"] for r in rows] == [r["run"] for r in pool_rows]
    for a, b in zip(rows, pool_rows):
        for c in RESULTS:
            assert a[c] == b[c] or (isinstance(a[c], float) and math.isnan(a[c]) and math.isnan(b[c])), (c, a, b)
    # the runs' files came back from the workers into the run folders
    assert all((tmp_path / r["run"] / "output.txt").is_file() for r in rows)


def test_cli_warns_of_a_parameter_the_deck_does_not_use(tmp_path, capsys):
    code = main(["batch", str(WEDGE), "--param", "phi=40", "--param", "ncycles=10", "--param", "spacing=1",
                 "--workers", "1", "--out", str(tmp_path)])
    cap = capsys.readouterr()
    assert code == 0
    assert ("warning: --param spacing: the deck does not use `spacing` (no [ … ] or @spacing mentions it); "
            "it changes nothing") in cap.err
    assert "1 runs, 0 failed" in cap.out
    rows = batch.read_table(tmp_path / "results.csv")
    assert rows[0]["run"] == "run-0001-phi=40-ncycles=10-spacing=1" and rows[0]["status"] == "ok"


def test_a_local_dask_cluster_keeps_its_scratch_inside_the_output_folder(tmp_path):
    """Issue 35: Dask's worker scratch went to the system's temporary folder, outside --out; it is
    out/.dask-scratch while the batch runs, removed at the end."""
    pytest.importorskip("dask.distributed")
    deck = tmp_path / "d.dat"
    deck.write_text("[r = 2 * a]\n")
    out = tmp_path / "out"
    seen = []
    rows = _rows(batch.run(deck, {"a": [1, 2]}, out, scheduler="local", workers=1, progress=False,
                           on_result=lambda row: seen.append(any((out / batch.DASK_SCRATCH).iterdir()))))
    assert [r["status"] for r in rows] == ["ok", "ok"] and seen == [True, True]
    assert not (out / batch.DASK_SCRATCH).exists()


def test_under_dask_a_file_named_by_an_expression_is_refused_with_the_reason(tmp_path):
    """Issue 35 item 4: a Dask worker gets the files the deck names literally; `program call [name]` names
    one only when the run gets there, so the worker does not have it: the row says why and what to do
    (the same deck runs on the process pool, where the worker reads the deck's folder)."""
    pytest.importorskip("dask.distributed")
    deck = tmp_path / "d.dat"
    deck.write_text("[name = 'sub' + string(a)]\nprogram call [name]\n")
    (tmp_path / "sub1.dat").write_text("model title 'from sub1'\n")
    rows = _rows(batch.run(deck, {"a": [1]}, tmp_path / "dask", scheduler="local", workers=1, progress=False))
    assert rows[0]["status"] == "error" and "no such file" in rows[0]["error"]
    assert "names literally" in rows[0]["error"] and "without --dask" in rows[0]["error"]
    local = _rows(batch.run(deck, {"a": [1]}, tmp_path / "pool", workers=1, progress=False))
    assert local[0]["status"] == "ok"
