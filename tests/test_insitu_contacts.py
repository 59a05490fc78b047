"""`block insitu` before any cycle: the joints between blocks take the in-situ stress and keep it.
Before the fix, a contact made by `block contact jmodel assign` (which brings the contacts up to
date) before `block contact material-table default property stiffness-normal …` still had no
stiffness when `block insitu` set its normal displacement, so its force fell to zero at the first
cycle, when it took the table's stiffness: a jointed model started far from equilibrium."""
import numpy as np
import pytest

from dec3d.session import run_deck

DECK = """model new
block create brick 0 1 0 1 0 1
block create brick 0 1 0 1 1 2
block zone generate edgelength 0.5 range position-z 0 1
block zone generate edgelength 0.34 range position-z 1 2
block zone cmodel assign elastic
block zone property young 1e9 poisson 0.25 density 2000
block contact jmodel assign elastic
block contact material-table default property stiffness-normal 1e10 stiffness-shear 1e10
block insitu stress -1e6 -2e6 -3e6 0 0 0
"""


def test_insitu_before_any_cycle_loads_the_joint(tmp_path):
    """Two zoned 1 m cubes stacked, σzz = -3 MPa set before any cycle: the joint's sub-contacts
    carry Fn = 3 MN in all (1e-9), no shear, and each its share −A σzz of its area A."""
    deck = tmp_path / "deck.dat"
    deck.write_text(DECK)
    s = run_deck(deck, out_dir=tmp_path)
    c, sc = s.model.store("contacts"), s.model.store("subcontacts")
    assert c.n == 1 and c["sub_count"][0] > 9
    rows = np.arange(c["sub_start"][0], c["sub_start"][0] + c["sub_count"][0])
    assert sc["fn"][rows].sum() == pytest.approx(3e6, rel=1e-9)
    np.testing.assert_allclose(sc["fn"][rows], 3e6 * sc["area"][rows], rtol=1e-12)
    assert np.abs(sc["fs"][rows]).max() <= 1e-9 * 3e6
    # the zones have it too
    zs = s.model.store("zones")
    np.testing.assert_array_equal(zs["stress"][: zs.n, :3], np.tile([-1e6, -2e6, -3e6], (zs.n, 1)))
    # and the joint keeps it when cycling: after one step the normal forces still add up to 3 MN
    # (within 1 %: one step of motion from the unbalance of the non-matching meshes) and each is
    # -kn A (un - udil) with the table's kn = 1e10 Pa/m
    s.command("model cycle 1")
    assert sc["fn"][rows].sum() == pytest.approx(3e6, rel=1e-2)
    np.testing.assert_allclose(sc["fn"][rows], -1e10 * sc["area"][rows] * (sc["un"][rows] - sc["udil"][rows]),
                               rtol=1e-9)
