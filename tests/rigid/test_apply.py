"""`block apply` / `block apply-remove`: values land in the block store; physics (time functions: tests/test_dynamic.py)."""
import numpy as np
import pytest

from dec3d.errors import BindError, CommandError, Dec3dError

TWO = """model new
block create brick 0 1 0 1 0 1
block create brick 0 1 0 1 1 2
block property density 1000
"""


def _run(session, text):
    session.run_items(session.load_text(text))
    return session.model.blocks


@pytest.mark.parametrize("kind, field, bit0", [("velocity", "velocity", 0), ("rvelocity", "spin", 3),
                                                ("force", "fapp", None), ("moment", "mapp", None)])
def test_each_component_lands_in_its_field(session, kind, field, bit0):
    for i, ax in enumerate("xyz"):
        b = _run(session, TWO + f"block apply {kind}-{ax} 2.5 range id 2\n")
        want = np.zeros(3)
        want[i] = 2.5
        assert b[field][1].tolist() == want.tolist()
        assert b[field][0].tolist() == [0, 0, 0]                  # range: block 1 untouched
        assert b["apply_fix"][0] == 0
        assert b["apply_fix"][1] == (0 if bit0 is None else 1 << (bit0 + i))
    b = _run(session, TWO + f"block apply {kind} 1 2 3\n")
    assert b[field].tolist() == [[1, 2, 3], [1, 2, 3]]
    assert b["apply_fix"].tolist() == [0, 0] if bit0 is None else [7 << bit0] * 2


def test_forces_add_velocities_set(session):
    b = _run(session, TWO + "block apply force-z -10\nblock apply force 1 0 -5\nblock apply moment-x 2\n"
                            "block apply moment-x 3\nblock apply velocity-x 0.1\nblock apply velocity-x 0.3\n"
                            "block apply rvel-z [0.5 * 2]\n")
    assert b["fapp"][0].tolist() == [1, 0, -15]
    assert b["mapp"][0].tolist() == [5, 0, 0]
    assert b["velocity"][0].tolist() == [0.3, 0, 0]
    assert b["spin"][0].tolist() == [0, 0, 1.0]
    assert b["apply_fix"][0] == (1 | 32)


def test_range_selects(session):
    b = _run(session, TWO + "block apply force-x 7 range position-z 1 2\n")
    assert b["fapp"][:, 0].tolist() == [0, 7]


def test_apply_remove_variants(session):
    full = TWO + "block apply velocity 1 2 3\nblock apply rvelocity 4 5 6\nblock apply force 1 1 1\nblock apply moment 2 2 2\n"
    b = _run(session, full + "block apply-remove\n")
    assert b["apply_fix"].tolist() == [0, 0] and not b["fapp"].any() and not b["mapp"].any()
    assert b["velocity"][0].tolist() == [1, 2, 3]          # the block keeps its velocity, no longer held
    b = _run(session, full + "block apply-remove force-y range id 1\n")
    assert b["fapp"].tolist() == [[1, 0, 1], [1, 1, 1]] and b["apply_fix"].tolist() == [63, 63]
    b = _run(session, full + "block apply-remove velocity\n")
    assert b["apply_fix"].tolist() == [56, 56] and b["mapp"].tolist() == [[2, 2, 2]] * 2
    b = _run(session, full + "block apply-remove rvelocity-y moment\n")
    assert b["apply_fix"].tolist() == [7 | 8 | 32] * 2 and not b["mapp"].any() and b["fapp"].all()
    b = _run(session, full + "block apply-remove velocity-z force\n")
    assert b["apply_fix"].tolist() == [3 | 56] * 2 and not b["fapp"].any()


def test_errors_name_line_and_column(session):
    # time functions: the table / FISH function must exist when the command runs (tests/test_dynamic.py)
    with pytest.raises(CommandError) as e:
        session.run_items(session.load_text(TWO + "block apply velocity-z 1 table 1 range id 2\n"))
    assert e.value.location.line == 5 and e.value.location.column == 32 and "no table 1" in str(e.value)
    with pytest.raises(CommandError) as e:
        session.run_items(session.load_text(TWO + "block apply vel-x 1 fish cos_ range pos-z -0.4 0\n"))
    assert e.value.location.line == 5 and "no FISH function `cos_`" in str(e.value)
    with pytest.raises(BindError) as e:
        session.load_text(TWO + "block apply force 1 2\n")
    assert e.value.location.line == 5 and "3" in str(e.value)
    with pytest.raises(BindError) as e:
        session.load_text(TWO + "block apply range id 2\n")
    assert e.value.location.line == 5 and "needs one of" in str(e.value)
    with pytest.raises(BindError) as e:
        session.load_text(TWO + "block apply force-x abc\n")
    assert e.value.location.line == 5 and e.value.location.column == 21
    with pytest.raises(Dec3dError) as e:
        session.load_text(TWO + "block apply-remove speed\n")
    assert e.value.location.line == 5


def test_failed_command_changes_nothing(session):
    b = _run(session, TWO)
    with pytest.raises(Dec3dError):
        session.run_items(session.load_text("block apply force-x [1/0]\n"))
    assert not b["fapp"].any()


PHYS = """model new
block create brick 0 1 0 1 0 2
block property density 1000
block mechanical damping none
model gravity 0 0 0
block mechanical timestep 1e-3
"""


def test_applied_force_accelerates_at_f_over_m(session):
    # m = 2000 kg, F = 1000 N -> a = 0.5 m/s^2; after n steps the half-step scheme gives
    # v = a n dt and u = a dt^2 n (n + 1) / 2
    b = _run(session, PHYS + "block apply force-z 1000\nmodel cycle 1000\n")
    n, dt, a = 1000, 1e-3, 0.5
    assert b["velocity"][0, 2] == pytest.approx(a * n * dt, rel=1e-9)
    assert b["disp"][0, 2] == pytest.approx(a * dt * dt * n * (n + 1) / 2, rel=1e-9)
    assert b["disp"][0, :2].tolist() == [0, 0]


def test_applied_moment_spins_the_block(session):
    b = _run(session, PHYS + "block apply moment-z 10\nmodel cycle 100\n")
    assert b["spin"][0, 2] > 0 and b["spin"][0, :2].tolist() == [0, 0]


def test_applied_velocity_moves_the_block_and_is_held(session):
    # gravity on: a held component does not accelerate; remove the apply and it does
    b = _run(session, PHYS + "model gravity 0 0 -10\nblock apply velocity-x 0.1 velocity-z 0\nmodel cycle 1000\n")
    assert b["disp"][0, 0] == pytest.approx(0.1 * 1.0, rel=1e-9)
    assert b["disp"][0, 2] == 0.0 and b["velocity"][0, 2] == 0.0
    b = _run(session, "block apply-remove velocity-z\nmodel cycle 10\n")
    assert b["velocity"][0, 2] == pytest.approx(-10 * 10 * 1e-3) and b["velocity"][0, 0] == pytest.approx(0.1)


def test_applied_rvelocity_is_held(session):
    b = _run(session, PHYS + "block apply rvelocity-z 0.5\nblock apply moment-z 1e6\nmodel cycle 100\n")
    assert b["spin"][0].tolist() == [0, 0, 0.5]
