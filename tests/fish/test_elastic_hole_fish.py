"""The FISH files of the elastic-hole verification (ElasticHole.fis, check.fis) compile with every intrinsic
they use, and run unmodified on a small zoned model of our own (a 2 x 1 x 1 m brick at x 1..3 in five
tetrahedra, tests/zoning_fixture.py). With zero stresses and displacements the error measures are those
of the Kirsch solution alone, computed here independently with numpy from the formulas the file states
(Kirsch, as in the 3DEC verification problem "cylindrical hole in an infinite elastic medium")."""
import shutil

import numpy as np
import pytest

from conftest import DECKS, NO_DECKS
from dec3d.errors import ExpressionError
from tests.zoning_fixture import zone_brick

if not DECKS.is_dir():
    pytest.skip(NO_DECKS, allow_module_level=True)

PREFIX = "peterzhu6667__pinn-cp-3dec__Elastic_Hole__"
P1, P2, A, BM, SM = 30e6, 15e6, 1.0, 3.9e9, 2.8e9


@pytest.fixture
def folder(tmp_path):
    for name in ("ElasticHole.fis", "check.fis"):
        shutil.copy(DECKS / f"{PREFIX}{name}.dat", tmp_path / name)
    return tmp_path


def test_the_functions_compile_with_every_intrinsic_they_use(session, folder):
    from dec3d.fish import compile_function, parse_block
    from dec3d.lang.parser import parse_deck

    names = []
    for f in ("ElasticHole.fis", "check.fis"):
        deck = parse_deck((folder / f).read_text(), str(folder / f))
        for block in deck.fish:
            fn = compile_function(session.fish_rt, parse_block(block, deck.filename, deck.source_lines))
            assert fn.unsupported == frozenset(), (block.name, fn.unsupported)
            names.append(fn.name)
    assert names == ["props", "nastr", "nadis", "checkerror"]


def _expected(m):
    zs, v = m.store("zones"), m.vertices
    c = v["pos"][zs["gp"][:, :4]].mean(axis=1)
    rad, th = np.hypot(c[:, 0], c[:, 2]), np.arctan2(c[:, 2], c[:, 0])
    q = (A / rad) ** 2
    sigre = 0.5 * (P1 + P2) * (1 - q) + 0.5 * (P1 - P2) * (1 - 4 * q + 3 * q * q) * np.cos(2 * th)
    sigte = 0.5 * (P1 + P2) * (1 + q) - 0.5 * (P1 - P2) * (1 + 3 * q * q) * np.cos(2 * th)
    errsr = np.abs(sigre).sum() / P1 * 100 / zs.n          # numerical stresses are all zero here
    errst = np.abs(sigte).sum() / P1 * 100 / zs.n
    nu = (3 * BM - 2 * SM) / (6 * BM + 2 * SM)
    p = v["pos"]
    r, t = np.hypot(p[:, 0], p[:, 2]), np.arctan2(p[:, 2], p[:, 0])
    o = A / r
    dise = 0.25 * ((P1 + P2) + (P1 - P2) * (4 * (1 - nu) - o * o) * np.cos(2 * t)) * o * A / SM
    dism = 0.25 * ((P1 + P2) + (P1 - P2) * (4 * (1 - nu) - 1.0)) / SM
    errd = np.abs(dise).sum() * 100 / (dism * v.n)
    on_axis = int(((p[:, 1] < 0.001) & (p[:, 2] < 0.001) & (r < 5)).sum())
    return errsr, errst, errd, on_axis


def test_the_error_functions_run_on_a_zoned_brick(session, folder):
    session.command("block create brick 1 3 0 1 0 1")
    zone_brick(session.model, 0)
    session.call(folder / "ElasticHole.fis")
    errsr, errst, errd, on_axis = _expected(session.model)
    v = session.variables
    assert v["errsr"] == pytest.approx(errsr, rel=1e-12)
    assert v["errst"] == pytest.approx(errst, rel=1e-12)
    assert v["errd"] == pytest.approx(errd, rel=1e-12)
    assert v["numrad"] == on_axis == 2
    out = session.output.getvalue().splitlines()
    assert out[0] == "numrad = 2" and out[1].startswith("errsr = ")
    assert session.fish_rt.auto_create is True                   # the file switches it back on at its end
    session.call(folder / "check.fis")
    with pytest.raises(ExpressionError) as e:                    # Itasca's bars for hexahedra: far above here
        session.command("[checkError(1.2,1.8,4.1)]")
    assert e.value.message == "Radial stress error is " + repr(v["errsr"])
    session.command("[checkError(100, 100, 100)]")               # generous bars pass silently
