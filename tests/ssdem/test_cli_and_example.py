"""`dec3d ssdem` end to end: files written, JSON/CSV/VTK readable, errors reported; the example runs."""
import csv
import json
from pathlib import Path

import numpy as np
import pytest

from dec3d.ssdem.cli import main

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "ssdem" / "layered_slope.toml"
APPENDIX = Path(__file__).parent / "data" / "appendix_a_example.txt"


def test_example_runs_with_bishop_comparison(tmp_path, capsys):
    assert main([str(EXAMPLE), "--out", str(tmp_path), "--compare", "bishop"]) == 0
    text = capsys.readouterr().out
    assert "FS (static DEM" in text and "Bishop simplified" in text
    names = {"summary.txt", "blocks.csv", "interfaces.csv", "steps.csv", "result.json",
             "figure.png", "blocks.vtu", "interfaces.vtu"}
    assert names <= {f.name for f in tmp_path.iterdir()}
    rec = json.loads((tmp_path / "result.json").read_text())
    q = rec["summary"]
    # regression values of this example (10 load steps, 30 slices x 3 rows)
    assert q["fs_dem"] == pytest.approx(1.163, abs=0.005)
    assert q["fs_bishop"] == pytest.approx(1.207, abs=0.005)
    assert q["fs_dem"] < q["fs_bishop"] and q["converged"] == 1.0
    assert rec["failure_surface"]["kind"] == "prescribed"
    assert len(rec["failure_surface"]["interfaces"]) == q["n_surface"]
    with open(tmp_path / "interfaces.csv") as fh:
        rows = list(csv.DictReader(fh))
    on = [r for r in rows if r["failure_surface"] == "1"]
    assert len(on) == q["n_surface"] and {"sigma_n", "tau", "fs", "yield_pct", "state"} <= set(rows[0])
    import meshio
    m = meshio.read(tmp_path / "blocks.vtu")
    assert sum(len(c.data) for c in m.cells) == len(rec["blocks"]["block"])
    assert (tmp_path / "figure.png").stat().st_size > 10_000


def test_grid_mesh_of_the_example(tmp_path):
    """Without [surface] the whole section is meshed; the run completes and reports its state."""
    text = EXAMPLE.read_text()
    text = text[:text.index("[surface]")] + "[mesh]\nsize = 1.5\nbottom = -8.0\n"
    f = tmp_path / "grid.toml"
    f.write_text(text)
    assert main([str(f), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    rec = json.loads((tmp_path / "out" / "result.json").read_text())
    assert rec["summary"]["converged"] == 1.0
    assert rec["failure_surface"]["kind"] in ("yield", "none")


def test_appendix_a_file_through_the_cli(tmp_path):
    assert main([str(APPENDIX), "--out", str(tmp_path), "--compare", "bishop", "--quiet"]) == 0
    rec = json.loads((tmp_path / "result.json").read_text())
    assert rec["format"] == "appendix-a" and rec["bishop"]["available"] is False
    np.testing.assert_allclose(sum(rec["blocks"]["fy"]), -50.0)      # reported back in kN


def test_bad_input_exits_2_with_file_and_line(tmp_path, capsys):
    f = tmp_path / "bad.toml"
    f.write_text(EXAMPLE.read_text().replace("ks = 1.2e5", "ks = -1.2e5"))
    assert main([str(f), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    line = next(i + 1 for i, ln in enumerate(f.read_text().splitlines()) if "ks = -1.2e5" in ln)
    assert f"{f}:{line}:" in err and "layer[2].ks" in err
    assert main([str(tmp_path / "missing.toml")]) == 2
