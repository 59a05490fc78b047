"""Itasca's elastic-hole verification (issue 10's acceptance deck) run verbatim: master.dat
calls the three zonings, ElasticHole.fis computes the average errors in FISH, and check.fis
stops the deck with `system.error` when one is over Itasca's bar."""
import re
import shutil

import pytest

from conftest import DECKS, NO_DECKS
from dec3d.cli import main

_HOLE = "peterzhu6667__pinn-cp-3dec__Elastic_Hole__"
BARS = {"ElasticHole-Hex": (1.2, 1.8, 4.1), "ElasticHole-tet": (2.2, 2.7, 4.2), "ElasticHole-HO": (2.4, 2.1, 4.3)}


@pytest.mark.skipif(not (DECKS / f"{_HOLE}master.dat").exists(), reason=NO_DECKS)
def test_master_deck_runs_as_written_and_meets_itascas_bars(tmp_path, capsys):
    for p in DECKS.glob(f"{_HOLE}*.dat"):          # the shared copies are flat: back under their names
        name = p.name[len(_HOLE):]
        shutil.copy(p, tmp_path / (name[:-4] if name.endswith(".fis.dat") else name))
    out = tmp_path / "out"
    assert main(["run", str(tmp_path / "master.dat"), "--out", str(out)]) == 0
    text = capsys.readouterr().out
    # the errors each deck lists after its cycles, in the order master.dat calls them
    found = [float(v) for v in re.findall(r"^(?:errsr|errst|errd) = (\S+)$", text, flags=re.M)]
    assert len(found) == 9
    for k, deck in enumerate(("ElasticHole-Hex", "ElasticHole-tet", "ElasticHole-HO")):
        for value, bar in zip(found[3 * k: 3 * k + 3], BARS[deck]):
            assert 0.0 < value <= bar
        assert (out / f"{deck}.sav").is_file()


@pytest.mark.skipif(not (DECKS / f"{_HOLE}master.dat").exists(), reason=NO_DECKS)
def test_check_fis_stops_the_deck_when_a_bar_is_missed(tmp_path, capsys):
    for name in ("ElasticHole-Hex.dat", "ElasticHole.fis.dat", "check.fis.dat"):
        shutil.copy(DECKS / f"{_HOLE}{name}", tmp_path / (name[:-4] if name.endswith(".fis.dat") else name))
    (tmp_path / "tight.dat").write_text("program call 'ElasticHole-Hex'\nprogram call 'check.fis'\n"
                                        "[checkError(0.5,1.8,4.1)]\n")
    assert main(["run", str(tmp_path / "tight.dat"), "--out", str(tmp_path / "out")]) == 1
    cap = capsys.readouterr()
    assert "Radial stress error is 1." in cap.out + cap.err
    assert "Traceback" not in cap.out + cap.err
