"""The `dec3d` command line: run (decks and Python drivers), translate, batch, repl, verify, ssdem, check, plot,
docs."""
from __future__ import annotations

import argparse
import os
import sys
import time as _time
from pathlib import Path

from . import __version__


def _run(args) -> int:
    from . import warmup
    from .timelimit import time_limit

    with time_limit(args.max_seconds) as limit:
        return _run_limited(args, limit, warmup)


def _summary(session, seconds: float) -> str:
    """The last line of `dec3d run`: wall time, the files written, the warnings to read."""
    out = Path(session.out_dir)
    names = []
    for p in sorted(session.files.created):
        try:
            names.append(str(p.relative_to(out.resolve())))
        except ValueError:
            names.append(str(p))
    shown = ", ".join(names[:6]) + (f" (+{len(names) - 6} more)" if len(names) > 6 else "")
    files = f"{len(names)} file{'s' if len(names) != 1 else ''} written in {out}" + (f": {shown}" if names else "")
    n = len(session.warnings)
    warn = f"; {n} warning{'s' if n != 1 else ''} (below)" if n else ""
    from .kcache import compile_seconds
    compiled = compile_seconds()
    kern = f" ({compiled:.0f} s of it compiling kernels, once)" if compiled >= 0.5 else ""
    return f"dec3d run: finished in {seconds:.1f} s{kern}; {files}{warn}"


def _run_limited(args, limit, warmup) -> int:
    session = None
    t0 = _time.perf_counter()
    helper = warmup.start()          # cold cache: half of the kernels compile on the other core
    try:
        from .errors import Dec3dError
        from .legacy_run import LegacySession
        from .session import Session

        deck = Path(args.deck)
        out = Path(args.out) if args.out else deck.resolve().parent
        try:
            out.mkdir(parents=True, exist_ok=True)
            if not os.access(out, os.W_OK | os.X_OK):
                raise PermissionError(13, "Permission denied")
        except OSError as exc:
            what = "is a file, not a folder" if out.exists() and not out.is_dir() else (exc.strerror or str(exc))
            print(f"error: the output folder '{out}' cannot be used: {what}", file=sys.stderr)
            return 2
        session = (Session if args.no_legacy else LegacySession)(   # legacy decks: translated in memory
            out_dir=out, echo=not args.quiet, allow_outside_paths=args.allow_outside_paths,
            allow_overwrite=args.allow_overwrite)
        session.trust_saves = args.trust_save
        session.skip_unsupported = args.skip_unsupported
        session.strict = args.strict
        session.allow_python = args.allow_python
        if args.allow_python or deck.suffix.lower() == ".py":
            from .itasca.driver import run_driver      # (and runs the Python files decks call)

            if deck.suffix.lower() == ".py":     # a Python driver, dec3d.itasca bound to this session
                return run_driver(session, deck)
        try:
            items = session.load_file(deck)          # parse and bind everything first
        except Dec3dError as exc:
            print(exc.format(), file=sys.stderr)
            print("nothing was run: fix the deck and run it again", file=sys.stderr)
            return 2
        try:
            session.run_items(items)
        except Dec3dError as exc:
            print(exc.format(), file=sys.stderr)
            print("the run stopped at this command; the model holds the state before it", file=sys.stderr)
            return 1
        finally:
            session.close_log()
            session.files.finish([session.log_path])     # the record of the files dec3d wrote (io/guard.py)
        print(_summary(session, _time.perf_counter() - t0), file=sys.stderr)
        for w in session.warnings:
            print(f"warning: {w}", file=sys.stderr)
        return 0
    except KeyboardInterrupt as exc:
        # Ctrl-C: the engine stops at the end of a batch (CycleInterrupted carries the step)
        step = getattr(exc, "step", None)
        if step is None:
            step = session.model.step if session is not None else 0
        if limit.expired:
            print(f"stopped at step {step}: the run reached --max-seconds {args.max_seconds:g}", file=sys.stderr)
            return 124
        print(f"interrupted at step {step}", file=sys.stderr)
        return 130
    finally:
        warmup.stop(helper)


def _seconds(text: str) -> float:
    """A time limit in seconds: a finite number > 0."""
    import math

    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected seconds, got {text!r}") from None
    if not (math.isfinite(v) and v > 0):
        raise argparse.ArgumentTypeError(f"expected a number of seconds > 0, got {text!r}")
    return v


def _batch(args) -> int:
    from .batch import BatchError, combinations, parse_param, run

    try:
        params = {}
        for text in args.param:
            name, values = parse_param(text)
            if name in params:
                raise BatchError(f"--param {name} is given twice")
            params[name] = values
        scheduler = "local" if args.dask == "local" else args.scheduler
        if args.dask not in (None, "local"):
            raise BatchError(f"--dask {args.dask!r}: only `local` (a LocalCluster); use --scheduler for a cluster")
        combinations(params, "zip" if args.zip else "grid")     # bad combinations stop here
        table = run(args.deck, params, args.out, mode="zip" if args.zip else "grid", workers=args.workers,
                    scheduler=scheduler, rerun_failed=args.rerun_failed, timeout=args.timeout)
    except BatchError as exc:
        print(f"error: {exc}", file=sys.stderr)
        print("nothing was run", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted: finished runs are kept; run the same command again to do the rest", file=sys.stderr)
        return 130
    rows = table.to_dict("records") if hasattr(table, "to_dict") else table
    failed = [r for r in rows if r["status"] != "ok"]
    print(f"{len(rows)} runs, {len(failed)} failed; table: {Path(args.out) / 'results.csv'}")
    return 1 if failed else 0


def _repl(args) -> int:
    from .repl import run_repl

    return run_repl(out_dir=args.out, history_file=args.history)


def _verify(args) -> int:
    from .verify import main as verify_main

    return verify_main(args.names, root=args.root)


def _plot(args) -> int:
    from .plot.cli import main as plot_main

    def restore(path):                  # a save: restored in a session of its own
        from .session import Session
        s = Session(out_dir=path.parent)
        s.command(f"model restore '{path.name}'")
        return s.model

    return plot_main(args, restore)


def _docs(args) -> int:
    from .docs import write_pages

    changed = write_pages(Path(args.dir))
    print(f"{len(changed)} page(s) written to {args.dir}")
    return 0


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv[:1] == ["ssdem"]:          # the slope solver has its own argument parser
        from .ssdem.cli import main as ssdem_main

        return ssdem_main(argv[1:])
    ap = argparse.ArgumentParser(prog="dec3d", description="3DEC-style distinct element program")
    ap.add_argument("--version", action="version", version=f"dec3d {__version__}")
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="run a deck, or a Python driver (script.py: `import itasca`, docs/python.md)")
    r.add_argument("deck")
    r.add_argument("--out", help="folder for outputs (default: the deck's folder)")
    r.add_argument("-q", "--quiet", action="store_true", help="do not echo commands")
    r.add_argument("--allow-outside-paths", action="store_true",
                   help="let the deck read and write files outside its folder and the output folder "
                        "(only for decks you trust; see docs/safety.md)")
    r.add_argument("--allow-overwrite", action="store_true",
                   help="let outputs replace existing files dec3d did not write (never the deck or another "
                        "file the run reads; see docs/safety.md)")
    r.add_argument("--max-seconds", type=_seconds, default=None, metavar="S",
                   help="stop the run after S seconds of wall time, as Ctrl-C would (exit status 124)")
    r.add_argument("--trust-save", action="store_true",
                   help="`model restore` installs the FISH functions and callbacks of every save it reads, "
                        "also of saves not made by you on this machine (only for saves you trust; docs/safety.md)")
    r.add_argument("--no-legacy", action="store_true",
                   help="refuse 3DEC 4/5 (legacy) decks instead of running their translation (docs/legacy.md)")
    r.add_argument("--skip-unsupported", action="store_true",
                   help="skip the lines dec3d does not implement yet (each is printed and warned about) "
                        "instead of stopping there")
    r.add_argument("--strict", action="store_true",
                   help="a range that selects nothing is an error (a warning otherwise)")
    r.add_argument("--allow-python", action="store_true",
                   help="let decks run Python files (`program call 'x.py'`); Python is code, decks are data "
                        "(docs/python.md)")
    r.set_defaults(fn=_run)
    t = sub.add_parser("translate", help="write the 3DEC 7+ equivalent of a 3DEC 4/5 (legacy) deck (docs/legacy.md)")
    t.add_argument("deck")
    t.add_argument("--out", help="file to write (default: standard output)")
    t.set_defaults(fn=lambda a: __import__("dec3d.legacy_run", fromlist=["translate_main"]).translate_main(a.deck, a.out))
    b = sub.add_parser("batch", help="run a deck for many parameter values (process pool or Dask) and "
                                     "collect one table")
    b.add_argument("deck")
    b.add_argument("--param", action="append", default=[], metavar="NAME=V1,V2,...",
                   help="a FISH variable of the deck and its values (repeat for more parameters)")
    mode = b.add_mutually_exclusive_group()
    mode.add_argument("--grid", action="store_true", help="every combination of the values (default)")
    mode.add_argument("--zip", action="store_true", help="the i-th value of every parameter together")
    where = b.add_mutually_exclusive_group()
    where.add_argument("--scheduler", help="address of a Dask scheduler (tcp://host:port); needs dec3d[dask]")
    where.add_argument("--dask", metavar="local", help="`local`: a Dask LocalCluster of --workers processes")
    b.add_argument("--workers", type=int, default=None, help="worker processes (default: the CPU count; "
                                                            "2 for --dask local)")
    b.add_argument("--out", required=True, help="folder for the runs' folders and results.csv")
    b.add_argument("--timeout", type=_seconds, default=None, metavar="S",
                   help="stop a run after S seconds of wall time; it is recorded with status `timeout`")
    b.add_argument("--rerun-failed", action="store_true", help="run again the runs that failed last time "
                                                              "(finished runs are always skipped)")
    b.set_defaults(fn=_batch)
    q = sub.add_parser("repl", help="interactive command prompt")
    q.add_argument("--out", help="folder for outputs (default: current folder)")
    q.add_argument("--history", help="history file (default: ~/.dec3d_history)")
    q.set_defaults(fn=_repl)
    v = sub.add_parser("verify", help="run the verification problems and print a pass/fail table")
    v.add_argument("names", nargs="*", help="problem folders to run (default: all)")
    v.add_argument("--root", default=None, help="verification folder (default: ./verification)")
    v.set_defaults(fn=_verify)
    sub.add_parser("ssdem", help="static Winkler-spring slope stability (dec3d ssdem -h)")
    c = sub.add_parser("check", help="say line by line what `dec3d run` would do with a deck and the files "
                                     "it calls (runs nothing; exit 1 if the run would stop, 2 if a deck "
                                     "cannot be read)")
    c.add_argument("decks", nargs="+")
    c.add_argument("-v", "--verbose", action="store_true", help="list every line with what happens to it")
    c.set_defaults(fn=lambda a: __import__("dec3d.check", fromlist=["main"]).main(a.decks, a.verbose))
    from .plot.cli import add_parser as add_plot
    add_plot(sub).set_defaults(fn=_plot)
    d = sub.add_parser("docs", help="write the command reference pages from the registry")
    d.add_argument("--dir", default="docs/commands")
    d.set_defaults(fn=_docs)
    args = ap.parse_args(argv)
    return args.fn(args)


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
