"""The TOML slope input: values, units, meshing, and errors naming file, line and field."""
from pathlib import Path

import numpy as np
import pytest

from dec3d.ssdem.readers.errors import SsdemInputError
from dec3d.ssdem.readers.toml_input import read_toml

GOOD = """\
title = "test slope"
units = "kN-m"

[profile]
points = [
    [0.0, 0.0],
    [10.0, 0.0],
    [20.0, 5.0],
    [30.0, 5.0],
]

[[layer]]
name = "top"
c = 10.0
phi = 25.0
gamma = 18.0
kn = 1.0e5
ks = 4.0e4

[[layer]]
name = "lower"
top = [[0.0, -1.0], [30.0, 1.0]]
c = 20.0
phi = 30.0
gamma = 20.0
kn = 2.0e5
ks = 8.0e4

[water]
ru = 0.2

[mesh]
size = 1.0
bottom = -4.0
"""
FILE = Path("slope.toml")


def read(text=GOOD):
    return read_toml(FILE, text=text)


def error(text) -> SsdemInputError:
    with pytest.raises(SsdemInputError) as exc:
        read(text)
    return exc.value


def line_of(text, needle, nth=1):
    hits = [i + 1 for i, ln in enumerate(text.splitlines()) if needle in ln]
    return hits[nth - 1]


def test_good_file_is_meshed_in_si_units():
    p = read()
    blk, itf = p.blocks, p.interfaces
    # the whole section is covered: area between profile and bottom
    area = np.trapezoid(p.profile[:, 1] + 4.0, p.profile[:, 0])
    assert blk.area.sum() == pytest.approx(area, rel=1e-12)
    assert p.settings.ru == 0.2 and p.settings.ru_mode == "standard"
    # properties by layer at the interface midpoint, converted to Pa and Pa/m
    lower = p.slope.layer_at(itf.mid[:, 0], itf.mid[:, 1]) == 1
    assert lower.any() and (~lower).any()
    np.testing.assert_allclose(itf.c_p[lower], 20e3)
    np.testing.assert_allclose(itf.kn[~lower], 1e8)
    # standard r_u: u = r_u * overburden at the midpoint
    k = int(np.argmin(itf.mid[:, 1]))
    x, y = itf.mid[k]
    assert itf.u_pore[k] == pytest.approx(0.2 * p.slope.overburden(x, y)[0])
    # base blocks fixed, side columns rollers (u_x and rotation fixed), the rest free
    assert blk.fixed.any() and (blk.fix[:, 0] & ~blk.fix[:, 1]).any()
    # the weight of every block is gamma * area of its layer
    np.testing.assert_allclose(-blk.force[:, 1].sum(), np.sum(p.slope.prop("gamma", blk.layer) * blk.area))


def test_lb_ft_units():
    text = GOOD.replace('units = "kN-m"', 'units = "lb-ft"')
    p = read(text)
    assert p.profile[2, 0] == pytest.approx(20 * 0.3048)
    assert p.slope.layers[0].c == pytest.approx(10 * 4.4482216152605 / 0.3048 ** 2)


@pytest.mark.parametrize("edit, field, needle", [
    (("kn = 2.0e5", "kn = -2.0e5"), "layer[2].kn", "kn = -2.0e5"),
    (("phi = 25.0", "phi = 95.0"), "layer[1].phi", "phi = 95.0"),
    (("gamma = 18.0", 'gamma = "heavy"'), "layer[1].gamma", 'gamma = "heavy"'),
    (("ru = 0.2", "r_u = 0.2"), "water.r_u", "r_u = 0.2"),
    (("[10.0, 0.0],", "[25.0, 0.0],"), "profile.points", "points = ["),
    (('top = [[0.0, -1.0], [30.0, 1.0]]\n', ""), "layer[2]", "[[layer]]"),
    (("c = 10.0\n", ""), "layer[1]", "[[layer]]"),
    (("size = 1.0", "size = 0.0"), "mesh.size", "size = 0.0"),
    (('units = "kN-m"', 'units = "furlongs"'), "units", 'units = "furlongs"'),
])
def test_bad_input_names_file_line_and_field(edit, field, needle):
    text = GOOD.replace(*edit)
    err = error(text)
    nth = 2 if field.startswith("layer[2]") and needle == "[[layer]]" else 1
    assert err.field == field
    assert err.file == str(FILE)
    assert err.line == line_of(text, needle, nth)
    assert err.format().startswith(f"{FILE}:{err.line}:")


def test_unknown_key_suggests_the_right_one():
    err = error(GOOD.replace("ru = 0.2", "r_u = 0.2"))
    assert "did you mean 'ru'" in err.format()


def test_syntax_error_has_its_line():
    text = GOOD.replace("c = 20.0", "c = = 20.0")
    err = error(text)
    assert err.line == line_of(text, "c = = 20.0") and err.field == "(syntax)"


def test_conflicting_water_and_missing_surface_data():
    err = error(GOOD.replace("ru = 0.2", "ru = 0.2\npiezometric = [[0.0, 0.0], [30.0, 2.0]]"))
    assert err.field == "water.piezometric"
    text = GOOD + '\n[surface]\ntype = "circle"\ncentre = [15.0, 15.0]\n'
    err = error(text)
    assert err.field == "surface" and "radius" in err.message and err.line == line_of(text, "[surface]")
    text = GOOD + '\n[surface]\ntype = "circle"\ncentre = [15.0, 40.0]\nradius = 3.0\n'
    err = error(text)
    assert err.field == "surface.type" and "below the ground" in err.message


def test_residual_needs_delta_res():
    err = error(GOOD.replace('name = "top"', 'name = "top"\nc_res = 2.0'))
    assert err.field == "layer[1]" and "delta_res" in err.message


def test_prescribed_polyline_surface_gives_slices():
    text = GOOD + '\n[surface]\ntype = "polyline"\npoints = [[8.0, 0.0], [12.0, -1.0], [19.0, 0.5], [24.0, 5.0]]\n'
    text = text.replace("size = 1.0\nbottom = -4.0", "slices = 12\nrows = 2")
    p = read(text)
    itf = p.interfaces
    assert itf.on_surface.sum() >= 12
    # every surface interface lies on the polyline
    ys = np.interp(itf.mid[itf.on_surface, 0], [8, 12, 19, 24], [0, -1, 0.5, 5])
    np.testing.assert_allclose(itf.mid[itf.on_surface, 1], ys, atol=1e-9)
    # slices are quadrilaterals or triangles
    assert set(np.diff(p.blocks.offsets).tolist()) <= {3, 4}
