"""`block gridpoint apply quiet[-x|-y|-z]` (3DEC's spelling of the viscous boundary, dec3d.model.quiet): the
same Lysmer–Kuhlemeyer dashpots as `block face apply quiet` on the boundary faces whose gridpoints are
all quiet, a gridpoint quiet along some axes keeping those axes only; the 1-D shear wave of DY3 leaves
through a base made quiet this way; bad input."""
import numpy as np
import pytest

from dec3d.errors import BindError, CommandError
from dec3d.model.quiet import QuietError, quiet_dashpots
from dec3d.session import Session

BLOCK = """model new
block create brick 0 2 0 1 0 1
block zone generate hexahedra divisions 2 2 2
block zone cmodel assign elastic
block zone property bulk 5e9 shear 3e9 density 2500
"""


def _dash(session, line):
    session.run_items(session.load_text(BLOCK + line))
    rows, c = quiet_dashpots(session.model)
    order = np.argsort(rows)
    return rows[order], c[order]


def test_gridpoint_quiet_gives_the_face_dashpots(tmp_path):
    """On the base z = 0 (2 m², n = −z): the same matrices as `block face apply quiet`, summing to
    A ρC_p on zz and A ρC_s on xx, yy."""
    r1, c1 = _dash(Session(out_dir=tmp_path), "block face apply quiet range position-z 0\n")
    r2, c2 = _dash(Session(out_dir=tmp_path), "block gridpoint apply quiet range position-z 0\n")
    assert np.array_equal(r1, r2)
    np.testing.assert_allclose(c2, c1, rtol=1e-14, atol=0)
    rho, k, g = 2500.0, 5e9, 3e9
    total = c2.sum(axis=0)
    assert total[2, 2] == pytest.approx(2.0 * np.sqrt(rho * (k + 4 * g / 3)), rel=1e-12)
    assert total[0, 0] == pytest.approx(2.0 * np.sqrt(rho * g), rel=1e-12)
    assert abs(total[0, 2]) < 1e-9 * total[2, 2]


def test_one_direction_keeps_that_axis_and_remove_undoes_it(tmp_path, capsys):
    s = Session(out_dir=tmp_path)
    r, c = _dash(s, "block gridpoint apply quiet-x range position-z 0\n")
    assert c[:, 0, 0].sum() == pytest.approx(2.0 * np.sqrt(2500.0 * 3e9), rel=1e-12)
    assert np.abs(c[:, 1:, :]).max() == 0.0 and np.abs(c[:, :, 1:]).max() == 0.0
    # a face quiet both ways is counted once
    s.command("block face apply quiet range position-z 0")
    r2, c2 = quiet_dashpots(s.model)
    assert c2.sum(axis=0)[2, 2] == pytest.approx(2.0 * np.sqrt(2500.0 * (5e9 + 4e9)), rel=1e-12)
    s.command("block face apply-remove quiet range position-z 0")
    s.command("block gridpoint apply-remove quiet-x range position-z 0")
    assert quiet_dashpots(s.model) is None
    s.command("block gridpoint apply quiet-y quiet-z range position-x 2")
    s.command("block gridpoint list range position 2 1 1")
    assert capsys.readouterr().out.rstrip().endswith("quiet-yz")
    s.command("block gridpoint apply-remove range position-x 2")
    assert quiet_dashpots(s.model) is None


def test_dy3_column_with_a_gridpoint_quiet_base(tmp_path):
    """verification/DY3 with `block gridpoint apply quiet` for its base: reflected amplitude below 5 % of
    the first arrival at the top, travel time H/C_s = 0.5 s within 1 %."""
    from conftest import ROOT

    deck = (ROOT / "verification" / "DY3_shear_wave_quiet_base" / "deck.dat").read_text()
    assert "block face apply quiet range position-z 0" in deck
    deck = deck.replace("block face apply quiet range position-z 0", "block gridpoint apply quiet range position-z 0")
    s = Session(out_dir=tmp_path)
    s.run_items(s.load_text(deck))
    assert not (s.model.faces["fquiet"][:, 0] > 0).any()
    assert s.variables["reflected"] < 0.05
    assert s.variables["travel"] == pytest.approx(0.5, rel=0.01)
    assert s.variables["doubled"] == pytest.approx(1.0, rel=0.01)


@pytest.mark.parametrize("line, error, words", [
    ("block gridpoint apply quiet velocity-x 0 range position-z 0", BindError, "cannot be combined"),
    ("block gridpoint apply quiet table 1 range position-z 0", BindError, "cannot be combined"),
    ("block gridpoint apply quiet range position 0 0 0", CommandError, "no boundary face"),
    ("block gridpoint apply quiet 3 range position-z 0", BindError, "unexpected value `3`"),
])
def test_bad_input(session, line, error, words):
    session.run_items(session.load_text(BLOCK + "table 1 add 0 0 1 1\n"))
    with pytest.raises(error, match=words):
        session.command(line)


def test_zone_without_properties(session):
    session.run_items(session.load_text("model new\nblock create brick 0 1 0 1 0 1\n"
                                        "block zone generate hexahedra divisions 1 1 1\n"))
    with pytest.raises(CommandError, match="no positive density"):
        session.command("block gridpoint apply quiet range position-z 0")


def test_properties_lost_later_stop_the_run(session):
    session.run_items(session.load_text(BLOCK + "block gridpoint apply quiet range position-z 0\n"))
    session.model.store("zones")["prop"][:] = 0.0
    with pytest.raises(QuietError, match="no positive density"):
        quiet_dashpots(session.model)


def test_save_restore_keeps_the_quiet_gridpoints(session):
    session.run_items(session.load_text(BLOCK + "block gridpoint apply quiet-x range position-z 0\nmodel save 'q'\n"
                                        "model new\nmodel restore 'q'\n"))
    rows, c = quiet_dashpots(session.model)
    assert len(rows) == 9
    assert c.sum(axis=0)[0, 0] == pytest.approx(2.0 * np.sqrt(2500.0 * 3e9), rel=1e-12)
    assert np.abs(c[:, 1:, :]).max() == 0.0
