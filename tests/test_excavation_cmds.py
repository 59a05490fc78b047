"""Commands the tunnel-liner example (examples/feblock/tunnel_liner.dat) needs: `block delete
reaction f` (an excavation keeping a fraction of its reaction), `block contact reset overlap`
(a support cast against rock that has moved starts unloaded), joined FE blocks sharing their
nodes, histories of FE gridpoints and of deleted blocks, history CSVs aligned by step."""
import csv
import io

import numpy as np
import pytest

from dec3d.errors import CommandError, Dec3dError
from dec3d.session import Session

KN, F0 = 1e10, 1e6          # joint stiffness [Pa/m] on unit faces; in-situ sigma_xx = -1 MPa -> 1 MN per contact


def _row(b) -> dict:
    return {int(i): r for r, i in enumerate(b["id"])}


def _three_in_a_row(tmp_path):
    """C (fixed) | A | B along x, unit cubes, joints kn = ks = 1e10 Pa/m, sigma_xx = -1 MPa on both joints."""
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    for line in ["model large-strain off", "block create brick -1 0 0 1 0 1 group 'C'",
                 "block create brick 0 1 0 1 0 1 group 'A'", "block create brick 1 2 0 1 0 1 group 'B'",
                 "block property density 1000", "block contact generate-subcontacts",
                 "block contact jmodel assign elastic",
                 f"block contact property stiffness-normal {KN} stiffness-shear {KN}",
                 "block insitu stress -1e6 0 0 0 0 0", "block fix range group 'C'"]:
        s.command(line)
    return s


@pytest.mark.parametrize("frac", [0.25, 0.5, 1.0])
def test_delete_with_reaction_keeps_that_fraction_of_the_contact_force(tmp_path, frac):
    """A block held between a fixed block and one that is deleted: the applied load is frac times
    the force B exerted on A (-1 MN along x, no moment about A's centroid: the sub-contacts are
    symmetric about it), and A moves out by (1 - frac) F0 / (kn A), the joint to C unloading to
    frac F0 (rigid blocks, the joint the only spring)."""
    s = _three_in_a_row(tmp_path)
    s.command(f"block delete reaction {frac} range group 'B'")
    b = s.model.blocks
    a = _row(b)[2]
    assert b.n == 2
    np.testing.assert_allclose(b["fapp"][a], [-frac * F0, 0, 0], atol=1e-6 * F0)
    np.testing.assert_allclose(b["mapp"][a], 0.0, atol=1e-6 * F0)
    s.command("model solve ratio 1e-8")
    assert b["disp"][a, 0] == pytest.approx((1 - frac) * F0 / KN, abs=1e-3 * F0 / KN)
    assert s.model.store("subcontacts")["fn"].sum() == pytest.approx(frac * F0, rel=1e-3, abs=1e-3 * F0)


def test_delete_reaction_keeps_an_off_centre_block_where_it_was(tmp_path):
    """M (2 x 1 x 1 m) on a fixed base, pressed by a fixed 1 m cube T over one end (in-situ
    sigma_zz = -1 MPa, solved: M tilts into equilibrium). Deleting T with its full reaction leaves
    M where it was (force and moment of the reaction both right: a wrong moment would tilt it);
    with half of it M rebounds by about half the compression of the base joint."""
    def run(frac):
        s = Session(out_dir=tmp_path, stdout=io.StringIO())
        for line in ["model large-strain off", "block create brick 0 2 0 1 -1 0 group 'base'",
                     "block create brick 0 2 0 1 0 1 group 'M'", "block create brick 0 1 0 1 1 2 group 'T'",
                     "block property density 1000", "block contact generate-subcontacts",
                     "block contact jmodel assign elastic",
                     f"block contact property stiffness-normal {KN} stiffness-shear {KN}",
                     "block insitu stress 0 0 -1e6 0 0 0", "block fix range group 'base'", "block fix range group 'T'",
                     "model solve ratio 1e-9"]:
            s.command(line)
        b = s.model.blocks
        m = _row(b)[2]
        before = b["disp"][m].copy(), b["spin"][m].copy()
        vpos = s.model.vertices["pos"]
        s.command(f"block delete reaction {frac} range group 'T'\nmodel solve ratio 1e-9")
        m = _row(b)[2]
        return before[0], b["disp"][m].copy(), b["fapp"][m].copy(), b["mapp"][m].copy(), vpos
    d0, d1, f, mom, _ = run(1.0)
    assert f[2] < -0.5 * F0 and abs(mom[1]) > 1e4                                 # off centre: a moment
    np.testing.assert_allclose(d1, d0, atol=1e-4 * F0 / KN)
    d0, d1, _, _, _ = run(0.5)
    assert d1[2] - d0[2] > 0.2 * F0 / KN                                          # rebounds


def test_delete_reaction_bad_input_changes_nothing(tmp_path):
    s = _three_in_a_row(tmp_path)
    with pytest.raises(Dec3dError, match="reaction"):
        s.command("block delete reaction 1.5 range group 'B'")
    assert s.model.blocks.n == 3 and not s.model.blocks["fapp"].any()
    s2 = Session(out_dir=tmp_path, stdout=io.StringIO())
    for line in ["model configure feblock", "block create brick 0 1 0 1 0 1 group 'fe'",
                 "block create brick 1 2 0 1 0 1 group 'B'", "feblock generate 1 1 1 range group 'fe'",
                 "block contact generate-subcontacts"]:
        s2.command(line)
    with pytest.raises(CommandError, match="not rigid; .*nothing was deleted"):
        s2.command("block delete reaction 0.5 range group 'B'")
    assert s2.model.blocks.n == 2


def test_contact_reset_overlap_starts_a_support_unloaded(tmp_path):
    """B made overlapping a fixed A by 0.1 mm: its contact pushes it off (kn 1e10 x 1e-4 = 1 MN)
    unless `block contact reset overlap` makes the overlap the unloaded state; then B stays put
    and a later push of 1 MN compresses the joint by 0.1 mm more, no less."""
    def run(reset):
        s = Session(out_dir=tmp_path, stdout=io.StringIO())
        for line in ["model large-strain off", "block create brick 0 1 0 1 0 1",
                     "block create brick 0 1 0 1 0.9999 1.9999", "block property density 1000",
                     "block contact generate-subcontacts", "block contact jmodel assign elastic",
                     f"block contact property stiffness-normal {KN} stiffness-shear {KN}", "block fix range id 1"]:
            s.command(line)
        ss = s.model.store("subcontacts")
        assert ss["fn"].sum() == pytest.approx(F0, rel=1e-6) or ss["un"].min() == pytest.approx(-1e-4, rel=1e-6)
        if reset:
            s.command("block contact reset overlap")
            assert not ss["fn"].any() and np.all(ss["un"] == ss["udil"])
        s.command("model solve ratio 1e-8")
        return s
    assert run(False).model.blocks["disp"][1, 2] > 0.5e-4            # pushed off
    s = run(True)
    assert abs(s.model.blocks["disp"][1, 2]) < 1e-9
    s.command(f"block apply force-z {-F0} range id 2")
    s.command("model solve ratio 1e-8")
    assert s.model.blocks["disp"][1, 2] == pytest.approx(-F0 / KN, rel=1e-3)


def test_joined_fe_blocks_share_their_nodes_and_act_as_one(tmp_path):
    """Two FE bricks 0-1 and 1-2 joined: the 8 master nodes of the common face are linked (its
    mid-face slave nodes are not), and a bar pulled at its end stretches as the one-block bar of
    two elements does: u = F L / (E A) = 1e5 x 2 / 1e9 = 0.2 mm (nu = 0, both exact)."""
    def bar(lines):
        s = Session(out_dir=tmp_path, stdout=io.StringIO())
        for line in ["model configure feblock", "model large-strain off", *lines,
                     "block zone cmodel assign elastic", "block zone property young 1e9 poisson 0 density 1000",
                     "block gridpoint apply velocity-x 0 range position-x 0",
                     "block gridpoint apply velocity-y 0 range position-y 0",
                     "block gridpoint apply velocity-z 0 range position-z 0",
                     "block face apply stress 1e5 0 0 0 0 0 range position-x 2", "model solve ratio 1e-8"]:
            s.command(line)
        v = s.model.vertices
        end = np.flatnonzero(np.isclose(v["pos"][:, 0], 2.0) & ~v["feslave"])
        return s, v["disp"][end, 0]
    s, u2 = bar(["block create brick 0 1 0 1 0 1", "block create brick 1 2 0 1 0 1",
                 "feblock generate 1 1 1", "block join on"])
    v = s.model.vertices
    assert (v["link"] >= 0).sum() == 8 and not (v["link"][v["feslave"]] >= 0).any()
    _, u1 = bar(["block create brick 0 2 0 1 0 1", "feblock generate 1 1 1"])
    np.testing.assert_allclose(u2, u1, rtol=1e-5)
    assert u1.mean() == pytest.approx(2e-4, rel=0.15)      # (face loads by thirds of triangles: not uniform)


def test_history_of_a_deleted_block_is_a_clear_error(tmp_path):
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command("block create brick 0 1 0 1 0 1\nblock create brick 0 1 0 1 1 2\nblock property density 1000\n"
              "block history name 'top' displacement-z position 0.5 0.5 1.5\nblock delete range id 2")
    with pytest.raises(CommandError, match="history 'top' .*follows block 2, which was deleted"):
        s.command("model cycle 20")


def test_history_export_aligns_histories_by_step(tmp_path):
    """A history made after 20 steps has empty cells for the steps before it, its first value on
    the row of step 30, not on the first row."""
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command("model gravity 0 0 -10\nblock create brick 0 1 0 1 0 1\nblock property density 1000\nblock history name 'a' velocity-z block-id 1\n"
              "model cycle 20\nblock history name 'b' velocity-z block-id 1\nmodel cycle 20\n"
              "history export 'a' 'b' file 'h.csv'")
    rows = list(csv.reader(open(tmp_path / "h.csv")))[1:]
    steps = [int(r[0]) for r in rows]
    assert steps == [10, 20, 30, 40]
    assert [r[3] for r in rows[:2]] == ["", ""] and float(rows[2][3]) == float(rows[2][2]) != 0.0
