"""The numba cache guard of dec3d/kcache.py (issue 9: caches that cannot go stale,
a notice on a cold start) and the kernel twin tests run once more with NUMBA_DISABLE_JIT=1."""
import os
import shutil
import subprocess
import sys
import types
from pathlib import Path

import pytest
from conftest import ROOT

from dec3d import kcache as K


def _copy_kernels(dst: Path) -> Path:
    shutil.copytree(ROOT / "dec3d" / "kernels", dst, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    return dst


def test_source_hash_follows_every_kernel_file(tmp_path):
    a = _copy_kernels(tmp_path / "a")
    b = _copy_kernels(tmp_path / "b")
    assert K.source_hash(a) == K.source_hash(b) == K.source_hash()
    (b / "polygon2d.py").write_text((b / "polygon2d.py").read_text() + "\n# edited\n")
    assert K.source_hash(b) != K.source_hash(a)
    (b / "polygon2d.py").unlink()
    assert K.source_hash(b) != K.source_hash(a)
    c = _copy_kernels(tmp_path / "c")               # a joint law (kernels/joints) is hashed too
    (c / "joints" / "mohr.py").write_text((c / "joints" / "mohr.py").read_text() + "\n# edited\n")
    assert K.source_hash(c) != K.source_hash(a)


def test_clear_stale_deletes_only_this_package_caches_and_stamps(tmp_path):
    src = tmp_path / "src"
    src.mkdir()
    (src / "jointlaw.py").write_text("x = 1\n")
    (src / "cycle.py").write_text("y = 2\n")
    cdir = tmp_path / "cache"
    cdir.mkdir()
    ours = ["jointlaw.coulomb_one-60.py311.nbi", "jointlaw.coulomb_one-60.py311.1.nbc",
            "cycle.run_steps-50.py311.nbi"]
    kept = ["other.f-1.py311.nbi", "cycle.cpython-311.pyc", "notes.txt"]
    for name in ours + kept:
        (cdir / name).write_text("")
    assert K.is_cold(cdir, src) is False
    assert K.clear_stale(cdir, "abc", src) is True
    assert sorted(p.name for p in cdir.iterdir()) == sorted(kept + [K.STAMP])
    assert (cdir / K.STAMP).read_text().strip() == "abc"
    assert K.is_cold(cdir, src) is True
    (cdir / ours[0]).write_text("")                     # compiled again under the same sources
    assert K.clear_stale(cdir, "abc", src) is False
    assert (cdir / ours[0]).exists()
    assert K.clear_stale(cdir, "def", src) is True      # a source changed
    assert not (cdir / ours[0]).exists()


def test_read_only_sources_cache_under_the_user_cache_dir(tmp_path, monkeypatch):
    src = tmp_path / "pkg" / "kernels"
    src.mkdir(parents=True)
    (src / "__pycache__").write_text("a file where numba wants a folder: not writable")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    cfg = types.SimpleNamespace(CACHE_DIR="")
    got = K.cache_dir(src, cfg)
    assert cfg.CACHE_DIR == str(tmp_path / "xdg" / "dec3d" / "numba")
    assert got.parent == Path(cfg.CACHE_DIR) and got.name.startswith("kernels_") and got.is_dir()
    # the user's own NUMBA_CACHE_DIR is kept
    cfg = types.SimpleNamespace(CACHE_DIR=str(tmp_path / "mine"))
    assert K.cache_dir(src, cfg).parent == tmp_path / "mine"
    assert cfg.CACHE_DIR == str(tmp_path / "mine")


_CALLER = "from numba import njit\nfrom .{} import g\n\n\n@njit(cache=True)\ndef f():\n    return g() + 10\n"
_CALLEE = "from numba import njit\n\n\n@njit(cache=True)\ndef g():\n    return {}\n"


@pytest.mark.parametrize("callee", ["callee", "sub.callee"])
def test_edited_callee_reaches_the_cached_caller(tmp_path, callee):
    """A package laid out like dec3d (the guard run by its __init__, a cached kernel that
    calls a cached kernel of another file, also in a sub-package as the joint laws are).
    Editing the callee's file changes what the caller returns in the next process; numba
    alone would keep the caller's old code. The notice is printed while compiling on a cold
    cache, not on a warm one."""
    pkg = tmp_path / "fakedec" / "kernels"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "sub" / "__init__.py").write_text("")
    cfile = pkg / (callee.replace(".", "/") + ".py")
    (tmp_path / "fakedec" / "__init__.py").write_text(
        "from pathlib import Path\nfrom dec3d.kcache import guard\n"
        "guard(Path(__file__).parent / 'kernels', 'fakedec.kernels')\n")
    (pkg / "__init__.py").write_text("")
    (pkg / "caller.py").write_text(_CALLER.format(callee))
    cfile.write_text(_CALLEE.format(1))
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    env["PYTHONPATH"] = os.pathsep.join([str(tmp_path), str(ROOT)])

    def run():
        out = subprocess.run([sys.executable, "-c", "from fakedec.kernels.caller import f; print(f())"],
                             capture_output=True, text=True, env=env, cwd=tmp_path, timeout=300)
        assert out.returncode == 0, out.stderr
        return int(out.stdout.split()[-1]), out.stderr.count(K.NOTICE)

    assert run() == (11, 1)              # cold: compiled, one notice
    assert run() == (11, 0)              # warm: loaded from the cache, silent
    cfile.write_text(_CALLEE.format(2))
    assert run() == (12, 1)              # the edit is seen through the caller's cache
    assert run() == (12, 0)


_MOVED_RUN = """
import sys
from pathlib import Path
import fakedec
from fakedec.kernels.caller import f
from dec3d import kcache
stamp = kcache.cache_dir(Path(fakedec.__file__).parent / 'kernels') / kcache.STAMP
if sys.argv[1] == 'moved':           # another process stamped other sources meanwhile
    stamp.write_text('0' * 64 + chr(10))
print(f())
print(sorted(p.name for p in stamp.parent.iterdir() if p.suffix == '.nbi'))
"""


@pytest.mark.parametrize("moved", [False, True])
def test_a_process_whose_sources_moved_on_caches_nothing(tmp_path, moved):
    """A process that imported the kernels, then saw another process stamp different sources
    (an edit or upgrade while it ran), compiles its own (old) code but writes none of it to the
    cache, and says so once; with the stamp unchanged it caches as usual."""
    pkg = tmp_path / "fakedec" / "kernels"
    pkg.mkdir(parents=True)
    (tmp_path / "fakedec" / "__init__.py").write_text(
        "from pathlib import Path\nfrom dec3d.kcache import guard\n"
        "guard(Path(__file__).parent / 'kernels', 'fakedec.kernels')\n")
    (pkg / "__init__.py").write_text("")
    (pkg / "caller.py").write_text(_CALLER.format("callee"))
    (pkg / "callee.py").write_text(_CALLEE.format(1))
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    env["PYTHONPATH"] = os.pathsep.join([str(tmp_path), str(ROOT)])
    out = subprocess.run([sys.executable, "-c", _MOVED_RUN, "moved" if moved else "same"], capture_output=True,
                         text=True, env=env, cwd=tmp_path, timeout=300)
    assert out.returncode == 0, out.stderr
    value, names = out.stdout.splitlines()[-2:]
    assert value == "11"
    if moved:
        assert names == "[]" and out.stderr.count(K.MOVED) == 1
    else:
        assert "caller" in names and "callee" in names and K.MOVED not in out.stderr


TWINS = ["tests/rigid/test_contactmap.py", "tests/rigid/test_kernels_rigid.py", "tests/rigid/test_cellmap.py",
         "tests/rigid/test_subgeom.py", "tests/geometry/test_kernels_vs_reference.py",
         "tests/rigid/test_bodyscale_kernel.py", "tests/rigid/test_water_kernels.py"]


def test_kernel_twins_pass_as_plain_python():
    """The kernels' Python path (NUMBA_DISABLE_JIT=1) against the same twins: a kernel that only
    works compiled (or only in Python) fails here."""
    env = dict(os.environ, NUMBA_DISABLE_JIT="1")
    out = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *TWINS],
                         capture_output=True, text=True, env=env, cwd=ROOT, timeout=600)
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-2000:]
    ran = sum(line.split("[")[0].count(".") for line in out.stdout.splitlines() if line.rstrip().endswith("%]"))
    assert ran >= 100, out.stdout[-3000:]


_BUNDLE_CALL = """
import numpy as np
from dec3d.kernels.bundles import Bodies, Groups, new_damping
from dec3d.kernels.motion import rigid_motion_groups as k
z = lambda: np.zeros((1, 3))
verts = np.array([[i, j, l] for l in (0.0, 1.0) for j in (0.0, 1.0) for i in (0.0, 1.0)])
groups = Groups(np.array([0, 1]), np.array([0]), np.ones(1), np.ones(1), np.ones(1), np.ones((1, 3)),
                np.eye(3)[None].copy(), np.full((1, 3), 0.5))
bodies = Bodies(np.ones(1), np.zeros(1, np.uint8), z(), z(), z(), z(), np.array([[0.0, 0.0, -1.0]]), z(),
                np.full((1, 3), 0.5), z(),
                np.array([0]), np.array([8]), verts)
out = np.zeros(4)
k(0.1, np.array([0.0, 0.0, -10.0]), False, new_damping(2, 0.8, 1), groups, bodies, 1e6, out)
print(bodies.vel[0, 2], sum(k.stats.cache_hits.values()), sum(k.stats.cache_misses.values()))
"""


def test_a_kernel_taking_bundles_is_loaded_from_the_cache_in_the_next_process(tmp_path):
    """Kernels take namedtuples of arrays (``kernels.bundles``): numba's cache must still hit for
    them, or every run would compile again. Two processes on one empty cache folder: the first
    compiles (a miss), the second loads (a hit) and gets the same step (a lone 1 kg block moving
    down at 1 m/s under g = −10 m/s², Δt 0.1 s, combined damping with no force history: half the
    local damping force, v = −1 − 10 (1 − 0.8/2) · 0.1 = −1.6 m/s)."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    env.update(PYTHONPATH=str(ROOT), NUMBA_CACHE_DIR=str(tmp_path / "cache"))

    def run():
        out = subprocess.run([sys.executable, "-c", _BUNDLE_CALL], capture_output=True, text=True, env=env,
                             cwd=tmp_path, timeout=600)
        assert out.returncode == 0, out.stderr[-3000:]
        v, hits, misses = out.stdout.split()
        return float(v), int(hits), int(misses)

    v, hits, misses = run()
    assert v == pytest.approx(-1.6, rel=1e-12) and (hits, misses) == (0, 1)
    assert run() == (v, 1, 0)
