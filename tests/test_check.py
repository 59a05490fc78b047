"""`dec3d check` says what `dec3d run` would do: it follows calls, flags undefined FISH names,
tells lines that do nothing apart, and agrees with the run on where it stops."""
import shutil

import pytest

from conftest import DECKS
from dec3d.check import DOES_NOTHING, ERROR, LEGACY, NOT_SUPPORTED, RUNNABLE, check_file
from dec3d.cli import main

MAIN = """model new
[a = 2.0]
program call 'sub/geo'
block create brick 0 1 0 1 0 [a]
block property density 1000
fish define foo
  local x = 1
end
plot 'Blocks' export bitmap filename "b.png"
model cycle 10
"""
GEO = """block create brick 0 1 0 1 [a] 3
program return
block nonsense
"""


def _deck(tmp_path, main=MAIN, geo=GEO):
    (tmp_path / "sub").mkdir(exist_ok=True)
    (tmp_path / "main.dat").write_text(main)
    (tmp_path / "sub" / "geo.dat").write_text(geo)
    return tmp_path / "main.dat"


def _by_line(reports):
    return {(r.file.rsplit("/", 1)[-1], r.line): (r.status, r.what) for r in reports}


def test_follows_calls_and_tells_lines_that_do_nothing(tmp_path):
    rep = _by_line(check_file(_deck(tmp_path)))
    assert rep[("main.dat", 3)] == (RUNNABLE, f"program call: reads {tmp_path / 'sub' / 'geo.dat'}")
    assert rep[("geo.dat", 1)] == (RUNNABLE, "block create brick")    # `a` comes from the caller
    assert rep[("geo.dat", 2)][0] == RUNNABLE
    assert rep[("geo.dat", 3)] == (DOES_NOTHING, "after `program return`: never read")
    assert rep[("main.dat", 6)] == (RUNNABLE, "fish define foo")     # compiled as the run compiles it
    assert rep[("main.dat", 9)] == (RUNNABLE, "plot")                # a picture (dec3d.plot)
    assert rep[("main.dat", 10)] == (RUNNABLE, "model cycle")
    # and the run agrees: it runs to the end
    assert main(["run", str(tmp_path / "main.dat"), "--out", str(tmp_path / "out"), "-q"]) == 0


def test_missing_called_file_and_undefined_names_stop_the_run(tmp_path, capsys):
    deck = _deck(tmp_path, MAIN.replace("model cycle 10", "call 'missing.dat'\n"
                                        "block property density [seqFact]\nblock apply force-x @cstav"))
    rep = _by_line(check_file(deck))
    assert rep[("main.dat", 10)][0] == ERROR
    assert rep[("main.dat", 10)][1].startswith(f"cannot read deck `missing.dat`: no such file (looked for "
                                               f"{tmp_path / 'missing.dat'}")
    assert rep[("main.dat", 11)][0] == ERROR and "undefined FISH variable `seqfact`" in rep[("main.dat", 11)][1]
    assert rep[("main.dat", 12)][0] == NOT_SUPPORTED and "`@cstav`" in rep[("main.dat", 12)][1]
    assert main(["check", str(deck)]) == 1
    out = capsys.readouterr().out
    assert f"{deck}:11:25: error: undefined FISH variable `seqfact`" in out
    assert f"dec3d run would stop before running anything, at {deck}:10" in out
    capsys.readouterr()
    assert main(["run", str(deck), "--out", str(tmp_path / "out"), "-q"]) != 0
    assert f"{deck}:10:6: error: cannot read deck `missing.dat`: no such file (looked for " \
           f"{tmp_path / 'missing.dat'}" in capsys.readouterr().err


def test_blockers_in_called_decks_are_reported_with_their_file(tmp_path, capsys):
    deck = _deck(tmp_path, geo="block create brick 0 1 0 1 1 3\nblock cut joint-set persistence 0.5\n")
    geo = tmp_path / "sub" / "geo.dat"
    reports = check_file(deck)
    bad = [r for r in reports if r.status not in (RUNNABLE, DOES_NOTHING)]
    assert [(r.file, r.line, r.status) for r in bad] == [(str(geo), 2, NOT_SUPPORTED)]
    assert main(["check", str(deck)]) == 1
    out = capsys.readouterr().out
    assert f"{geo}:2:21: not supported yet: keyword `persistence` is not supported yet" in out
    assert "(in 2 files)" in out
    # the run stops at the same line
    assert main(["run", str(deck), "--out", str(tmp_path / "out"), "-q"]) != 0
    assert f"{geo}:2:21: error: keyword `persistence` is not supported yet" in capsys.readouterr().err


def test_a_file_that_calls_itself(tmp_path):
    (tmp_path / "a.dat").write_text("call 'b.dat'\n")
    (tmp_path / "b.dat").write_text("call 'a.dat'\n")
    rep = _by_line(check_file(tmp_path / "a.dat"))
    assert rep[("b.dat", 1)] == (ERROR, "`a.dat` calls itself (directly or through other files)")


@pytest.mark.parametrize("what", ["folder", "missing"])
def test_missing_file_or_folder_is_a_clean_error(tmp_path, capsys, what):
    target = tmp_path if what == "folder" else tmp_path / "nope.dat"
    assert main(["check", str(target)]) == 2
    cap = capsys.readouterr()
    why = "is a folder, not a deck file" if what == "folder" else "does not exist"
    assert cap.err == f"dec3d check: error: `{target}` {why}\n"
    assert "Traceback" not in cap.out + cap.err


_HOLE = "peterzhu6667__pinn-cp-3dec__Elastic_Hole__"


@pytest.mark.skipif(not (DECKS / f"{_HOLE}master.dat").exists(),
                    reason="the shared decks (DEC3D_SHARED or ../shared/decks) are not here")
def test_elastic_hole_master_reports_the_called_decks(tmp_path):
    """The shared copies are flat; put them back under the names master.dat calls."""
    for p in DECKS.glob(f"{_HOLE}*.dat"):
        name = p.name[len(_HOLE):]
        shutil.copy(p, tmp_path / (name[:-4] if name.endswith(".fis.dat") else name))
    reports = check_file(tmp_path / "master.dat")
    files = {r.file.rsplit("/", 1)[-1] for r in reports}
    assert {"master.dat", "ElasticHole-Hex.dat", "ElasticHole-tet.dat", "ElasticHole-HO.dat", "check.fis"} <= files
    blocked = {r.file.rsplit("/", 1)[-1] for r in reports if r.status in (ERROR, NOT_SUPPORTED)}
    assert blocked == set()        # zoning (tet, hexahedra, high-order), zone properties, insitu: all bind
    plots = [r for r in reports if r.file.endswith("master.dat") and r.what.startswith("plot")]
    assert len(plots) == 9 and {r.status for r in plots} == {RUNNABLE}
    # `[checkError(...)]` binds (the function is defined); the FISH functions that read zones and
    # gridpoints use only intrinsics dec3d has: every define is runnable
    calls = [r for r in reports if r.file.endswith("master.dat") and r.line in (8, 16, 24)]
    assert {r.status for r in calls} == {RUNNABLE}
    defines = [r for r in reports if r.what.startswith("fish define")]
    assert len(defines) >= 4 and {r.status for r in defines} == {RUNNABLE}


# a function with an intrinsic dec3d lacks and one with 3DEC 5 FISH compile (the run reads the deck), and
# stop the run only when called; `c` reaches `a` through its body
CALLS = """block create brick 0 1 0 1 0 1
fish define b
  out('x')
end
fish define a
  a = block.gp.temperature(1)
end
fish define c
  c = a + 1
end
model title 'ran'
[io.out('a is only a string here')]
{line13}
"""


@pytest.mark.parametrize("line13, status, when, says", [
    ("@a", NOT_SUPPORTED, "run", "would run the lines before {deck}:13 and stop there"),
    ("[x = c]", NOT_SUPPORTED, "run", "would run the lines before {deck}:13 and stop there"),
    ("[b]", LEGACY, "run", "would run the lines before {deck}:13 and stop there"),
    ("fish callback add c 1.0", NOT_SUPPORTED, "cycle", "would stop at the first cycling step after {deck}:13"),
    ("model title 'no call'", RUNNABLE, "bind", "would run to the end: no line calls the FISH functions above")])
def test_lines_that_call_functions_that_cannot_run_are_reported_where_the_run_stops(tmp_path, capsys, line13,
                                                                                    status, when, says):
    deck = tmp_path / "d.dat"
    deck.write_text(CALLS.format(line13=line13))
    reports = check_file(deck)
    by = {r.line: r for r in reports}
    assert (by[2].status, by[2].when) == (LEGACY, "called") and (by[5].status, by[5].when) == (NOT_SUPPORTED, "called")
    assert by[8].status == RUNNABLE and by[11].status == RUNNABLE and by[12].status == RUNNABLE
    assert (by[13].status, by[13].when) == (status, when)
    assert main(["check", str(deck)]) == 1
    assert says.format(deck=deck) in capsys.readouterr().out
    # the run agrees: it runs line 11 (the title) and stops at line 13 only when that line calls the function
    rc = main(["run", "-q", str(deck), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    if when == "run":
        assert rc == 1 and f"called from {deck}:13" in err
    else:
        assert rc == 0
