"""The cycle as an ordered list of steps (`RigidEngine.steps`, built per run by `_Run`): the list a
rigid-only and a mixed rigid/zoned model get, and that the rigid batch cut into kernel calls of
one step each (Ctrl-C/progress granularity) changes no number."""
import io
import sys
from pathlib import Path

import numpy as np

import dec3d
from dec3d.physics import steps
from test_split_runs import stack

sys.path.insert(0, str(Path(__file__).parents[1] / "deformable"))
from test_zone_split_runs import DECK as MIXED  # noqa: E402  (a rigid block on a zoned one)


def names(s):
    return [repr(st) for st in s.model.rigid_engine.steps]


def test_rigid_model_steps(tmp_path):
    s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command(stack(2) + "model cycle 30\n")
    e = s.model.rigid_engine
    assert names(s) == ["RigidBatch", "Clock", "Hooks"]
    assert s.model.step == 30 and e.steps[0].run.done == 30
    assert e.timings["cycle"] > 0.0


def test_mixed_model_steps(tmp_path):
    s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command(MIXED + "model cycle 20\n")
    assert names(s) == ["MixedContacts", "RigidBatch", "ZoneStep", "Clock", "Hooks"]
    run = s.model.rigid_engine.steps[0].run
    assert run.mixed and run.done == 20
    assert np.abs(s.model.blocks["velocity"]).max() > 0.0     # the rigid block moved (MixedContacts ran)


def test_rigid_batch_in_one_step_calls_is_bit_identical(tmp_path, monkeypatch):
    def state():
        s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
        s.command(stack(2) + "model cycle 30\n")        # (the default body scaling settles it in ~80)
        b = s.model.blocks
        return b["centroid"].copy(), b["velocity"].copy(), s.model.stores["subcontacts"]["fn"].copy()

    whole = state()
    monkeypatch.setattr(steps, "CHUNK_SECONDS", 1e-15)     # every kernel call after the first: one step
    cut = state()
    assert np.abs(whole[1]).max() > 1e-5
    for a, b in zip(whole, cut):
        assert np.array_equal(a, b)
