"""Small CLI promises: unknown verification names are an error; a plot notice is printed once."""
import pytest

from dec3d.cli import main


@pytest.mark.parametrize("names", [["NOPE"], ["R3", "NOPE"]])
def test_verify_unknown_name_is_an_error(names, capsys):
    assert main(["verify", *names]) == 2
    cap = capsys.readouterr()
    assert cap.out == ""                                     # nothing ran, no table
    assert cap.err.startswith("dec3d verify: error: no verification problem named `NOPE` in ")
    assert "R3_block_on_spring" in cap.err                   # the names there are


@pytest.mark.parametrize("quiet", [True, False])
def test_plot_notice_once_per_run(tmp_path, capsys, quiet):
    """Two pictures of a model with no blocks: both written, the notice that there is nothing to draw once."""
    deck = tmp_path / "p.dat"
    deck.write_text("model new\nplot create 'Blocks'\nplot 'Blocks' export bitmap filename 'b.png'\n"
                    "[x = 1]\nplot 'Stress' export bitmap filename 's.png'\n")
    assert main(["run", str(deck), "--out", str(tmp_path)] + (["-q"] if quiet else [])) == 0
    out = capsys.readouterr().out
    assert out.count("nothing to draw") == 1
    assert (tmp_path / "b.png").exists() and (tmp_path / "s.png").exists()
