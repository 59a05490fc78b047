"""Hybrid bolts (issue 28, part 2): the dowel kernel against a plain-Python twin, a dowel across a
sliding joint through the engine, bad input, save/restore and block deletion.

The twin is written from ``physics.dowels``' formulas: the velocity of each side at the dowel point
(v + ω × r about the centroid one step back, or the given zone velocity), the point moved by the mean,
the shear part of the relative displacement Δu_s = Δu − (Δu·t) t, F ← F − k Δu_s projected across
the axis, |F| ≤ F_y, rupture once |Σ Δu_s| ≥ u_r, moments r × F of −F on A and F on B. It shares no
code or constants with ``dec3d.kernels.dowel``."""
from __future__ import annotations

import io

import numpy as np
import pytest

from dec3d.errors import Dec3dError
from dec3d.session import Session


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def twin_step(dt, D, B):
    for i in range(len(D["axis"])):
        t = D["axis"][i]
        vel = []
        for s in range(2):
            if D["hz"][i][s]:
                vel.append(list(D["hvel"][i][s]))
                continue
            h = D["blk"][i][s]
            r = [D["pos"][i][k] - (B["cen"][h][k] - B["vel"][h][k] * dt) for k in range(3)]
            w = _cross(B["spin"][h], r)
            vel.append([B["vel"][h][k] + w[k] for k in range(3)])
        D["pos"][i] = [D["pos"][i][k] + dt * (vel[0][k] + vel[1][k]) / 2 for k in range(3)]
        du = [(vel[1][k] - vel[0][k]) * dt for k in range(3)]
        along = sum(du[k] * t[k] for k in range(3))
        du = [du[k] - along * t[k] for k in range(3)]
        D["us"][i] = [D["us"][i][k] + du[k] for k in range(3)]
        kd, fy, ur = D["prop"][i]
        past = D["state"][i] & 6
        if past & 4:
            f = [0.0, 0.0, 0.0]
            st = past
        else:
            f = [D["fs"][i][k] - kd * du[k] for k in range(3)]
            fa = sum(f[k] * t[k] for k in range(3))
            f = [f[k] - fa * t[k] for k in range(3)]
            st = past
            mag = sum(x * x for x in f) ** 0.5
            if fy > 0 and mag > fy:
                f = [x * fy / mag for x in f]
                st = st | 3
            if ur > 0 and sum(x * x for x in D["us"][i]) ** 0.5 >= ur:
                f = [0.0, 0.0, 0.0]
                st = (st & 2) | 4
        D["fs"][i] = f
        D["state"][i] = st
        for s, sg in ((0, -1.0), (1, 1.0)):
            if D["hz"][i][s]:
                D["moment"][i][s] = [0.0, 0.0, 0.0]
            else:
                h = D["blk"][i][s]
                r = [D["pos"][i][k] - B["cen"][h][k] for k in range(3)]
                D["moment"][i][s] = _cross(r, [sg * x for x in f])


def _case(seed):
    rng = np.random.default_rng(seed)
    d = 5
    ax = rng.normal(size=(d, 3))
    D = {"axis": ax / np.linalg.norm(ax, axis=1)[:, None],
         "blk": np.array([[0, 1], [1, 2], [2, 0], [0, 2], [1, 0]], np.int64),
         "hz": np.array([[0, 0], [0, 1], [1, 0], [0, 0], [0, 0]], np.int8), "hvel": rng.normal(0, 1e-2, (d, 2, 3)),
         "pos": rng.normal(0, 1, (d, 3)), "prop": np.array([[1e7, 0, 0], [2e7, 300.0, 0], [1e7, 0, 2e-4],
                                                             [5e6, 200.0, 5e-4], [1e7, 1e3, 0]]),
         "fs": rng.normal(0, 50, (d, 3)), "us": rng.normal(0, 1e-5, (d, 3)),
         "state": np.array([0, 0, 0, 0, 4], np.int32),
         "moment": np.zeros((d, 2, 3))}
    B = {"vel": rng.normal(0, 1e-2, (3, 3)), "spin": rng.normal(0, 1e-2, (3, 3)), "cen": rng.normal(0, 1, (3, 3))}
    return D, B


def test_dowel_kernel_matches_twin():
    from dec3d.kernels.dowel import dowel_step

    D, B = _case(3)
    tw = {k: v.tolist() for k, v in D.items()}
    tb = {k: v.tolist() for k, v in B.items()}
    dt = 1e-3
    for _ in range(30):
        dowel_step(dt, D["axis"], D["blk"], D["hz"], D["hvel"], D["pos"], D["prop"], D["fs"], D["us"],
                   D["state"], D["moment"], B["vel"], B["spin"], B["cen"])
        twin_step(dt, tw, tb)
    for k in ("pos", "fs", "us", "moment"):
        np.testing.assert_allclose(D[k], np.array(tw[k]), rtol=1e-10, atol=1e-12, err_msg=k)
    assert D["state"].tolist() == tw["state"]
    st = D["state"]
    assert (st & 1).any() and (st & 4).any() and (st == 0).any()    # yielding, ruptured and elastic dowels


# ------------------------------------------------------------------ through the engine
SLIDE = """model new
block create brick -2 2 -2 2 -2 0
block create brick -1 1 -1 1 0 1
block property density 2500
block fix range position-z -2 0
block contact jmodel assign mohr
block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 friction 0
structure hybrid create by-line 0 0 0.9 0 0 -1.5 segments 6
structure hybrid property young 200e9 cross-sectional-area 5e-4 grout-stiffness 1e9 grout-cohesion 1e9
structure hybrid property dowel-stiffness 1e7 dowel-yield 2e4
block fix velocity range id 2
block initialize velocity-x 1e-3 range id 2
"""


def _run(text, tmp_path, s=None):
    s = s or Session(out_dir=tmp_path, stdout=io.StringIO())
    s.run_items(s.load_text(text))
    return s


def test_dowel_follows_its_stiffness_then_holds_the_yield_force(tmp_path):
    s = _run(SLIDE + "model cycle 200\n", tmp_path)
    st = s.model.stores["cable_dowels"]
    assert st.n == 1 and st["blk"][0].tolist() == [1, 0]            # from the top block into the base
    u = float(np.linalg.norm(st["us"][0]))
    assert u > 0 and np.linalg.norm(st["fs"][0]) == pytest.approx(1e7 * u, rel=1e-9)
    # the base (side B) is dragged along with the top block (+x); the top block is held back
    assert st["fs"][0, 0] > 0 and s.model.blocks["fapp"][1, 0] < 0
    _run("model cycle 2000\n", tmp_path, s)
    assert np.linalg.norm(st["us"][0]) > 2e4 / 1e7
    assert np.linalg.norm(st["fs"][0]) == pytest.approx(2e4, rel=1e-12) and st["state"][0] & 1


def test_dowel_ruptures(tmp_path):
    s = _run(SLIDE + "structure hybrid property dowel-rupture 1e-3\nmodel cycle 3000\n", tmp_path)
    st = s.model.stores["cable_dowels"]
    assert st["state"][0] & 4 and not st["fs"][0].any()
    assert "ruptured" in _run("structure hybrid list\n", tmp_path, s).stdout.getvalue()


def test_save_restore_and_delete(tmp_path):
    a = _run(SLIDE + "structure hybrid history name 'fd' shear-force component-id 1\nhistory interval 10\n"
             "model cycle 100\n", tmp_path)
    p = tmp_path / "h.sav"
    _run(f"model save '{p}'\nmodel cycle 100\n", tmp_path, a)
    b = _run(f"model restore '{p}'\nmodel cycle 100\n", tmp_path)
    np.testing.assert_array_equal(a.model.stores["cable_dowels"]["fs"], b.model.stores["cable_dowels"]["fs"])
    h = b.model.history_set.items[0]
    assert h.values[-1] == pytest.approx(np.linalg.norm(b.model.stores["cable_dowels"]["fs"][0]), rel=1e-12)
    _run("block delete range id 2\nmodel cycle 10\n", tmp_path, b)
    assert b.model.stores["cable_dowels"].n == 0
    # the dowel's force on the base went with it: what is left is the cable's own, along z (grout) and, tiny,
    # across it (the node links pass on the sideways part of the axial force where the cable has turned)
    fs_before = np.linalg.norm(a.model.stores["cable_dowels"]["fs"][0])
    assert np.abs(b.model.blocks["fapp"][0, :2]).max() < 1e-5 * fs_before


@pytest.mark.parametrize("line, where, what", [
    ("structure hybrid create by-line 0 0 0 1 0 0 segments 0", " 0", "segments"),
    ("structure hybrid property dowel-stiffness -1", "-1", "dowel-stiffness"),
    ("structure hybrid property dowel-yield -5 range id 1", "-5", "dowel-yield"),
])
def test_bad_values_refused_at_their_column(tmp_path, line, where, what):
    s = _run(SLIDE, tmp_path)
    with pytest.raises(Dec3dError) as exc:
        _run(line + "\n", tmp_path, s)
    assert exc.value.location is not None and exc.value.location.line == 1
    assert exc.value.location.column == line.rindex(where) + 1 + (where[0] == " "), exc.value.format()
    assert what in exc.value.format()


def test_bolt_in_no_block_is_refused(tmp_path):
    s = _run(SLIDE, tmp_path)
    with pytest.raises(Dec3dError, match="lies in no block") as exc:
        _run("structure hybrid create by-line 5 5 5 6 6 6 segments 3\n", tmp_path, s)
    assert exc.value.location.line == 1 and exc.value.location.column > 1
    assert s.model.stores["cable_dowels"].n == 1


def test_dowel_on_a_zoned_block_loads_its_gridpoints(tmp_path):
    """A rigid block sliding on a zoned base across a hybrid bolt: the base side of the dowel follows a
    4-node zone, and the dowel's force reaches the base's gridpoints whole (Σ wᵢ F = F)."""
    s = _run("""model new
block create brick -1 1 -1 1 -1 0
block create brick -0.5 0.5 -0.5 0.5 0 0.5
block zone generate edgelength 0.5 range position-z -1 0
block zone cmodel assign elastic range position-z -1 0
block zone property bulk 1e9 shear 1e9 density 2500 range position-z -1 0
block property density 2500 range position-z 0 0.5
block gridpoint apply velocity 0 0 0 range position-z -1
block contact jmodel assign mohr
block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 friction 0
structure hybrid create by-line 0.1 0.1 0.4 0.1 0.1 -0.8 segments 6
structure hybrid property young 200e9 cross-sectional-area 5e-4 grout-stiffness 1e9 grout-cohesion 1e9
structure hybrid property dowel-stiffness 1e7 dowel-yield 2e4
block fix velocity range position-z 0 0.5
block initialize velocity-x 1e-3 range position-z 0 0.5
model cycle 200
""", tmp_path)
    st = s.model.stores["cable_dowels"]
    assert st["hz"][0].tolist() == [0, 1] and abs(st["hw"][0, 1].sum() - 1.0) < 1e-12
    f = st["fs"][0]
    assert f[0] > 100.0 and np.linalg.norm(f) == pytest.approx(1e7 * np.linalg.norm(st["us"][0]), rel=1e-9)
    # the grout acts along the (vertical) bolt: the horizontal load on the gridpoints is the dowel's, and a
    # little (1e-5) the cable's, whose nodes are linked across it and pass on the sideways part of its axial
    # force where the sliding block has turned it
    v = s.model.vertices
    np.testing.assert_allclose(v["fapp"][: v.n, :2].sum(axis=0), f[:2], rtol=1e-4)
    # excavating the zoned base: its dowel goes, the bolt's nodes there are free, the loads they had put on
    # the sliding block and the base's gridpoints are taken back (a later `block fill` finds none)
    fapp_b = s.model.blocks["fapp"][1].copy()
    _run("block excavate range position-z -1 0\nmodel cycle 20\n", tmp_path, s)
    assert "dowel(s) lay in the excavated blocks" in s.stdout.getvalue() and st.n == 0
    assert abs(v["fapp"][: v.n]).max() < 1e-9 and abs(s.model.blocks["fapp"][1, 0]) < abs(fapp_b[0])
    assert np.isfinite(s.model.stores["cable_segments"]["fa"]).all()

