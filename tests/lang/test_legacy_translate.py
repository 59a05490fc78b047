"""dec3d translate: small 3DEC 4/5 decks, one construct each, and the 3DEC 7+ text expected
(dec3d.lang.legacy; docs/legacy.md)."""
import math

import pytest

from dec3d.lang.legacy import looks_legacy, translate_text
from dec3d.lang.legacy.commands import _modern_orientation
from dec3d.lang.legacy.hull import convex_excess, hull_faces, solid_volume

NOTE = "; dec3d translate: could not translate: "


def tr(text: str) -> str:
    return translate_text(text, "old.dat").text


@pytest.mark.parametrize("old, new", [
    ("new", "model new"),
    ("poly brick 0,1 0,1 0,1 reg 2", "block create brick 0 1 0 1 0 1 region 2 group 'mat1' slot 'material'"),
    ("jset dip 90 dd 90 origin 0.5,0,0", "block cut joint-set dip 90 dip-direction 90 origin 0.5 0 0"),
    ("bound xvel=0 range x -0.1 0.1", "block gridpoint apply velocity-x 0 range position-x -0.1 0.1"),
    ("bound stress -1e6 0 0 0 0 0 range x 9.9 10.1", "block face apply stress -1e6 0 0 0 0 0 range position-x 9.9 10.1"),
    ("gravity 0 0 -9.81", "model gravity 0 0 -9.81"),
    ("grav 0,-9.81,0", "model gravity 0 -9.81 0"),
    ("set grav 0,-9.81,0", "model gravity 0 -9.81 0"),
    ("damp auto", "block mechanical damping global"),
    ("DAMP LOCAL", "block mechanical damping local"),
    ("damp local 0.8", "block mechanical damping local 0.8"),
    ("cycle 100", "model cycle 100"),
    ("step 100", "model cycle 100"),
    ("solve ratio 1e-5", "model solve ratio 1e-5"),
    ("solve time 1 cyc 100", "model solve time 1 cycles 100"),
    ("solve ratio @rat cyc 10000", "model solve ratio @rat cycles 10000"),
    ("hist time", "model history mechanical time-total"),
    ("history interval 10", "history interval 10"),
    ("hist unbal", "model history mechanical unbalanced-maximum"),
    ("hist @nf2", "fish history @nf2"),
    ("hist xdis 0.5 0.5 0.5", "block history displacement-x position 0.5 0.5 0.5"),
    ("hist nf_sum @x @y @z", "block contact history force-normal position @x @y @z"),
    ("fix range reg 2", "block fix range region 2"),
    ("fix reg @base", "block fix range region @base"),
    ("free range x 0 1 y 0 1", "block free range position-x 0 1 position-y 0 1"),
    ("save arch.sav", "model save 'arch.sav'"),
    ("restore arch", "model restore 'arch'"),
    ("save @name", "model save @name"),
    ("call geometry.dat", "program call 'geometry.dat'"),
    ("pl hist 2 v 1", "plot item create chart-history history '2' vs '1'"),
    ("plot bitmap plot dispM filename @f", "plot bitmap plot dispM filename @f"),
    ("gen edge 0.5 range reg 3", "block zone generate edgelength 0.5 range region 3"),
    ("title my model", "model title 'my model'"),
    ("insitu stress -1e6 -1e6 -2e6 0 0 0", "block insitu stress -1e6 -1e6 -2e6 0 0 0"),
    ("bound stress -1e6 0 0 0 0 0 range x 10", None),
    ("change cons=1 range reg 1", "block zone cmodel assign elastic range region 1"),
    ("prop mat=2 dens=2600 k=1e9 g=5e8", "block property density 2600 range group 'mat2' slot 'material'\n"
                                         "block zone property bulk 1e9 shear 5e8 range group 'mat2' slot 'material'"),
    ("list @sf", "fish list @sf"),
    ("seek", "block hide off"),
    ("prop mat=2 dens=2300 ; stone", "block property density 2300 range group 'mat2' slot 'material' ; stone"),
])
def test_one_command(old, new):
    if new is None:          # `range x 10`: one value, not a pair
        assert tr(old).startswith(NOTE)
    else:
        assert tr(old) == new


def test_poly_faces_with_continuations_keep_their_lines():
    old = ("poly reg 3 mat 2 con 1 &\n"
           "face ID 1 0 0 0  0 1 0  1 0 0 &\n"
           "face ID 2 0 0 0  0 0 1  0 1 0 &\n"
           "face ID 3 0 0 0  1 0 0  0 0 1 &\n"
           "face ID 4 1 0 0  0 1 0  0 0 1 &\n"
           " \n"
           "new")
    assert tr(old).split("\n") == [
        "block create polyhedron &",
        "face 0 0 0 0 1 0 1 0 0 &",
        "face 0 0 0 0 0 1 0 1 0 &",
        "face 0 0 0 1 0 0 0 0 1 &",
        "face 1 0 0 0 1 0 0 0 1 region 3 group 'mat2' slot 'material'",
        "",
        "model new"]


def test_poly_prism_a_b():
    old = "poly region 4 prism &\na (0,0,2) (1,0,2) (0,1,2) &\nb (0,0,3) (1,0,3) (0,1,3)"
    assert tr(old).split("\n") == ["block create prism &", "face-1 0 0 2 1 0 2 0 1 2 &",
                                   "face-2 0 0 3 1 0 3 0 1 3 region 4 group 'mat1' slot 'material'"]


def test_materials_and_change():
    old = "prop mat=1 dens=2300\nchange mat=1 range reg 2"
    assert tr(old).split("\n") == ["block property density 2300 range group 'mat1' slot 'material'",
                                   "block group 'mat1' slot 'material' range region 2",
                                   "block property density 2300 range region 2"]


def test_joint_material_is_applied_by_change_jmat():
    old = "prop jmat 3 jkn @kn jks 1e8 jfric 30 jcoh 0 jten 0\nchange jmat=3"
    props = "stiffness-normal @kn stiffness-shear 1e8 friction 30 cohesion 0 tension 0"
    assert tr(old).split("\n") == ["; joint material 3 is given to contacts by `change jmat=3`",
                                   f"block contact property {props}",
                                   f"block contact material-table default property {props}"]


def test_change_jmat_without_properties_is_a_noted_line():
    out = tr("change jmat=5")
    assert out.startswith(NOTE + "change jmat=5") and "prop jmat=5" in out


def test_hidden_blocks_take_part_in_the_mechanics_and_are_hidden_again_before_a_cut():
    out = tr("hide reg 2\ncycle 10\nsolve\njset dip 0 dd 0\nseek\ncycle 10").split("\n")
    assert out[0] == "block hide range region 2"
    assert out[1].startswith("block hide off ; dec3d translate: the hidden blocks take part in the mechanics")
    assert out[2:] == ["model cycle 10", "model solve", "block hide range region 2",
                       "block cut joint-set dip 90 dip-direction 0", "block hide off", "model cycle 10"]


def test_named_ranges_become_groups_of_their_own_slot():
    out = tr("range name col reg 3\nrange name both union nrange col\nfix range col").split("\n")
    assert out == ["block group 'col' slot 'col' range region 3",
                   "block group 'both' slot 'both' range union group 'col' slot 'col'",
                   "block fix range group 'col' slot 'col'"]


def test_fish_def_array_command_loop_and_intrinsics():
    old = """def setup
  array buf(10)
  bi = block_head
  loop while bi # 0
    v = b_vol(bi) * pi
    zi = b_zone(bi)
    bi = b_next(bi)
  endloop
  oo = out('n ' + string(sqrt(4)))
  command
    DAMP LOCAL
  end_command
end
setup"""
    out = tr(old).split("\n")
    assert out[0] == "fish define setup"
    assert out[1] == "  buf = array.create(10)"
    assert out[2] == "  bi = block.head"
    assert out[4] == "    v = block.vol(bi) * math.pi"
    assert out[5].startswith("    zi = b_zone(bi) " + NOTE + "`b_zone`")
    assert out[6] == "    bi = block.next(bi)"
    assert out[7] == "  endloop"
    assert out[8] == "  oo = io.out('n ' + string(math.sqrt(4)))"
    assert out[10] == "    block mechanical damping local"
    assert out[11:] == ["  end_command", "end", "[setup]"]


def test_fish_file_output_maps_to_file_intrinsics():
    old = ("def w\n  o = open('s.txt', 1, 1)\n  n = write(buf, 3)\n  c = close\n  l = lose_array(buf)\n"
           "  k = close()\nend")
    assert tr(old).split("\n")[1:6] == ["  o = file.open('s.txt', 1, 1)", "  n = file.write(buf, 3)",
                                        "  c = file.close", "  l = 0", "  k = file.close()"]


def test_define_and_endcommand_spellings():
    out = tr("define f\n  command\n    cycle 5\n  endcommand\nend").split("\n")
    assert out == ["fish define f", "  command", "    model cycle 5", "  endcommand", "end"]


def test_deck_function_named_like_an_intrinsic_stays_the_decks():
    out = tr("def out\n  out = 1\nend\ndef g\n  g = out(2)\nend").split("\n")
    assert out[4] == "  g = out(2)"


def test_lines_it_cannot_translate_become_comments():
    t = translate_text("frobnicate 3\nprint max", "old.dat")
    assert t.text.split("\n") == [NOTE + "frobnicate 3  (the command `frobnicate`)",
                                  NOTE + "print max  (this `print`/`list`)"]
    assert t.untranslated == 2


def test_looks_legacy():
    assert looks_legacy("new\npoly brick 0 1 0 1 0 1")
    assert looks_legacy("def f\n f = 1\nend")
    assert not looks_legacy("model new\nblock create brick 0 1\nfish define f\n  f = 1\nend\n[f]")
    assert not looks_legacy("; new\nmodel new")
    # a modern continuation line may start with a word that was a 3DEC 5 command
    assert not looks_legacy("block create tunnel dip 0 &\n  boundary 9 radius-ratio 1.4\nblock contact property friction 30 ...\n"
                            "  range group 'a'")


def test_line_map_points_at_the_original_column():
    t = translate_text("; c\nprop mat=1   dens=2300\n", "old.dat")
    line = t.text.split("\n")[1]
    col = line.index("2300") + 1
    assert t.map.where(2, col) == (2, 19)          # `2300` in the original line
    assert t.map.where(2, 1) == (2, 1)


def test_old_dip_convention_y_up():
    # a horizontal joint in 3DEC 5 (dip 0: normal +y, up) is vertical in z-up terms, facing +y (north)
    assert _modern_orientation(0, 0) == (90.0, 0.0)
    # dip 90 toward +x stays a plane of normal +x
    assert _modern_orientation(90, 90) == (90.0, 90.0)
    d, a = _modern_orientation(30, 0)     # normal (0, cos30, sin30): dip acos(sin30)=60, toward +y
    assert math.isclose(d, 60.0) and math.isclose(a, 0.0, abs_tol=1e-9)


def test_non_convex_poly_is_built_as_its_hull_with_a_note():
    # a unit cube whose top face is a roof folded inward by 0.1 (a concave fold): its hull is the cube
    p = lambda *c: " ".join(str(x) for x in c)
    faces = [[(0, 0, 0), (0, 1, 0), (1, 1, 0), (1, 0, 0)], [(0, 0, 1), (0.5, 0, 0.9), (0.5, 1, 0.9), (0, 1, 1)],
             [(0.5, 0, 0.9), (1, 0, 1), (1, 1, 1), (0.5, 1, 0.9)], [(0, 0, 0), (1, 0, 0), (1, 0, 1), (0.5, 0, 0.9), (0, 0, 1)],
             [(0, 1, 0), (0, 1, 1), (0.5, 1, 0.9), (1, 1, 1), (1, 1, 0)], [(0, 0, 0), (0, 0, 1), (0, 1, 1), (0, 1, 0)],
             [(1, 0, 0), (1, 1, 0), (1, 1, 1), (1, 0, 1)]]
    old = "poly reg 1 &\n" + " &\n".join("face " + " ".join(p(*c) for c in f) for f in faces)
    out = tr(old)
    assert "not convex (a corner 0.196 m outside a face's plane)" in out
    assert "volume 0.95 -> 1 (+5.26 %)" in out
    assert out.count("face ") == 6                   # the cube's six faces
    import numpy as np
    arrays = [np.array(f, dtype=float) for f in faces]
    assert math.isclose(solid_volume(arrays), 0.95) and math.isclose(convex_excess(arrays), 0.2 / math.sqrt(1.04))
    hull, vol = hull_faces(np.vstack(arrays), 1e-9)
    assert len(hull) == 6 and math.isclose(vol, 1.0)


def test_fish_line_columns_and_lines_after_an_expanded_line_map_back():
    old = "def f\n  if 1 = 2 then\n    cxi = c_cx(ci)\n  endif\n  y = 1 / zz\nend\n"
    t = translate_text(old, "old.dat")
    lines = t.text.split("\n")
    k = lines.index("  y = 1 / zz") + 1            # `c_cx` became five lines: this one moved down by 4
    assert k == 9
    assert t.map.where(k, lines[k - 1].index("zz") + 1) == (5, 11)


def test_a_run_time_error_names_the_original_line(tmp_path):
    from dec3d.errors import Dec3dError
    from dec3d.legacy_run import LegacySession

    deck = tmp_path / "old.dat"
    deck.write_text("new\ndef f\n  if 1 = 2 then\n    cxi = c_cx(ci)\n  endif\n  y = 1 / 0\nend\n@f\n")
    s = LegacySession(out_dir=tmp_path, notice=lambda t: None)
    with pytest.raises(Dec3dError) as info:
        s.run_items(s.load_file(deck))
    loc = info.value.location
    assert (loc.file, loc.line) == (str(deck), 6) and loc.text == "  y = 1 / 0"


def test_legacy_file_output_runs(tmp_path):
    from dec3d.legacy_run import LegacySession

    deck = tmp_path / "old.dat"
    deck.write_text("def w\n  array buf(2)\n  buf(1) = 'a 1'\n  buf(2) = 2.5\n  o = open('s.txt', 1, 1)\n"
                    "  n = write(buf, 2)\n  c = close\n  l = lose_array(buf)\nend\n@w\n")
    out = tmp_path / "out"
    s = LegacySession(out_dir=out, notice=lambda t: None)
    s.run_items(s.load_file(deck))
    assert (out / "s.txt").read_text() == "a 1\n2.5\n"


def test_3dec7_lines_in_a_legacy_deck_are_kept():
    old = ("new\nblock create brick 0 1 0 1 0 1 &\n   group 'a'\nfish define f\n  f = block.head\nend\n"
           "model gravity 0 0 -10 ; z\ncycle 10")
    assert tr(old).split("\n") == ["model new", "block create brick 0 1 0 1 0 1 &", "   group 'a'",
                                   "fish define f", "  f = block.head", "end", "model gravity 0 0 -10 ; z",
                                   "model cycle 10"]
