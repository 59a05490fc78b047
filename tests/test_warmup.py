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
