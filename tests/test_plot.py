"""Pictures (dec3d.plot): the `plot` commands of real decks write PNGs whose content is checked, not only
that a file exists: colours where a block of known displacement is drawn, the plastic-state legend's
colours on zones of known state, the joint planes, a history chart, `dec3d plot` from a .pvd."""
import numpy as np
import pytest

from dec3d.cli import main
from dec3d.plot.items import Item, UnknownItem, item_from_name, item_from_words
from dec3d.plot.render import STATE_COLOURS, render
from dec3d.plot.scene import scene_from_files, scene_from_model

TWO_BLOCKS = """model new
block create brick 0 1 0 1 0 1 group 'left'
block create brick 2 3 0 1 0 1 group 'right'
block property density 2000
block fix range position-x 0 1
model gravity 0 0 -9.81
model history mechanical unbalanced-maximum
block history displacement-z position 2.5 0.5 1
model cycle 100
"""


def _image(path):
    import matplotlib.image as mpimg

    img = mpimg.imread(str(path))
    return (img[:, :, :3] * 255).round().astype(int) if img.dtype != np.uint8 else img[:, :, :3].astype(int)


def _drawn(img, background=(255, 255, 255)) -> int:
    """Pixels that are not the background."""
    return int((np.abs(img - np.array(background)).sum(axis=2) > 30).sum())


def _session(tmp_path, text):
    from dec3d.session import Session

    s = Session(out_dir=tmp_path)
    for line in text.strip().splitlines():
        s.command(line)
    return s


def _hex(c):
    return np.array([int(c[i:i + 2], 16) for i in (1, 3, 5)])


def test_displacement_contour_colours_each_block_by_its_displacement(tmp_path):
    """The fixed block (displacement 0) is drawn in the colour of the bottom of the scale (jet: dark blue),
    the falling one (one uniform displacement, the maximum) in that of the top (dark red), at the centre
    of each block's front face."""
    s = _session(tmp_path, TWO_BLOCKS)
    b = s.model.blocks
    dz = b["disp"][:, 2]
    assert sorted(dz)[1] == 0.0 and dz.min() < -1e-3                      # one fell, one held
    pic, notices = render(scene_from_model(s.model), [Item("contour", "displacement")], tmp_path / "d.png")
    assert notices == []
    img = _image(tmp_path / "d.png")
    np.testing.assert_array_equal(img, pic.image)
    assert _drawn(img) > 0.1 * img.shape[0] * img.shape[1]
    fell = int(np.argmin(dz))
    held = 1 - fell
    for row, colour in ((fell, (128, 0, 0)), (held, (0, 0, 128))):        # jet's two ends
        x, y, z = b["centroid"][row]                                              # the block's centroid now
        r, c = pic.pixel_of([x, y - 0.5, z])                                 # its front face (y = 0) seen from −y
        got = img[r - 2:r + 3, c - 2:c + 3].reshape(-1, 3).mean(axis=0)
        assert np.abs(got - colour).max() < 40, (row, got)


def test_plastic_state_is_drawn_with_the_legend_colours(tmp_path):
    """Two zones far apart, one `shear-n`, one `none`: each drawn in its category's colour."""
    import pyvista as pv

    from dec3d.plot.scene import Scene

    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 0, 1], [0, 1, 0],
                    [3, 0, 0], [4, 0, 0], [3, 0, 1], [3, 1, 0]], dtype=float)
    grid = pv.UnstructuredGrid(np.array([4, 0, 1, 2, 3, 4, 4, 5, 6, 7]), np.array([10, 10], np.uint8), pts)
    grid.cell_data["plastic_label"] = np.array([1, 0], np.uint8)
    grid.cell_data["zone_id"] = np.array([1, 2])
    pic, _ = render(Scene(solids=[grid]), [Item("state", "state")], tmp_path / "s.png")
    img = pic.image
    # a point inside each tetra's front face (y = 0): a third of the way from its corner
    for x0, label in ((0.0, "shear-n"), (3.0, "none")):
        r, c = pic.pixel_of([x0 + 0.3, 0.0, 0.3])
        got = img[r - 1:r + 2, c - 1:c + 2].reshape(-1, 3).mean(axis=0)
        assert np.abs(got - _hex(STATE_COLOURS[label])).max() < 25, (label, got)


def test_deck_plot_commands_write_pictures(tmp_path):
    """The forms of shared/decks: plot create / item create block / chart-history / export bitmap of a
    named plot (no extension: .png) and of the current one / a plot the deck never made / clear /
    background / active; an item dec3d does not draw is a notice."""
    deck = tmp_path / "d.dat"
    deck.write_text(TWO_BLOCKS + """plot create
plot clear
plot active on
plot background 'white'
plot item create block
plot export bitmap filename 'geometry.png'
plot create 'Unbalanced Force'
plot item create chart-history history '1' vs '2'
plot 'Unbalanced Force' export bitmap filename 'Unbalanced Force'
plot 'RadialDisp' export bitmap filename "disp.png"
plot create 'J'
plot item create block contact contour normal-stress
plot item create block zone contour stress-zz
plot item create ball
plot 'J' export bitmap filename 'j.png' size 400 300
""")
    assert main(["run", str(deck), "--out", str(tmp_path / "out")]) == 0
    out = tmp_path / "out"
    geo = _image(out / "geometry.png")
    assert geo.shape == (600, 800, 3) and _drawn(geo) > 0.1 * 600 * 800
    # the two groups in two colours of the group palette
    chart = _image(out / "Unbalanced Force.png")
    assert _drawn(chart) > 2000 and (np.abs(chart - [31, 119, 180]).sum(axis=2) < 40).sum() > 100   # the line
    disp = _image(out / "disp.png")
    assert (np.abs(disp - [128, 0, 0]).sum(axis=2) < 60).sum() > 1000      # the falling block, top of the scale
    j = _image(out / "j.png")
    assert j.shape == (300, 400, 3)


def test_deck_plot_notices(tmp_path, capsys):
    deck = tmp_path / "d.dat"
    deck.write_text(TWO_BLOCKS + "plot 'Stress' export bitmap filename 's.png'\nplot item create ball\n"
                    "plot item create ball\nplot view reset\nplot cre 'B'\nplot backg 'nocolour'\n"
                    "plot it cr block\nplot exp bitm fil 'b.png'\n")
    assert main(["run", str(deck), "--out", str(tmp_path), "-q"]) == 0
    out = capsys.readouterr().out
    assert "plot 'Stress' was not made in this deck" in out
    assert out.count("plot item `ball` is not drawn by dec3d") == 1 and "d.dat:11:1" in out
    assert "`plot view` is a view setting" in out
    assert "background 'nocolour' is not a colour" in out and "plot 'B' written to b.png" in out   # abbreviated
    assert _drawn(_image(tmp_path / "b.png")) > 10000


def test_items_from_words_and_names():
    assert item_from_words(["block"]).kind == "blocks"
    assert item_from_words("block contour displacement".split()) == Item("contour", "displacement")
    assert item_from_words("zone contour stress-zz".split()) == Item("contour", "stress-zz")
    assert item_from_words("block zone contour stress-zz".split()) == Item("contour", "stress-zz")
    assert item_from_words("zone contour stress quantity zz".split()) == Item("contour", "stress-zz")
    assert item_from_words("zone contour stress quantity minimum".split()) == Item("contour", "stress-min")
    assert item_from_words("zone label state".split()).kind == "state"
    assert item_from_words("block contact contour shear-stress".split()) == Item("joints", "shear-stress")
    assert item_from_words("block vector velocity".split()) == Item("vector", "velocity")
    assert item_from_words("chart-history history 1 vs 2".split()) == Item("chart", "history", ("1",), "2")
    assert item_from_name("stress-zz") == Item("contour", "stress-zz")
    assert item_from_name("displacement-x") == Item("contour", "displacement-x")
    with pytest.raises(UnknownItem):
        item_from_words(["ball"])
    with pytest.raises(UnknownItem):
        item_from_name("nonsense")


def test_joint_planes_tile_the_contact_and_carry_its_values(tmp_path):
    """Two blocks pressed together: the joint file has one quadrilateral per sub-contact on the common
    face x = 1 that together tile the 1 x 1 face, with the store's normal stress; the picture colours them."""
    import meshio

    s = _session(tmp_path, """model new
block create brick 0 1 0 1 0 1
block create brick 1 2 0 1 0 1
block property density 2000
block contact generate-subcontacts
block contact property stiffness-normal 1e9 stiffness-shear 1e9 friction 30
block fix range position-x 0 1
block apply force -1e4 0 0 range position-x 1 2
model cycle 200
block vtk 'p'""")
    m = meshio.read(tmp_path / "p_joints_0000.vtu")
    quads = m.cells_dict["quad"]
    p = m.points[quads]
    assert np.allclose(p[:, :, 0], 1.0, atol=1e-6)
    tri = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]) + np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 0])
    assert abs(0.5 * np.linalg.norm(tri, axis=1).sum() - 1.0) < 1e-6      # the face, once
    # the shares of the face: inside it (squares about its corners would stick out), and covering it
    assert p[:, :, 1:].min() > -1e-9 and p[:, :, 1:].max() < 1 + 1e-9
    grid = np.stack(np.meshgrid(np.linspace(0.05, 0.95, 7), np.linspace(0.05, 0.95, 7)), -1).reshape(-1, 2)

    def inside(pt, quad):                   # a point in a convex (or degenerate-to-triangle) quadrilateral
        q = quad[:, 1:]
        cr = [(q[(i + 1) % 4] - q[i])[0] * (pt - q[i])[1] - (q[(i + 1) % 4] - q[i])[1] * (pt - q[i])[0]
              for i in range(4)]
        return all(c >= -1e-12 for c in cr) or all(c <= 1e-12 for c in cr)
    assert all(sum(inside(g, quad) for quad in p) >= 1 for g in grid)
    from dec3d.io.contactvtk import contact_point_data
    _, data = contact_point_data(s.model)
    np.testing.assert_array_equal(m.cell_data["normal_stress"][0], data["normal_stress"])
    sn = m.cell_data["normal_stress"][0]
    assert (sn > 0).all() and abs((sn * m.cell_data["area"][0]).sum() - 1e4) < 1e3      # it carries the push
    np.testing.assert_array_equal(m.cell_data["opening"][0], np.maximum(data["normal_displacement"], 0))
    sc = scene_from_files(tmp_path / "p.pvd")
    assert sc.joints is not None and len(sc.solids) == 1
    pic, notices = render(sc, [Item("joints", "normal-stress")], tmp_path / "j.png")
    assert notices == [] and _drawn(pic.image) > 5000


def test_cli_plot_from_pvd(tmp_path, capsys):
    _session(tmp_path, TWO_BLOCKS + "block vtk 'b'\nmodel save 'b'")
    assert main(["plot", str(tmp_path / "b.pvd"), "--item", "displacement", "--item", "blocks",
                 "--out", str(tmp_path / "pics")]) == 0
    for name in ("b_displacement.png", "b_blocks.png"):
        assert _drawn(_image(tmp_path / "pics" / name)) > 10000
    # from the save: the same model, the same picture
    assert main(["plot", str(tmp_path / "b.sav"), "--item", "displacement", "--out", str(tmp_path / "sav")]) == 0
    np.testing.assert_array_equal(_image(tmp_path / "sav" / "b_displacement.png"),
                                  _image(tmp_path / "pics" / "b_displacement.png"))
    assert main(["plot", str(tmp_path / "b.pvd"), "--item", "nonsense"]) == 2
    assert "unknown item 'nonsense'" in capsys.readouterr().err
    assert main(["plot", str(tmp_path / "missing.pvd")]) == 2


def test_a_picture_that_cannot_be_drawn_is_a_warning_not_the_end_of_the_run(tmp_path, monkeypatch):
    """No OpenGL for VTK (a machine without one): the deck goes on, the warning names the line."""
    import dec3d.plot.draw as draw

    def broken(*a, **k):
        raise RuntimeError("no OpenGL context")

    monkeypatch.setattr(draw, "draw_plot", broken)
    s = _session(tmp_path, "model new\nblock create brick 0 1 0 1 0 1\nplot export bitmap filename 'x.png'\n"
                           "block create brick 2 3 0 1 0 1")
    assert s.model.blocks.n == 2                                    # the line after ran
    assert len(s.warnings) == 1 and "plot 'Plot01' was not drawn (RuntimeError: no OpenGL context)" in s.warnings[0]
    assert not (tmp_path / "x.png").exists()


HANG = """model new
block create brick -0.5 0.5 -0.5 0.5 -1 0
block property density 2000
model gravity 0 0 -10
structure cable create by-line 0 0 -0.9 0 0 2 segments 29
structure cable property young 200e9 cross-sectional-area 1e-4 grout-stiffness 1e8 grout-cohesion 1e9
structure node fix velocity range id 30
model cycle 500
"""

BEAM = """model new
model configure feblock
block create brick 0 10 0 1 0 1
feblock generate 1 1 1 integration 3
block zone cmodel assign elastic
block zone property density 2000 young 1e6 poisson 0.2
block gridpoint apply velocity 0 0 0 range position-x 0
block gridpoint apply force-z [-100.0/3.0] range position-x 10 position-z 1
model large-strain off
model cycle 300
"""


def test_cables_and_fe_blocks_are_drawn(tmp_path):
    """A cable item draws the cable's lines coloured by axial force (the top, loaded end red); an FE
    cantilever's stress contour draws its elements (not the polyhedron of its block as well)."""
    s = _session(tmp_path, HANG)
    sc = scene_from_model(s.model)
    assert sc.cables is not None and sc.cables.n_cells == 29
    pic, notices = render(sc, [Item("cable", "axial-force")], tmp_path / "c.png")
    assert notices == []
    top = np.asarray(sc.cables.points)[np.argmax(np.asarray(sc.cables.points)[:, 2])]
    r, c = pic.pixel_of(top - [0, 0, 0.05])
    near = pic.image[r - 3:r + 4, c - 3:c + 4].reshape(-1, 3).astype(int)
    assert ((near[:, 0] > 100) & (near[:, 2] < 80)).any()        # red (high tension) by the fixed top node
    f = _session(tmp_path / "fe", BEAM)
    sf = scene_from_model(f.model)
    assert sf.fe is not None and all((np.asarray(g.cell_data.get("kind", [0])) != 2).all() for g in sf.grids())
    pic, notices = render(sf, [Item("contour", "stress-xx")], tmp_path / "fe.png")
    assert notices == [] and _drawn(pic.image) > 5000


def test_readme_pictures_exist_and_are_small():
    import re

    from conftest import ROOT

    names = re.findall(r"\]\((docs/img/[^)]+\.png)\)", (ROOT / "README.md").read_text(encoding="utf-8"))
    assert len(names) >= 2
    for n in names:
        assert 10_000 < (ROOT / n).stat().st_size < 200_000, n


def test_check_tells_which_plot_lines_draw(tmp_path):
    from dec3d.check import DOES_NOTHING, RUNNABLE, check_file

    deck = tmp_path / "d.dat"
    deck.write_text("model new\nplot create 'A'\nplot item create block contour displacement\nplot item create ball\n"
                    "plot view reset\nplot 'A' export bitmap filename 'a.png'\n")
    rep = {r.line: (r.status, r.what) for r in check_file(deck)}
    assert rep[2] == rep[3] == rep[6] == (RUNNABLE, "plot")
    assert rep[4][0] == DOES_NOTHING and "`ball` is not drawn by dec3d" in rep[4][1]
    assert rep[5] == (DOES_NOTHING, "plot view: a view setting of 3DEC's plot window, skipped")
