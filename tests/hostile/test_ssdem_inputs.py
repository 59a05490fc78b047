"""Bad and hostile inputs of `dec3d ssdem` (issue 15): each ends in one clear error
naming file:line and field, exit status 2, no traceback, and nothing written outside
the output folder; resources are estimated before they are spent; result.json is the
same bytes on every run."""
import os
import subprocess
import sys
from pathlib import Path

import pytest

from dec3d.ssdem.cli import main

ROOT = Path(__file__).resolve().parents[2]
APPENDIX = ROOT / "tests" / "ssdem" / "data" / "appendix_a_example.txt"

SLOPE = """\
title = "robustness"
[profile]
points = [[0.0, 0.0], [10.0, 0.0], [30.0, 10.0], [45.0, 10.0]]
[[layer]]
c = 10.0
phi = 20.0
gamma = 20.0
kn = 3.5e5
ks = 1.0e5
[surface]
type = "circle"
centre = [12.0, 24.0]
radius = 24.0
[mesh]
slices = 6
rows = 1
[analysis]
steps = 2
"""
GRID = SLOPE[:SLOPE.index("[surface]")] + "[mesh]\nsize = 2.5\nbottom = -5.0\n[analysis]\nsteps = 2\n"


def tree(folder: Path) -> set:
    return {p.relative_to(folder) for p in folder.rglob("*")}


def run(tmp_path, capsys, name: str, content, *args) -> tuple[int, str, Path]:
    """Write `content` to tmp_path/name, run the CLI into tmp_path/out; check that only
    the input and (on success) out/ exist afterwards."""
    f = tmp_path / name
    if isinstance(content, bytes):
        f.write_bytes(content)
    else:
        f.write_text(content)
    out = tmp_path / "out"
    before = tree(tmp_path)
    rc = main([str(f), "--out", str(out), "--quiet", *args])
    err = capsys.readouterr().err
    assert "Traceback" not in err
    new = tree(tmp_path) - before
    assert all(p.parts[0] == "out" for p in new), new
    if rc != 0:
        assert not new, "a refused input wrote files"
    return rc, err, f


def first_line(err: str) -> str:
    return err.splitlines()[0]


def test_input_that_is_not_utf8(tmp_path, capsys):
    rc, err, f = run(tmp_path, capsys, "bin.toml", b"title = 'a'\n\xff\xfe = 1\n")
    assert rc == 2
    assert first_line(err) == (f"{f}:2:1: error: field '(file)': the file is not UTF-8 text "
                               "(byte 0xff at line 2, column 1)")
    text = APPENDIX.read_bytes().replace(b"1.5\t0.5", b"1.5\t0\xe9.5", 1)
    rc, err, f = run(tmp_path, capsys, "bin.txt", text)
    assert rc == 2 and first_line(err).startswith(f"{f}:3:6: error: field '(file)': the file is not UTF-8 text")


def test_utf8_byte_order_mark_is_accepted(tmp_path, capsys):
    rc, _, _ = run(tmp_path, capsys, "bom.toml", "\ufeff" + SLOPE)
    assert rc == 0 and (tmp_path / "out" / "result.json").is_file()


@pytest.mark.parametrize("value", ["[" * 5000 + "1" + "]" * 5000, "{b = " * 3000 + "1" + "}" * 3000])
def test_deeply_nested_toml(tmp_path, capsys, value):
    rc, err, f = run(tmp_path, capsys, "deep.toml", SLOPE + f"x = {value}\n")
    line = len(SLOPE.splitlines()) + 1
    col = len("x = ") + (33 if value[0] == "[" else 5 * 32 + 1)
    assert rc == 2
    assert first_line(err) == f"{f}:{line}:{col}: error: field '(syntax)': arrays or tables nested more than 32 deep"


def lines_with(line_no: int, new: str) -> str:
    lines = APPENDIX.read_text().splitlines()
    lines[line_no - 1] = new
    return "\n".join(lines) + "\n"


def test_appendix_a_missing_column_names_its_line_and_record(tmp_path, capsys):
    # line 8 holds the corners of block 1: "2 0 2 1 1 1 1 0", one value left out
    rc, err, f = run(tmp_path, capsys, "miss.txt", lines_with(8, "2 0 2 1 1 1 1"))
    assert rc == 2
    assert first_line(err) == (f"{f}:8:14: error: field 'nodes[1]': line 8 holds 7 of the 8 values "
                               "(x1 y1 x2 y2 x3 y3 x4 y4) of this record: 1 missing")
    # a spring line (item 8, block 2) short of one value
    rc, err, f = run(tmp_path, capsys, "miss2.txt", lines_with(23, "1e5 4e4 1e5 4e4 1e5 4e4 1e5"))
    assert rc == 2 and first_line(err).startswith(f"{f}:23:28: error: field 'springs[2]': line 23 holds 7 of the 8")


def test_appendix_a_extra_column_names_its_line_and_record(tmp_path, capsys):
    # line 13 holds the force on block 1: "0 0 0"
    rc, err, f = run(tmp_path, capsys, "extra.txt", lines_with(13, "0 0 0 7"))
    assert rc == 2
    assert first_line(err) == (f"{f}:13:7: error: field 'force[1]': line 13 holds 4 values, the record "
                               "has 3 values (fx fy m): 1 extra")
    rc, err, f = run(tmp_path, capsys, "extra2.txt", lines_with(27, "0 90 180 270 0"))
    assert rc == 2 and first_line(err).startswith(f"{f}:27:14: error: field 'angles[1]': line 27 holds 5 values")


def test_appendix_a_every_single_line_defect_is_named_at_its_line():
    """A value dropped from the end or the start of any line, or one added, of the
    example: the error names that line (the stream reading alone named line 18 or 30)."""
    from dec3d.ssdem.readers.appendix_a import read_appendix_a
    from dec3d.ssdem.readers.errors import SsdemInputError
    lines = APPENDIX.read_text().splitlines()
    checked = 0
    for no, line in enumerate(lines, start=1):
        toks = line.split()
        edits = [line + " 3"] + ([" ".join(toks[:-1]), " ".join(toks[1:])] if len(toks) > 1 else [])
        for new in edits:
            with pytest.raises(SsdemInputError) as exc:
                read_appendix_a(Path("a.txt"), text=lines_with(no, new))
            assert exc.value.line == no, (no, new, exc.value.message)
            checked += 1
    assert checked == 28 * 3 + 6          # 28 lines of several numbers, 6 of one


def test_appendix_a_free_layout_still_reads(tmp_path, capsys):
    """Line breaks are free in the format: all numbers on one line read as before."""
    rc, _, _ = run(tmp_path, capsys, "oneline.txt", " ".join(APPENDIX.read_text().split()) + "\n")
    assert rc == 0


def test_appendix_a_block_count_over_the_budget(tmp_path, capsys):
    rc, err, f = run(tmp_path, capsys, "huge.txt", lines_with(1, "1000000000000"))
    assert rc == 2
    assert first_line(err) == (f"{f}:1:1: error: field 'n_blocks': 1000000000000 blocks is over the budget of "
                               "200000 blocks (about 3.03e+07 GiB of memory)")
    assert "--max-blocks N" in err


def test_grid_size_over_the_budget_and_raising_it(tmp_path, capsys):
    text = GRID.replace("size = 2.5", "size = 0.01")
    rc, err, f = run(tmp_path, capsys, "fine.toml", text)
    line = text.splitlines().index("size = 0.01") + 1
    assert rc == 2
    # section area 10*5 + 20*10 + 15*15 = 475 m^2, over 0.01^2 m^2 per block (+ 4500 columns)
    assert first_line(err) == (f"{f}:{line}:1: error: field 'mesh.size': the mesh would have about 4.75e+06 "
                               "blocks (block size 0.01 over the section); the budget is 200000 blocks (about 6.05 GiB)")
    # a budget below this mesh refuses it; one above lets it run
    rc, err, _ = run(tmp_path, capsys, "grid.toml", GRID, "--max-blocks", "50")
    assert rc == 2 and "the budget is 50 blocks" in err
    rc, _, _ = run(tmp_path, capsys, "grid.toml", GRID, "--max-blocks", "500")
    assert rc == 0


def test_slices_over_the_budget(tmp_path, capsys):
    text = SLOPE.replace("slices = 6", "slices = 100000000")
    rc, err, f = run(tmp_path, capsys, "slices.toml", text)
    line = text.splitlines().index("slices = 100000000") + 1
    assert rc == 2
    assert first_line(err) == (f"{f}:{line}:1: error: field 'mesh.slices': the mesh would have about 2e+08 blocks "
                               "(100000000 slices of 1 rows); the budget is 200000 blocks (about 6.05 GiB)")


@pytest.mark.parametrize("key", ["steps", "max_iterations"])
def test_load_steps_and_iterations_are_bounded(tmp_path, capsys, key):
    text = SLOPE.replace("steps = 2", f"{key} = 100000000")
    rc, err, f = run(tmp_path, capsys, "steps.toml", text)
    line = text.splitlines().index(f"{key} = 100000000") + 1
    assert rc == 2
    assert first_line(err) == f"{f}:{line}:1: error: field 'analysis.{key}': must be <= 10000, got 100000000"


def test_result_json_is_the_same_bytes_on_every_run(tmp_path, capsys):
    f = tmp_path / "slope.toml"
    f.write_text(SLOPE)
    assert main([str(f), "--out", str(tmp_path / "a"), "--quiet", "--compare", "bishop"]) == 0
    assert main([str(f), "--out", str(tmp_path / "b"), "--quiet", "--compare", "bishop"]) == 0
    assert (tmp_path / "a" / "result.json").read_bytes() == (tmp_path / "b" / "result.json").read_bytes()
    assert b"timings" not in (tmp_path / "a" / "result.json").read_bytes()
    assert b'"solve"' in (tmp_path / "a" / "timings.json").read_bytes()


def test_a_symlink_in_the_output_folder_is_not_followed(tmp_path, capsys):
    outside = tmp_path / "elsewhere.txt"
    outside.write_text("keep me")
    out = tmp_path / "out"
    out.mkdir()
    (out / "summary.txt").symlink_to(outside)
    f = tmp_path / "slope.toml"
    f.write_text(SLOPE)
    assert main([str(f), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert first_line(err) == (f"dec3d ssdem: error: {out / 'summary.txt'} is a symbolic link or not a regular "
                               "file; dec3d ssdem writes only regular files inside the output folder (remove it first)")
    assert outside.read_text() == "keep me" and sorted(p.name for p in out.iterdir()) == ["summary.txt"]


def test_out_that_is_a_file_and_input_that_is_not(tmp_path, capsys):
    f = tmp_path / "slope.toml"
    f.write_text(SLOPE)
    assert main([str(f), "--out", str(f), "--quiet"]) == 2
    assert first_line(capsys.readouterr().err) == f"dec3d ssdem: error: --out {f}: exists and is not a folder"
    assert main([str(tmp_path), "--quiet"]) == 2
    assert first_line(capsys.readouterr().err) == f"dec3d ssdem: error: {tmp_path} is not a regular file"


def test_default_output_folder_is_named_after_the_input_beside_the_working_folder(tmp_path):
    """Without --out the files go to ./<stem>_ssdem; the stem is a name, not a path."""
    deck = tmp_path / "in" / "..slope.toml"
    deck.parent.mkdir()
    deck.write_text(SLOPE)
    work = tmp_path / "work"
    work.mkdir()
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    p = subprocess.run([sys.executable, "-m", "dec3d", "ssdem", str(deck), "--quiet"], cwd=work, env=env,
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0 and "Traceback" not in p.stderr
    assert [q.name for q in work.iterdir()] == ["..slope_ssdem"]
    assert sorted(q.name for q in tmp_path.iterdir()) == ["in", "work"]
    assert sorted(q.name for q in deck.parent.iterdir()) == ["..slope.toml"]


def test_coordinates_that_would_overflow_are_refused(tmp_path, capsys):
    text = SLOPE.replace("[30.0, 10.0], [45.0, 10.0]", "[30.0, 1e300], [45.0, 1e300]")
    rc, err, f = run(tmp_path, capsys, "huge.toml", text)
    assert rc == 2
    assert first_line(err) == (f"{f}:3:1: error: field 'profile.points': coordinates must be between -1e+09 "
                               "and 1e+09, got 1e+300")
    rc, err, f = run(tmp_path, capsys, "radius.toml", SLOPE.replace("radius = 24.0", "radius = 1e200"))
    assert rc == 2
    assert first_line(err) == f"{f}:13:1: error: field 'surface.radius': must be between -1e+09 and 1e+09, got 1e+200"


def test_critical_circle_on_flat_ground_is_a_clean_error(tmp_path, capsys):
    """Nothing drives a slip on flat unloaded ground: no circle, said so (not FS 1e15)."""
    text = SLOPE.replace("[[0.0, 0.0], [10.0, 0.0], [30.0, 10.0], [45.0, 10.0]]", "[[0.0, 0.0], [45.0, 0.0]]")
    text = text.replace('type = "circle"\ncentre = [12.0, 24.0]\nradius = 24.0', 'type = "critical"\nbottom = -10.0')
    rc, err, f = run(tmp_path, capsys, "flat.toml", text)
    assert rc == 2
    assert first_line(err) == f"{f}:11:1: error: field 'surface.type': the circle search found no valid slip circle"
    assert "RuntimeWarning" not in err


def test_control_characters_of_the_input_are_not_written_raw(tmp_path, capsys):
    """Issue 35: a title (or a layer name) holding ESC sequences reached summary.txt as raw bytes, which
    a terminal runs when the file is shown; they are written as visible escapes."""
    text = SLOPE.replace('title = "robustness"', 'title = "rob\\u001b[31mustness"').replace(
        "[[layer]]\n", '[[layer]]\nname = "clay\\u001b]0;owned\\u0007"\n', 1)
    rc, _, _ = run(tmp_path, capsys, "esc.toml", text)
    assert rc == 0
    for name in ("summary.txt", "blocks.csv", "interfaces.csv", "steps.csv", "result.json"):
        data = (tmp_path / "out" / name).read_bytes()
        assert b"\x1b" not in data and b"\x07" not in data, name
    assert "rob\\x1b[31mustness" in (tmp_path / "out" / "summary.txt").read_text()
