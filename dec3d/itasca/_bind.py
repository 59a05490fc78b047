"""Models for Python drivers: ``dec3d.Model`` and the one ``dec3d.itasca`` is bound to.

Itasca's ``itasca`` module has one global model. dec3d keeps a *current* ``Model`` (made on first
use, or bound by ``it.bind(model)`` / ``with model.bound():``) so that several models can live in one
interpreter (a parameter study) while unmodified 3DEC scripts still see one global state.

A ``Model`` wraps a ``dec3d.session.Session`` (the model, its FISH state and the output-folder rules
of decks: files written stay in ``out_dir``; see docs/safety.md). The objects and arrays the API hands
out remember the model state they were taken from: after `model new` or `model restore` (which replace
that state) using one raises ``StaleError`` instead of reading old data.
"""
from __future__ import annotations

import sys
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterator


class ItascaError(RuntimeError):
    """A command run through ``it.command`` (or ``it.cycle``) failed; the message is dec3d's report
    (file:line:column of the command text, the line, a caret), after the Python line that ran it."""

    def __init__(self, message: str, report: str = ""):
        super().__init__(message)
        self.report = report


class StaleError(RuntimeError):
    """An object or array taken from a model state that is gone (`model new`, `model restore`) or from
    a store whose rows changed since (blocks made or deleted, contacts detected again)."""


class CallbackError(RuntimeError):
    """A Python callback raised while the model cycled: cycling stopped and the model is back at its state
    before the cycling command; the user's exception is chained (``__cause__``) with its traceback."""


def _caller() -> str:
    """file:line of the first frame outside dec3d (the user's script line), or ''."""
    f = sys._getframe(1)
    here = str(Path(__file__).resolve().parent.parent)
    while f is not None:
        name = f.f_code.co_filename
        if not name.startswith(here) and not name.startswith("<frozen"):
            return f"{name}:{f.f_lineno}"
        f = f.f_back
    return ""


class Model:
    """One dec3d model driven from Python (3DEC's Python API on it: ``dec3d.itasca``).

        m = dec3d.Model(out_dir="runs/a")
        m.command("block create brick 0 1 0 1 0 1")
        with m.bound():                 # dec3d.itasca functions act on m inside the block
            it.block.count()

    out_dir: the output folder (default: the working folder; inside `dec3d run script.py` the run's output
    folder, and a relative out_dir is taken from there); every file the model's commands write stays in it
    unless ``allow_outside_paths``. base_dir: the folder relative names in commands are read
    from first (default: the working folder; `dec3d run script.py`: the script's folder).
    allow_python: let decks this model runs call Python files (`program call 'x.py'`)."""

    def __init__(self, out_dir: str | Path | None = None, *, base_dir: str | Path | None = None,
                 echo: bool = False, allow_outside_paths: bool = False, allow_overwrite: bool = False,
                 allow_python: bool = False, session: Any = None):
        if session is None:
            from ..session import Session

            base = DEFAULT_OUT[0]
            if base is not None:        # inside `dec3d run script.py`: under the run's output folder
                out_dir = base if out_dir is None else Path(base) / out_dir

            session = Session(out_dir=out_dir, echo=echo, allow_outside_paths=allow_outside_paths,
                              allow_overwrite=allow_overwrite)
        self.session = session
        session.allow_python = bool(allow_python or getattr(session, "allow_python", False))
        if session.allow_python:
            from . import driver  # noqa: F401  (runs the Python files decks call)
        session.itasca_model = self
        self.base_dir = Path(base_dir) if base_dir is not None else Path.cwd()
        #: Python callbacks: [position, function, name] sorted by position (``it.set_callback``)
        self.callbacks: list[list] = []
        #: > 0 while a callback runs (commands that cycle or change the block set are refused then)
        self.in_callback = 0

    # ------------------------------------------------------------------ state
    @property
    def state(self):
        """The model state now (``dec3d.model.model.Model``; replaced by `model new`/`model restore`)."""
        return self.session.model

    def command(self, text: str) -> None:
        """Run 3DEC commands: one line or several (a triple-quoted block; `...`/`&` continuations as in
        decks). A failing command raises ``ItascaError`` with dec3d's report; the commands before it ran."""
        from ..errors import Dec3dError
        from .callbacks import attach

        if not isinstance(text, str):
            raise TypeError(f"command takes a string of 3DEC commands, not a {type(text).__name__}")
        s = self.session
        try:
            items = s.load_text(text, "<command>", self.base_dir)
            if self.in_callback:
                _refuse_in_callback(items)
            for chunk in _chunks(items):
                attach(self)
                s.run_items(chunk)
            attach(self)
        except Dec3dError as exc:
            at = _caller()
            _in_script(exc, text, at)
            report = exc.format()
            raise ItascaError(f"{at + ': ' if at else ''}it.command failed:\n{report}", report) from None

    def cycle(self, n: int) -> None:
        """Take ``n`` mechanical steps (`model cycle n`)."""
        import operator

        try:
            k = operator.index(n) if type(n) is not bool else -1      # ints and numpy integers
        except TypeError:
            k = -1
        if k < 0:
            raise ValueError(f"cycle takes a whole number of steps ≥ 0, not {n!r}")
        self.command(f"model cycle {k}")

    # ------------------------------------------------------------------ binding
    @contextmanager
    def bound(self) -> Iterator["Model"]:
        """``with model.bound():`` binds ``dec3d.itasca`` to this model inside the block (the model bound
        before comes back after it, also when the block raises)."""
        prev = _CURRENT[0]
        _CURRENT[0] = self
        try:
            yield self
        finally:
            _CURRENT[0] = prev

    def __repr__(self) -> str:
        st = self.session.model
        return f"<dec3d.Model: {st.blocks.n} blocks, step {st.step}, out_dir '{self.session.out_dir}'>"


def _in_script(exc, text: str, at: str) -> None:
    """When the failing command text is a string literal of the script line ``at`` (file:line) that ran it,
    point the error at the script: its file, the line and column inside the literal (a text built at run
    time keeps `<command>` and its own line numbers)."""
    import ast

    from ..errors import SourceLocation

    loc = exc.location
    if loc is None or loc.file != "<command>" or loc.stack or ":" not in at:
        return
    path, _, line = at.rpartition(":")
    try:
        src = Path(path).read_text(encoding="utf-8")
        tree = ast.parse(src)
    except (OSError, SyntaxError, ValueError):
        return
    for node in ast.walk(tree):
        if (isinstance(node, ast.Call) and node.args and isinstance(node.args[0], ast.Constant)
                and node.args[0].value == text and node.lineno <= int(line) <= (node.end_lineno or node.lineno)):
            lit = node.args[0]
            seg = ast.get_source_segment(src, lit) or ""
            body = seg.lstrip("rRuU")
            quote = 3 if body[:3] in ('"""', "'''") else 1
            start = lit.col_offset + (len(seg) - len(body)) + quote      # 0-based column of the text's first char
            col = loc.column + (start if loc.line == 1 else 0)
            n = lit.lineno + loc.line - 1
            lines = src.splitlines()
            shown = lines[n - 1] if n <= len(lines) else loc.text          # the caret sits under the script's line
            exc.location = SourceLocation(path, n, col, shown, loc.length, ())
            return


def _refuse_in_callback(items: list) -> None:
    """Inside a callback the engine's step loop is running on the block set it started with: the commands a
    FISH callback may not run (they cycle, replace the model or change its blocks) are refused here too."""
    from ..errors import CommandError
    from ..fish.sections import _cycle_bound

    for it in items:
        path = getattr(getattr(it, "command", None), "path", ())
        if path and _cycle_bound(path):
            raise CommandError(f"`{' '.join(path)}` cannot run in a Python callback: the cycle that calls it is "
                               "still going on (cycle again, or change the blocks, after it returns)", it.location)


def _chunks(items: list) -> list[list]:
    """Items split after every `model new` / `model restore` (the Python callbacks are attached again to
    the model state those make before the next command runs)."""
    out, cur = [], []
    for it in items:
        cur.append(it)
        path = getattr(getattr(it, "command", None), "path", ())
        if path[:1] == ("model",) and path[1:2] in (("new",), ("restore",)):
            out.append(cur)
            cur = []
    if cur:
        out.append(cur)
    return out


#: the output folder of the `dec3d run script.py` running now (None outside one): the folder new Models
#: write into by default, and the folder their relative ``out_dir`` is taken from
DEFAULT_OUT: list[Path | None] = [None]

#: the model ``dec3d.itasca`` acts on (None: one is made on first use)
_CURRENT: list[Model | None] = [None]


def current() -> Model:
    """The model ``dec3d.itasca`` acts on now; the first use makes one (output folder: the working
    folder), as Itasca's program has one model from the start."""
    m = _CURRENT[0]
    if m is None:
        m = _CURRENT[0] = Model()
    return m


def bind(model: Model | None) -> Model | None:
    """Make ``model`` the one ``dec3d.itasca`` acts on (None: a fresh one at the next use); returns the
    model bound before."""
    if model is not None and not isinstance(model, Model):
        raise TypeError(f"bind takes a dec3d.Model, not a {type(model).__name__}")
    prev, _CURRENT[0] = _CURRENT[0], model
    return prev


class Handle:
    """What every object of the API holds: its ``Model`` and the model state it was found in."""

    __slots__ = ("_api", "_state")

    def __init__(self, api: Model):
        self._api = api
        self._state = api.session.model

    def _model(self):
        st = self._api.session.model
        if st is not self._state:
            raise StaleError(f"{self!r} belongs to a model state that is gone (`model new` or `model restore` "
                             "ran since it was found); find it again")
        return st
