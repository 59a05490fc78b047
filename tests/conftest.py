import importlib.util
import os
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
# The public 3DEC decks are not part of the repository: DEC3D_SHARED names a folder holding `decks/`
# (default: `shared/` beside the repository). Tests that read them skip, with NO_DECKS as the reason,
# when the folder is absent.
SHARED = Path(os.environ.get("DEC3D_SHARED", ROOT.parent / "shared"))
# no warm-up process (dec3d/warmup.py) from the `dec3d run`s of the tests: tests/test_warmup.py
# runs it itself
os.environ.setdefault("DEC3D_WARMUP", "0")
# the key that signs saves (dec3d.io.savesign) lives in a folder of the test run, not in the user's
# ~/.config/dec3d: the tests neither read nor make the real one
if "DEC3D_CONFIG_DIR" not in os.environ:
    import tempfile

    os.environ["DEC3D_CONFIG_DIR"] = tempfile.mkdtemp(prefix="dec3d-test-config-")
DECKS = SHARED / "decks"
NO_DECKS = (f"public 3DEC decks not found at {DECKS}: set DEC3D_SHARED=<folder holding decks/> "
            "or place shared/ beside the repository (README, 'Set up')")
# a module that reads the decks starts with:
#     if not DECKS.is_dir():
#         pytest.skip(NO_DECKS, allow_module_level=True)


#: what the tests import: dec3d's dependencies and its test extras (pyproject.toml)
NEEDED = ("numpy", "numba", "lark", "scipy", "meshio", "pyvista", "prompt_toolkit", "rich", "matplotlib",
          "hypothesis", "dask", "xdist")


def pytest_configure(config):
    """A Python without dec3d's dependencies (a `pytest` from another environment) gets one clear
    message instead of an import error for every test module."""
    missing = [m for m in NEEDED if importlib.util.find_spec(m) is None]
    if not missing:
        # FISH raises Python's recursion limit when a session is made (dec3d.fish.runtime); the tests
        # raise it once here, so that no test sees it change under it (hypothesis warns when it does)
        from dec3d.fish.runtime import _deep_enough

        _deep_enough()
    if missing:
        pytest.exit(f"this Python ({sys.executable}) lacks {', '.join(missing)}: install dec3d and its test "
                    "extras into it first, `pip install -e \".[test]\"` (README, 'Set up'), or run the "
                    "`pytest` of the environment where you did", returncode=4)


@pytest.hookimpl(tryfirst=True)
def pytest_cmdline_main(config):
    """The suite runs on every core, up to four worker processes (pytest-xdist, a test extra), unless
    the command line says otherwise (`-n 0`: one process, as for a debugger). Runs before xdist reads
    its options. Each worker compiles or loads the kernels from numba's shared cache on disk."""
    opt = config.option
    if getattr(opt, "numprocesses", "absent") is None and not os.environ.get("PYTEST_XDIST_WORKER") \
            and not getattr(opt, "usepdb", False) and not getattr(opt, "collectonly", False):
        opt.numprocesses = "auto"
        opt.maxprocesses = opt.maxprocesses or 4
        if opt.dist == "no":
            opt.dist = "worksteal"


@pytest.fixture
def session(tmp_path):
    import io

    from dec3d.session import Session

    out = io.StringIO()
    s = Session(out_dir=tmp_path, stdout=out)
    s.output = out
    return s
