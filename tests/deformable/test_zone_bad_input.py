"""Bad input of issue 10 on zoned blocks: gridpoint ranges that select nothing warn with file:line
and change nothing; zone properties missing at cycle time name the blocks and the `model cycle`
line; negative and inconsistent moduli are refused where they are given, nothing changed."""
import numpy as np
import pytest

from dec3d.errors import Dec3dError
from dec3d.session import Session


def _cube(tmp_path, *extra):
    s = Session(out_dir=tmp_path)
    s.command("block create brick 0 1 0 1 0 1\nblock create brick 3 4 0 1 0 1\n"
              "block zone generate edgelength 0.5 range position-x 0 1")
    for line in extra:
        s.command(line)
    lines = []
    s.write = lines.append
    return s, lines


def _gp_state(s):
    v = s.model.vertices
    return {k: v[k].copy() for k in ("fapp", "disp", "velocity", "fixity")}


@pytest.mark.parametrize("line,what", [
    ("block gridpoint apply velocity-z 0 range position-z 5", "block gridpoint apply"),
    ("block gridpoint apply force 0 0 -1e3 range position-z 5", "block gridpoint apply"),
    ("block gridpoint apply-remove velocity range position-z 5", "block gridpoint apply-remove"),
    ("block gridpoint initialize velocity-x 0.1 range position-z 5", "block gridpoint initialize"),
    ("block gridpoint initialize displacement 1 2 3 range position-z 5", "block gridpoint initialize"),
])
def test_gridpoint_range_that_selects_nothing_warns_with_its_line(tmp_path, line, what):
    s, lines = _cube(tmp_path, "block gridpoint apply velocity-z 0 range position-z 0")
    before = _gp_state(s)
    s.command(line)
    warn = [ln for ln in lines if ln.startswith("warning:")]
    # one warning, the range's own (dec3d.lang.unsupported.empty_range), at the range's column
    assert len(warn) == 1 and "the range selects no gridpoint" in warn[0], (what, warn)
    assert f":1:{line.index('position-z') + 1}:" in warn[0]
    after = _gp_state(s)
    assert all(np.array_equal(before[k], after[k]) for k in before)


def test_gridpoint_range_on_a_rigid_block_says_why(tmp_path):
    """The range holds the rigid block's vertices only: the warning says they are not gridpoints."""
    s, lines = _cube(tmp_path)
    s.command("block gridpoint apply velocity 0 0 0 range position-x 3 4")
    assert any("selected no gridpoint (the range holds only vertices of rigid blocks" in ln for ln in lines)
    assert not s.model.vertices["fapp"].any()


def test_missing_properties_at_cycle_time_name_blocks_and_the_cycle_line(tmp_path):
    deck = tmp_path / "d.dat"
    deck.write_text("block create brick 0 1 0 1 0 1\nblock create brick 2 3 0 1 0 1\n"
                    "block zone generate edgelength 0.5\nblock zone cmodel assign elastic\n"
                    "block zone property young 1e9 poisson 0.2 density 2000 range position-x 0 1\n"
                    "model cycle 3\n")
    s = Session(out_dir=tmp_path)
    with pytest.raises(Dec3dError, match=r"bulk must be > 0 Pa \(not set\): 43 zone\(s\) of blocks 2 .*density must be > 0 kg/m³ \(not set\): "
                       r"43 zone\(s\) of blocks 2") as exc:
        s.call(deck)
    loc = exc.value.location
    assert loc is not None and loc.line == 6                 # the `model cycle` line
    assert s.model.step == 0 and not s.model.vertices["disp"].any()


@pytest.mark.parametrize("line,msg", [
    ("block zone property bulk -3e9 shear 1e9", r"`bulk` must be in \(0, 1e\+16\]"),
    ("block zone property shear -1e9 bulk 3e9", r"`shear` must be in \(0, 1e\+16\]"),
    ("block zone property young 0 poisson 0.2", r"`young` must be in \(0, 1e\+16\]"),
    ("block zone property young 1e9 poisson 0.7", r"`poisson` must be in \(-1, 0.5\)"),
    ("block zone property young 1e9 poisson -1.5", r"`poisson` must be in \(-1, 0.5\)"),
    ("block zone property bulk 3e9 poisson 0.2", "give bulk/shear or young/poisson, not both"),
])
def test_negative_or_inconsistent_moduli_are_refused(tmp_path, line, msg):
    s, _ = _cube(tmp_path, "block zone cmodel assign elastic", "block zone property bulk 3e9 shear 2e9 density 2e3")
    before = s.model.store("zones")["prop"].copy()
    with pytest.raises(Dec3dError, match=msg) as exc:
        s.command(line)
    assert exc.value.location is not None and exc.value.location.line == 1
    assert np.array_equal(s.model.store("zones")["prop"], before)
