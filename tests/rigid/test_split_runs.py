"""A run split into several `model cycle` commands takes exactly the steps of one run.

Found on the cube-stack benchmark: each `model cycle` worked Δt out afresh from the contact
stiffnesses it found, while one long run kept the Δt of its first step, so a 3 × 3 × 3 stack
cycled as 10 × `model cycle 10` differed from `model cycle 100` by as much as its own speeds
(and reached equilibrium 2.8× sooner). Δt now follows the stiffnesses at every detection, and
a run that starts between detections goes on with the Δt the last run used there. With density
scaling by body (the default of static runs) it also goes on with the masses of the last
detection (they are worked out from the geometry, which moves in between); both scalings are
checked, each over steps in which its stack still moves.
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


#: Eq. (87) scaling (`mass-scale on`) and the default (by body), which settles the stack in
#: about 100 steps: its runs are shorter
EQ87 = "block mechanical mass-scale on\n"


def run(tmp_path, chunks, save_at=None, extra=EQ87):
    s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command(stack(3) + extra)
    for i, c in enumerate(chunks):
        s.command(f"model cycle {c}")
        if save_at == i:
            s.command("model save 'mid'")
            s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
            s.command("model restore 'mid'")
    b = s.model.blocks
    return s.model.step, b["centroid"].copy(), b["velocity"].copy(), s.model.stores["subcontacts"]["fn"].copy()


@pytest.mark.parametrize("chunks,extra", [([10] * 12, EQ87), ([7] * 17 + [1], EQ87), ([3, 50, 13, 54], EQ87),
                                          ([10] * 5, ""), ([7] * 7 + [1], ""), ([3, 20, 13, 14], "")])
def test_split_run_is_bit_identical_to_one_run(tmp_path, chunks, extra):
    total = sum(chunks)
    one = run(tmp_path, [total], extra=extra)
    split = run(tmp_path, chunks, extra=extra)
    assert one[0] == split[0] == total
    assert np.abs(one[2]).max() > 1e-4          # the stack is still moving: the comparison means something
    for a, b in zip(one[1:], split[1:]):
        assert np.array_equal(a, b)


@pytest.mark.parametrize("chunks,extra", [([47, 73], EQ87), ([23, 27], "")])
def test_save_restore_between_detections_continues_bit_identically(tmp_path, chunks, extra):
    one = run(tmp_path, [sum(chunks)], extra=extra)
    split = run(tmp_path, chunks, save_at=0, extra=extra)   # steps 47, 23 lie between two detections
    assert np.abs(one[2]).max() > 1e-4
    for a, b in zip(one[1:], split[1:]):
        assert np.array_equal(a, b)


def test_body_scaling_split_after_a_change_of_fixity_works_its_masses_out_again(tmp_path):
    """A block fixed between two runs changes what the body scaling depends on: the second run
    does not take the first one's masses back, it works them out again (as one fresh run would)."""
    s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command(stack(2) + "model cycle 13\n")
    from dec3d.physics.rigid import engine
    from dec3d.physics.steps import _Run

    e = engine(s.model)
    first = _Run(e, 1, None)
    kept = first.gimass.copy()
    assert np.array_equal(kept, s.model.blocks["scaled_mass"][first.gmember[first.gstart[:-1]]])
    s.command("block fix range position-z 0 1\n")
    again = _Run(e, 1, None)
    fresh = e._masses(again.gstart, again.gmember, again.gmass, again.giscalar, e.dt)[1]
    assert np.array_equal(again.gimass, fresh)
    assert not np.array_equal(again.gimass, kept)
