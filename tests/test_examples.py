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


def test_masonry_wall_holds_below_friction_and_slides_above(tmp_path):
    """The top course holds a push of 0.3 x its weight (tan 35° = 0.70) and slides under 0.9 x."""
    import numpy as np

    from dec3d.session import run_deck

    run_deck(ROOT / "examples" / "rigid" / "masonry_wall.dat", out_dir=tmp_path)
    data = np.genfromtxt(tmp_path / "top.csv", delimiter=",", names=True)
    step, ux = data[data.dtype.names[0]], data[data.dtype.names[-1]]
    push = step[0] + 2000                                  # the second push starts here
    held = ux[step <= push]
    assert np.abs(held).max() < 5e-5                       # elastic only: tens of µm
    assert ux[-1] > 2e-3 and np.all(np.diff(ux[step > push + 500]) > 0)   # sliding on
    assert (tmp_path / "wall.pvd").read_text().count("<DataSet") >= 10
    # the snapshots carry what moved: between two snapshots the point displacement grows by exactly
    # what the points moved, and the top course has slid (> 2 mm) in the last one
    import meshio

    first, last = (meshio.read(tmp_path / f"wall_{k:04d}.vtu") for k in (0, 20))
    du = last.point_data["displacement"] - first.point_data["displacement"]
    np.testing.assert_allclose(du, last.points - first.points, atol=1e-12)
    assert last.point_data["displacement"][:, 0].max() > 2e-3
