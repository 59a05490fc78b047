"""A fresh clone: plain `pytest` (no current folder on sys.path, unlike `python -m pytest`) collects
every test module, and without the public decks the deck tests are skipped with one clear reason,
not turned into empty-parameter skips."""
import os
import subprocess
import sys

import pytest

from conftest import ROOT


def test_plain_pytest_collects_every_module_and_skips_the_deck_tests_with_one_reason(tmp_path):
    # -I: isolated, as the `pytest` script runs (no current folder and no PYTHONPATH on sys.path)
    env = {**os.environ, "DEC3D_SHARED": str(tmp_path / "nowhere")}
    run = subprocess.run([sys.executable, "-I", "-m", "pytest", "--collect-only", "-q", "-rs", "-p", "no:cacheprovider"],
                         cwd=ROOT, env=env, capture_output=True, text=True, timeout=300)
    out = run.stdout + run.stderr
    assert run.returncode == 0, out
    collected = {ln.split(":")[0] for ln in run.stdout.splitlines() if ln.startswith("tests/") and ": " in ln}
    modules = {str(p.relative_to(ROOT)) for p in (ROOT / "tests").rglob("test_*.py")}
    skips = [ln for ln in run.stdout.splitlines() if ln.startswith("SKIPPED")]
    reason = f"public 3DEC decks not found at {tmp_path / 'nowhere' / 'decks'}: set DEC3D_SHARED="
    assert "tests/test_decks.py" in modules - collected and skips, out
    for m in modules - collected:               # a module not collected was skipped whole, for the decks
        assert any(f" {m}:" in s and reason in s for s in skips), f"{m} not collected:\n{out}"
    assert all(reason in s for s in skips), out
    assert "empty parameter" not in out and "ERROR" not in out


def test_a_python_without_the_dependencies_gets_one_clear_message(monkeypatch):
    """`pytest` of another environment (no numba, lark, …): one message saying what to install, not an
    import error per test module."""
    import importlib.util

    import conftest

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name in ("numba", "lark") else real(name, *a))
    with pytest.raises(pytest.exit.Exception) as e:
        conftest.pytest_configure(None)
    assert e.value.returncode == 4
    assert "lacks numba, lark: install dec3d and its test extras into it first" in str(e.value)
