"""Cold start on two cores: a second process compiles kernels while ``dec3d run`` compiles
the others, the two meeting in the middle.

On a cold kernel cache (``kcache.COLD``: first run after install or after an upgrade) the first
run of a rigid-block deck spends most of its time compiling, in the order it needs the kernels:
block geometry, detection (cell map, common plane, sub-contacts, gaps, carry-over), then the
cycle (joint law, motion, balance). ``start`` launches ``python -m dec3d.warmup``, which

1. runs the tiny models of ``STAGES`` with the kernels executed as plain Python (no
   compilation: numba's dispatcher hands back the Python function) and records each kernel
   called from Python with the numba types of its arguments, in the order of the first call;
2. compiles them in the reverse order (what the deck needs last first), each written to
   numba's on-disk cache, and stops at the first kernel it finds there already: the deck's
   process, compiling from the front, has got that far.

The deck's process looks in the cache before compiling each kernel, so it loads what the
warm-up has finished: each core compiles about half. Results do not depend on it: the same
kernels compile to the same code in either process. When the Python run of a stage fails,
the stages are run compiled, one after the other (the warm-up then only helps with the kernels
the deck needs after the deck's process has reached them).

``DEC3D_WARMUP=0`` turns it off (the test suite does, except the test of this module).
"""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile

#: the tiny models: (what it compiles, deck lines). The last is a deck's order of work in small
#: (build, solve, cycle): the compile order is the reverse of its calls, then those of the others
STAGES = (
    ("cycle", ["model new", "block create brick 0 1 0 1 0 1", "block property density 2000",
               "model gravity 0 0 -10", "model cycle 3"]),
    ("detection", ["model new", "block create brick 0 1 0 1 0 1", "block create brick 0 1 0 1 1 2",
                   "block property density 2000", "block contact property stiffness-normal 1e9 stiffness-shear 1e9",
                   "block fix range position-z 0 0.5", "model gravity 0 0 -10", "model solve cycles 3",
                   "model cycle 3"]),
)
#: the kernels recorded and compiled: those of this package
PACKAGE = "dec3d.kernels"


def wanted() -> bool:
    """A warm-up is worth starting: the kernel cache is cold, numba compiles, the user did not
    turn it off."""
    from . import kcache

    return kcache.COLD and os.environ.get("DEC3D_WARMUP", "1") != "0"


def start() -> subprocess.Popen | None:
    """Launch the warm-up process when ``wanted``; None otherwise (or when it cannot start)."""
    if not wanted():
        return None
    try:
        return subprocess.Popen([sys.executable, "-m", "dec3d.warmup"], stdin=subprocess.DEVNULL,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    except OSError:
        return None


def stop(proc: subprocess.Popen | None) -> None:
    """End the warm-up when the deck is done before it (nothing it writes is needed any more)."""
    if proc is None or proc.poll() is not None:
        return
    proc.terminate()
    try:
        proc.wait(timeout=5)
    except subprocess.TimeoutExpired:
        proc.kill()


def _run(lines: list[str], tmp: str) -> None:
    from .session import Session

    s = Session(out_dir=tmp, echo=False)
    for line in lines:
        s.command(line)


class _Recorder:
    """While active, a kernel of ``PACKAGE`` that has no compiled version for its arguments runs
    as plain Python instead of compiling; each call made from Python (not from inside another
    kernel) is kept once as (dispatcher, argument types) in ``calls``, in the order of first call.

    numba's dispatcher calls ``_compile_for_args`` when no compiled version fits and calls what
    it returns; here that is the Python function (wrapped to know the call depth)."""

    def __init__(self):
        self.calls: list = []
        self._seen: set = set()
        self._depth = 0

    def __enter__(self):
        from numba.core.dispatcher import Dispatcher

        self._orig = Dispatcher._compile_for_args
        rec = self

        def compile_for_args(disp, *args, **kws):
            if not (getattr(disp.py_func, "__module__", "") or "").startswith(PACKAGE):
                return rec._orig(disp, *args, **kws)
            if rec._depth == 0 and not kws:
                sig = tuple(disp.typeof_pyval(a) for a in args)
                if (id(disp), sig) not in rec._seen:
                    rec._seen.add((id(disp), sig))
                    rec.calls.append((disp, sig))

            def run(*a, **k):
                rec._depth += 1
                try:
                    return disp.py_func(*a, **k)
                finally:
                    rec._depth -= 1
            return run

        Dispatcher._compile_for_args = compile_for_args
        return self

    def __exit__(self, *exc):
        from numba.core.dispatcher import Dispatcher

        Dispatcher._compile_for_args = self._orig
        return False


def plan(recorded: list[list]) -> list:
    """Compile order from the calls recorded per stage: the last stage's in reverse, then the
    others' (not already listed), each stage in reverse."""
    order, seen = [], set()
    for calls in [recorded[-1]] + list(recorded[:-1]):
        for disp, sig in reversed(calls):
            if (id(disp), sig) not in seen:
                seen.add((id(disp), sig))
                order.append((disp, sig))
    return order


def compile_plan(order: list) -> int:
    """Compile (or load) each (dispatcher, types) in turn; stop at the first one loaded from the
    on-disk cache (the deck's process compiled it: it has done those before it too). Returns
    how many were taken from the front of ``order``."""
    for i, (disp, sig) in enumerate(order):
        hits = sum(disp.stats.cache_hits.values())
        disp.compile(sig)
        if sum(disp.stats.cache_hits.values()) > hits:
            return i
    return len(order)


def run_stages() -> list[str]:
    """Record the stages' kernels (Python run) and compile them as ``plan`` orders; returns the
    stages whose kernels are all in the cache. Falls back to running the stages compiled."""
    with tempfile.TemporaryDirectory(prefix="dec3d-warmup-") as tmp:
        try:
            recorded = []
            for _, lines in STAGES:
                with _Recorder() as rec:
                    _run(lines, tmp)
                recorded.append(rec.calls)
        except Exception:  # noqa: BLE001 - a kernel that does not run as Python: compile the stages
            for _, lines in STAGES:
                _run(lines, tmp)
            return [name for name, _ in STAGES]
    order = plan(recorded)
    done = {(id(d), sig) for d, sig in order[:compile_plan(order)]}
    return [name for (name, _), calls in zip(STAGES, recorded)
            if all((id(d), sig) in done for d, sig in calls)]


if __name__ == "__main__":
    print(" ".join(run_stages()))
