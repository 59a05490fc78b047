"""Rigid engine end to end through decks: settlement on a joint spring, blow-up message, determinism."""
import numpy as np
import pytest

from dec3d.errors import Dec3dError
from dec3d.physics.rigid import engine

DECK = """model new
block create brick 0 1 0 1 -1 0
block create brick 0 1 0 1 0 1
block property density 2000
model gravity 0 0 -10
block contact jmodel assign elastic
block contact material-table default property stiffness-normal 10e6 stiffness-shear 10e6
block fix range position-z -1 0
"""


def _run(session, extra):
    session.run_items(session.load_text(DECK + extra))
    return engine(session.model)


def test_block_on_spring_settles_at_mg_over_k(session):
    e = _run(session, "model solve ratio 1e-7\n")
    b = session.model.blocks
    assert b["disp"][1, 2] == pytest.approx(-2.000e-3, rel=5e-3)   # R3: mg/k = 2.000 mm
    assert e.subcontacts["fn"].sum() == pytest.approx(20000.0, rel=1e-3)
    assert e.contacts["type"].tolist() == [6]


def test_blow_up_names_step_and_block(session):
    """The block sits between the fixed base and a fixed lid, so it cannot fly off: with a
    time step far above Eq. (87) its oscillation grows until the run stops."""
    with pytest.raises(Dec3dError, match=r"unstable at step \d+: block 2"):
        _run(session, "block create brick 0 1 0 1 1 2\nblock property density 2000\nblock fix range position-z 1 2\n"
                      "block contact jmodel assign mohr\nblock contact material-table default property stiffness-normal 1e10 tension 1e30 cohesion 1e30\n"
                      "block mechanical damping none\nblock mechanical timestep 0.01\nmodel cycle 200\n")
    assert np.isfinite(session.model.vertices["pos"]).all()


def test_same_deck_twice_is_bit_identical(tmp_path):
    from dec3d.session import Session
    out = []
    for k in range(2):
        s = Session(out_dir=tmp_path)
        s.run_items(s.load_text(DECK + "block initialize velocity-x 0.01 range position-z 0 1\nmodel cycle 300\n"))
        out.append(s.model.vertices["pos"].copy())
    assert np.array_equal(out[0], out[1])
