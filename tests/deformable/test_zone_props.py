"""`block zone cmodel assign` and `block zone property`: what they store, zone ranges, and
clear errors for bad input (with the deck location)."""
import numpy as np
import pytest

from dec3d.errors import Dec3dError
from dec3d.model.zones import ZMODEL_ELASTIC, ZMODEL_NULL, ZP_BULK, ZP_DENSITY, ZP_SHEAR
from dec3d.session import Session


@pytest.fixture
def s(tmp_path):
    s = Session(out_dir=tmp_path)
    s.command("block create brick 0 1 0 1 0 2")
    s.command("block zone generate edgelength 0.5")
    return s


def _zc(s):
    zs = s.model.store("zones")
    return s.model.vertices["pos"][zs["gp"][:, :4]].mean(axis=1)


def test_young_poisson_become_bulk_and_shear(s):
    s.command("block zone cmodel assign elastic")
    s.command("block zone property young 1e9 poisson 0.25 density 2000")
    p = s.model.store("zones")["prop"]
    assert np.allclose(p[:, ZP_BULK], 1e9 / (3 * 0.5)) and np.allclose(p[:, ZP_SHEAR], 1e9 / 2.5)
    assert np.all(p[:, ZP_DENSITY] == 2000)
    # poisson alone keeps E (from the stored K and G); young alone keeps ν
    s.command("block zone prop pois 0.3")
    assert np.allclose(p[:, ZP_SHEAR], 1e9 / 2.6, rtol=1e-12)
    assert np.allclose(p[:, ZP_BULK], 1e9 / (3 * 0.4), rtol=1e-12)
    s.command("block zone property young 2e9")
    assert np.allclose(p[:, ZP_SHEAR], 2e9 / 2.6, rtol=1e-12)
    assert np.allclose(p[:, ZP_BULK], 2e9 / (3 * 0.4), rtol=1e-12)


def test_bulk_and_shear_by_zone_range(s):
    s.command("block zone property bulk 3.9e9 shear 2.8e9 range position-z 0 1")
    p = s.model.store("zones")["prop"]
    low = _zc(s)[:, 2] <= 1.0
    assert low.any() and (~low).any()
    assert np.all(p[low, ZP_BULK] == 3.9e9) and np.all(p[low, ZP_SHEAR] == 2.8e9)
    assert np.all(p[~low, ZP_BULK] == 0) and np.all(p[~low, ZP_SHEAR] == 0)


def test_cmodel_null_clears_stress_and_group_range_reaches_zones_of_the_block(s):
    s.command("block group 'rock'")
    s.command("block zone cmodel assign elastic range group 'rock'")
    zs = s.model.store("zones")
    assert np.all(zs["cmodel"] == ZMODEL_ELASTIC)
    zs["stress"][:] = 1.0
    s.command("block zone cmodel assign null range position-z 1 2")
    high = _zc(s)[:, 2] >= 1.0
    assert np.all(zs["cmodel"][high] == ZMODEL_NULL) and np.all(zs["stress"][high] == 0.0)
    assert np.all(zs["cmodel"][~high] == ZMODEL_ELASTIC) and np.all(zs["stress"][~high] == 1.0)


@pytest.mark.parametrize("line,msg", [
    ("block zone property", "needs a property: young, poisson, bulk, shear, density, cohesion, friction, tension, dilation"),
    ("block zone property bulk -1e9", r"`bulk` must be in \(0, 1e\+16\]"),
    ("block zone property shear 0", r"`shear` must be in \(0, 1e\+16\]"),
    ("block zone property young -5", r"`young` must be in \(0, 1e\+16\]"),
    ("block zone property poisson 0.5 young 1e9", r"`poisson` must be in \(-1, 0.5\)"),
    ("block zone property poisson -1 young 1e9", r"`poisson` must be in \(-1, 0.5\)"),
    ("block zone property density 0", r"`density` must be in \(0, 1e\+09\]"),
    ("block zone property bulk 1e9 young 1e9", "give bulk/shear or young/poisson, not both"),
    ("block zone property young 1e9", r"`block zone property young` needs poisson too: \d+ zone\(s\) in range"),
    ("block zone property poisson 0.2", r"needs young too"),
    ("block zone cmodel assign plastic", "elastic|null"),
    ("block zone cmodel assign", "needs model"),
])
def test_bad_input_is_a_clear_error_with_its_location(s, line, msg):
    before = s.model.store("zones")["prop"].copy()
    with pytest.raises(Dec3dError, match=msg) as exc:
        s.command(line)
    loc = exc.value.location                             # file:line:col of the offending word
    assert loc is not None and loc.line == 1 and loc.column >= 1
    assert np.array_equal(s.model.store("zones")["prop"], before)


def test_no_zone_in_range_is_a_warning(tmp_path):
    s = Session(out_dir=tmp_path)
    s.command("block create brick 0 1 0 1 0 1")
    lines = []
    s.write = lines.append
    s.command("block zone property density 2000")
    assert any("selected no zone" in ln and "block zone generate" in ln for ln in lines)
