"""No deck destroys its own inputs, and outputs replace only files dec3d wrote (docs/safety.md).

Without `--out` the output folder is the deck's own folder, so every case runs with the deck and
its outputs in one folder: a save, a history export or a log file onto the running deck, a file it
calls or a save it restored — by a literal name (refused when bound: nothing runs) or by an
expression (refused when the command runs), directly or through a symbolic or hard link — is
refused with the location of the name, and the file keeps its bytes. A second run writing the same
outputs still works; a file dec3d did not write (or one changed since) is replaced only with
`allow_overwrite`. A save stopped by Ctrl-C leaves no temporary file and the previous save whole.
"""
import io
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from dec3d.errors import Dec3dError
from dec3d.io.guard import MANIFEST
from dec3d.session import Session

ROOT = Path(__file__).resolve().parents[2]
BRICK = "block create brick 0 1 0 1 0 1\nblock property density 1000\n"
HIST = "block history displacement-z position 0.5 0.5 0.5\n"


def run(folder: Path, text: str, name: str = "d.dat", **kw):
    """Write `text` as folder/<name> and run it with folder as the output folder: (session, error)."""
    deck = folder / name
    deck.write_text(text)
    s = Session(out_dir=folder, stdout=io.StringIO(), **kw)
    try:
        s.call(deck)
    except Dec3dError as exc:
        return s, exc
    return s, None


def snapshot(folder: Path) -> dict:
    return {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file() and not p.is_symlink()}


def where(err):
    return Path(err.location.file).name, err.location.line, err.location.column


def test_a_save_onto_the_running_deck_is_refused_when_bound(tmp_path):
    text = BRICK + "model save 'd.dat'\n"
    s, err = run(tmp_path, text)
    assert err.message == (f"`d.dat` would replace the running deck ({tmp_path / 'd.dat'}), which this run "
                           "reads: a run never writes over its own inputs")
    assert where(err) == ("d.dat", 3, 12)
    assert s.model.blocks.n == 0                       # refused at binding: nothing ran
    assert (tmp_path / "d.dat").read_text() == text
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.dat"]


def test_dec3d_run_exits_2_and_names_the_place(tmp_path):
    deck = tmp_path / "deck.dat"
    text = BRICK + HIST + "history export 1 file 'deck.dat'\n"
    deck.write_text(text)
    r = subprocess.run([sys.executable, "-m", "dec3d", "run", str(deck), "-q"], capture_output=True, text=True,
                       cwd=ROOT, env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert r.returncode == 2
    assert f"{deck}:4:23: error: `deck.dat` would replace the running deck" in r.stderr
    assert "Traceback" not in r.stderr
    assert deck.read_text() == text
    assert sorted(p.name for p in tmp_path.iterdir()) == ["deck.dat"]


def test_a_log_file_onto_a_called_file_is_refused_before_the_call_is_read(tmp_path):
    inc = "block property density 2000\n"
    (tmp_path / "inc.dat").write_text(inc)
    s, err = run(tmp_path, BRICK + "program log-file 'inc.dat'\nprogram log on\nprogram call 'inc'\n")
    assert err.message.startswith(f"`inc.dat` would replace the deck `inc` ({tmp_path / 'inc.dat'}), which this run reads")
    assert where(err) == ("d.dat", 3, 18)
    assert (tmp_path / "inc.dat").read_text() == inc


def test_a_called_file_cannot_overwrite_its_caller(tmp_path):
    (tmp_path / "inc.dat").write_text("model save 'd.dat'\n")
    text = BRICK + "program call 'inc'\n"
    s, err = run(tmp_path, text)
    assert err.message.startswith("`d.dat` would replace the running deck")
    assert where(err) == ("inc.dat", 1, 12)
    assert (tmp_path / "d.dat").read_text() == text


def test_an_output_onto_the_restored_save_is_refused(tmp_path):
    s, err = run(tmp_path, BRICK + "model save 'stage1'\n", name="first.dat")
    assert err is None
    saved = (tmp_path / "stage1.sav").read_bytes()
    s, err = run(tmp_path, "model restore 'stage1'\nblock property density 3000\nmodel save 'stage1'\n")
    assert err.message == (f"`stage1.sav` would replace the file `stage1` ({tmp_path / 'stage1.sav'}), "
                           "which this run reads: a run never writes over its own inputs")
    assert where(err) == ("d.dat", 3, 12)
    assert (tmp_path / "stage1.sav").read_bytes() == saved
    # the same when the name comes from an expression: refused when the save runs, after the restore
    s, err = run(tmp_path, "model restore 'stage1'\n[n = 'stage' + string(1)]\nmodel save [n]\n")
    assert err.message == (f"`stage1.sav` would replace the state file `stage1` "
                           f"({tmp_path / 'stage1.sav'}), which this run reads: a run never writes over its own "
                           "inputs")
    assert where(err) == ("d.dat", 3, 12)
    assert s.model.blocks.n == 1                       # the restore ran
    assert (tmp_path / "stage1.sav").read_bytes() == saved


def test_a_save_the_run_wrote_may_be_restored_and_written_again(tmp_path):
    s, err = run(tmp_path, BRICK + "model save 'a'\nmodel restore 'a'\nmodel save 'a'\n")
    assert err is None and zipfile.is_zipfile(tmp_path / "a.sav")


def test_names_from_expressions_are_checked_when_the_command_runs(tmp_path):
    text = BRICK + "[f = 'd' + '.dat']\nmodel save [f]\n"
    s, err = run(tmp_path, text)
    assert err.message.startswith("`d.dat` would replace the running deck")
    assert where(err) == ("d.dat", 4, 12)
    assert s.model.blocks.n == 1                       # the lines before it ran
    assert (tmp_path / "d.dat").read_text() == text


def test_a_deck_called_at_run_time_is_an_input_too(tmp_path):
    inc = "block property density 2000\n"
    (tmp_path / "inc.dat").write_text(inc)
    s, err = run(tmp_path, BRICK + HIST + "[c = 'inc']\nprogram call [c]\nmodel cycle 2\n"
                 "history export 1 file [c + '.dat']\n")
    assert err.message.startswith(f"`inc.dat` would replace the deck `inc` ({tmp_path / 'inc.dat'})")
    assert where(err) == ("d.dat", 7, 23)
    assert (tmp_path / "inc.dat").read_text() == inc


@pytest.mark.parametrize("link", ["symlink", "hardlink"])
def test_a_link_to_the_deck_leads_to_the_deck(tmp_path, link):
    text = BRICK + "model save 'alias.sav'\n"
    deck = tmp_path / "d.dat"
    deck.write_text(text)
    (os.symlink if link == "symlink" else os.link)(deck, tmp_path / "alias.sav")
    s, err = run(tmp_path, text)
    assert "would replace the running deck" in err.message
    assert where(err) == ("d.dat", 3, 12)
    assert deck.read_text() == text


def test_a_second_run_replaces_its_own_outputs(tmp_path):
    text = (BRICK + HIST + "model cycle 3\nmodel save 'one'\nblock vtk 'v'\nhistory export 1 file 'h.csv'\n"
            "program log-file 'state.txt'\nprogram log on\n[io.out('done')]\nprogram log off\n")
    s, err = run(tmp_path, text)
    assert err is None
    s.close_log()
    first = snapshot(tmp_path)
    assert {"one.sav", "v.pvd", "v_0000.vtu", "h.csv", "h_1.png", "state.txt", MANIFEST} <= set(first)
    s, err = run(tmp_path, text)
    assert err is None
    s.close_log()
    again = snapshot(tmp_path)
    assert set(again) == set(first)
    assert all(again[k] == first[k] for k in first if k != "state.txt")   # deterministic outputs
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".dec3d-") and p.name != MANIFEST]


def test_a_file_dec3d_did_not_write_is_replaced_only_when_the_user_says_so(tmp_path):
    (tmp_path / "notes.txt").write_text("mine\n")
    (tmp_path / "old.sav").write_bytes(b"a 3DEC save, not a zip")
    for line, col, name in [("program log-file 'notes.txt'", 18, "notes.txt"), ("model save 'old'", 12, "old.sav")]:
        s, err = run(tmp_path, BRICK + line + "\n")
        assert err.message == (f"`{name}` would replace the existing file {tmp_path / name}, which dec3d did "
                               "not write (or which was changed since)")
        assert "--allow-overwrite" in err.hint
        assert where(err) == ("d.dat", 3, col)
    assert (tmp_path / "notes.txt").read_text() == "mine\n"
    assert (tmp_path / "old.sav").read_bytes() == b"a 3DEC save, not a zip"
    s, err = run(tmp_path, BRICK + "model save 'old'\n", allow_overwrite=True)
    assert err is None and zipfile.is_zipfile(tmp_path / "old.sav")
    # never the deck itself, even so
    s, err = run(tmp_path, BRICK + "model save 'd.dat'\n", allow_overwrite=True)
    assert "would replace the running deck" in err.message


def test_an_output_changed_by_the_user_since_is_not_replaced(tmp_path):
    text = BRICK + HIST + "model cycle 2\nhistory export 1 file 'h.csv'\n"
    s, err = run(tmp_path, text)
    assert err is None
    (tmp_path / "h.csv").write_text("edited by hand\n")
    s, err = run(tmp_path, text)
    assert err.message.startswith(f"`h.csv` would replace the existing file {tmp_path / 'h.csv'}")
    assert (tmp_path / "h.csv").read_text() == "edited by hand\n"


def test_the_manifest_is_not_an_output_a_deck_may_write(tmp_path):
    s, err = run(tmp_path, BRICK + f"program log-file '{MANIFEST}'\n")
    assert "dec3d's record of the files it wrote" in err.message
    assert where(err) == ("d.dat", 3, 18)


def test_ctrl_c_during_a_save_leaves_no_temporary_file_and_the_old_save_whole(tmp_path, monkeypatch):
    s, err = run(tmp_path, BRICK + "model save 'keep'\n")
    assert err is None
    before = snapshot(tmp_path)
    calls = []

    def interrupted(self, *a, **kw):
        calls.append(a[0])
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real_writestr(self, *a, **kw)

    real_writestr = zipfile.ZipFile.writestr
    monkeypatch.setattr(zipfile.ZipFile, "writestr", interrupted)
    with pytest.raises(KeyboardInterrupt):
        s.command("block property density 2000\nmodel save 'keep'\n")
    monkeypatch.undo()
    assert len(calls) == 2
    assert snapshot(tmp_path) == before                   # no temporary file; keep.sav has its bytes
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(before)


def test_batch_results_are_written_through_a_temporary_file_removed_on_ctrl_c(tmp_path, monkeypatch):
    from dec3d import batch

    path = tmp_path / "results.csv"
    path.write_text("old\n")

    def boom(*a, **kw):
        raise KeyboardInterrupt

    monkeypatch.setattr(batch.csv, "writer", boom)
    with pytest.raises(KeyboardInterrupt):
        batch._write_csv(path, [{"run": "a"}], ["run"])
    monkeypatch.undo()
    batch._write_json(tmp_path / "r.json", {"a": 1})
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.json", "results.csv"]
    assert path.read_text() == "old\n"


def test_without_the_record_saves_and_vtk_files_are_still_dec3d_s_own(tmp_path):
    text = BRICK + HIST + "model cycle 2\nmodel save 's'\nblock vtk 'v'\nhistory export 1 file 'h.csv'\n"
    s, err = run(tmp_path, text)
    assert err is None
    (tmp_path / MANIFEST).unlink()                     # outputs of a run from before the record existed
    s, err = run(tmp_path, text.replace("history export 1 file 'h.csv'\n", ""))
    assert err is None                                 # s.sav (a dec3d zip) and v.pvd / v_0000.vtu (VTK XML)
    s, err = run(tmp_path, text)
    assert err.message.startswith(f"`h.csv` would replace the existing file {tmp_path / 'h.csv'}")
    assert where(err) == ("d.dat", 7, 23)


def test_sessions_from_python_one_after_another_replace_their_own_outputs(tmp_path):
    """A deck run from Python (load_file + run_items, no `dec3d run`) records what it wrote when the
    top-level run_items ends, so the next session in the same folder may replace its log and tables."""
    import io

    from dec3d.session import Session

    deck = tmp_path / "d.dat"
    deck.write_text("program log on\n[a = 1]\nblock create brick 0 1 0 1 0 1\nmodel history mechanical ratio\n"
                    "block property density 1000\nmodel cycle 2\nhistory export '1' file 'h.csv'\n")
    for _ in range(2):
        s = Session(out_dir=tmp_path, stdout=io.StringIO())
        s.run_items(s.load_file(deck))
    assert (tmp_path / "dec3d.log").is_file() and (tmp_path / "h.csv").is_file()
    (tmp_path / "h.csv").write_text("edited by hand\n")          # changed since: kept
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    with pytest.raises(Exception, match="which dec3d did not write"):
        s.run_items(s.load_file(deck))
    assert (tmp_path / "h.csv").read_text() == "edited by hand\n"
