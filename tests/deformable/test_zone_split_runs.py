"""A model with a rigid block resting on a zoned block: a run split into two `model cycle`
commands, or saved and restored between them, takes exactly the steps of one run — also when
the split falls between two contact detections (Δt and the surface-triangle weights of the
contact points are the ones the last run was using, kept in the settings and contact stores)."""
import io

import numpy as np
import pytest

import dec3d

DECK = """model new
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


def run(tmp_path, chunks, save_at=None):
    s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command(DECK)
    for i, c in enumerate(chunks):
        s.command(f"model cycle {c}")
        if save_at == i:
            s.command("model save 'z'")
            s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
            s.command("model restore 'z'")
    m = s.model
    return (m.vertices["pos"].copy(), m.vertices["velocity"].copy(), m.stores["zones"]["stress"].copy(),
            m.blocks["velocity"].copy(), m.stores["subcontacts"]["fn"].copy())


@pytest.mark.parametrize("save", [False, True])
def test_mixed_model_split_between_detections_is_one_run(tmp_path, save):
    one = run(tmp_path, [120])
    split = run(tmp_path, [47, 73], save_at=0 if save else None)
    assert np.abs(one[3]).max() > 1e-6 and one[4].sum() > 0      # the rigid block is moving and in contact
    for a, b in zip(one, split):
        assert np.array_equal(a, b)
