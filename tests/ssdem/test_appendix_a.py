"""The thesis's Appendix A text format on a hand-written file: one test per item.

data/appendix_a_example.txt, in kN and m: two fixed unit squares (blocks 0, 1), two free
unit squares on them (2, 3) and a triangle on block 3 (4), entered as the thesis says, a
quadrilateral with a repeated corner.  Lines: 1 n; 2-6 centroids; 7-11 vertices;
12-16 forces; 17 nb; 18-19 boundary centroids; 20 strength; 21-25 springs; 26-30 angles;
31 iterations; 32 delta_peak; 33 delta_res; 34 r_u.
"""
from pathlib import Path

import numpy as np
import pytest

from dec3d.ssdem import safety, solve
from dec3d.ssdem.readers.appendix_a import read_appendix_a
from dec3d.ssdem.readers.errors import SsdemInputError

EXAMPLE = Path(__file__).parent / "data" / "appendix_a_example.txt"
LINES = EXAMPLE.read_text().splitlines()


def read(lines=None, **kw):
    text = "\n".join(LINES if lines is None else lines) + "\n"
    return read_appendix_a(EXAMPLE, text=text, **kw)


def edited(line_no: int, new: str) -> list[str]:
    out = list(LINES)
    out[line_no - 1] = new
    return out


def fails(lines, field: str, line: int):
    with pytest.raises(SsdemInputError) as exc:
        read(lines)
    err = exc.value
    assert err.field == field and err.line == line and err.file == str(EXAMPLE)
    msg = err.format()
    assert f"{EXAMPLE}:{line}:" in msg and f"'{field}'" in msg
    return err


def test_item1_number_of_blocks():
    assert read().blocks.n == 5
    fails(edited(1, "0"), "n_blocks", 1)
    fails(edited(1, "five"), "n_blocks", 1)


def test_item2_centroids_are_the_dof_points():
    p = read()
    np.testing.assert_allclose(p.blocks.ref[4], [1.6666667, 2.3333333])
    np.testing.assert_allclose(p.blocks.ref[2], [0.5, 1.5])
    fails(edited(5, "1.5 2.5"), "centroid[3]", 5)          # outside block 3


def test_item3_vertices_counter_clockwise_from_bottom_right_and_triangles():
    p = read()
    assert np.diff(p.blocks.offsets).tolist() == [4, 4, 4, 4, 3]
    np.testing.assert_allclose(p.blocks.polygon(4), [[2, 2], [2, 3], [1, 2]])
    np.testing.assert_allclose(p.blocks.area, [1, 1, 1, 1, 0.5])
    # side numbers of the interfaces follow the typed vertices: block 3's top (1) meets block 4's bottom (3)
    itf = p.interfaces
    k = int(np.flatnonzero((itf.a == 3) & (itf.b == 4) | (itf.a == 4) & (itf.b == 3))[0])
    sides = {int(itf.a[k]): int(itf.side_a[k]), int(itf.b[k]): int(itf.side_b[k])}
    assert sides == {3: 1, 4: 3}
    fails(edited(9, "0 1 0 2 1 2 1 1"), "nodes[2]", 9)      # clockwise: inverted block
    fails(edited(10, "1.5 1 1.5 2 0.5 2 0.5 1"), "nodes[3]", 10)   # overlaps block 2


def test_item4_forces_at_the_centroids():
    p = read()
    np.testing.assert_allclose(p.blocks.force[4], [0.0, -10e3, 0.0])   # kN -> N
    np.testing.assert_allclose(p.blocks.force[:, 1].sum(), -50e3)
    fails(edited(13, "0 minus20 0"), "force[1].fy", 13)


def test_item5_number_of_boundary_blocks():
    assert read().blocks.fixed.tolist() == [True, True, False, False, False]
    fails(edited(17, "9"), "n_boundary", 17)


def test_item6_boundary_centroids_match_blocks():
    fails(edited(19, "7.5 0.5"), "boundary[1]", 19)


def test_item7_strength():
    itf = read().interfaces
    np.testing.assert_allclose(itf.c_p, 10e3)
    np.testing.assert_allclose(itf.c_r, 5e3)
    np.testing.assert_allclose(itf.tan_p, np.tan(np.radians(30)))
    np.testing.assert_allclose(itf.tan_r, np.tan(np.radians(25)))
    err = fails(edited(20, "10 -30 5 25"), "strength.phi_peak", 20)
    assert err.location.column == 4


def test_item8_springs_per_side():
    p = read()
    np.testing.assert_allclose(p.interfaces.kn, 1e8)        # kN/m^3 -> N/m^3
    np.testing.assert_allclose(p.interfaces.ks, 4e7)
    err = fails(edited(24, "1e5 4e4 1e5 4e4 1e5 -4e4 1e5 4e4"), "springs[3].ks_left", 24)
    assert "negative stiffness" in err.message
    # the two sides of a free-free interface disagree: the mean is used, with a note
    p = read(edited(23, "3e5 4e4 1e5 4e4 1e5 4e4 1e5 4e4"))   # block 2, right side
    itf = p.interfaces
    k = int(np.flatnonzero((itf.a == 2) & (itf.b == 3) | (itf.a == 3) & (itf.b == 2))[0])
    assert p.interfaces.kn[k] == pytest.approx(2e8)
    assert any("mean" in n for n in p.notes)


def test_item9_angles_checked_against_the_geometry():
    read()                                                # 180 and 0 (n and -n) both accepted
    fails(edited(30, "0 90 100 270"), "angles[4].a_left", 30)


def test_item10_iterations_are_load_steps():
    assert read().settings.n_steps == 5
    fails(edited(31, "0"), "iterations", 31)


def test_item11_delta_peak_is_ignored():
    a = solve.run(read())
    b = solve.run(read(edited(32, "0.5")))
    np.testing.assert_array_equal(a.u, b.u)
    assert any("ignored" in n for n in read().notes)


def test_item12_delta_res():
    np.testing.assert_allclose(read().interfaces.del_res, 0.01)
    fails(edited(33, "0"), "delta_res", 33)


def test_item13_pore_pressure_ratio_as_the_listing():
    p = read()
    assert p.settings.ru == 0.1 and p.settings.ru_mode == "listing"
    fails(edited(34, "1.5"), "ru", 34)


def test_truncated_and_extra_data():
    fails(LINES[:-1], "ru", 33)
    fails(LINES + ["7"], "(end of file)", 35)


def test_example_runs_and_carries_its_weight():
    p = read()
    st = solve.run(p)
    s = safety.evaluate(p, st)
    assert not st.removed.any() and all(r.converged for r in st.steps)
    itf = p.interfaces
    # the two fixed blocks carry all 50 kN through the interfaces at y = 1
    base = np.isclose(itf.mid[:, 1], 1.0) & np.isclose(itf.normal[:, 1] ** 2, 1.0)
    assert np.sum(s.sigma_n[base] * itf.length[base]) == pytest.approx(50e3, rel=1e-9)
