"""Quiet (viscous) boundaries and table-driven face stresses (`block face apply quiet`,
`block face apply stress-… table|history table`, dec3d.model.quiet): binding and bad input, the
dashpot matrices against ρC_p / ρC_s by hand, the area shares against the applied-stress loads,
the time step with dashpots, a wave absorbed (and, without the quiet base, not), save/restore."""
import math

import numpy as np
import pytest

from dec3d.errors import BindError, CommandError, NotSupportedError

RHO, K, G = 2000.0, 5.0e7, 3.0e7
ZP = math.sqrt(RHO * (K + 4.0 * G / 3.0))          # ρ C_p = (ρ (K + 4G/3))^½
ZS = math.sqrt(RHO * G)                            # ρ C_s = (ρ G)^½


def _block(session, zoning="hexahedra divisions 2 2 2", props=f"bulk {K} shear {G} density {RHO}", box="0 1 0 1 0 1"):
    session.command(f"block create brick {box}\nblock zone generate {zoning}\nblock zone cmodel assign elastic")
    if props:
        session.command(f"block zone property {props}")


# ------------------------------------------------------------------ binding and bad input

def test_binding_and_bad_input(session):
    _block(session)
    with pytest.raises(BindError, match="needs stress"):
        session.command("block face apply range position-z 0")
    with pytest.raises(BindError, match="multiplies a stress"):
        session.command("table 1 add (0,0) (1,1)\nblock face apply quiet table 1 range position-z 0")
    with pytest.raises(NotSupportedError, match="history fish"):
        session.command("block face apply stress-xz 1 history fish @f range position-z 0")
    with pytest.raises(BindError, match="give the table once"):
        session.command("block face apply stress-xz 1 table 1 history table 1 range position-z 0")
    with pytest.raises(BindError, match="history"):
        session.command("block face apply stress-xz 1 history banana 1")
    with pytest.raises(CommandError, match="there is no table 7"):
        session.command("block face apply stress-xz 1 table 7 range position-z 0")
    with pytest.raises(CommandError, match="selected no boundary face"):
        session.command("block face apply quiet range position-z 5")
    assert not (session.model.faces["fquiet"] > 0).any()
    session.command("table 1 add (0,0) (1,1)\nblock face apply stress-xz -1 hist tab 1 range position-z 0")
    f = session.model.faces
    assert (f["fdyn_tab"] == 0).sum() == 8 and np.allclose(f["fdyn"][f["fdyn_tab"] == 0, 4], -1.0)


def test_quiet_refused_on_rigid_blocks_and_without_properties(session):
    session.command("block create brick 0 1 0 1 -1 0\nblock face triangulate radial")
    with pytest.raises(CommandError, match="rigid blocks take no quiet boundary"):
        session.command("block face apply quiet range position-z -1")
    session.command("model new")
    _block(session, props="")                      # zoned, elastic, no density or moduli
    with pytest.raises(CommandError, match=r"zones .* have no positive density, bulk and shear"):
        session.command("block face apply quiet range position-z 1")
    with pytest.raises(BindError, match=r"`density` must be in \(0, 1e\+09\]"):      # the binder stops ρ ≤ 0 itself
        session.command(f"block zone property bulk {K} shear {G} density 0")
    session.command("block zone property density 2000")             # moduli still 0
    with pytest.raises(CommandError, match="no positive density, bulk and shear"):
        session.command("block face apply quiet range position-z 1")
    assert not (session.model.faces["fquiet"] > 0).any()      # nothing was set by the failed commands


# ------------------------------------------------------------------ dashpots by hand

def test_dashpots_of_a_hexahedral_base_by_hand(session):
    """Base 1 × 1 of 2 × 2 hexahedral zone faces: a corner gridpoint has a quarter of one quadrilateral
    (1/16 m²), an edge one 2/16, the centre 4/16; each C = a diag(ρC_s, ρC_s, ρC_p) for the normal −z."""
    from dec3d.model.quiet import quiet_dashpots
    _block(session)
    session.command("block face apply quiet range position-z 0")
    rows, c = quiet_dashpots(session.model)
    pos = session.model.vertices["pos"][rows]
    assert np.allclose(pos[:, 2], 0.0) and len(rows) == 9
    on_edge = (np.isclose(pos[:, 0], 0) | np.isclose(pos[:, 0], 1)).astype(int) + \
        (np.isclose(pos[:, 1], 0) | np.isclose(pos[:, 1], 1)).astype(int)
    area = np.array([4, 2, 1])[on_edge] / 16.0
    want = area[:, None, None] * np.diag([ZS, ZS, ZP])[None]
    assert np.allclose(c, want, rtol=1e-12, atol=1e-9 * ZP)


def test_dashpots_on_a_slanted_tetrahedral_face(session):
    """Tetrahedral zoning, quiet on the four side faces of a block: Σ C over all gridpoints is
    Σ_faces A (ρC_s I + (ρC_p − ρC_s) n nᵀ) = 2 diag(ρC_p + ρC_s, ρC_p + ρC_s, 2ρC_s) for unit side faces."""
    from dec3d.model.quiet import quiet_dashpots
    _block(session, zoning="edgelength 0.3")
    session.command("block face apply quiet range position-x 0\nblock face apply quiet range position-x 1\n"
                    "block face apply quiet range position-y 0\nblock face apply quiet range position-y 1")
    rows, c = quiet_dashpots(session.model)
    total = c.sum(axis=0)
    assert np.allclose(total, 2.0 * np.diag([ZP + ZS, ZP + ZS, 2.0 * ZS]), rtol=1e-10)
    assert np.allclose(c, np.transpose(c, (0, 2, 1)))         # symmetric


@pytest.mark.parametrize("zoning", ["hexahedra divisions 2 3 2", "edgelength 0.4", "high-order-tetra"])
def test_area_shares_give_the_applied_stress_loads(session, zoning):
    """`face_shares` loads a uniform stress exactly as `block face apply stress` does (thirds,
    hexahedral quadrilaterals, 6-node triangles)."""
    from dec3d.model.face_loads import loadable_faces
    from dec3d.model.quiet import face_shares
    if zoning == "high-order-tetra":
        session.command("model configure highorder")
        _block(session, zoning="edgelength 0.4")
        session.command("block zone generate high-order-tetra")
    else:
        _block(session, zoning=zoning)
    s = np.array([-1.0e6, -2.0e6, -3.0e6, 4.0e5, -5.0e5, 6.0e5])
    session.command("block face apply stress " + " ".join(str(x) for x in s))
    m = session.model
    rows = np.flatnonzero(loadable_faces(m))
    fi, node, share = face_shares(m, rows, np.tile(s, (len(rows), 1)))
    sig = np.array([[s[0], s[3], s[4]], [s[3], s[1], s[5]], [s[4], s[5], s[2]]])
    got = np.zeros((m.vertices.n, 3))
    np.add.at(got, node, share @ sig.T)
    assert np.allclose(got, m.vertices["fface"], atol=1e-6 * 6.0e6)
    assert len(np.unique(fi)) <= len(rows)


# ------------------------------------------------------------------ table-driven stresses

def test_table_stress_loads_and_interpolation(session):
    from dec3d.model.quiet import dynamic_face_loads, table_value
    _block(session)
    session.command("table 'p' add (0,0) (0.1,2) (0.3,-1)\n"
                    "block face apply stress-zz -1e5 history table 'p' range position-z 1")
    (xs, ys, rows, unit), = dynamic_face_loads(session.model)
    assert np.allclose(unit.sum(axis=0), [0.0, 0.0, -1e5])   # σ·n A on the top, n = +z, A = 1
    assert table_value(xs, ys, 0.05) == pytest.approx(1.0)
    assert table_value(xs, ys, 0.2) == pytest.approx(0.5)
    assert table_value(xs, ys, 9.0) == pytest.approx(-1.0) and table_value(xs, ys, -1.0) == 0.0
    assert not np.any(session.model.vertices["fface"])         # the fixed loads are untouched
    session.command("table 2 add (0,1)")
    with pytest.raises(CommandError, match="another table"):
        session.command("block face apply stress-zz 1 table 2 range position-z 1")
    assert len(dynamic_face_loads(session.model)) == 1
    session.command("block face apply-remove quiet range position-z 1")          # stress stays
    assert len(dynamic_face_loads(session.model)) == 1
    session.command("block face apply-remove stress range position-z 1")
    assert dynamic_face_loads(session.model) == []


def test_apply_remove_keywords(session):
    _block(session)
    session.command("block face apply quiet stress-zz -1e5 range position-z 0")
    f, v = session.model.faces, session.model.vertices
    assert (f["fquiet"][:, 0] > 0).sum() == 8 and np.any(v["fface"])
    session.command("block face apply-remove stress")
    assert (f["fquiet"][:, 0] > 0).sum() == 8 and not np.any(v["fface"])
    session.command("block face apply stress-zz -1e5 range position-z 0\nblock face apply-remove")
    assert not (f["fquiet"] > 0).any() and not np.any(v["fface"])


# ------------------------------------------------------------------ time step, absorption

def _column(session, quiet=True, nz=40, height=20.0, wave="s"):
    """A 1-D column (rho 2000, G 20 MPa, K 33.3 MPa: Cs 100 m/s, Cp 173.2 m/s) with a Ricker pulse
    of 0.01 m/s entered on the base as 2ρC v, a shear wave in x (`wave` "s", stress-xz) or a
    compression wave in z ("p", stress-zz); returns (incident peak at the base, first peak at the
    top, largest |v| at the top after the base's reflection could come back)."""
    c = 100.0 if wave == "s" else math.sqrt((3.33333e7 + 4 * 2e7 / 3) / 2000.0)
    held, comp, key = ("yz", "x", "stress-xz") if wave == "s" else ("xy", "z", "stress-zz")
    session.command(f"block create brick 0 1 0 1 0 {height}\nblock zone generate hexahedra divisions 1 1 {nz}\n"
                    "block zone cmodel assign elastic\nblock zone property bulk 3.33333e7 shear 2e7 density 2000\n"
                    + "".join(f"block gridpoint apply velocity-{a} 0\n" for a in held)
                    + "block mechanical damping none")
    f0, t0 = 10.0, 0.15
    ts = np.arange(0.0, 0.3001, 0.001)
    a = (math.pi * f0 * (ts - t0)) ** 2
    pts = " ".join(f"({t:.4f},{0.01 * (1 - 2 * x) * math.exp(-x):.8g})" for t, x in zip(ts, a))
    tt = height / c
    session.command(f"table 1 add {pts}\n" + ("block face apply quiet range position-z 0\n" if quiet else "")
                    + f"block face apply {key} {-2 * 2000 * c} table 1 range position-z 0\n"
                    f"block history name 'vb' velocity-{comp} position 0 0 0\n"
                    f"block history name 'vt' velocity-{comp} position 0 0 {height}\nhistory interval 1\n"
                    f"model solve time {t0 + 3.5 * tt}")
    h = {x.name: (np.array(x.times), np.array(x.values)) for x in session.model.history_set.items}
    tb, vb = h["vb"]
    tv, vt = h["vt"]
    inc = vb[tb < t0 + tt].max()
    first = vt[(tv > t0 + 0.5 * tt) & (tv < t0 + 1.5 * tt)].max()
    back = np.abs(vt[tv > t0 + 2.5 * tt]).max()
    return inc, first, back


@pytest.mark.parametrize("wave", ["s", "p"])
def test_quiet_base_absorbs_and_free_base_reflects(session, tmp_path, wave):
    inc, first, back = _column(session, wave=wave)
    assert inc == pytest.approx(0.01, rel=0.02)              # 2ρC v on a quiet base sends v up
    assert first == pytest.approx(0.02, rel=0.02)            # doubled at the free top
    assert back / first < 0.05
    import io

    from dec3d.session import Session
    s2 = Session(out_dir=tmp_path / "free", stdout=io.StringIO())
    inc2, first2, back2 = _column(s2, quiet=False, wave=wave)
    assert inc2 == pytest.approx(0.02, rel=0.05)             # a free base moves with 2 v
    assert back2 / first2 > 0.5                              # and sends the pulse back up


def test_time_step_allows_for_dashpots(session):
    """The step of a gridpoint with dashpot c is ((c² + 4km)^½ − c)/k (k Δt²/4 + c Δt/2 = m): smaller
    than Eq. 84's 2 (m/k)^½; static (scaled) and dynamic runs stay stable with every face quiet."""
    from dec3d.physics.rigid import RunError
    from dec3d.physics.zones import ZoneStepper
    _block(session, zoning="hexahedra divisions 2 2 2")
    m = session.model
    before = ZoneStepper(m, RunError).natural_timestep()
    session.command("block face apply quiet")
    zst = ZoneStepper(m, RunError)
    after = zst.natural_timestep()
    r = zst.masters
    mm, kk, cc = zst.mtot[r], zst.ktot[r], zst.cdash[r]
    assert after == pytest.approx(((np.sqrt(cc * cc + 4 * kk * mm) - cc) / kk).min(), rel=1e-12)
    assert after < before == pytest.approx((2 * np.sqrt(mm / kk)).min(), rel=1e-12)
    session.command("block gridpoint initialize velocity-x 0.1")
    session.command("block mechanical damping none\nmodel cycle 400")
    v = m.vertices["velocity"]
    assert np.isfinite(v).all() and np.abs(v).max() < 0.01          # the dashpots drained the motion
    session.command("block mechanical damping local\nblock face apply stress-zz -1e6 range position-z 1\n"
                    "block gridpoint apply velocity 0 0 0 range position-z 0\nmodel solve ratio 1e-5")
    assert np.isfinite(m.vertices["disp"]).all()


def test_save_restore_keeps_quiet_faces_and_tables(session):
    _block(session, zoning="hexahedra divisions 1 1 4", box="0 1 0 1 0 4")
    session.command("block gridpoint apply velocity-y 0\nblock gridpoint apply velocity-z 0\n"
                    "block mechanical damping none\ntable 1 add (0,0) (0.01,1) (0.02,0)\n"
                    "block face apply quiet range position-z 0\n"
                    "block face apply stress-xz -1e5 table 1 range position-z 0\nmodel cycle 20\nmodel save 'q'")
    f = session.model.faces
    quiet, dyn, tab = f["fquiet"].copy(), f["fdyn"].copy(), f["fdyn_tab"].copy()
    session.command("model cycle 30")
    straight = session.model.vertices["velocity"].copy()
    session.command("model new\nmodel restore 'q'")
    f = session.model.faces
    assert np.array_equal(f["fquiet"], quiet) and np.array_equal(f["fdyn"], dyn) and np.array_equal(f["fdyn_tab"], tab)
    assert session.model.settings.mechanical["face_tables"][0]["y"] == [0.0, 1.0, 0.0]
    session.command("model cycle 30")
    assert np.array_equal(session.model.vertices["velocity"], straight)      # the clock of the table goes on
    assert np.abs(straight[:, 0]).max() > 0


def test_bad_face_tables_in_a_save_file_are_refused():
    from dec3d.io.state import _settings_problem
    assert "face_tables" in _settings_problem({"mechanical": {"face_tables": [{"id": 1, "x": [0, 1], "y": [0]}]}})
    assert "face_tables" in _settings_problem({"mechanical": {"face_tables": [{"id": 1, "x": [1, 0], "y": [0, 0]}]}})
    assert "face_tables" in _settings_problem({"mechanical": {"face_tables": [{"id": None, "x": [0], "y": [0]}]}})
    assert _settings_problem({"mechanical": {"face_tables": [{"id": "p", "x": [0, 1], "y": [0, 1]}]}}) is None


def test_quiet_on_an_fe_block(session):
    """An FE block takes the impedances of its elements: Σ C over the base = A diag(ρC_s, ρC_s, ρC_p)."""
    from dec3d.model.quiet import quiet_dashpots
    session.command("model configure feblock\nblock create brick 0 2 0 1 0 1\nfeblock generate 1 1 1\n"
                    "feblock change cmodel elastic young 1e7 poisson 0.25 density 2000\n"
                    "block face apply quiet range position-z 0")
    e, nu, rho = 1e7, 0.25, 2000.0
    k, g = e / (3 * (1 - 2 * nu)), e / (2 * (1 + nu))
    rows, c = quiet_dashpots(session.model)
    want = 2.0 * np.diag([math.sqrt(rho * g), math.sqrt(rho * g), math.sqrt(rho * (k + 4 * g / 3))])
    assert np.allclose(c.sum(axis=0), want, rtol=1e-10)
    assert np.allclose(session.model.vertices["pos"][rows, 2], 0.0)
    # every face quiet after a first run (the next run must not keep that run's larger Δt): the
    # dashpots of the mid-face slave nodes count at their masters, the motion drains away
    session.command("block face apply-remove\nblock gridpoint initialize velocity-x 0.1\n"
                    "block mechanical damping none\nmodel cycle 2\nblock face apply quiet\nmodel cycle 1000")
    v = session.model.vertices["velocity"]
    assert np.isfinite(v).all() and np.abs(v).max() < 1e-6
