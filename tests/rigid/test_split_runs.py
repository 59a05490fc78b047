"""A run split into several `model cycle` commands takes exactly the steps of one run.

Found on the cube-stack benchmark: each `model cycle` worked Δt out afresh from the contact
stiffnesses it found, while one long run kept the Δt of its first step, so a 3 × 3 × 3 stack
cycled as 10 × `model cycle 10` differed from `model cycle 100` by as much as its own speeds
(and reached equilibrium 2.8× sooner). Δt now follows the stiffnesses at every detection, and
a run that starts between detections goes on with the Δt the last run used there.
"""
import io

import numpy as np
import pytest

import dec3d


def stack(n: int) -> str:
    lines = ["model new", f"block create brick 0 {n} 0 {n} -1 0"]
    lines += [f"block create brick {i} {i + 1} {j} {j + 1} {k} {k + 1}"
              for i in range(n) for j in range(n) for k in range(n)]
    lines += ["block property density 2600", "block fix range position-z -1 0", "model gravity 0 0 -9.81",
              "block contact jmodel assign mohr",
              "block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 "
              "friction 34.38"]
    return "\n".join(lines) + "\n"


def run(tmp_path, chunks, save_at=None):
    s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command(stack(3))
    for i, c in enumerate(chunks):
        s.command(f"model cycle {c}")
        if save_at == i:
            s.command("model save 'mid'")
            s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
            s.command("model restore 'mid'")
    b = s.model.blocks
    return s.model.step, b["centroid"].copy(), b["velocity"].copy(), s.model.stores["subcontacts"]["fn"].copy()


@pytest.mark.parametrize("chunks", [[10] * 12, [7] * 17 + [1], [3, 50, 13, 54]])
def test_split_run_is_bit_identical_to_one_run(tmp_path, chunks):
    total = sum(chunks)
    one = run(tmp_path, [total])
    split = run(tmp_path, chunks)
    assert one[0] == split[0] == total
    assert np.abs(one[2]).max() > 1e-4          # the stack is still moving: the comparison means something
    for a, b in zip(one[1:], split[1:]):
        assert np.array_equal(a, b)


def test_save_restore_between_detections_continues_bit_identically(tmp_path):
    one = run(tmp_path, [120])
    split = run(tmp_path, [47, 73], save_at=0)   # step 47 lies between two detections
    for a, b in zip(one[1:], split[1:]):
        assert np.array_equal(a, b)
