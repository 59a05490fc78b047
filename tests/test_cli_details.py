"""Small CLI promises: unknown verification names are an error; the plot notice is printed once."""
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
    deck = tmp_path / "p.dat"
    deck.write_text("model new\nplot create 'Blocks'\nplot 'Blocks' export bitmap filename 'b.png'\n"
                    "[x = 1]\nplot 'Stress' export bitmap filename 's.png'\n")
    assert main(["run", str(deck), "--out", str(tmp_path)] + (["-q"] if quiet else [])) == 0
    out = capsys.readouterr().out
    assert out.count("notice: `plot` commands are display-only") == 1
