"""The callback functions of the public decks run unmodified, as callbacks, on small models of our own
(the deck files are copied at test time, never into the repository):

- SAFEGO `03_Fish.dat` joint_force sums the sub-contact forces of the contacts grouped
  'BrickToFoundation' in slot 'components'; on a 1 x 1 x 0.5 m brick (density 2000 kg/m³, g = 10 m/s²)
  settled on a fixed base the normal force is its weight, 1 × 1 × 0.5 × 2000 × 10 = 1e4 N, and the
  shear force is zero; the deck's `fish history @norm_bedjoint_B` / `history rename` lines record it.
- `servo_spring.dat` srv_update (law 0, the spring) runs every step, at position -100 (before the step's
  forces), and updates every 20 steps: F = F0 + k dy with dy the y displacement of the beam gridpoint
  nearest its probe point.
"""
import shutil

import pytest

from conftest import DECKS, NO_DECKS

if not DECKS.is_dir():
    pytest.skip(NO_DECKS, allow_module_level=True)

SAFEGO = "yopi1838__Hanze_SAFEGO__"


def run_with_deck(session, tmp_path, deck: str, as_name: str, text: str) -> None:
    """Copy the public deck ``deck`` into tmp_path as ``as_name`` and run ``text`` (which calls it)."""
    shutil.copy(DECKS / deck, tmp_path / as_name)
    run = tmp_path / "run.dat"
    run.write_text(text)
    session.call(run)


def test_safego_joint_force_as_a_callback_records_the_bed_joint_force(session, tmp_path):
    run_with_deck(
        session, tmp_path, f"{SAFEGO}1WB_EUCENTRE__1WB_SIN-01__03_Fish.dat", "03_Fish.dat",
        "block create brick 0 1 0 1 0 1\nblock create brick 0 1 0 1 1 1.5\nblock property density 2000\n"
        "block contact jmodel assign elastic\nblock contact property stiffness-normal 1e10 stiffness-shear 1e10\n"
        "model gravity 0 0 -10\nblock fix range position-z 0 1\n"
        "block contact group 'BrickToFoundation' slot 'components'\n"
        "call '03_Fish.dat'\n"
        "history interval 50\n"
        "fish history @norm_bedjoint_B\nhistory rename \"norm_bedjoint_B\" name \"1\"\n"
        "fish history @shear_bedjoint_B\nhistory rename \"shear_bedjoint_B\" name \"2\"\n"
        "fish callback add joint_force 0.1 interval 10\n"
        "model cycle 3000\n")
    v = session.variables
    assert v["norm_bedjoint_b"] == pytest.approx(1e4, rel=1e-2)
    assert abs(v["shear_bedjoint_b"]) < 1e-6 * 1e4
    assert v["norm_bedjoint_t"] == 0.0 and v["shearforce"] == v["shear_bedjoint_b"] - v["shear_bedjoint_t"]
    hs = session.model.history_set
    h1, h2 = hs.find("1"), hs.find("2")
    assert h1.label == "fish norm_bedjoint_b" and h1.steps[-1] == 3000 and len(h1.steps) == 60
    assert h1.values[-1] == v["norm_bedjoint_b"] and h2.values[-1] == v["shear_bedjoint_b"]


def test_servo_spring_callback_follows_the_beam(session, tmp_path):
    run_with_deck(
        session, tmp_path, f"{SAFEGO}servo_spring.dat", "servo_spring.dat",
        "block create brick 0 1.292 0 2.47 0 0.21\nblock create brick 0 1.292 2.47 2.68 0 0.21\n"
        "block property density 2000\nblock contact jmodel assign elastic\n"
        "block contact property stiffness-normal 1e9 stiffness-shear 1e9\n"
        "model gravity 0 -10 0\nblock fix range position-y 0 2.47\n"
        "fish define cstav\n  ncstav = 0.0\nend\n"          # the deck's law 1 reads it; law 0 (used) does not
        "call 'servo_spring.dat'\nmodel cycle 99\n[dy_99 = block.gp.disp.y(srv_gp)]\nmodel cycle 1\n"
        "[dy_now = block.gp.disp.y(srv_gp)]\n")
    v = session.variables
    assert v["srv_calls"] == 5                                  # 100 steps, one update every 20
    assert v["dy_now"] < -1e-7                                  # the beam has settled on the base
    # position -100: the last update ran before step 100's forces, on the state after step 99
    assert v["srv_dy"] == v["dy_99"] != v["dy_now"]
    assert v["srv_f"] == pytest.approx(v["srv_f0"] + v["srv_k"] * v["dy_99"], rel=1e-15)
    # the lowest force goes with the lowest beam position (the beam bounces while it settles)
    assert v["srv_dymin"] <= v["dy_99"] and v["srv_fmin"] == pytest.approx(
        v["srv_f0"] + v["srv_k"] * v["srv_dymin"], rel=1e-15)
    pos = session.model.vertices["pos"][v["srv_gp"] - 1]
    assert pos[1] == pytest.approx(2.68 + v["dy_now"], abs=1e-12)    # a gridpoint of the beam's top face
