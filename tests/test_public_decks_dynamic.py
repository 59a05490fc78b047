"""Issue 14's public decks run to the end: compas_3dec's V8_eigen folder (eigen.dat, then dynmas.dat
restoring the "sqpmodes" that eigen.dat saved, gravity.dat, then displacement.dat restoring its
grav.sav), all in one folder as their authors ran them, and SAFEGO's Geo_Prep.dat.

The decks are read from $DEC3D_SHARED/decks at test time and copied into tmp_path (never into the
repository). The files they call and that were not published are stand-ins written here:
`geometry.dat` (a small masonry wall on two supports, groups 'Blocks' and 'Supports', the support
under the left half in region 0, which displacement.dat lifts) and `Groningen.dec` (a 12-course
wall between the support and top beam that Geo_Prep.dat adds)."""
from __future__ import annotations

import io
import math
import re
import shutil

import numpy as np
import pytest

from conftest import DECKS, NO_DECKS
from dec3d.check import RUNNABLE, check_file
from dec3d.physics.dynamic import dynamic_time, is_dynamic
from dec3d.session import Session

V8 = "BlockResearchGroup__compas_3dec__docs__examples__"
V8_DECKS = {"eigen.dat": f"{V8}V8_eigen__eigen.dat", "dynmas.dat": f"{V8}V8_eigen__dynmas.dat",
            "gravity.dat": f"{V8}V8_eigen__gravity.dat", "displacement.dat": f"{V8}displacement.dat"}
GEO_PREP = "yopi1838__Hanze_SAFEGO__Geo_Prep.dat"

GEOMETRY = """; stand-in for compas_3dec's geometry.dat (not published): a wall of two courses in running bond
; on two support blocks; the left support is region 0 (displacement.dat lifts region 0)
block create brick -0.1 0.6 -0.1 0.1 -0.2 0 group 'Supports' region 0
block create brick 0.6 1.3 -0.1 0.1 -0.2 0 group 'Supports' region 2
block create brick 0.0 0.4 -0.1 0.1 0.0 0.2 group 'Blocks' region 1
block create brick 0.4 0.8 -0.1 0.1 0.0 0.2 group 'Blocks' region 1
block create brick 0.8 1.2 -0.1 0.1 0.0 0.2 group 'Blocks' region 1
block create brick 0.0 0.2 -0.1 0.1 0.2 0.4 group 'Blocks' region 1
block create brick 0.2 0.6 -0.1 0.1 0.2 0.4 group 'Blocks' region 1
block create brick 0.6 1.0 -0.1 0.1 0.2 0.4 group 'Blocks' region 1
block create brick 1.0 1.2 -0.1 0.1 0.2 0.4 group 'Blocks' region 1
"""
WALL_VOLUME = 1.2 * 0.2 * 0.4 + 2 * 0.7 * 0.2 * 0.2

# Groningen.dec stand-in: L × H wall, T thick in z, N courses; even courses 3 bricks, odd ones 4 (half
# bricks at the ends)
L, H, T, N = 1.292, 2.58, 0.21, 12


def _groningen() -> str:
    h = H / N
    out = ["; stand-in for SAFEGO's Groningen.dec (not published): 12 courses in running bond"]
    for k in range(N):
        cuts = [0, L / 3, 2 * L / 3, L] if k % 2 == 0 else [0, L / 6, L / 2, 5 * L / 6, L]
        out += [f"block create brick {a:.6f} {b:.6f} {k * h:.6f} {(k + 1) * h:.6f} 0 {T}"
                for a, b in zip(cuts[:-1], cuts[1:])]
    return "\n".join(out) + "\n"


def _need(*names):
    for n in names:
        if not (DECKS / n).is_file():
            pytest.skip(NO_DECKS)


def _run(folder, deck, extra=""):
    out = io.StringIO()
    s = Session(out_dir=folder / "out", stdout=out)
    s.run_items(s.load_file(folder / deck))
    if extra:
        s.command(extra)
    return s, out.getvalue()


def _finite_state(model):
    b = model.blocks
    for f in ("centroid", "velocity", "spin", "force", "disp"):
        assert np.all(np.isfinite(b[f][: b.n])), f
    assert np.all(np.isfinite(model.vertices["pos"][: model.vertices.n]))


@pytest.fixture(scope="module")
def v8(tmp_path_factory):
    _need(*V8_DECKS.values())
    folder = tmp_path_factory.mktemp("v8")
    for name, src in V8_DECKS.items():
        shutil.copy(DECKS / src, folder / name)
    (folder / "geometry.dat").write_text(GEOMETRY, encoding="utf-8")
    return folder


def test_every_line_of_the_v8_decks_binds(v8):
    for name in V8_DECKS:
        reports = check_file(v8 / name)
        bad = [f"{name}:{r.line}: {r.status}: {r.what}" for r in reports if r.status != RUNNABLE]
        assert not bad, "\n".join(bad)
        assert reports


def test_v8_chain_runs_in_order_in_one_folder(v8):
    import meshio

    out = v8 / "out"
    # --- eigen.dat: 8 modes of the wall on its fixed supports
    s, text = _run(v8, "eigen.dat")
    f = np.array([s.results[f"eigen.f{i}"] for i in range(1, 9)])
    assert np.all(np.isfinite(f)) and np.all(f > 0) and np.all(np.diff(f) >= 0)
    # the lowest mode lies between the rigid-body estimates the contact springs allow: a brick of the
    # wall (0.2 × 0.2 × 0.4 m, 1500 kg/m³) bouncing on its full bed joint with kn = 100e9 Pa/m is the
    # stiffest single-body mode √(kn A / m)/2π; the whole wall rocking cannot be faster than that
    m_brick = 1500 * 0.4 * 0.2 * 0.2
    assert f[0] < math.sqrt(100e9 * 0.4 * 0.2 / m_brick) / (2 * math.pi)
    assert "notice: `block dynamic eigen setmode` is display-only" in text
    mesh = meshio.read(out / "eigen_modes.vtu")
    assert mesh.field_data["frequency"].tolist() == pytest.approx(f.tolist(), rel=1e-12)
    supports = np.isin(s.model.vertices["block"][: s.model.vertices.n], [0, 1])   # rows of blocks 1 and 2
    for i in range(1, 9):
        shape = mesh.point_data[f"mode_{i}"]
        assert np.abs(shape).max() == pytest.approx(1.0, rel=1e-12)
        assert np.abs(shape[supports]).max() == 0.0          # fixed supports do not move
    assert (out / "sqpmodes.sav").is_file()

    # --- dynmas.dat restores "sqpmodes" and turns dynamic mode on; we cycle on to see time advance
    s, text = _run(v8, "dynmas.dat", "model cycle 50\n[dt = mech.timestep]")
    assert "dynamic mode        : on" in text and "density scaling     : off (real masses)" in text
    assert is_dynamic(s.model)
    dt = s.variables["dt"]
    assert dt > 0 and dynamic_time(s.model) == pytest.approx(50 * dt, rel=1e-12)
    _finite_state(s.model)
    # no gravity yet and nothing loaded: the wall stays put
    assert np.abs(s.model.blocks["velocity"][: s.model.blocks.n]).max() < 1e-9

    # --- gravity.dat: gravity in ten steps, then the state and contacts written by FISH
    s, text = _run(v8, "gravity.dat")
    for name in ("init.sav", "grav.sav", "init_state.txt", "grav_state.txt", "contact_grav.txt"):
        assert (out / name).is_file(), name
    _finite_state(s.model)
    # the unbalanced force of every masonry block, weight put back (rz = unbal + m g) is its weight
    # again: each is at rest on its bed joint
    grav = (out / "grav_state.txt").read_text()
    rz = [float(v) for v in re.findall(r"^forces = [^,]+,[^,]+,(\S+) 1$", grav, flags=re.M)]
    masses = [float(v) for v in re.findall(r"^mass\s+(\S+)", grav, flags=re.M)][2:]
    assert len(rz) == 7 and len(masses) == 7
    for r, m in zip(rz, masses):
        assert r == pytest.approx(-9.81 * m, rel=1e-3)
    vol = sum(float(v) for v in re.findall(r"^volume\s+(\S+)", grav, flags=re.M))
    assert vol == pytest.approx(WALL_VOLUME, rel=1e-12)

    # --- displacement.dat: restores grav.sav, lifts region 0 for 522 steps, solves, writes, exits
    before = s.model.blocks["centroid"][0].copy()
    s, text = _run(v8, "displacement.dat")
    txt = (out / "Displacement_step_1_distance_0.001m.txt").read_text()
    dt = float(re.search(r"^timestep =\s+(\S+)", txt, flags=re.M).group(1))
    lifted = s.model.blocks["centroid"][0] - before
    assert lifted[2] == pytest.approx(522 * dt * 0.001, rel=1e-9)
    assert abs(lifted[0]) < 1e-12 and abs(lifted[1]) < 1e-12
    ratio = float(re.search(r"^solve ratio =\s+(\S+)", txt, flags=re.M).group(1))
    assert 0 <= ratio < 1e-5
    assert (out / "Displacement_step_1_distance_0.001m_contacts.txt").is_file()
    assert (out / "Displacement_step_1_distance_0.001m.sav").is_file()
    _finite_state(s.model)
    # everything the decks wrote is in the output folder: the deck folder holds only what we put there
    assert sorted(p.name for p in v8.iterdir()) == sorted([*V8_DECKS, "geometry.dat", "out"])


def test_geo_prep_runs_with_a_stub_groningen_dec(tmp_path):
    _need(GEO_PREP)
    shutil.copy(DECKS / GEO_PREP, tmp_path / "Geo_Prep.dat")
    (tmp_path / "Groningen.dec").write_text(_groningen(), encoding="utf-8")
    reports = check_file(tmp_path / "Geo_Prep.dat")
    assert reports and all(r.status == RUNNABLE for r in reports)
    s, _ = _run(tmp_path, "Geo_Prep.dat")
    m = s.model
    b = m.blocks
    # 42 bricks (6 courses of 3, 6 of 4); only course 1 has its centroid (y = 0.3225) in the window
    # rows the deck leaves visible, so the cut at z = 0.105 splits its 4 bricks in two wythes (+4);
    # in the back wythe one brick lies across each pair of vertical cuts: 3 pieces, the middle one
    # deleted (+1 each); plus the support and the top beam
    assert b.n == 42 + 4 + 1 + 1 + 2
    h = H / N
    removed = h * (T - 0.105) * ((0.4038 - 0.3230) + (0.9690 - 0.8883))
    total = float(np.sum(b["volume"][: b.n]))
    assert total == pytest.approx(L * H * T - removed + L * 0.05 * T + L * 0.10 * T, rel=1e-9)
    c = b["centroid"][: b.n]
    gone = (c[:, 0] > 0.3230) & (c[:, 0] < 0.4038) & (c[:, 2] > 0.105) & (np.abs(c[:, 1] - 1.5 * h) < h / 2)
    assert not gone.any()
    masonry = m.groups.code("Masonry")
    assert masonry > 0
    in_masonry = (b["group"][: b.n] == masonry).any(axis=1)
    assert int(in_masonry.sum()) == b.n - 2
    assert (tmp_path / "out" / "GEO_WALL.sav").is_file()
    _finite_state(m)
