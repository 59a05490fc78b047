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
    folder = ROOT / "commands"
    for name, text in pages().items():
        p = folder / name
        assert p.exists(), f"commands/{name} missing: run `dec3d docs`"
        assert p.read_text(encoding="utf-8") == text, f"commands/{name} is stale: run `dec3d docs`"
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
    text = (ROOT / "commands" / page_name(cmd)).read_text(encoding="utf-8")
    examples = _examples(text)
    assert examples, f"{cmd.name} has no example"
    for ex in examples:
        deck = parse_deck(ex)
        call = Binder(deck, BindContext({}, lenient_names=True)).bind(deck.lines[0])
        assert call.command is cmd, ex


LAYERS = {  # module -> packages of dec3d it must not import
    "kernels": {"lang", "commands", "model", "physics", "io", "ssdem", "geometry", "fe", "session", "repl", "cli"},
    "lang": {"commands", "model", "physics", "kernels", "io", "ssdem", "geometry", "fe", "session"},
    "model": {"commands", "lang", "session", "repl", "cli"},
    "geometry": {"commands", "lang", "session", "repl", "cli"},
    "physics": {"commands", "lang", "session", "repl", "cli"},
    "fish": {"session", "repl", "cli", "kernels"},
}


def test_imports_follow_the_layers():
    bad = []
    for layer, forbidden in LAYERS.items():
        for f in (ROOT / "dec3d" / layer).rglob("*.py"):
            tree = ast.parse(f.read_text(encoding="utf-8"))
            for node in ast.walk(tree):
                names = []
                if isinstance(node, ast.ImportFrom):
                    mod = node.module or ""
                    if node.level:           # relative: resolve against the package
                        pkg = f.relative_to(ROOT).with_suffix("").parts[:-node.level]
                        mod = ".".join(pkg + ((mod,) if mod else ()))
                    names = [mod]
                elif isinstance(node, ast.Import):
                    names = [a.name for a in node.names]
                for n in names:
                    parts = n.split(".")
                    if parts[0] == "dec3d" and len(parts) > 1 and parts[1] in forbidden:
                        bad.append(f"{f.relative_to(ROOT)} imports {n}")
    assert not bad, "\n".join(bad)


def test_kernels_import_only_numpy_numba_math_config():
    for f in (ROOT / "dec3d" / "kernels").rglob("*.py"):
        tree = ast.parse(f.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                for a in node.names:
                    assert a.name.split(".")[0] in {"numpy", "numba", "math"}, f"{f}: {a.name}"
            elif isinstance(node, ast.ImportFrom):
                mod = node.module or ""
                ok = mod.split(".")[0] in {"numpy", "numba", "math", "__future__"} or \
                    (node.level and mod in ("", "config")) or mod == "dec3d.config" or node.level == 1
                assert ok, f"{f}: from {mod}"


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
