"""FISH block.force.unbal / block.moment (out-of-balance loads from the sub-contact forces as they
stand), block.subcontact.face with block.face.pos / bface, and system.command (compas_3dec decks)."""
import pytest

from dec3d.errors import Dec3dError

STACK = ("block create brick 0 1 0 1 -1 0\nblock create brick 0 1 0 1 0 1\nblock property density 1000\n"
         "block contact jmodel assign elastic\nblock contact property stiffness-normal 1e8 stiffness-shear 1e8\n"
         "block fix range id 1\nmodel gravity 0 0 -10\n")


def test_unbalanced_force_is_zero_at_rest_and_the_reaction_on_a_fixed_block(session):
    session.command(STACK + "model solve ratio 1e-9\n"
                    "[fz2 = block.force.unbal.z(2)]\n[fz1 = block.force.unbal.z(1)]\n"
                    "[f2 = block.force.unbal(2)]\n[m2 = block.moment(2)]\n[mx1 = block.moment.x(1)]")
    v = session.variables
    assert abs(v["fz2"]) < 1e-6 * 1e4                       # the upper block (10 kN) is in equilibrium
    assert v["fz1"] == pytest.approx(-2e4, rel=1e-6)        # the base carries both weights: its reaction
    assert abs(v["f2"].x) < 1e-6 and abs(v["f2"].y) < 1e-6
    assert max(abs(v["m2"].x), abs(v["m2"].y), abs(v["m2"].z)) < 1e-6 * 1e4
    assert abs(v["mx1"]) < 1e-6 * 1e4


def test_applied_force_and_moment_on_a_free_block(session):
    session.command("block create brick 0 1\nblock property density 1\nblock apply force 1 2 3\n"
                    "block apply moment 0 0 5\n[f = block.force.unbal(1)]\n[mz = block.moment.z(1)]")
    f = session.variables["f"]
    assert (f.x, f.y, f.z) == (1.0, 2.0, 3.0)
    assert session.variables["mz"] == 5.0


def test_subcontact_face_and_face_position(session):
    session.command(STACK + "fish define faces\n  n = 0\n  loop foreach s block.subcontact.list\n"
                    "    f = block.subcontact.face(s)\n    if f then\n      n = n + 1\n"
                    "      zs = zs + block.face.pos(block.face.bface(f))->z + 1.0\n"
                    "    endif\n  endloop\n  faces = n\nend\n[zs = 0.0]\n[k = faces]")
    k = session.variables["k"]
    assert k > 0
    assert session.variables["zs"] == pytest.approx(k, abs=1e-12)     # each face at z = 0 adds 1


def test_system_command_runs_a_command_and_exit_stops_the_deck(session):
    session.command("[system.command('block create brick 2 3')]")
    assert session.model.blocks.n == 1
    session.command("fish define stop\n  system.command('exit')\nend\n@stop\nblock create brick 5 6")
    assert session.model.blocks.n == 1                       # the line after `exit` did not run


@pytest.mark.parametrize("line, message", [
    ("[system.command(3)]", r"`system.command` takes a command \(a string\), not a"),
    ("[system.command('block frobnicate')]", r"frobnicate"),
    ("[x = block.force.unbal(9)]", r"there is no block with id 9"),
    ("[x = block.face.pos(0)]", r"there is no face 0"),
])
def test_bad_input(session, line, message):
    session.command("block create brick 0 1")
    with pytest.raises(Dec3dError, match=message):
        session.command(line)
