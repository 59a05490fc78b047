"""Zoned blocks do not cycle yet: `model cycle` says so and changes nothing (it must never
quietly move a zoned block as a rigid body)."""
import numpy as np
import pytest

from dec3d.errors import Dec3dError
from dec3d.session import Session


def test_cycling_a_zoned_model_is_refused_and_changes_nothing(tmp_path):
    s = Session(out_dir=tmp_path)
    for line in ("block create brick 0 1 0 1 0 1", "block create brick 0 1 0 1 -1 0", "block property density 2000",
                 "block fix range position-z -1 0", "model gravity 9.81",
                 "block zone generate edgelength 0.5 range position-z 0 1"):
        s.command(line)
    before = s.model.vertices["pos"].copy()
    with pytest.raises(Dec3dError, match="zoned .deformable. blocks do not cycle yet"):
        s.command("model cycle 10")
    assert s.model.step == 0 and np.array_equal(s.model.vertices["pos"], before)
