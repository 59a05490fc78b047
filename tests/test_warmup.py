"""dec3d/warmup.py: on a cold kernel cache `dec3d run` compiles the cycle kernels in a second
process (issue 9, cold start)."""
import os
import subprocess
import sys

from conftest import ROOT

from dec3d import kcache, warmup


def test_wanted_only_on_a_cold_cache_and_when_not_turned_off(monkeypatch):
    monkeypatch.setattr(kcache, "COLD", True)
    monkeypatch.setenv("DEC3D_WARMUP", "1")
    assert warmup.wanted()
    monkeypatch.setenv("DEC3D_WARMUP", "0")
    assert not warmup.wanted() and warmup.start() is None
    monkeypatch.setenv("DEC3D_WARMUP", "1")
    monkeypatch.setattr(kcache, "COLD", False)
    assert not warmup.wanted() and warmup.start() is None
    warmup.stop(None)                          # nothing to stop


def test_warmup_fills_a_cold_cache_with_the_cycle_kernels(tmp_path):
    """The warm-up process, on an empty cache folder, leaves the cached cycle and detection
    kernels there (what the deck's process then loads instead of compiling), and says which
    stages it ran; a `dec3d run` afterwards finds the cache warm."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    env.update(PYTHONPATH=str(ROOT), NUMBA_CACHE_DIR=str(tmp_path / "cache"), DEC3D_WARMUP="1")
    out = subprocess.run([sys.executable, "-m", "dec3d.warmup"], capture_output=True, text=True, env=env,
                         cwd=tmp_path, timeout=900)
    assert out.returncode == 0, out.stderr[-3000:]
    assert out.stdout.splitlines()[-1].split() == ["cycle", "detection"]
    cached = {p.name.split("-")[0] for p in (tmp_path / "cache").rglob("*.nbi")}
    for kernel in ("cycle._run_steps_1", "subgeom.subcontacts_batch", "contactmap.cp_batch"):
        assert kernel in cached, sorted(cached)
    probe = "from dec3d import kcache; print(kcache.COLD)"
    assert subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, env=env,
                          timeout=300).stdout.strip() == "False"


def test_recorder_runs_kernels_as_python_and_keeps_the_calls_from_python():
    """Inside ``_Recorder`` a kernel of the package runs as plain Python (nothing compiled) and
    each call made from Python is kept once with its argument types; the kernels it calls are
    not kept; a kernel outside the package compiles as usual."""
    import numpy as np
    from numba import njit, types

    def inner(x):
        return x * 2.0

    inner.__module__ = "dec3d.kernels.fake"
    inner_k = njit(inner)

    def outer(a):
        s = 0.0
        for v in a:
            s += inner_k(v)
        return s

    def other(x):
        return x + 1

    outer.__module__ = "dec3d.kernels.fake"
    outer_k = njit(outer)
    other_k = njit(other)
    with warmup._Recorder() as rec:
        assert outer_k(np.arange(4.0)) == 12.0
        assert outer_k(np.arange(3.0)) == 6.0
        assert inner_k(1.5) == 3.0
        assert other_k(1) == 2
    assert [(d.py_func.__name__, s) for d, s in rec.calls] == [
        ("outer", (types.float64[::1],)), ("inner", (types.float64,))]
    assert outer_k.signatures == [] and inner_k.signatures == []
    assert len(other_k.signatures) == 1
    assert outer_k(np.arange(4.0)) == 12.0 and len(outer_k.signatures) == 1     # compiles after


class _FakeKernel:
    """Stands in for a dispatcher: ``compile`` notes the order, a cache hit when ``cached``."""

    def __init__(self, name, log, cached=False):
        from collections import Counter
        from types import SimpleNamespace

        self.name, self.log, self.cached = name, log, cached
        self.stats = SimpleNamespace(cache_hits=Counter())

    def compile(self, sig):
        self.log.append(self.name)
        if self.cached:
            self.stats.cache_hits[sig] += 1


def test_plan_reverses_the_deck_stage_and_compiling_stops_where_the_deck_has_got_to():
    log = []
    a, b, c, d = (_FakeKernel(n, log) for n in "abcd")
    order = warmup.plan([[(a, (1,)), (d, (1,))], [(a, (1,)), (b, (1,)), (c, (1,))]])
    assert [k.name for k, _ in order] == ["c", "b", "a", "d"]
    assert warmup.compile_plan(order) == 4 and log == ["c", "b", "a", "d"]
    log.clear()
    b.cached = True                      # the deck's process compiled b: it has done a too
    assert warmup.compile_plan(order) == 1 and log == ["c", "b"]
