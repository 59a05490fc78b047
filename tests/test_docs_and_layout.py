"""The command reference, the import direction of the layers, the README and CI script."""
import ast
import re
from pathlib import Path

import pytest

from conftest import ROOT
from dec3d.commands import load_all
from dec3d.commands.registry import REGISTRY
from dec3d.docs import page_name, pages

load_all()


def test_every_command_has_an_up_to_date_page():
    folder = ROOT / "docs" / "commands"
    for name, text in pages().items():
        p = folder / name
        assert p.exists(), f"docs/commands/{name} missing: run `dec3d docs`"
        assert p.read_text(encoding="utf-8") == text, f"docs/commands/{name} is stale: run `dec3d docs`"
    for cmd in REGISTRY.commands.values():
        assert (folder / page_name(cmd)).exists()


def _examples(page: str) -> list[str]:
    m = re.search(r"## Examples\n\n```\n(.*?)```", page, re.S)
    return [ln for ln in m.group(1).splitlines() if ln.strip()] if m else []


@pytest.mark.parametrize("path", sorted(REGISTRY.commands), ids=" ".join)
def test_page_examples_parse_and_bind_to_their_command(path):
    from dec3d.commands.binder import BindContext, Binder
    from dec3d.lang.parser import parse_deck

    cmd = REGISTRY.commands[path]
    text = (ROOT / "docs" / "commands" / page_name(cmd)).read_text(encoding="utf-8")
    examples = _examples(text)
    assert examples, f"{cmd.name} has no example"
    for ex in examples:
        deck = parse_deck(ex)
        call = Binder(deck, BindContext({}, lenient_names=True)).bind(deck.lines[0])
        assert call.command is cmd, ex


# The layer rules of docs/architecture.md ("Layers and the import direction"): for each part of
# the package, the parts of dec3d it may import (itself always). Anything not listed is an upward
# import; a new package has to be placed here before it can be imported by anyone.
BASE = {"errors", "config", "units"}             # imported by every layer (kernels: config only)
MAY_IMPORT = {
    "errors": set(),
    "config": set(),
    "units": set(),                              # which units reports name (none unless declared)
    "kcache": set(),                             # run by dec3d/__init__ before any kernel loads
    "kernels": {"config"},                       # and numpy, numba, math only (next test)
    "lang": {"errors"},                          # knows no commands
    "fish": BASE | {"lang"},                     # the FISH language: knows no commands or model layout
    "geometry": BASE | {"kernels"},
    "model": BASE | {"geometry", "kernels"},
    "io": BASE | {"model", "geometry", "kernels"},
    "physics": BASE | {"model", "geometry", "kernels", "io"},
    "commands": BASE | {"lang", "fish", "model", "geometry", "kernels", "io", "physics", "plot"},
    "plot": BASE | {"model", "io", "physics"},    # pictures: the model's VTK data drawn off screen
    "session": BASE | {"lang", "fish", "commands", "model", "geometry", "kernels", "io", "physics"},
    "check": BASE | {"lang", "fish", "commands", "session"},
    # the itasca-compatible Python API on sessions (docs/python.md); reached from the top (cli, __init__)
    "itasca": BASE | {"lang", "fish", "commands", "session", "model", "geometry", "kernels", "io", "physics"},
    "batch": BASE | {"lang", "commands", "session", "timelimit", "io"},
    "legacy_run": BASE | {"lang", "session", "commands"},    # `dec3d run` of 3DEC 4/5 decks: translated in memory
    "timelimit": BASE | {"fish", "physics"},     # stops a run: the engine's and FISH's stop flags
    "warmup": BASE | {"kcache", "session"},      # the cold-start helper process of `dec3d run`      # runs decks in sessions, in processes or on Dask
    "docs": BASE | {"lang", "commands"},
    "ssdem": {"errors"},                         # independent of the rest; only the CLI and verify reach it
    "verify_fields": BASE | {"model"},            # closed-form fields verify compares the model with
    "verify": None, "repl": None, "cli": None, "__init__": None, "__main__": None,   # top: anything
}


def _part(parts: tuple[str, ...]) -> str:
    """The layer of a module path inside dec3d (`("dec3d", "kernels", "motion")` -> "kernels")."""
    return parts[1] if len(parts) > 1 else "__init__"


def _dec3d_imports(f: Path, root: Path = ROOT) -> list[tuple[int, str]]:
    """Every dec3d module `f` imports (at any depth of the file), relative imports resolved:
    `from .. import model` in dec3d/kernels/x.py is `dec3d.model`."""
    rel = f.relative_to(root).with_suffix("").parts
    package = rel[:-1]                           # the package the module lives in (also for __init__)
    found = []
    for node in ast.walk(ast.parse(f.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[:len(package) - (node.level - 1)]
                if node.module:
                    found.append((node.lineno, ".".join(base + (node.module,))))
                else:
                    found += [(node.lineno, ".".join(base + (a.name,))) for a in node.names]
            elif node.module == "dec3d":
                found += [(node.lineno, "dec3d." + a.name) for a in node.names]
            else:
                found.append((node.lineno, node.module or ""))
        elif isinstance(node, ast.Import):
            found += [(node.lineno, a.name) for a in node.names]
    return [(ln, m) for ln, m in found if m.split(".")[0] == "dec3d"]


def layer_violations(root: Path) -> list[str]:
    bad = []
    for f in sorted((root / "dec3d").rglob("*.py")):
        rel = f.relative_to(root).with_suffix("").parts
        layer = _part(rel)
        assert layer in MAY_IMPORT, f"{f.relative_to(root)}: dec3d.{layer} has no layer rule in this test"
        allowed = MAY_IMPORT[layer]
        if allowed is None:
            continue
        for line, mod in _dec3d_imports(f, root):
            target = _part(tuple(mod.split(".")))
            if target != layer and target not in allowed:
                bad.append(f"{f.relative_to(root)}:{line}: dec3d.{layer} imports {mod}")
    return bad


def test_imports_follow_the_layers():
    bad = layer_violations(ROOT)
    assert not bad, "\n".join(bad)


def test_ssdem_is_reached_only_from_the_cli_and_verify():
    users = {_part(f.relative_to(ROOT).with_suffix("").parts)
             for f in (ROOT / "dec3d").rglob("*.py")
             for _, m in _dec3d_imports(f) if _part(tuple(m.split("."))) == "ssdem"}
    assert users <= {"ssdem", "cli", "verify"}, users


def test_the_layer_check_catches_upward_imports(tmp_path):
    """The check itself: a kernel reaching the model (the hole the old test had), lang reaching
    commands, ssdem reaching the rigid engine and commands reaching the session are all caught."""
    pkg = tmp_path / "dec3d"
    for sub, name, text in [("kernels", "k.py", "from .. import model\nfrom . import other\nfrom ..config import X\n"),
                            ("lang", "p.py", "def f():\n    from ..commands import registry\n"),
                            ("ssdem", "s.py", "import dec3d.physics.rigid\nfrom dec3d import errors\n"),
                            ("commands", "c.py", "from dec3d import session\nfrom ..model import store\n")]:
        (pkg / sub).mkdir(parents=True, exist_ok=True)
        (pkg / sub / name).write_text(text)
    assert layer_violations(tmp_path) == [
        "dec3d/commands/c.py:1: dec3d.commands imports dec3d.session",
        "dec3d/kernels/k.py:1: dec3d.kernels imports dec3d.model",
        "dec3d/lang/p.py:2: dec3d.lang imports dec3d.commands",
        "dec3d/ssdem/s.py:1: dec3d.ssdem imports dec3d.physics.rigid"]


#: the kernel modules with one more standard-library import: the one that lists its folder (the
#: joint-law plug-ins, kernels/joints) and the named bundles of arrays (namedtuple)
FINDS_PLUGINS = {"joints/__init__.py": {"importlib", "pkgutil"}, "zmodels/__init__.py": {"importlib", "pkgutil"},
                 "bundles.py": {"collections"}, "zmodels/_common.py": {"collections"}}


def test_kernels_import_only_numpy_numba_math_config():
    kernels = ROOT / "dec3d" / "kernels"
    for f in kernels.rglob("*.py"):
        extra = FINDS_PLUGINS.get(f.relative_to(kernels).as_posix(), set())
        for node in ast.walk(ast.parse(f.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                for a in node.names:
                    assert a.name.split(".")[0] in {"numpy", "numba", "math"} | extra, f"{f}: {a.name}"
            elif isinstance(node, ast.ImportFrom) and not node.level:
                assert (node.module or "").split(".")[0] in {"numpy", "numba", "math", "__future__"} | extra \
                    or node.module == "dec3d.config" or node.module.startswith("dec3d.kernels"), f"{f}: from {node.module}"
    # relative imports of kernels are held to dec3d.kernels and dec3d.config by test_imports_follow_the_layers


def test_ci_runs_the_readme_test_command():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    m = re.search(r"Install the test extras and run the tests:\n\n    (.+)\n", readme)
    assert m, "README must give the test command"
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    assert m.group(1) in ci.splitlines()


def test_no_eval_exec_or_pickle_in_the_package():
    for f in (ROOT / "dec3d").rglob("*.py"):
        src = f.read_text(encoding="utf-8")
        for pat in (r"\beval\(", r"\bexec\(", r"pickle\.load", r"allow_pickle\s*=\s*True"):
            assert not re.search(pat, src), f"{f}: {pat}"


def test_the_top_level_commands_folder_points_to_the_reference():
    """The project's layout keeps a top-level `commands/`: an index pointing to `docs/commands/`, where the
    generated pages are (they no longer share a folder name with the package `dec3d/commands/`)."""
    index = (ROOT / "commands" / "README.md").read_text(encoding="utf-8")
    assert "docs/commands/README.md" in index and (ROOT / "docs" / "commands" / "README.md").is_file()
    assert sorted(p.name for p in (ROOT / "commands").iterdir()) == ["README.md"]
