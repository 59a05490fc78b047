"""`block zone apply` / `block zone apply-remove` (issue 34): body forces per unit volume on zones.

Physics against closed forms: a 1 × 1 × H column fixed at its base whose gridpoints are held in the two
directions other than the load's is a 1-D problem, u(z) = f (H z − z²/2) / E', E' = K + 4G/3 for a load
along z and G across it, so the top moves f H² / (2 E'). At equilibrium the zone stresses also meet the
virial identity Σ V σ_za = Σ z_n F_a,n over the loads on the gridpoints: the reactions sit at z = 0, so the
mean σ_za is exactly f V H/2 / V = f H / 2 (up to the solve's ratio). The split of the loads is checked
against the volume (Σ F = f V), against the corner/mid-edge shares of a 10-node zone and against gravity
(`force 0 0 −ρg` moves a model exactly as `model gravity 0 0 −g`). Bad input: file:line:column.
"""
import numpy as np
import pytest

from dec3d.errors import BindError, Dec3dError, NotSupportedError
from dec3d.session import Session
from zoning_fixture import zone_brick

E, NU = 1e9, 0.25
K, G = E / (3 * (1 - 2 * NU)), E / (2 * (1 + NU))
H = 2.0
_ELASTIC = ["block zone cmodel assign elastic", f"block zone property young {E:g} poisson {NU} density 2000"]


def _session(tmp_path, lines):
    s = Session(out_dir=tmp_path)
    for line in lines:
        s.command(line)
    return s


def _column(tmp_path, axis, apply_line):
    return _session(tmp_path, ["block create brick 0 1 0 1 0 2", "block zone generate edgelength 0.25", *_ELASTIC,
                               "block gridpoint apply velocity 0 0 0 range position-z 0",
                               *[f"block gridpoint apply velocity-{o} 0" for o in "xyz" if o != axis],
                               apply_line, "model solve ratio 1e-7"])


@pytest.mark.parametrize("axis,line", [("z", "block zone apply force-z -2e4"),
                                       ("x", "block zone apply force-x -2e4"),
                                       ("y", "block zone apply force-y 3e4"),
                                       ("z", "block zone apply force 0 0 -2e4")])
def test_column_under_a_body_force_against_the_closed_form(tmp_path, axis, line):
    s = _column(tmp_path, axis, line)
    a = "xyz".index(axis)
    f = float(line.split()[-1])
    v, zs = s.model.vertices, s.model.store("zones")
    modulus = K + 4 * G / 3 if axis == "z" else G
    top = v["pos"][:, 2] > H - 1e-9
    # the top moves f H² / (2 E'): on average within 0.3 % on this mesh of tetrahedra (measured 0.06-0.09 %),
    # every top gridpoint within 1 % (measured 0.5 %)
    want = f * H * H / (2 * modulus)
    assert abs(v["disp"][top, a].mean() - want) <= 3e-3 * abs(want)
    assert np.abs(v["disp"][top, a] - want).max() <= 1e-2 * abs(want)
    # virial identity: the volume-weighted mean σ_za is f H / 2 (σ tension positive)
    comp = {"x": 4, "y": 5, "z": 2}[axis]           # xz, yz, zz of xx yy zz xy xz yz
    mean = float((zs["volume"] * zs["stress"][:, comp]).sum() / zs["volume"].sum())
    assert mean == pytest.approx(f * H / 2, rel=2e-4)


def _loads(s):
    from dec3d.physics.zone_loads import body_loads
    m = s.model
    zs = m.store("zones")
    rows = np.arange(zs.n)
    four, ten = rows[zs["nnode"] == 4], rows[zs["nnode"] == 10]
    return body_loads(m, m.vertices["pos"], four, ten)


def test_loads_sum_to_force_times_volume_and_respect_the_range(tmp_path):
    s = _session(tmp_path, ["block create brick 0 1 0 1 0 2", "block zone generate edgelength 0.5", *_ELASTIC,
                            "block zone apply force 1e3 -2e3 3e3 range position-z 0 1"])
    zs = s.model.store("zones")
    rows, f, mag = _loads(s)
    # the zones with centroids below z = 1 hold half the 2 m³ column: Σ F = f · 1 m³ (to round-off)
    assert np.allclose(f.sum(axis=0), [1e3, -2e3, 3e3], rtol=1e-12, atol=0)
    assert np.allclose(mag, np.linalg.norm(f, axis=1))
    assert np.all(s.model.vertices["pos"][rows, 2] <= 1.0 + 1e-9)
    low = zs["fbody"][:, 2] != 0
    assert low.sum() and (~low).sum() and zs["volume"][low].sum() == pytest.approx(1.0, rel=1e-12)


def test_a_ten_node_zone_takes_the_consistent_loads(tmp_path):
    """Straight-edged 10-node tetrahedron of volume V: −f V/20 at each corner, f V/5 at each mid-edge node."""
    from zone_fixtures import zone_tet10
    s = Session(out_dir=tmp_path)
    s.command("block create tetrahedron 0 0 0 2 0 0 0 3 0 0 0 1.5")
    zone_tet10(s.model, 0)
    for line in [*_ELASTIC, "block zone apply force-y -600"]:
        s.command(line)
    rows, f, _ = _loads(s)
    gp = s.model.store("zones")["gp"][0]
    vol = 2 * 3 * 1.5 / 6
    got = dict(zip(rows.tolist(), f[:, 1]))
    assert np.allclose([got[r] for r in gp[:4]], 600 * vol / 20, rtol=1e-12)
    assert np.allclose([got[r] for r in gp[4:]], -600 * vol / 5, rtol=1e-12)
    assert np.allclose(f[:, [0, 2]], 0.0)


@pytest.mark.parametrize("zoning", ["tetrahedra", "mixed-hexahedra", "ten-node"])
def test_a_body_force_of_rho_g_moves_the_model_as_gravity_does(tmp_path, zoning):
    """Same split as the lumped (4-node) or consistent (10-node) weight: the same motion to round-off."""
    def run(load):
        s = Session(out_dir=tmp_path)
        if zoning == "ten-node":
            from zone_fixtures import zone_tet10
            s.command("block create tetrahedron 0 0 0 1 0 0 0 1 0 0 0 1")
            zone_tet10(s.model, 0)
        else:
            s.command("block create brick 0 1 0 1 0 1")
            if zoning == "tetrahedra":
                s.command("block zone generate edgelength 0.5")
            else:
                zone_brick(s.model, 0, mixed=True)
        for line in [*_ELASTIC, "block gridpoint apply velocity 0 0 0 range position-z 0", load, "model cycle 60"]:
            s.command(line)
        return s.model.vertices["disp"].copy()
    grav = run("model gravity 0 0 -10")
    body = run("block zone apply force 0 0 -2e4")
    assert np.abs(grav).max() > 0
    assert np.abs(body - grav).max() <= 1e-10 * np.abs(grav).max()


def test_a_new_value_replaces_the_old_and_apply_remove_clears(tmp_path):
    s = _session(tmp_path, ["block create brick 0 1 0 1 0 1", "block zone generate edgelength 0.5", *_ELASTIC,
                            "block zone apply force-z -1e3", "block zone apply force-z -2e3"])
    fb = lambda: s.model.store("zones")["fbody"]            # noqa: E731
    assert np.all(fb()[:, 2] == -2e3)                       # replaced, not added
    s.command("block zone apply force 1 2 3")
    s.command("block zone apply force-x 5")
    assert np.all(fb() == [5, 2, 3])
    s.command("block zone apply-remove force-y range position-z 0 0.5")
    low = s.model.store("zones")["fbody"][:, 1] == 0
    assert low.any() and (~low).any() and np.all(fb()[~low] == [5, 2, 3]) and np.all(fb()[low] == [5, 0, 3])
    s.command("block zone apply-remove")
    assert not fb().any()
    s.command("block gridpoint apply velocity 0 0 0 range position-z 0\nmodel cycle 20")
    assert not s.model.vertices["disp"].any()               # no load left: nothing moves


def test_save_and_restore_keep_the_body_force(tmp_path):
    lines = ["block create brick 0 1 0 1 0 1", "block zone generate edgelength 0.5", *_ELASTIC,
             "block gridpoint apply velocity 0 0 0 range position-z 0", "block zone apply force-x 4e3 range position-z 0.5 1"]
    a = _session(tmp_path, lines)
    a.command(f"model save '{tmp_path / 'st'}'")
    b = Session(out_dir=tmp_path)
    b.command(f"model restore '{tmp_path / 'st'}'")
    np.testing.assert_array_equal(b.model.store("zones")["fbody"], a.model.store("zones")["fbody"])
    for s in (a, b):
        s.command("model cycle 40")
    assert np.abs(a.model.vertices["disp"][:, 0]).max() > 0
    np.testing.assert_array_equal(b.model.vertices["disp"], a.model.vertices["disp"])


# ----------------------------------------------------------------------------- bad input
_SETUP = "block create brick 0 1 0 1 0 1\nblock zone generate edgelength 0.5\n"


@pytest.mark.parametrize("line,kind,at,msg", [          # at: where the column points (a keyword's value)
    ("block zone apply source 1e3", NotSupportedError, "1e3", "not supported: a heat source needs thermal analysis"),
    ("block zone apply well 1e-3 range position-z 0 1", NotSupportedError, "1e-3", "not supported: a fluid source"),
    ("block zone apply force 1 2 3 force-x 1", BindError, "1\n", "not both"),
    ("block zone apply range position-z 0 1", BindError, "block", "needs force"),
    ("block zone apply force-z", BindError, "force-z", "needs a value"),
])
def test_bad_input_names_file_line_and_column_before_anything_runs(tmp_path, line, kind, at, msg):
    deck = tmp_path / "d.dat"
    deck.write_text(_SETUP + line + "\n")
    s = Session(out_dir=tmp_path)
    with pytest.raises(kind, match=msg) as exc:
        s.call(deck)
    loc = exc.value.location
    assert loc.file.endswith("d.dat") and loc.line == 3 and loc.column == (line + "\n").index(at) + 1, loc
    assert s.model.blocks.n == 0                          # refused at binding: line 1 did not run


def test_a_range_without_zones_warns_with_its_line(tmp_path):
    s = Session(out_dir=tmp_path)
    out = []
    s.write = out.append
    s.command("block create brick 0 1 0 1 0 1")
    s.command("block zone apply force-z -1")
    assert any(ln.startswith("warning:") and "selected no zone (there are no zones" in ln for ln in out)
    s.command("block zone generate edgelength 0.5")
    s.command("block zone apply force-z -1 range position-z 5 6")
    assert any("the range selects no zone" in ln and ":1:" in ln for ln in out), out
    zs = s.model.store("zones")
    assert "fbody" not in zs or not zs["fbody"].any()


def test_not_finite_is_refused(tmp_path):
    s = _session(tmp_path, [*_SETUP.strip().split("\n")])
    with pytest.raises(Dec3dError, match="not a finite number|must be finite"):
        s.command("block zone apply force-x [1e308*10]")


def test_the_implicit_solve_takes_the_body_force(tmp_path):
    """`model solve … implicit` (its residual sums the same loads): the explicit answer of the z column."""
    out = {}
    for how in ("implicit", ""):
        s = _session(tmp_path, ["block create brick 0 1 0 1 0 2", "block zone generate edgelength 0.25", *_ELASTIC,
                                "block gridpoint apply velocity 0 0 0 range position-z 0",
                                "block gridpoint apply velocity-x 0", "block gridpoint apply velocity-y 0",
                                "block zone apply force-z -2e4", f"model solve ratio 1e-9 {how}"])
        out[how] = s.model.vertices["disp"][:, 2].copy()
    want = -2e4 * H * H / (2 * (K + 4 * G / 3))
    assert out["implicit"].min() == pytest.approx(want, rel=1e-2)
    assert np.abs(out["implicit"] - out[""]).max() <= 1e-5 * abs(want)


def test_energy_counts_the_work_of_the_body_force_as_gravity_s(tmp_path):
    """`model energy`: the `body` work of `force 0 0 −ρg` is gravity's, and the balance closes."""
    from dec3d.physics.energy import values

    def run(load):
        s = _session(tmp_path, ["block create brick 0 1 0 1 0 1", "block zone generate edgelength 0.5", *_ELASTIC,
                                "block gridpoint apply velocity 0 0 0 range position-z 0", load,
                                "model energy active on", "model cycle 100"])
        return values(s.model)
    grav, body = run("model gravity 0 0 -10"), run("block zone apply force 0 0 -2e4")
    assert body["body"] > 0 and body["body"] == pytest.approx(grav["body"], rel=1e-12)
    assert abs(body["error-relative"]) < 1e-9
