"""Cold start on two cores: a second process compiles the kernels of the cycle while
``dec3d run`` parses the deck, builds the blocks and compiles contact detection.

On a cold kernel cache (``kcache.COLD``: first run after install or after an upgrade) the first
run of a rigid-block deck spends most of its time compiling: detection (cell map, common
plane, sub-contacts) and then the cycle (joint law, motion, balance) — in that order, one after
the other, in one process. ``start`` launches ``python -m dec3d.warmup`` which runs two tiny
models of its own in a temporary folder: first one falling block (compiles the cycle, which the
deck needs last), then two stacked blocks (the detection kernels, loaded from the cache when the
deck's process wrote them first). Each process writes what it compiled to numba's on-disk
cache, and each looks there before compiling, so the deck's process loads what the warm-up has
finished. Results do not depend on it: the same kernels compile to the same code in either
process.

``DEC3D_WARMUP=0`` turns it off (the test suite does, except the test of this module).
"""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile

#: the tiny models: (what it compiles, deck lines)
STAGES = (
    ("cycle", ["model new", "block create brick 0 1 0 1 0 1", "block property density 2000",
               "model gravity 0 0 -10", "model cycle 3"]),
    ("detection", ["model new", "block create brick 0 1 0 1 0 1", "block create brick 0 1 0 1 1 2",
                   "block property density 2000", "block contact property stiffness-normal 1e9 stiffness-shear 1e9",
                   "block fix range position-z 0 0.5", "model gravity 0 0 -10", "model cycle 3"]),
)


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


def run_stages() -> list[str]:
    """Run the tiny models (in a temporary output folder); returns the stages done."""
    from .session import Session

    done = []
    with tempfile.TemporaryDirectory(prefix="dec3d-warmup-") as tmp:
        for name, lines in STAGES:
            s = Session(out_dir=tmp, echo=False)
            for line in lines:
                s.command(line)
            done.append(name)
    return done


if __name__ == "__main__":
    print(" ".join(run_stages()))
