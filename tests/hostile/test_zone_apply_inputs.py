"""Hostile inputs to `block zone apply force…` / `block zone apply-remove`: non-finite values from
expressions are refused where they are written, huge body forces stop the run with the model kept, an
empty range or null zones change nothing, and a 10-node model's loads survive save and restore."""
import io

import numpy as np
import pytest

from dec3d.errors import CommandError
from dec3d.fish.values import FishValueError
from dec3d.session import Session

ZONED = """model new
model gravity 0 0 -10
block create brick 0 1 0 1 0 1
block zone generate edgelength 0.5
block zone cmodel assign elastic
block zone property young 1e9 poisson 0.25 density 2000
block gridpoint fix velocity range position-z 0
"""


def _deck(tmp_path, text):
    deck = tmp_path / "deck.dat"
    deck.write_text(text)
    return deck


@pytest.mark.parametrize("line, message", [
    ("block zone apply force 0 0 [1e308*10]", "numeric overflow: the result is not a finite number"),
    ("block zone apply force-z [1/0]", "division by zero"),
    ("block zone apply force-z [math.sqrt(-1)]", "outside its domain"),
])
def test_non_finite_expressions_are_refused_where_written(session, tmp_path, line, message):
    with pytest.raises(FishValueError) as e:
        session.call(_deck(tmp_path, ZONED + line + "\n"))
    assert message in e.value.message and e.value.location.line == 8
    zs = session.model.store("zones")
    assert "fbody" not in zs or not zs["fbody"].any()


@pytest.mark.parametrize("line", ["block zone apply force 0 0 1e308", "block zone apply force-x 1e200"])
def test_a_huge_body_force_stops_the_run_with_the_model_kept(session, tmp_path, line):
    with pytest.raises(CommandError) as e:
        session.call(_deck(tmp_path, ZONED + line + "\nmodel cycle 3\n"))
    assert "the model is back at its state before this command" in e.value.message
    v = session.model.vertices
    assert session.model.step == 0 and np.isfinite(v["pos"]).all() and not v["velocity"].any()


def _run(tmp_path, text):
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.run_items(s.load_text(text))
    return s.model.vertices["disp"].copy()


def test_an_empty_range_and_null_zones_take_no_load(tmp_path):
    null = "block zone cmodel assign null range position-z 0.5 1\n"
    want = _run(tmp_path, ZONED + null + "model cycle 10\n")
    got = _run(tmp_path, ZONED + null + "block zone apply force-z -1e5 range position-z 0.5 1\n"
               "block zone apply force-z -1e5 range position-z 100\nmodel cycle 10\n")
    assert np.array_equal(want, got)


def test_ten_node_loads_survive_save_and_restore(tmp_path):
    ten = ZONED.replace("model new\n", "model new\nmodel configure highorder\n") + \
        "block zone generate high-order-tetra\nblock zone apply force-z -1e5\n"
    once = _run(tmp_path, ten + "model cycle 6\n")
    saved = _run(tmp_path, ten + "model cycle 3\nmodel save 'z10'\nblock zone apply-remove\nmodel restore 'z10'\n"
                 "model cycle 3\n")
    assert np.abs(once).max() > 0 and np.array_equal(once, saved)
