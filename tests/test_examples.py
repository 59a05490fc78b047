"""Every deck in examples/ runs."""
import pytest

from conftest import ROOT
from dec3d.cli import main

# decks called by another example are run through their caller
EXAMPLES = sorted(p for p in (ROOT / "examples").rglob("*.dat") if p.name != "settings.dat")


@pytest.mark.parametrize("deck", EXAMPLES, ids=lambda p: str(p.relative_to(ROOT / "examples")))
def test_example_runs(deck, tmp_path):
    assert main(["run", str(deck), "--out", str(tmp_path), "-q"]) == 0


def test_language_example_results(tmp_path):
    from dec3d.session import run_deck

    s = run_deck(ROOT / "examples" / "language" / "main.dat", out_dir=tmp_path)
    assert s.model.settings.gravity == (0.0, 0.0, -9.81)
    assert s.model.settings.title == "Language tour" and s.model.settings.configure == ["dynamic"]
    assert s.variables["rho"] == 2650.0 and "density_of_granite" in s.fish
