"""Files a deck writes stay in the output folder; reads look beside the deck, then there.

Every case runs in a tmp folder holding the deck folder `deck/`, the output folder `out/` and a
sibling `outside/`; the whole tree is listed (with every file's bytes) before and after, and
nothing outside `out/` may appear or change. Refused names stop the deck when it is bound
(nothing runs: the model has no blocks) with the exact message at the name's line and column.
"""
import errno
import io
import os
import subprocess
import sys
from pathlib import Path

import pytest

from dec3d.errors import Dec3dError
from dec3d.session import Session

ROOT = Path(__file__).resolve().parents[2]
BRICK = "block create brick 0 1 0 1 0 1\nblock property density 1000\n"


@pytest.fixture
def tree(tmp_path):
    for d in ("deck", "out", "outside"):
        (tmp_path / d).mkdir()
    (tmp_path / "outside" / "keep.txt").write_text("precious\n")
    return tmp_path


def listing(root: Path) -> dict[str, bytes | str]:
    """Every path under root: file bytes, 'dir', or 'link -> target'."""
    out = {}
    for p in sorted(root.rglob("*")):
        rel = str(p.relative_to(root))
        if p.is_symlink():
            out[rel] = "link -> " + os.readlink(p)
        elif p.is_dir():
            out[rel] = "dir"
        else:
            out[rel] = p.read_bytes()
    return out


def changes_outside_out(before, after):
    """Paths added, removed or changed that are not under out/."""
    keys = set(before) | set(after)
    return sorted(k for k in keys if before.get(k) != after.get(k) and not k.startswith("out/"))


def run_deck_text(tree, text, allow=False, name="d.dat"):
    """Bind and run `text` as deck/<name> with out/ as the output folder; returns (session, error)."""
    deck = tree / "deck" / name
    deck.write_text(text)
    s = Session(out_dir=tree / "out", stdout=io.StringIO(), allow_outside_paths=allow)
    try:
        s.call(deck)
    except Dec3dError as exc:
        return s, exc
    return s, None


REFUSED = [
    # (line 3 of the deck, column of the name, message); {out}/{outside} are filled in
    ("block vtk '../../x'", 11, "`../../x.pvd` is outside the output folder {out}: a deck writes only there"),
    ("block vtk '.'", 11, "`.` names a folder, not a file"),
    ("block vtk filename 'a/..'", 20, "`a/..` names a folder, not a file"),
    ("model save '../deck/d.dat'", 12, "`../deck/d.dat` is outside the output folder {out}: a deck writes only there"),
    ("model save '{outside}/x'", 12, "`{outside}/x.sav` is outside the output folder {out}: a deck writes only there"),
    ("model save '/dev/full'", 12, "`/dev/full.sav` is outside the output folder {out}: a deck writes only there"),
    ("model save 'sub/'", 12, "`sub/` names a folder, not a file"),
    ("history export 1 file '../h.csv'", 23, "`../h.csv` is outside the output folder {out}: a deck writes only there"),
    ("history export 1 file '.'", 23, "`.` names a folder, not a file"),
    ("program log-file '../deck/d.dat'", 18,
     "`../deck/d.dat` is outside the output folder {out}: a deck writes only there"),
    ("program log-file '{outside}/.bashrc' append", 18,
     "`{outside}/.bashrc` is outside the output folder {out}: a deck writes only there"),
    ("model save '" + "n" * 300 + "'", 12, "`" + "n" * 159 + "…` is longer than 255 bytes, too long for a file name"),
    ("model save 'link/x'", 12, "`link/x.sav` is outside the output folder {out}: a deck writes only there"),
    ("block vtk 'link/v'", 11, "`link/v.pvd` is outside the output folder {out}: a deck writes only there"),
]


@pytest.mark.parametrize("line,col,message", REFUSED, ids=[r[0][:40] for r in REFUSED])
def test_a_write_that_leaves_the_output_folder_is_refused_when_bound(tree, line, col, message):
    (tree / "out" / "link").symlink_to(tree / "outside")        # a symlink inside out/ that points out
    fill = {"out": tree / "out", "outside": tree / "outside"}
    before = listing(tree)
    s, err = run_deck_text(tree, BRICK + line.format(**fill) + "\nblock vtk 'after'\n")
    assert err is not None
    assert err.message == message.format(**fill)
    assert (Path(err.location.file).name, err.location.line, err.location.column) == ("d.dat", 3, col)
    assert s.model.blocks.n == 0                  # refused at binding: nothing ran
    after = listing(tree)
    assert changes_outside_out(before, after) == ["deck/d.dat"]     # only the deck this test wrote
    assert {k for k in after if k.startswith("out/")} == {"out/link"}


def test_allowed_writes_land_in_the_output_folder(tree):
    before = listing(tree)
    s, err = run_deck_text(tree, BRICK + "block history displacement-z position 0.5 0.5 0.5\n"
                                        "model cycle 20\nmodel save 'stage/one'\nmodel save '{}'\n"
                                        "block vtk 'v.vtu'\nhistory export 1 file 'h.csv'\n"
                                        "program log-file 'run.log'\nprogram log on\n[io.out('done')]\n"
                           .format(tree / "out" / "abs.sav"))
    assert err is None
    s.close_log()
    after = listing(tree)
    assert changes_outside_out(before, after) == ["deck/d.dat"]
    assert sorted(k for k in after if k.startswith("out/")) == [
        "out/.dec3d-outputs.json", "out/abs.sav", "out/h.csv", "out/h_1.png", "out/run.log", "out/stage", "out/stage/one.sav",
        "out/v.pvd", "out/v_0000.vtu"]
    assert after["out/run.log"].decode().splitlines()[-1] == "done"


def test_a_name_given_by_an_expression_is_checked_when_it_runs(tree):
    before = listing(tree)
    s, err = run_deck_text(tree, BRICK + "[f = '../outside/evil']\nmodel save [f]\n")
    assert err.message == f"`../outside/evil.sav` is outside the output folder {tree / 'out'}: a deck writes only there"
    assert (err.location.line, err.location.column) == (4, 12)
    assert s.model.blocks.n == 1                   # the commands before it ran
    assert changes_outside_out(before, listing(tree)) == ["deck/d.dat"]


def test_a_history_name_cannot_steer_the_plot_file(tree):
    s, err = run_deck_text(tree, BRICK + "block history name '../../evil' displacement-z position 0.5 0.5 0.5\n"
                                         "model cycle 10\nhistory export '../../evil' file 'h.csv'\n")
    assert err is None
    assert sorted(p.name for p in (tree / "out").iterdir()) == [".dec3d-outputs.json", "h.csv", "h_.._.._evil.png"]
    assert sorted(p.name for p in tree.iterdir()) == ["deck", "out", "outside"]


def test_the_flag_lets_a_trusted_deck_write_outside_but_never_to_a_device(tree):
    s, err = run_deck_text(tree, BRICK + f"model save '{tree / 'outside' / 'x'}'\n", allow=True)
    assert err is None and (tree / "outside" / "x.sav").is_file()
    s, err = run_deck_text(tree, BRICK + "program log-file '/dev/full'\n", allow=True)
    assert err.message == "`/dev/full` is a device, not a regular file: dec3d writes only regular files"
    assert err.location.line == 3


# ---------------------------------------------------------------- reads


def test_program_call_of_a_system_file_is_refused_without_showing_it(tree):
    s, err = run_deck_text(tree, BRICK + "program call '/etc/passwd'\n")
    text = err.format()
    assert err.message == ("`/etc/passwd` is outside the deck's folder and the output folder: a deck reads "
                           "only there")
    assert (err.location.line, err.location.column) == (3, 14)
    assert "root:" not in text and s.model.blocks.n == 0


@pytest.mark.parametrize("allow", [False, True])
def test_a_device_behind_a_link_is_never_read(tree, allow):
    (tree / "deck" / "z.dat").symlink_to("/dev/zero")
    s, err = run_deck_text(tree, BRICK + "call 'z'\n", allow=allow)
    assert err.message == f"`z` ({tree / 'deck' / 'z.dat'}) is a device, not a regular file: dec3d reads only regular files"
    assert err.location.line == 3 and s.model.blocks.n == 0


def test_dev_zero_as_a_top_level_deck_is_refused():
    with pytest.raises(Dec3dError) as e:
        Session(stdout=io.StringIO()).call("/dev/zero")
    assert e.value.message == "cannot read deck `/dev/zero`: it is a device, not a regular file"


def test_an_include_cycle_through_another_spelling_is_refused(tree):
    (tree / "deck" / "sub").mkdir()
    s, err = run_deck_text(tree, BRICK + "program call 'sub/../d.dat'\n")
    assert err.message == "`d.dat` calls itself (directly or through other files)"
    assert (err.location.line, err.location.column) == (3, 1)


def test_a_deck_calling_itself_by_an_expression_stops_cleanly(tree):
    s, err = run_deck_text(tree, BRICK + "[n = 'd.dat']\nprogram call [n]\n")
    assert err.message == "`d.dat` calls itself (directly or through other files)"
    assert (err.location.line, err.location.column) == (4, 1)
    assert s.model.blocks.n == 1


def test_calls_look_beside_the_calling_deck_then_in_the_output_folder(tree):
    (tree / "deck" / "sub").mkdir()
    (tree / "deck" / "sub" / "inner.dat").write_text("call 'part'\n")          # part.dat beside inner.dat
    (tree / "deck" / "sub" / "part.dat").write_text("block create brick 0 1 0 1 5 6\n")
    (tree / "out" / "generated.dat").write_text("block create brick 0 1 0 1 9 10\n")
    s, err = run_deck_text(tree, BRICK + "call 'sub/inner'\ncall 'generated'\n")
    assert err is None and s.model.blocks.n == 3


def test_restore_finds_a_file_beside_the_deck_and_one_saved_in_the_output_folder(tree):
    s, err = run_deck_text(tree, BRICK + "model save 'shipped'\n")
    (tree / "out" / "shipped.sav").rename(tree / "deck" / "shipped.sav")
    s, err = run_deck_text(tree, "model restore 'shipped'\nmodel save 'mine'\nmodel new\nmodel restore 'mine'\n")
    assert err is None and s.model.blocks.n == 1


def test_restore_of_a_missing_file_says_where_it_looked(tree):
    s, err = run_deck_text(tree, "model restore 'gone'\n")
    d, o = tree / "deck", tree / "out"
    assert err.message == (f"cannot read state file `gone`: no such file (looked for {d}/gone.sav, {d}/gone, "
                           f"{o}/gone.sav, {o}/gone)")
    assert (err.location.line, err.location.column) == (1, 15)


# ---------------------------------------------------------------- run-time write errors


def test_a_full_disk_under_the_log_is_one_clean_error(tree, monkeypatch):
    s = Session(out_dir=tree / "out", stdout=io.StringIO())
    s.command("program log on")

    class Full(io.StringIO):
        def write(self, text):
            raise OSError(errno.ENOSPC, "No space left on device")

    s._log_handle = Full()
    with pytest.raises(Dec3dError) as e:
        s.command("[io.out('x')]")
    assert e.value.message == (f"cannot write the log file '{tree / 'out' / 'dec3d.log'}': no space left on the "
                               "device; logging is off")
    s.command("[io.out('still here')]")          # the session goes on, logging off
    assert s.stdout.getvalue().splitlines()[-1] == "still here"


def test_an_os_error_while_writing_is_a_command_error(tree, monkeypatch):
    import dec3d.io.vtk as vtk

    def full(*a, **k):
        raise OSError(errno.ENOSPC, "No space left on device", "v_0000.vtu")

    monkeypatch.setattr(vtk, "write_vtu", full)
    s = Session(out_dir=tree / "out", stdout=io.StringIO())
    with pytest.raises(Dec3dError) as e:
        s.command("block create brick 0 1 0 1 0 1\nblock vtk 'v'")
    assert e.value.message == "file error 'v_0000.vtu': no space left on the device"
    assert e.value.location.line == 2


# ---------------------------------------------------------------- through the command line


def dec3d(*args, cwd=None):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.run([sys.executable, "-m", "dec3d", *map(str, args)], capture_output=True, text=True,
                          env=env, cwd=cwd or ROOT, timeout=300)


def test_cli_refuses_overwriting_the_deck_with_status_2(tree):
    deck = tree / "deck" / "d.dat"
    deck.write_text(BRICK + "model save '../deck/d.dat'\n")
    before = listing(tree)
    r = dec3d("run", deck, "--out", tree / "out", "-q")
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert r.stderr.splitlines()[0] == (f"{deck}:3:12: error: `../deck/d.dat` is outside the output folder "
                                        f"{tree / 'out'}: a deck writes only there")
    assert listing(tree) == before


def test_cli_out_that_is_a_file_is_refused(tree):
    (tree / "out.txt").write_text("x")
    deck = tree / "deck" / "d.dat"
    deck.write_text(BRICK)
    r = dec3d("run", deck, "--out", tree / "out.txt", "-q")
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert r.stderr.strip() == f"error: the output folder '{tree / 'out.txt'}' cannot be used: is a file, not a folder"


def test_cli_run_time_write_failure_is_status_1_without_traceback(tree):
    (tree / "out" / "sub").write_text("a file where a folder should be")
    deck = tree / "deck" / "d.dat"
    deck.write_text(BRICK + "block vtk 'sub/v'\n")
    r = dec3d("run", deck, "--out", tree / "out", "-q")
    assert r.returncode == 1 and "Traceback" not in r.stderr
    assert r.stderr.splitlines()[0] == (f"{deck}:3:1: error: file error '{tree / 'out' / 'sub'}': a file stands "
                                        "where a folder is needed")


def test_cli_flag_widens_the_rules(tree):
    deck = tree / "deck" / "d.dat"
    deck.write_text(BRICK + f"model save '{tree / 'outside' / 'y'}'\n")
    r = dec3d("run", deck, "--out", tree / "out", "-q", "--allow-outside-paths")
    assert r.returncode == 0, r.stderr
    assert (tree / "outside" / "y.sav").is_file()


def test_a_link_beside_the_deck_to_a_file_outside_is_refused(tree):
    (tree / "outside" / "lib.dat").write_text("block create brick 0 1 0 1 0 1\n")
    (tree / "deck" / "lib.dat").symlink_to(tree / "outside" / "lib.dat")
    s, err = run_deck_text(tree, BRICK + "call 'lib'\n")
    assert err.message == (f"`lib` ({tree / 'outside' / 'lib.dat'}) is outside the deck's folder and the output "
                           "folder: a deck reads only there")
    s, err = run_deck_text(tree, BRICK + "call 'lib'\n", allow=True)
    assert err is None and s.model.blocks.n == 2


def test_a_read_that_climbs_out_is_refused_when_bound(tree):
    (tree / "outside" / "x.sav").write_bytes(b"")
    s, err = run_deck_text(tree, BRICK + "model cycle 1\nmodel restore '../outside/x'\n")
    assert err.message == ("`../outside/x` is outside the deck's folder and the output folder: a deck reads "
                           "only there")
    assert (err.location.line, err.location.column) == (4, 15) and s.model.blocks.n == 0


@pytest.mark.skipif(hasattr(os, "geteuid") and os.geteuid() == 0, reason="root may write into a read-only folder")
def test_cli_read_only_out_is_refused(tree):
    ro = tree / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    deck = tree / "deck" / "d.dat"
    deck.write_text(BRICK + "model save 's'\n")
    try:
        r = dec3d("run", deck, "--out", ro, "-q")
    finally:
        ro.chmod(0o755)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert r.stderr.strip() == f"error: the output folder '{ro}' cannot be used: Permission denied"


def test_a_deck_with_a_byte_order_mark_runs(tree):
    deck = tree / "deck" / "bom.dat"
    deck.write_bytes(b"\xef\xbb\xbf" + BRICK.encode())
    s = Session(out_dir=tree / "out", stdout=io.StringIO())
    s.call(deck)
    assert s.model.blocks.n == 1


def test_a_restore_reads_what_the_run_saved_not_an_older_copy_beside_the_deck(tree):
    s, err = run_deck_text(tree, BRICK + "block create brick 0 1 0 1 3 4\nmodel save 'stage'\n")
    (tree / "out" / "stage.sav").rename(tree / "deck" / "stage.sav")          # 2 blocks, from an earlier run
    s, err = run_deck_text(tree, BRICK + "model save 'stage'\nmodel new\nmodel restore 'stage'\n")
    assert err is None and s.model.blocks.n == 1


def test_control_characters_in_a_refused_name_are_not_echoed(tree):
    s, err = run_deck_text(tree, BRICK + "model save '../\x1b[2Jx'\n")
    # a control character inside a string is a syntax error (the deck never runs); the message
    # shows it as an escape, so the terminal is not driven
    assert err.message == "control character \\x1b in a string"
    assert "\x1b" not in err.format()
