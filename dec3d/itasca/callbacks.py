"""Python callbacks during cycling (Itasca's ``itasca.set_callback`` / ``remove_callback``).

``set_callback(func, position)``: ``func`` (a function, or the name of one in the calling script's
globals, as Itasca takes it) is called with no arguments at every step while the model cycles, in order
of ``position``. As for FISH callbacks (``fish callback add``, dec3d.commands.fish_cmds): a negative
position runs before the step's forces (what it sets acts in that step), a position ≥ 0 after the step's
motion (it sees the state the step left). Callbacks belong to the ``dec3d.Model`` (they stay through
`model new` and `model restore`).

A callback that raises stops the cycling at once: ``CallbackError`` (naming the callback and the step)
with the user's exception chained, traceback included. As for every error while cycling, the model is
back at its state before the cycling command (``RigidEngine.cycle`` restores it), consistent and intact.
"""
from __future__ import annotations

import math
import sys
from typing import Callable

from ._bind import CallbackError, Model, current


def _user_frame():
    """The first frame outside dec3d.itasca (the user's code that called us)."""
    here = __file__.rsplit("/", 1)[0].rsplit("\\", 1)[0]
    f = sys._getframe(1)
    while f is not None and f.f_code.co_filename.startswith(here):
        f = f.f_back
    return f


def _resolve(func, registered=()) -> tuple[Callable, str]:
    """(function, name) of ``func``: a callable, or a name looked up in the registered callbacks, then in the
    calling code's locals and globals, then in ``__main__`` (Itasca passes callbacks by name)."""
    if callable(func):
        return func, getattr(func, "__name__", repr(func))
    if isinstance(func, str):
        for c in registered:
            if c[2] == func:
                return c[1], func
        f = _user_frame()
        scopes = (f.f_locals, f.f_globals) if f is not None else ()
        for scope in (*scopes, sys.modules["__main__"].__dict__):
            fn = scope.get(func)
            if callable(fn):
                return fn, func
        raise ValueError(f"there is no Python function named '{func}'")
    raise TypeError(f"a callback is a function (or its name), not a {type(func).__name__}")


def _position(position) -> float:
    try:
        p = float(position)
    except (TypeError, ValueError):
        raise TypeError(f"a callback position is a number, not {position!r}") from None
    if not math.isfinite(p):
        raise ValueError(f"a callback position is a finite number, not {position!r}")
    return p


def set_callback(func, position: float = 0.0, model: Model | None = None) -> None:
    """Call ``func()`` at every cycling step at ``position`` (< 0: before the step's forces; ≥ 0: after
    its motion). The same function at the same position twice is one callback."""
    api = model or current()
    fn, name = _resolve(func)
    p = _position(position)
    if any(c[1] is fn and c[0] == p for c in api.callbacks):
        return
    api.callbacks.append([p, fn, name])
    api.callbacks.sort(key=lambda c: c[0])          # stable: same position keeps the order given
    attach(api)


def remove_callback(func, position: float | None = None, model: Model | None = None) -> None:
    """Remove the callback ``func`` (at ``position``; every position when omitted). ValueError when it is
    not set."""
    api = model or current()
    fn, name = _resolve(func, api.callbacks)
    keep = [c for c in api.callbacks if not (c[1] is fn and (position is None or c[0] == _position(position)))]
    if len(keep) == len(api.callbacks):
        where = "" if position is None else f" at position {position}"
        raise ValueError(f"remove_callback: '{name}' is not a callback{where}")
    api.callbacks[:] = keep


def run(api: Model, before: bool, step: int) -> None:
    for p, fn, name in list(api.callbacks):
        if (p < 0) != before:
            continue
        api.in_callback += 1
        try:
            fn()
        except Exception as exc:
            raise CallbackError(f"Python callback '{name}' (position {p:g}) raised at step {step}: "
                                f"{type(exc).__name__}: {exc}; cycling stopped, the model is back at its state before "
                                "this cycling command") from exc
        finally:
            api.in_callback -= 1


class PyAfter:
    """Step hook of the rigid engine (after each step's motion): the callbacks at positions ≥ 0."""

    def __init__(self, api: Model):
        self.api = api

    @property
    def interval(self) -> int:
        return 1 if any(c[0] >= 0 for c in self.api.callbacks) else 0

    def __call__(self, eng) -> None:
        if self.api.callbacks:
            run(self.api, False, int(eng.step))


class PyBefore:
    """A step of the cycle, first in the step list: the callbacks at negative positions, before the
    step's forces; the engine's batch is one step long while there are any."""
    timing = "hooks"

    def __init__(self, api: Model, run_: object):
        self.api, self.run_ = api, run_

    def prepare(self) -> None:
        pass

    def advance(self, n: int) -> int:
        if not any(c[0] < 0 for c in self.api.callbacks):
            return n
        run(self.api, True, int(self.run_.m.step) + 1)
        return 1


class _MakeBefore:
    def __init__(self, api: Model):
        self.api = api

    def __call__(self, run_) -> PyBefore:
        return PyBefore(self.api, run_)


def attach(api: Model) -> None:
    """Give the model state's engine the hooks that call ``api``'s callbacks (once; when it has any)."""
    if not api.callbacks:
        return
    from ..physics.rigid import engine

    eng = engine(api.session.model)
    if not any(isinstance(h, PyAfter) and h.api is api for h in eng.step_hooks):
        eng.step_hooks.insert(0, PyAfter(api))
    if not any(isinstance(f, _MakeBefore) and f.api is api for f in eng.pre_steps):
        eng.pre_steps.append(_MakeBefore(api))
