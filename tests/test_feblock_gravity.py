"""`feblock gravity [delete] [range]` (issue 12; dec3d's reading of a command the FE-block text
names without defining): FE blocks carry the consistent gravity forces of the text's Eq. (8) under
`model gravity` by default, `feblock gravity delete` takes them off the FE blocks in range,
`feblock gravity` puts them back; kept through `model save|restore`."""
import io

import numpy as np
import pytest

from dec3d.errors import Dec3dError
from dec3d.session import Session

E, NU, RHO, G, H = 1e9, 0.25, 2000.0, 10.0, 1.0
M = E * (1 - NU) / ((1 + NU) * (1 - 2 * NU))      # constrained modulus, 1.2 GPa
SETTLE = RHO * G * H * H / (2 * M)                # top of a confined column under its own weight

SETUP = ["model configure feblock", "block create brick 0 1 0 1 0 1", "block create brick 3 4 0 1 0 1",
         "feblock generate 0.5 0.5 0.5 integration 3", "block zone cmodel assign elastic",
         f"block zone property young {E:g} poisson {NU:g} density {RHO:g}", f"model gravity 0 0 {-G:g}",
         "block gridpoint apply velocity-z 0 range position-z 0",
         *[f"block gridpoint apply velocity-{a} 0 range position-{a} {c}" for a, cs in (("x", (0, 1, 3, 4)),
                                                                                      ("y", (0, 1))) for c in cs]]


def _session(tmp_path, extra=()):
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    for line in [*SETUP, *extra]:
        s.command(line)
    return s


def _tops(m):
    v = m.vertices
    top = np.abs(v["pos"][:, 2] - H) < 1e-9
    return [-v["disp"][top & (v["block"] == k), 2].mean() for k in (0, 1)]


def _base_reaction(m):
    es = m.store("feblocks")
    return [-(es["stress"][es["block"] == k, 2] * es["volume"][es["block"] == k]).sum() / H for k in (0, 1)]


def test_delete_takes_the_weight_off_the_fe_blocks_in_range_and_gravity_puts_it_back(tmp_path):
    """Two FE cubes on rollers: with gravity deleted on the one at x 3-4 it carries no load and does
    not move; the other settles by rho g H²/(2M) = 8.333 micro-m (a quadratic field, which 20-node
    elements hold: bar 1e-4) and its mean vertical stress carries half its weight. `feblock gravity`
    puts the load back: the second settles the same."""
    s = _session(tmp_path, ["feblock gravity delete range position-x 3 4", "model solve ratio 1e-8"])
    m = s.model
    es = m.store("feblocks")
    assert list(es["gravity"][es["block"] == 0]) == [1] * 8 and list(es["gravity"][es["block"] == 1]) == [0] * 8
    a, b = _tops(m)
    assert a == pytest.approx(SETTLE, rel=1e-4)
    assert abs(b) < 1e-12
    wa, wb = _base_reaction(m)
    assert wa == pytest.approx(RHO * G * H / 2, rel=1e-6)        # mean sigma_zz x volume / H: half the weight
    assert abs(wb) < 1e-6
    s.command("feblock gravity")
    s.command("model solve ratio 1e-8")
    a2, b2 = _tops(m)
    assert a2 == pytest.approx(SETTLE, rel=1e-4) and b2 == pytest.approx(SETTLE, rel=1e-4)


def test_gravity_choice_survives_save_and_restore(tmp_path):
    s = _session(tmp_path, ["feblock gravity delete range position-x 0 1", "model save 'g'"])
    t = Session(out_dir=tmp_path, stdout=io.StringIO())
    t.command("model restore 'g'")
    es = t.model.store("feblocks")
    assert np.array_equal(es["gravity"], s.model.store("feblocks")["gravity"])
    assert list(es["gravity"]) == [0] * 8 + [1] * 8
    t.command("model solve ratio 1e-8")
    a, b = _tops(t.model)
    assert abs(a) < 1e-12 and b == pytest.approx(SETTLE, rel=1e-4)


def test_no_fe_block_in_range_is_a_warning_and_changes_nothing(tmp_path):
    out = io.StringIO()
    s = Session(out_dir=tmp_path, stdout=out)
    for line in [*SETUP, "block create brick 6 7 0 1 0 1", "feblock gravity delete range position-x 6 7"]:
        s.command(line)
    assert "warning" in out.getvalue() and "`feblock gravity` found no FE block in range" in out.getvalue()
    assert (s.model.store("feblocks")["gravity"] == 1).all()


def test_needs_configure_and_rejects_bad_words(tmp_path):
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command("block create brick 0 1 0 1 0 1")
    for cmd in ("feblock gravity", "feblock gravity delete"):
        with pytest.raises(Dec3dError, match=r"`feblock gravity` needs `model configure feblock` first"):
            s.command(cmd)
    assert "feblocks" not in s.model.stores
    t = _session(tmp_path)
    with pytest.raises(Dec3dError, match=r"remove"):
        t.command("feblock gravity remove")
    assert (t.model.store("feblocks")["gravity"] == 1).all()
