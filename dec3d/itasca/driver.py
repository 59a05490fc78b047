"""Running Python drivers: `dec3d run script.py`, and `program call 'x.py'` from a deck.

A driver runs as ``__main__`` with ``import itasca`` giving ``dec3d.itasca`` (``alias_itasca``), bound to
the run's model: the session `dec3d run` made with the output folder of decks (``--out``, default the
script's folder; files its commands write stay in it, docs/safety.md), relative names in commands read
from the script's folder, then the output folder. The script runs in its own folder (the working folder
while it runs, as 3DEC drivers expect for their own ``open()``/``np.loadtxt`` of sibling files).

A deck that calls a Python file is refused when it is read (nothing runs) unless the user passed
``--allow-python`` (``Session.allow_python``; ``dec3d.commands.program_cmds.python_call``): Python is code,
a deck is data, and a deck from elsewhere must not run code by being read. With it, the file runs when the
deck reaches the call (``_run_from_deck``, registered here), bound to the deck's model; an error in it
stops the deck at that `program call` line.
"""
from __future__ import annotations

import sys
import traceback
from pathlib import Path

from ._bind import ItascaError, Model

#: the modules `import itasca ...` finds (the top-level ``itasca`` shim package installs the same)
SUBMODULES = ("block", "block.contact", "block.subcontact", "block.face", "block.gridpoint", "block.zone",
              "blockarray", "contactarray", "gridpointarray", "zonearray", "fish", "structure")


def alias_itasca() -> None:
    """Make ``import itasca`` (and ``itasca.block``, ``from itasca import blockarray`` …) give dec3d's."""
    import importlib

    import dec3d.itasca as it

    sys.modules["itasca"] = it
    for name in SUBMODULES:
        mod = sys.modules.get(f"dec3d.itasca.{name}") or importlib.import_module(f"dec3d.itasca.{name}")
        sys.modules[f"itasca.{name}"] = mod
    sys.modules["itasca.structure.cable"] = it.structure.cable
    sys.modules["itasca.structure.node"] = it.structure.node
    sys.modules["itasca.structure.beam"] = it.structure.beam
    sys.modules["itasca.structure.dowel"] = it.structure.dowel


def model_of(session, base_dir: Path) -> Model:
    api = getattr(session, "itasca_model", None)
    if api is None:
        api = Model(session=session)
    api.base_dir = Path(base_dir)
    return api


def exec_script(api: Model, path: Path, argv: list[str] | None = None) -> None:
    """Run the Python file ``path`` as ``__main__`` (``runpy.run_path``: compiled first, so a syntax error
    stops it before anything runs) with ``dec3d.itasca`` bound to ``api``."""
    import os
    import runpy

    alias_itasca()
    from ._bind import DEFAULT_OUT

    old_argv, old_cwd, old_out = sys.argv, os.getcwd(), DEFAULT_OUT[0]
    sys.argv = [str(path), *(argv or [])]
    DEFAULT_OUT[0] = Path(api.session.out_dir).resolve()     # dec3d.Model()s the script makes write there
    os.chdir(path.resolve().parent)          # the script's own open()/os.path calls: beside it, as in 3DEC
    try:
        with api.bound():
            runpy.run_path(str(path.resolve()), run_name="__main__")
    finally:
        sys.argv, DEFAULT_OUT[0] = old_argv, old_out
        os.chdir(old_cwd)


def run_driver(session, path: Path) -> int:
    """`dec3d run script.py`: exit status 0 (done), 1 (stopped by an error), 2 (not valid Python)."""
    api = model_of(session, path.resolve().parent)
    try:
        if not path.is_file():
            print(f"error: cannot read the script '{path}': it is not a file", file=sys.stderr)
            return 2
        session.files.read(path, "the running script")
        try:
            exec_script(api, path)
        except SyntaxError as exc:
            print(f"{exc.filename}:{exc.lineno}:{exc.offset or 1}: error: {exc.msg}", file=sys.stderr)
            if exc.text:
                print(f"    {exc.text.rstrip()}", file=sys.stderr)
            print("nothing was run: fix the script and run it again", file=sys.stderr)
            return 2
        except ItascaError as exc:
            print(str(exc), file=sys.stderr)
            print("the script stopped at this command; the model holds the state before it", file=sys.stderr)
            return 1
        except SystemExit as exc:
            return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
        except KeyboardInterrupt:
            raise
        except Exception:
            _print_user_traceback(path)
            print("the script stopped with this error", file=sys.stderr)
            return 1
    finally:
        session.close_log()
        session.files.finish([session.log_path])
    for w in session.warnings:
        print(f"warning: {w}", file=sys.stderr)
    return 0


def _print_user_traceback(path: Path) -> None:
    """The traceback of the script's error without the frames of dec3d and of ``runpy`` (in every chained
    exception too: a callback's error shows the user's callback, then the script line that cycled)."""
    import runpy

    hidden = (str(Path(__file__).resolve().parent.parent), str(Path(runpy.__file__).resolve()))
    top = traceback.TracebackException(*sys.exc_info())
    te, seen = top, set()
    while te is not None and id(te) not in seen:
        seen.add(id(te))
        te.stack = traceback.StackSummary.from_list(
            [f for f in te.stack if not (f.filename.startswith("<frozen runpy")
                                         or str(Path(f.filename).resolve()).startswith(hidden))])
        te = te.__cause__ or te.__context__
    print("".join(top.format()), end="", file=sys.stderr)


# -------------------------------------------------------------------- `program call 'x.py'` in a deck

def _run_from_deck(session, path: Path, where) -> None:
    from ..errors import CommandError

    api = model_of(session, path.parent)
    try:
        exec_script(api, path)
    except ItascaError as exc:
        raise CommandError(f"the Python file `{path.name}` stopped: {exc}", where) from None
    except SyntaxError as exc:
        raise CommandError(f"`{path.name}` is not valid Python: line {exc.lineno}: {exc.msg}", where) from None
    except Exception as exc:
        tb = traceback.extract_tb(exc.__traceback__)
        at = next((f for f in reversed(tb) if f.filename == str(path.resolve())), None)
        line = f" (line {at.lineno}: {at.line})" if at is not None else ""
        raise CommandError(f"the Python file `{path.name}` raised {type(exc).__name__}: {exc}{line}", where) from exc


def _register() -> None:
    from ..commands.program_cmds import PYTHON_RUNNER

    PYTHON_RUNNER[0] = _run_from_deck


_register()
