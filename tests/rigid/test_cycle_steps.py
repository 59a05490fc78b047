"""The cycle as an ordered list of steps (`RigidEngine.steps`, built per run by `_Run`): the list a
rigid-only and a mixed rigid/zoned model get, and that the rigid batch cut into kernel calls of
one step each (Ctrl-C/progress granularity) changes no number."""
import io

import numpy as np

import dec3d
from dec3d.physics import rigid
from test_split_runs import stack

MIXED = """model new
block create brick 0 1 0 1 0 1
block create brick 0 1 0 1 1 2
block property density 2000
block zone generate edgelength 0.5 range position-z 0 1
block zone cmodel assign elastic
block zone property bulk 5e8 shear 3e8 density 2000
block gridpoint apply velocity 0 0 0 range position-z 0
model gravity 0 0 -10
block contact jmodel assign elastic
block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9
"""


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
        s.command(stack(2) + "model cycle 80\n")
        b = s.model.blocks
        return b["centroid"].copy(), b["velocity"].copy(), s.model.stores["subcontacts"]["fn"].copy()

    whole = state()
    monkeypatch.setattr(rigid, "CHUNK_SECONDS", 1e-15)     # every kernel call after the first: one step
    cut = state()
    assert np.abs(whole[1]).max() > 1e-5
    for a, b in zip(whole, cut):
        assert np.array_equal(a, b)
