"""Bishop's simplified method and the circle search."""
import numpy as np
import pytest

from dec3d.ssdem import bishop
from dec3d.ssdem.geometry import polygon_area_centroid
from dec3d.ssdem.soil import Layer, Slope

FK = np.array([[0.0, 34.2], [91.9, 34.2], [171.9, 74.2], [260.0, 74.2]])   # ft


def slope(c=600.0, phi=20.0, gamma=120.0, ru=0.0, profile=FK, ru_mode="standard"):
    lay = Layer("s", c=c, phi=phi, c_res=c, phi_res=phi, gamma=gamma, kn=1.0, ks=1.0, delta_res=1.0,
                tensile=0.0, cutoff=False)
    return Slope(profile=profile, layers=[lay], ru=ru, ru_mode=ru_mode)


def test_undrained_circle_equals_the_moment_of_the_slip_mass():
    """phi = 0: FS = c R^2 theta / (W * lever), with W and its lever from the slip-mass polygon."""
    s = slope(c=1000.0, phi=0.0)
    xc, yc, R = 120.0, 90.0, 61.1
    res = bishop.bishop(s, (xc, yc), R, n=4000)
    x0, x1 = res["x_entry"], res["x_exit"]
    xs = np.linspace(x0, x1, 20001)
    arc = np.column_stack([xs, yc - np.sqrt(R * R - (xs - xc) ** 2)])
    top = np.column_stack([xs[::-1], s.ground(xs[::-1])])
    poly = np.concatenate([arc, top[1:-1]])
    area, cen = polygon_area_centroid(poly, np.array([0, len(poly)]))
    t0, t1 = np.arctan2(arc[0, 1] - yc, arc[0, 0] - xc), np.arctan2(arc[-1, 1] - yc, arc[-1, 0] - xc)
    expected = 1000.0 * R * R * abs(t1 - t0) / (120.0 * area[0] * (cen[0, 0] - xc))
    assert res["fs"] == pytest.approx(expected, rel=2e-4)
    assert res["fs_ordinary"] == pytest.approx(res["fs"], rel=1e-12)


@pytest.mark.parametrize("ru, published", [(0.0, 2.080), (0.25, 1.766)])
def test_fredlund_krahn_circle(ru, published):
    assert bishop.bishop(slope(ru=ru), (120.0, 90.0), 61.1)["fs"] == pytest.approx(published, rel=0.01)


def test_search_finds_no_worse_circle_than_a_given_one():
    s = slope()
    found = bishop.search(s, bottom=0.0)
    assert found["fs"] <= bishop.bishop(s, (120.0, 90.0), 61.1)["fs"]
    # it is a local minimum: nudging the circle raises FS
    xc, yc = found["centre"]
    r = found["radius"]
    for d in ([1, 0, 0], [0, 1, 0], [0, 0, 1], [-1, 0, 0], [0, -1, 0]):
        f = bishop.fs_circles(s, xc + d[0], yc + d[1], r + d[2], n=60)[0]
        assert f >= found["fs"] - 2e-3


def test_listing_ru_mode_is_weaker_than_standard_here():
    std = bishop.bishop(slope(ru=0.25), (120.0, 90.0), 61.1)["fs"]
    lst = bishop.bishop(slope(ru=0.25, ru_mode="listing"), (120.0, 90.0), 61.1)["fs"]
    dry = bishop.bishop(slope(), (120.0, 90.0), 61.1)["fs"]
    assert std < lst < dry


def test_fit_circle():
    t = np.linspace(-2.5, -0.7, 9)
    pts = np.column_stack([3 + 7 * np.cos(t), -1 + 7 * np.sin(t)])
    (xc, yc), r = bishop.fit_circle(pts)
    assert (xc, yc, r) == pytest.approx((3.0, -1.0, 7.0), abs=1e-9)
