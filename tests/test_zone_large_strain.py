"""`model large-strain on|off` with deformable (zoned) blocks: in large strain the gridpoints move,
the stress increments are taken on the current geometry and zone volumes follow; in small strain the
geometry stays where it was made (regression for the help text, which said large strain was not
implemented for deformable blocks)."""
import math

import numpy as np
import pytest

from dec3d.session import run_deck

DECK = """model new
model large-strain {mode}
block create brick 0 1 0 1 0 1
block zone generate edgelength 0.5
block zone cmodel assign elastic
block zone property young 1e9 poisson 0 density 2000
block gridpoint apply velocity-z 0 range position-z 0
block gridpoint apply velocity-z -1e-4 range position-z 1
model cycle 1000
"""


def _compress(tmp_path, mode):
    """A zoned 1 m cube (E = 1 GPa, ν = 0) squeezed 10 % between its base and its top (moved down
    1e-4 m per step for 1000 steps)."""
    d = tmp_path / mode
    d.mkdir()
    (d / "deck.dat").write_text(DECK.format(mode=mode))
    s = run_deck(d / "deck.dat", out_dir=d)
    return s.model


@pytest.mark.parametrize("mode", ["on", "off"])
def test_zoned_cube_squeezed_in_large_and_small_strain(tmp_path, mode):
    """Large strain: the top gridpoints are at z = 0.9 m, the zones' volume is 0.9 of the start
    (0.1 %), and σzz is E ln(L0 / L) = 105.36 MPa (the stress increments E Δu / L on the current length
    add up to the logarithmic strain; 0.5 %). Small strain: the gridpoints stay at z = 1 m, the volume
    is unchanged and σzz is E Δu / L0 = 100 MPa (0.5 %)."""
    m = _compress(tmp_path, mode)
    v, zs = m.vertices, m.store("zones")
    top = v["zoned"] & (np.abs(v["disp"][:, 2] + 0.1) < 1e-9)
    assert top.sum() == 9
    szz = zs["stress"][: zs.n, 2]
    p = v["pos"]
    g = zs["gp"][: zs.n, :4]
    a, b, c, d = (p[g[:, i]] for i in range(4))
    vol_now = np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) / 6.0
    if mode == "on":
        np.testing.assert_allclose(p[top, 2], 0.9, atol=1e-12)
        assert vol_now.sum() / zs["volume"][: zs.n].sum() == pytest.approx(1.0, abs=1e-12)   # volumes follow
        assert vol_now.sum() == pytest.approx(0.9, rel=1e-3)
        assert szz.mean() == pytest.approx(-1e9 * math.log(1 / 0.9), rel=5e-3)
    else:
        np.testing.assert_allclose(p[top, 2], 1.0, atol=1e-12)
        assert zs["volume"][: zs.n].sum() == pytest.approx(1.0, rel=1e-12)
        assert vol_now.sum() == pytest.approx(1.0, rel=1e-12)
        assert szz.mean() == pytest.approx(-1e8, rel=5e-3)


def test_large_strain_help_says_what_it_does_for_zones():
    """The command's help no longer calls large strain unimplemented for deformable blocks."""
    from dec3d.commands.registry import REGISTRY

    spec = REGISTRY.commands[("model", "large-strain")]
    text = spec.details.lower()
    assert "not implemented" not in text and "deformable" in text and "gridpoint" in text
