"""Batch runs: one deck, many parameter values, one table (`dec3d batch`, ``dec3d.batch.run``).

    rows = dec3d.batch.run("wedge.dat", {"phi": [32, 33, 34]}, out="runs", workers=2)

Each run is a fresh ``Session`` whose ``parameters`` are the run's values: FISH variables before the deck
is bound (so `[phi]` and `@phi` bind), kept through `model new`, and a deck's own `[phi = …]` (its
default for `dec3d run`) does not replace them. Every run writes into its own folder
``<out>/run-0001-phi=32`` with ``result.json`` (its row) and ``output.txt`` (what it printed); a rerun
skips runs whose ``result.json`` holds the same values. The table (``results.csv``, and
``results.parquet`` with pyarrow) has one row per run in run order: the parameters, ``status`` (ok |
error), ``error`` (the dec3d message with file:line:column), ``wall_s``, the final value of every
history (``<name>.final``) and the figures the deck reported (``session.results``).

Runs go to a ``ProcessPoolExecutor`` (spawn) by default, or to a Dask cluster (``scheduler=
"tcp://host:port"`` or ``"local"``; ``pip install dec3d[dask]``): the deck and the files it calls or
reads (found by binding it) are sent with each task, written into a temporary folder on the worker
and run there; the row and the files written come back. Nothing relies on a shared file system.
"""
from __future__ import annotations

import csv
import io
import json
import math
import os
import re
import shutil
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from contextlib import redirect_stderr, redirect_stdout
from itertools import product
from pathlib import Path
from typing import Any, Callable, Iterable

#: columns every row has, in this order, before the parameters' and the results'
FIXED = ("run", "status", "error", "wall_s")
#: largest total size of the files one Dask run sends back (bytes); more stays on the worker
RETURN_MAX_BYTES = 256 * 2**20
#: seconds to wait for a Dask scheduler before giving up (no run has started by then)
CONNECT_TIMEOUT = 5.0
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
_INT = re.compile(r"[+-]?\d+\Z")


class BatchError(Exception):
    """Bad batch input (parameters, deck, scheduler): reported before any run starts."""


# ------------------------------------------------------------------ parameters
def parse_value(text: str) -> Any:
    """A `--param` value as the deck language reads it: whole number → int, number → float, else text
    (quotes removed)."""
    t = text.strip()
    if _INT.match(t):
        return int(t)
    try:
        v = float(t)
    except ValueError:
        v = None
    if v is not None and math.isfinite(v):
        return v
    if len(t) >= 2 and t[0] == t[-1] and t[0] in "'\"":
        t = t[1:-1]
    return t


def parse_param(text: str) -> tuple[str, list]:
    """``name=v1,v2,…`` → (name, [values])."""
    name, eq, values = text.partition("=")
    name = name.strip()
    if not eq or not values.strip():
        raise BatchError(f"--param {text!r}: write name=value1,value2,…")
    if not _NAME.match(name):
        raise BatchError(f"--param {text!r}: `{name}` is not a FISH variable name (letters, digits, _)")
    vals = [parse_value(v) for v in values.split(",")]
    if any(v == "" for v in vals):
        raise BatchError(f"--param {text!r}: an empty value")
    return name.lower(), vals


def combinations(params: dict[str, Iterable], mode: str = "grid") -> list[dict[str, Any]]:
    """The runs: every combination (``grid``, the first name varying slowest) or the values side by
    side (``zip``: every list the same length)."""
    if mode not in ("grid", "zip"):
        raise BatchError(f"mode {mode!r}: grid or zip")
    names = [str(n).lower() for n in params]
    if len(set(names)) != len(names):
        raise BatchError("a parameter is given twice")
    for n in names:
        if not _NAME.match(n):
            raise BatchError(f"`{n}` is not a FISH variable name (letters, digits, _)")
    lists = [list(v) if isinstance(v, (list, tuple, range)) else [v] for v in params.values()]
    if any(not v for v in lists):
        raise BatchError("a parameter has no values")
    for vals in lists:
        for v in vals:
            if isinstance(v, bool) or not isinstance(v, (int, float, str)) or (
                    isinstance(v, float) and not math.isfinite(v)):
                raise BatchError(f"parameter value {v!r}: a finite number or a text")
    if not names:
        return [{}]
    if mode == "zip":
        if len({len(v) for v in lists}) != 1:
            raise BatchError("--zip: every --param needs the same number of values "
                             f"({', '.join(f'{n}: {len(v)}' for n, v in zip(names, lists))})")
        return [dict(zip(names, vals)) for vals in zip(*lists)]
    return [dict(zip(names, vals)) for vals in product(*lists)]


def run_name(index: int, values: dict[str, Any]) -> str:
    """The run's folder name: ``run-0001-phi=33.5-c=0`` (characters unsafe in a file name → ``_``)."""
    parts = [f"run-{index:04d}"] + [f"{k}={_fmt(v)}" for k, v in values.items()]
    name = "-".join(parts)
    name = re.sub(r"[^A-Za-z0-9_.=+\-]", "_", name)
    return name[:120]


def _fmt(v) -> str:
    return repr(v) if isinstance(v, float) else str(v)


# ------------------------------------------------------------------ what the deck uses
def _deck_files(deck: Path, samples: list[dict[str, Any]]) -> tuple[list[Path], set[str]]:
    """Files the deck reads (itself, files it calls, literal input names) and the FISH names its lines
    use. Found by binding the deck with the runs' values, the first set that binds; a deck that binds
    with none gives just itself (each run then reports its binding error)."""
    from .commands.binder import CommandCall
    from .commands.values import InPath
    from .errors import Dec3dError
    from .lang.parser import parse_deck
    from .session import Enter, Session

    files = [deck]
    with tempfile.TemporaryDirectory() as tmp:
        items = []
        for sample in samples:
            s = Session(out_dir=tmp, parameters=sample, stdout=io.StringIO())
            try:
                items = s.load_file(deck)
                break
            except Dec3dError:
                continue
        for it in items:
            if isinstance(it, Enter):
                files.append(Path(it.path))
            elif isinstance(it, CommandCall):
                for p in it.command.positional + it.command.keywords:
                    value = it.args.get(p.key)
                    if isinstance(p.value, InPath) and isinstance(value, str):
                        try:
                            files.append(s.in_path(value, it.location, p.value.exts))
                        except Dec3dError:
                            pass
    names: set[str] = set()
    for f in files:
        try:
            text = f.read_bytes().decode("utf-8", errors="replace")
            parsed = parse_deck(text, str(f))
        except (OSError, Dec3dError):
            continue
        for line in parsed.lines:
            for tok in line.tokens:
                if tok.type == "ATNAME":
                    names.add(str(tok)[1:].lower())
                elif tok.type == "EXPR":
                    body = re.sub(r"'[^']*'|\"[^\"]*\"", " ", str(tok)[1:-1])
                    names.update(n.lower() for n in re.findall(r"[A-Za-z_][A-Za-z0-9_.]*", body))
    seen, unique = set(), []
    for f in files:
        r = f.resolve()
        if r not in seen and r.is_file():
            seen.add(r)
            unique.append(r)
    return unique, names


def unused_parameters(deck: str | Path, names: Iterable[str]) -> list[str]:
    """Parameter names no `[ … ]` or `@name` of the deck (or the files it calls) mentions."""
    deck = Path(deck)
    _, used = _deck_files(deck, [{n: 0 for n in names}])
    return [n for n in names if n.lower() not in used]


# ------------------------------------------------------------------ one run (in a worker)
def _history_finals(model) -> dict[str, float]:
    hs = getattr(model, "history_set", None)
    out = {}
    for h in (hs.items if hs is not None else []):
        vals = [v for v in h.values if isinstance(v, (int, float)) and math.isfinite(v)]
        out[f"{h.name}.final"] = float(vals[-1]) if vals else None
    return out


def run_one(deck: str, values: dict[str, Any], out_dir: str, timeout: float | None = None) -> dict[str, Any]:
    """Run ``deck`` with ``values`` into ``out_dir``; return the row (never raises for a bad deck).
    ``timeout``: seconds of wall time after which the run is stopped (status ``timeout``)."""
    from .errors import Dec3dError
    from .session import Session
    from .timelimit import time_limit

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    row: dict[str, Any] = {"status": "ok", "error": ""}
    t0 = time.perf_counter()
    session = None
    with open(out / "output.txt", "w", encoding="utf-8") as log, redirect_stdout(log), redirect_stderr(log):
        limit = None
        try:
            with time_limit(timeout) as limit:
                session = Session(out_dir=out, stdout=log, parameters=values)
                items = session.load_file(deck)
                session.run_items(items)
        except Dec3dError as exc:
            row.update(status="error", error=exc.format().splitlines()[0] + (f" ({exc.hint})" if exc.hint else ""))
            print(exc.format(), file=log)
        except KeyboardInterrupt:
            if limit is not None and limit.expired:
                step = session.model.step if session is not None else 0
                row.update(status="timeout", error=f"stopped at step {step} after {timeout:g} s (--timeout)")
                print(row["error"], file=log)
            else:
                row.update(status="error", error="interrupted")
        except Exception as exc:           # an engine bug must not stop the other runs
            row.update(status="error", error=f"internal error: {type(exc).__name__}: {exc}")
            import traceback

            traceback.print_exc(file=log)
        finally:
            if session is not None:
                session.close_log()
                session.files.finish([session.log_path])
    row["wall_s"] = time.perf_counter() - t0
    if session is not None:
        row.update(_history_finals(session.model))
        for k, v in session.results.items():
            row[str(k)] = float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else v
    for k, v in list(row.items()):
        if isinstance(v, float) and not math.isfinite(v):
            row[k] = None                  # no NaN or infinity in the table
    return row


def _run_local(task: dict) -> dict:
    """Process-pool task: run in the run's own folder."""
    return run_one(task["deck"], task["values"], task["out"], task.get("timeout"))


def _run_shipped(task: dict) -> dict:
    """Dask task: write the shipped files into a temporary folder, run there, send back the row and
    the files written (relative name → bytes)."""
    from .io.paths import DASK_MISSING, missing_hint

    # (a file a run names by an expression was not sent to this worker: the hint says so)
    with tempfile.TemporaryDirectory(prefix="dec3d-batch-") as tmp, missing_hint(DASK_MISSING):
        src = Path(tmp) / "deck"
        out = Path(tmp) / "out"
        for rel, data in task["files"].items():
            p = src / rel
            p.parent.mkdir(parents=True, exist_ok=True)
            p.write_bytes(data)
        row = run_one(str(src / task["deck_rel"]), task["values"], str(out), task.get("timeout"))
        if row.get("error"):
            # the message names the deck where the user has it, not the worker's temporary copy
            row["error"] = row["error"].replace(str(src) + os.sep, task["deck_dir"])
        files, total = {}, 0
        for p in sorted(out.rglob("*")):
            if p.is_file() and not p.is_symlink():
                size = p.stat().st_size
                if total + size > RETURN_MAX_BYTES:
                    row["error"] = (row["error"] + "; " if row["error"] else "") + \
                        f"output files over {RETURN_MAX_BYTES // 2**20} MiB were not sent back"
                    break
                total += size
                files[p.relative_to(out).as_posix()] = p.read_bytes()
        if row.get("error"):
            files["output.txt"] = files.get("output.txt", b"").replace((str(src) + os.sep).encode(),
                                                                        task["deck_dir"].encode())
        return {"row": row, "files": files}


# ------------------------------------------------------------------ the batch
def run(deck: str | Path, params: dict[str, Iterable], out: str | Path = "batch", *, mode: str = "grid",
        workers: int | None = None, scheduler: str | None = None, client=None, retries: int = 3,
        rerun_failed: bool = False, progress: bool | str | None = None,
        on_result: Callable[[dict], None] | None = None, warn: Callable[[str], None] | None = None,
        timeout: float | None = None):
    """Run ``deck`` once per combination of ``params`` ({name: [values]}); return the table (a pandas
    DataFrame when pandas is installed, else a list of dicts), also written to ``out/results.csv``.

    workers: processes of the local pool (default: the CPU count). scheduler: a Dask scheduler address
    (``tcp://host:port``) or ``"local"`` (a LocalCluster of ``workers`` processes); client: a Dask
    ``Client`` to use instead. retries: times Dask runs a failed task again (a run lost with its worker is
    rescheduled by Dask, up to its ``allowed-failures``). progress: a bar (True), a line per run (False),
    None: a bar on a terminal, "off": nothing. on_result(row): called as each run finishes, and
    ``results.csv`` is written again (a batch stopped half-way keeps its table). timeout: seconds a run
    may take (status ``timeout``).
    """
    deck = Path(deck)
    if not deck.is_file():
        raise BatchError(f"cannot read deck `{deck}`: no such file")
    runs = combinations(params, mode)
    names = list(runs[0])
    out = Path(out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise BatchError(f"the output folder '{out}' cannot be used: {exc.strerror or exc}") from None
    files, used = _deck_files(deck, runs)
    say = warn or (lambda m: print(f"warning: {m}", file=sys.stderr))
    for n in names:
        if n not in used:
            say(f"--param {n}: the deck does not use `{n}` (no [ … ] or @{n} mentions it); it changes nothing")

    rows: dict[int, dict] = {}
    todo = []
    for i, values in enumerate(runs, 1):
        rdir = out / run_name(i, values)
        prev = _read_result(rdir / "result.json", values)
        if prev is not None and (prev["status"] == "ok" or not rerun_failed):
            rows[i] = prev
        else:
            todo.append((i, values, rdir))

    client_own = cluster = None
    if todo and (scheduler is not None or client is not None):
        if client is None:
            client, cluster = _dask_client(scheduler, workers, out / DASK_SCRATCH)
            client_own = client

    def finish(i, values, rdir, row, shipped=None):
        full = {"run": rdir.name, **values, **row}
        if shipped:
            for rel, data in shipped.items():
                p = (rdir / rel).resolve()
                if rdir.resolve() in p.parents:
                    p.parent.mkdir(parents=True, exist_ok=True)
                    p.write_bytes(data)
        rdir.mkdir(parents=True, exist_ok=True)
        _write_json(rdir / "result.json", {"values": values, "row": full})
        rows[i] = full
        done = [rows[k] for k in sorted(rows)]
        _write_csv(out / "results.csv", done, _columns(done, names))     # the table so far
        if on_result is not None:
            on_result(full)
        return full

    bar = _Progress(len(runs), len(runs) - len(todo), progress)
    try:
        if todo and client is not None:
            base = deck.resolve().parent
            shipped = {}
            for f in files:
                try:
                    rel = f.relative_to(base)
                except ValueError:
                    continue                        # only files under the deck's folder are sent
                if f.is_file() and not f.is_symlink():
                    shipped[rel.as_posix()] = f.read_bytes()
            futures = {}
            for i, values, rdir in todo:
                task = {"files": shipped, "deck_rel": deck.resolve().relative_to(base).as_posix(),
                        # the folder as the user named it, so messages read as in a local run
                        "deck_dir": "" if str(deck.parent) == "." else str(deck.parent) + os.sep,
                        "values": values, "timeout": timeout}
                fut = client.submit(_run_shipped_task, task, retries=retries, pure=False,
                                    key=f"dec3d-batch-{os.getpid()}-{time.time_ns()}-{i}")
                futures[fut] = (i, values, rdir)
            from dask.distributed import as_completed as dask_completed

            for fut in dask_completed(list(futures)):
                i, values, rdir = futures[fut]
                try:
                    res = fut.result()
                    row, back = res["row"], res["files"]
                except Exception as exc:        # the task itself was lost too often
                    row, back = {"status": "error", "error": f"the run was lost: {type(exc).__name__}: {exc}",
                                 "wall_s": None}, None
                bar.done(finish(i, values, rdir, row, back))
        elif todo:
            import multiprocessing

            n = max(1, min(workers or os.cpu_count() or 1, len(todo)))
            with _one_thread_each(), \
                    ProcessPoolExecutor(max_workers=n, mp_context=multiprocessing.get_context("spawn")) as pool:
                futures = {pool.submit(_run_local, {"deck": str(deck), "values": values, "out": str(rdir),
                                                    "timeout": timeout}):
                           (i, values, rdir) for i, values, rdir in todo}
                for fut in as_completed(futures):
                    i, values, rdir = futures[fut]
                    try:
                        row = fut.result()
                    except Exception as exc:    # a worker process died (killed, out of memory)
                        row = {"status": "error", "error": f"the worker process died: {type(exc).__name__}: {exc}",
                               "wall_s": None}
                    bar.done(finish(i, values, rdir, row))
    finally:
        bar.close()
        if client_own is not None:
            _quiet_close(client_own, cluster)
            if cluster is not None:
                shutil.rmtree(out / DASK_SCRATCH, ignore_errors=True)

    table = [rows[i] for i in sorted(rows)]
    columns = _columns(table, names)
    _write_csv(out / "results.csv", table, columns)
    _write_parquet(out / "results.parquet", table, columns)
    try:
        import pandas as pd
    except ImportError:
        return [{c: r.get(c) for c in columns} for r in table]
    return pd.DataFrame([{c: r.get(c) for c in columns} for r in table], columns=columns)


#: thread-pool sizes of the numerical libraries, one per worker process (as Dask's nanny sets them): a
#: run is one thread of work, and BLAS threads spinning in every process of a pool steal the cores
_THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS")


class _one_thread_each:
    """Spawned pool workers inherit the environment: one library thread each unless the user set it."""

    def __enter__(self):
        self.saved = {k: os.environ.get(k) for k in _THREAD_VARS}
        for k, v in self.saved.items():
            if v is None:
                os.environ[k] = "1"

    def __exit__(self, *exc):
        for k, v in self.saved.items():
            if v is None:
                os.environ.pop(k, None)
        return False


def _run_shipped_task(task: dict) -> dict:
    return _run_shipped(task)


#: the scratch folder of the LocalCluster's workers, inside the batch's output folder (Dask's default is
#: the system's temporary folder: a batch writes nothing outside --out); removed when the batch ends
DASK_SCRATCH = ".dask-scratch"


def _dask_client(scheduler: str | None, workers: int | None, scratch: Path | None = None):
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise BatchError("Dask is not installed: pip install dec3d[dask] (or dask[distributed])") from None
    if scheduler in (None, "local"):
        import logging

        extra = {"local_directory": str(scratch)} if scratch is not None else {}
        cluster = LocalCluster(n_workers=workers or 2, threads_per_worker=1, processes=True,
                               dashboard_address=None, silence_logs=logging.CRITICAL, **extra)
        return Client(cluster), cluster
    if not re.match(r"^(tcp|tls|inproc|ucx)://", scheduler):
        raise BatchError(f"--scheduler {scheduler!r}: give an address such as tcp://host:8786, or --dask local")
    try:
        return Client(scheduler, timeout=CONNECT_TIMEOUT), None
    except (OSError, TimeoutError) as exc:
        raise BatchError(f"cannot reach the Dask scheduler at {scheduler} within {CONNECT_TIMEOUT:g} s "
                         f"({type(exc).__name__}); no run was started") from None


def _quiet_close(client, cluster) -> None:
    """Close a client (and the LocalCluster this batch started) without Dask's shutdown chatter."""
    import logging

    loggers = [logging.getLogger(n) for n in ("distributed", "tornado", "asyncio")]
    levels = [lg.level for lg in loggers]
    for lg in loggers:
        lg.setLevel(logging.CRITICAL)
    try:
        client.close()
        if cluster is not None:
            cluster.close()
    finally:
        for lg, lv in zip(loggers, levels):
            lg.setLevel(lv)


def _read_result(path: Path, values: dict) -> dict | None:
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(data, dict) or data.get("values") != values or not isinstance(data.get("row"), dict):
        return None
    row = data["row"]
    return row if row.get("status") in ("ok", "error") else None


def _replace(path: Path, data: bytes) -> None:
    """Write ``path`` whole or not at all (a killed batch never leaves half a result): a temporary file
    beside it replaces it in one step, and is removed on every other way out (Ctrl-C included)."""
    fd, tmp = tempfile.mkstemp(prefix=".dec3d-batch-", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        mask = os.umask(0)
        os.umask(mask)
        os.chmod(tmp, 0o666 & ~mask)          # mkstemp makes 0600: the mode an ordinary open gives
        os.replace(tmp, path)
        tmp = None
    finally:
        if tmp is not None:
            Path(tmp).unlink(missing_ok=True)


def _write_json(path: Path, data) -> None:
    _replace(path, json.dumps(data, indent=1, allow_nan=False).encode("utf-8"))


def _columns(table: list[dict], names: list[str]) -> list[str]:
    rest = sorted({k for r in table for k in r} - set(FIXED) - set(names))
    return ["run", *names, "status", "error", "wall_s", *rest]


def _cell(v) -> str:
    if v is None:
        return ""
    if isinstance(v, float):
        return repr(v)                        # shortest text that reads back to the same double
    return str(v)


def _write_csv(path: Path, table: list[dict], columns: list[str]) -> None:
    buf = io.StringIO(newline="")
    w = csv.writer(buf)
    w.writerow(columns)
    for r in table:
        w.writerow([_cell(r.get(c)) for c in columns])
    _replace(path, buf.getvalue().encode("utf-8"))


def _write_parquet(path: Path, table: list[dict], columns: list[str]) -> None:
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        return
    pq.write_table(pa.Table.from_pylist([{c: r.get(c) for c in columns} for r in table]), path)


def read_table(path: str | Path) -> list[dict]:
    """``results.csv`` back as rows (numbers as floats, empty cells as None)."""
    out = []
    with open(path, newline="", encoding="utf-8") as f:
        for r in csv.DictReader(f):
            row = {}
            for k, v in r.items():
                if v == "":
                    row[k] = None
                    continue
                try:
                    row[k] = float(v) if k not in ("run", "status", "error") else v
                except ValueError:
                    row[k] = v
            out.append(row)
    return out


class _Progress:
    """A rich bar on a terminal, else one line per finished run."""

    def __init__(self, total: int, done: int, bar: bool | None):
        self.total, self.count = total, done
        self.silent = bar == "off"
        if self.silent:
            bar = False
        elif bar is None:
            bar = sys.stderr.isatty()
        self.bar = None
        if bar:
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeElapsedColumn

            self.bar = Progress("[progress.description]{task.description}", BarColumn(), MofNCompleteColumn(),
                                TimeElapsedColumn(), transient=False)
            self.bar.start()
            self.task = self.bar.add_task("batch", total=total, completed=done)
        elif done and not self.silent:
            print(f"{done} of {total} runs already finished (skipped)", flush=True)

    def done(self, row: dict) -> None:
        self.count += 1
        if self.bar is not None:
            self.bar.update(self.task, advance=1, description=row["run"])
            return
        if self.silent:
            return
        wall = row.get("wall_s")
        t = f" in {wall:.2f} s" if isinstance(wall, float) else ""
        what = "ok" if row["status"] == "ok" else f"error: {row['error']}"
        print(f"[{self.count}/{self.total}] {row['run']}: {what}{t}", flush=True)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.stop()
