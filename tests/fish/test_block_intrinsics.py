"""FISH block intrinsics read the current model: a 2 x 1 x 1 m brick of density 1000 kg/m³
has volume 2 m³, mass 2000 kg and its centroid at (1, 0.5, 0.5)."""
import pytest

from dec3d.errors import ExpressionError


def test_block_list_and_properties(session):
    session.command("block create brick 0 2 0 1 0 1\nblock create brick 0 1 0 1 1 2\n"
                    "block property density 1000\nblock group 'top' range position-z 1.5\n"
                    "block fix range position-z 1.5")
    session.command("fish define report\n loop foreach b block.list\n"
                    "  io.out(string.build('%1 %2 %3 %4', block.id(b), block.pos(b), block.group(b), block.fix(b)))\n"
                    " endloop\n report = list.size(block.list)\nend\n[n = report]\n"
                    "[io.out(block.pos.z(block.find(2)))]\n[io.out(block.find(99))]\n"
                    "[v1 = block.vol(1)]\n[m1 = block.mass(1)]\n[m2 = block.mass(2)]")
    out = session.output.getvalue().splitlines()
    assert out[0] == "1 (1.0,0.5,0.5)  false"
    assert out[1] == "2 (0.5,0.5,1.5) top true"
    assert out[2:] == ["1.5", "0"]
    v = session.variables
    assert v["n"] == 2
    assert v["v1"] == pytest.approx(2.0, rel=1e-12) and v["m1"] == pytest.approx(2000.0, rel=1e-12)
    assert v["m2"] == pytest.approx(1000.0, rel=1e-12)
    session.command("[vz = block.vel.z(1)]\n[dx = block.disp(1)->x]")
    assert session.variables["vz"] == 0.0 and session.variables["dx"] == 0.0


def test_missing_block_is_a_clear_error(session):
    with pytest.raises(ExpressionError) as e:
        session.command("[m = block.mass(7)]")
    assert "`block.mass`: there is no block with id 7" in e.value.message and e.value.location.column == 6
