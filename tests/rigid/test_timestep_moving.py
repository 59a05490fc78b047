"""The rigid time step (3DEC theory text, Eqs. 87-88: Δt = frac · 2 (M_min / K_max)^½, K_max = the
largest contact stiffness times the largest face area) counts only the blocks that move: a block whose
six velocity components are all held (`block fix`, or `block apply velocity` with the rotations fixed)
adds neither its mass nor its faces (physics.rigid.RigidEngine.timestep)."""
import math

import pytest

FRAC = 0.1
KN = 1e7                      # Pa/m, stiffness-normal = stiffness-shear
RHO = 2000.0


def _model(session, base_extra: str):
    """A 1 m cube (m = 2000 kg, largest face 1 m²) on a 16 × 4 × 1 m base (m = 128 000 kg, top face 64 m²)."""
    session.command("model new\nblock create brick -8 8 -2 2 -1 0\nblock create brick 0 1 0 1 0 1\n"
                    f"block property density {RHO:g}\nblock contact jmodel assign elastic\n"
                    f"block contact material-table default property stiffness-normal {KN:g} stiffness-shear {KN:g}\n"
                    + base_extra + "model dynamic active on\nmodel cycle 2")
    return session.model.rigid_engine.dt


def test_small_block_on_a_fixed_base_sets_the_step(session):
    dt = _model(session, "block fix range position-z -1 0\n")
    want = FRAC * 2.0 * math.sqrt(RHO * 1.0 / (KN * 1.0))
    assert dt == pytest.approx(want, rel=1e-12)


def test_a_free_base_still_counts(session):
    """The same base free to move: its 64 m² face enters K_max (8 times smaller step)."""
    dt = _model(session, "")
    assert dt == pytest.approx(FRAC * 2.0 * math.sqrt(RHO / (KN * 64.0)), rel=1e-12)


def test_a_base_driven_by_an_applied_velocity_does_not_count(session):
    """`block apply velocity` holds the three translations; with its rotations fixed it is held still
    (the quake bench's base); with only the translations held it still turns and counts."""
    dt = _model(session, "block fix rotation range position-z -1 0\nblock apply velocity 0.1 0 0 range position-z -1 0\n")
    assert dt == pytest.approx(FRAC * 2.0 * math.sqrt(RHO / KN), rel=1e-12)
    dt = _model(session, "block apply velocity 0.1 0 0 range position-z -1 0\n")
    assert dt == pytest.approx(FRAC * 2.0 * math.sqrt(RHO / (KN * 64.0)), rel=1e-12)


def test_all_blocks_fixed_falls_back_to_all_blocks(session):
    """Nothing moves: Δt from every block, as before (no division by an empty set)."""
    dt = _model(session, "block fix\n")
    assert dt == pytest.approx(FRAC * 2.0 * math.sqrt(RHO / (KN * 64.0)), rel=1e-12)


def test_defaults_of_another_joint_model_are_left_out(session):
    """Material-table defaults set for mohr (friction) and then `jmodel assign elastic`: the elastic
    step uses the stiffnesses and ignores the friction it has no column for (this raised a KeyError)."""
    session.command("model new\nblock create brick -8 8 -2 2 -1 0\nblock create brick 0 1 0 1 0 1\n"
                    f"block property density {RHO:g}\nblock contact jmodel assign mohr\n"
                    "block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 friction 30\n"
                    "block contact jmodel assign elastic\n"
                    f"block contact material-table default property stiffness-normal {KN:g} stiffness-shear {KN:g}\n"
                    "block fix range position-z -1 0\nmodel dynamic active on\nmodel cycle 2")
    assert session.model.rigid_engine.dt == pytest.approx(FRAC * 2.0 * math.sqrt(RHO / KN), rel=1e-12)
