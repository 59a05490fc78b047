"""Block commands run from deck text and from the example decks."""
import io
import json
import math
import zipfile

import numpy as np
import pytest
import pyvista as pv

from conftest import ROOT
from dec3d.errors import Dec3dError
from dec3d.session import Session, run_deck

EXAMPLES = ROOT / "examples" / "blocks"


def run(text, tmp_path):
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command(text)
    return s


def test_jointed_cube_example(tmp_path):
    s = run_deck(EXAMPLES / "jointed_cube.dat", out_dir=tmp_path)
    b = s.model.blocks
    assert b.n == 64 and abs(b["volume"].sum() - 1000.0) <= 1e-12 * 1000
    assert (b["density"] == 2650.0).all()
    col = s.model.groups.slot_index(b, "level")
    assert (b["group"][:, col] == s.model.groups.code("top")).sum() == 16
    assert (s.model.faces["group"][:, 0] == s.model.groups.code("base")).sum() == 16
    grid = pv.read(tmp_path / "jointed_cube_0000.vtu")
    assert grid.n_cells == 64
    np.testing.assert_array_equal(grid.cell_data["block_id"], b["id"])
    assert (tmp_path / "jointed_cube.pvd").exists() and (tmp_path / "jointed_cube.sav").exists()


def test_tunnel_quarter_example(tmp_path):
    s = run_deck(EXAMPLES / "tunnel_quarter.dat", out_dir=tmp_path)
    b = s.model.blocks
    hole = 0.5 * 40 * math.sin(2 * math.pi / 40)
    assert b.n == 100
    assert b["volume"].sum() == pytest.approx(100.0 - hole / 4, rel=1e-13)
    assert (b["leader"] == b["leader"][0]).all()          # one joined body
    assert (s.model.faces["group"][:, 0] == s.model.groups.code("right")).sum() == 5
    assert pv.read(tmp_path / "tunnel_quarter_0000.vtu").n_cells == 100


def test_wall_example(tmp_path):
    s = run_deck(EXAMPLES / "wall_openings.dat", out_dir=tmp_path)
    b = s.model.blocks
    assert b["volume"].sum() == pytest.approx(2.4 * 0.2 * 1.2 + 2.6 * 0.3 * 0.2 - 0.6 * 0.2 * 0.4, rel=1e-12)
    masonry = b["group"][:, 0] == s.model.groups.code("masonry")
    assert masonry.sum() == b.n - 1
    assert (b["face_count"][masonry] > 6).all() and b["face_count"][~masonry][0] == 6
    # no brick sits inside the window
    c = b["centroid"]
    assert not np.any((c[:, 0] > 0.9) & (c[:, 0] < 1.5) & (c[:, 2] > 0.6) & (c[:, 2] < 1.0))


def test_shapes_example(tmp_path):
    s = run_deck(EXAMPLES / "shapes.dat", out_dir=tmp_path)
    b = s.model.blocks
    assert b["volume"].sum() == pytest.approx(8.0 + 4.0 + 4.0 / 3.0, rel=1e-12)
    g = s.model.groups
    tet = b["group"][:, 0] == g.code("tet")
    assert tet.sum() == 1 and b["centroid"][tet][0, 0] == pytest.approx(6.5)
    assert pv.read(tmp_path / "shapes_0000.vtu").n_cells == b.n


def test_hidden_blocks_are_not_cut_and_hide_forms(tmp_path):
    s = run("""block create brick 0 1 0 1 0 1
block create brick 2 3 0 1 0 1 group 'keep'
block hide group 'keep'
block cut joint-set dip 0 origin 0 0 0.5
block hide off
block hide pos-x 0 1
block cut joint-set dip 90 dip-direction 90 origin 2.5 0 0
block hide off""", tmp_path)
    vols = sorted(s.model.blocks["volume"])
    np.testing.assert_allclose(vols, [0.5, 0.5, 0.5, 0.5])
    s.command("block hide")
    assert s.model.blocks["hidden"].all()


def test_range_words_in_commands(tmp_path):
    s = run("""block create brick 0 4 0 1 0 1
block cut joint-set dip 90 dip-direction 90 spacing 1
block group 'a' range id-list 1 2
block group 'b' slot 'x' range id 2
block group 'c' slot 'other' range group 'a' not
block delete range group-intersection 'a' 'b'
block delete range sphere centre 3.5 0.5 0.5 radius 0.1 union position-x 0.5""", tmp_path)
    assert sorted(s.model.blocks["id"]) == [3]


def test_save_restore_save_arrays_identical(tmp_path):
    s = run("""block create brick 0 2 0 2 0 2 group 'rock'
block cut joint-set dip 60 dip-direction 30 spacing 0.7
block property density 2500
block join range id-list 1 2
model save 'a'""", tmp_path)
    before = s.model
    s.command("model restore 'a'\nmodel save 'b'")
    assert s.model is not before
    with zipfile.ZipFile(tmp_path / "a.sav") as za, zipfile.ZipFile(tmp_path / "b.sav") as zb:
        names = za.namelist()
        assert names == zb.namelist()
        for n in names:
            if n != "meta.json":
                assert za.read(n) == zb.read(n), n
        # a restore takes the saved record as it is (the restore line is not added): the files are identical
        assert json.loads(zb.read("meta.json"))["records"][-1] == "block join range id-list 1 2"
    assert (tmp_path / "a.sav").read_bytes() == (tmp_path / "b.sav").read_bytes()
    # with the same command record, restore -> save reproduces the whole file
    t = Session(out_dir=tmp_path, stdout=io.StringIO())
    t.command("model restore 'b'")
    t.record[:] = []
    t.command("model save 'e'")
    u = Session(out_dir=tmp_path, stdout=io.StringIO())
    u.command("model restore 'e'")
    u.record[:] = []
    u.command("model save 'f'")
    assert (tmp_path / "e.sav").read_bytes() == (tmp_path / "f.sav").read_bytes()


def test_failed_restore_keeps_the_model(tmp_path):
    s = run("block create brick 0 1 0 1 0 1\nmodel save 'ok'", tmp_path)
    (tmp_path / "bad.sav").write_bytes(b"not a zip")
    model = s.model
    with pytest.raises(Dec3dError, match="cannot read state file") as info:
        s.command("model restore 'bad'")
    assert s.model is model and s.model.blocks.n == 1
    assert info.value.location.line == 1


def test_bad_geometry_names_the_line_and_face(tmp_path):
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    deck = tmp_path / "bad.dat"
    deck.write_text("model new\nblock create brick 0 1\n"
                    "block create polyhedron face 0,0,0 1,0,0 1,1,0.3 0,1,0 face 0,0,0 0,0,1 1,0,0 &\n"
                    "   face 0,0,0 0,1,0 0,0,1 face 1,0,0 0,0,1 1,1,0.3\n")
    with pytest.raises(Dec3dError) as info:
        s.call(deck)
    assert info.value.location.line == 3
    assert "face 1 is not planar" in str(info.value)
    assert s.model.blocks.n == 1                 # the brick stays, nothing half-made
    for text, words in [
        ("block create prism face-1 0 0 0 1 0 0 0 1 0 face-2 0 0 0 1 0 0 0 1 0", "zero volume"),
        ("block create polyhedron face 0,0,0 1,0,0 0,1,0 face 0,0,0 0,0,1 1,0,0 face 0,0,0 0,1,0 0,0,1 "
         "face 1,0,0 0,0,1 0.2,0.2,0.2", "open"),
        ("block create tunnel radius 1 length 0 0 boundary 2", "empty"),
    ]:
        with pytest.raises(Dec3dError, match=words) as info:
            s.command(text)
        assert info.value.location.line == 1
    assert s.model.blocks.n == 1


def test_block_vtk_interval_and_off(tmp_path):
    from dec3d.io.vtk import periodic_vtk

    s = run("block create brick 0 1 0 1 0 1\nblock vtk 'series' interval 10", tmp_path)
    m = s.model
    m.step, m.time = 5, 0.5
    assert periodic_vtk(m) is None
    m.step, m.time = 10, 1.0
    assert periodic_vtk(m).endswith("series_0001.vtu")
    s.command("block vtk off")
    m.step = 100
    assert periodic_vtk(m) is None
    reader = pv.get_reader(tmp_path / "series.pvd")
    assert list(reader.time_values) == [0.0, 1.0]


def test_block_list_and_tolerance(tmp_path):
    s = run("block create brick 0 1 0 1 0 1 group 'rock'\nblock tolerance 1e-4\nblock list\n"
            "block list information", tmp_path)
    out = s.stdout.getvalue()
    assert "rock" in out and "tolerance 0.0001\n" in out and s.model.tolerance == 1e-4     # no unit declared
