"""Deck conveniences of the public decks (issue 14): `history name … label`, `history rename`,
range `region` (and `r=<i>`, `block.region`), `block contact material-table add`, and
`block history … gridpointid | zone-id | block-id`."""
import numpy as np
import pytest

from dec3d.errors import Dec3dError
from dec3d.kernels.joints import P_KN, P_KS
from dec3d.kernels.joints.mohr import P_TANF
from dec3d.physics.history import histories
from dec3d.physics.rigid import engine

CUBE_FACES = ("face 0 0 0 1 0 0 1 1 0 0 1 0 face 0 0 1 1 0 1 1 1 1 0 1 1 face 0 0 0 1 0 0 1 0 1 0 0 1 "
              "face 0 1 0 1 1 0 1 1 1 0 1 1 face 0 0 0 0 1 0 0 1 1 0 0 1 face 1 0 0 1 1 0 1 1 1 1 0 1")


# ------------------------------------------------------------------------------------- histories
def _two_histories(session):
    session.command("block create brick 0 1 0 1 0 1\nblock property density 1000\n"
                    "model history mechanical time-total\nblock history displacement-z block-id 1")
    return histories(session.model)


def test_history_name_label_sets_the_label_shown_in_the_csv(session, tmp_path):
    hs = _two_histories(session)
    session.command("history name '2' label 'C2_MiddleSail'\nmodel gravity 0 0 -10\nhistory interval 5\n"
                    "model cycle 10\nhistory export 2 file 'h.csv'")
    assert hs.find(2).label == "C2_MiddleSail"
    header = (session.out_dir / "h.csv").read_text().splitlines()[0]
    assert header == "step,time,2 (C2_MiddleSail)"


def test_history_rename_then_refer_by_the_new_name(session):
    hs = _two_histories(session)
    session.command("history rename \"2\" name \"dz\"\nhistory name 'dz' label 'settlement'")
    h = hs.find("dz")
    assert (h.id, h.name, h.label) == (2, "dz", "settlement")
    assert hs.find("2") is None


def test_history_rename_and_label_survive_save_and_restore(session):
    _two_histories(session)
    session.command("history rename 2 name 'dz'\nhistory name 'dz' label 'sink'\nmodel save 'h'\n"
                    "model new\nmodel restore 'h'")
    h = histories(session.model).find("dz")
    assert (h.id, h.label) == (2, "sink")


@pytest.mark.parametrize("line, message", [
    ("history rename 9 name 'x'", r"there is no history 9"),
    ("history name 'nope' label 'x'", r"there is no history nope"),
    ("history rename 2 name '1'", r"a history named '1' exists already"),
    ("history name 1", r"label"),
])
def test_history_rename_and_label_errors(session, line, message):
    _two_histories(session)
    with pytest.raises(Dec3dError, match=message):
        session.command(line)


# ---------------------------------------------------------------------------------------- region
def _call(session, line):
    from dec3d.commands.binder import BindContext, Binder
    from dec3d.lang.parser import parse_deck

    deck = parse_deck(line)
    return Binder(deck, BindContext({})).bind(deck.lines[0])


def test_region_numbers_from_r_select_blocks_and_their_vertices(session):
    session.command(f"block create group 'Supports' poly {CUBE_FACES} r=3\n"
                    "block create brick 2 3 0 1 0 1\n"
                    "block create brick 4 5 0 1 0 1 region 3\n"
                    "block apply velocity-z 0.001 range region 3\n"
                    "[r1 = block.region(1)]\n[r2 = block.region(2)]")
    b = session.model.blocks
    assert b["region"][:3].tolist() == [3, 0, 3]
    assert session.variables["r1"] == 3 and session.variables["r2"] == 0
    # vertices, faces and gridpoints are in the region of their block
    assert session.range_mask(_call(session, "block hide range region 3"), "vertex").sum() == 16
    # the applied velocity went to blocks 1 and 3 only (what `range region 3` selected)
    assert (b["apply_fix"][:3] != 0).tolist() == [True, False, True]


def test_region_survives_cut_and_save(session):
    session.command("block create brick 0 1 0 1 0 2 region 7\nblock cut joint-set dip 0 dip-direction 0 "
                    "origin 0 0 1\nmodel save 'r'\nmodel new\nmodel restore 'r'")
    assert session.model.blocks["region"][:2].tolist() == [7, 7]


def test_region_needs_a_whole_number(session):
    session.command("block create brick 0 1")
    with pytest.raises(Dec3dError, match="expected an integer, got 0.5"):
        session.command("block apply velocity-z 0.1 range region 0.5")


# ------------------------------------------------------------------------ material-table add
STACK = ("block create brick 0 1 0 1 0 1 group 'lo' slot 'components'\n"
         "block create brick 0 1 0 1 1 2 group 'hi' slot 'components'\n"
         "block create brick 0 1 0 1 2 3 group 'top' slot 'components'\n"
         "block property density 1000\n"
         "block contact jmodel assign mohr\n"
         "block contact material-table default prop stiffness-normal 1e9 stiffness-shear 1e9 friction 30\n")


def _props_by_pair(session):
    session.command("block contact generate-subcontacts")      # contacts that follow the defaults take them now
    e = engine(session.model)
    c = e.contacts
    return {(int(c["ida"][i]), int(c["idb"][i])): c["prop"][i] for i in range(c.n)}


def test_material_table_add_gives_group_pairs_their_own_properties(session):
    session.command(STACK + "block contact material-table add jmodel mohr prop stiffness-normal 5e9 "
                    "stiffness-shear 2e9 friction 40 range group-intersection 'lo' 'hi' slot 'components'")
    props = _props_by_pair(session)
    assert set(props) == {(1, 2), (2, 3)}
    assert props[(1, 2)][[P_KN, P_KS]].tolist() == [5e9, 2e9]
    assert props[(1, 2)][P_TANF] == pytest.approx(np.tan(np.radians(40)), rel=1e-12)
    assert props[(2, 3)][[P_KN, P_KS]].tolist() == [1e9, 1e9]      # the default
    assert session.results["material-table.count"] == 1.0


def test_material_table_entry_reaches_contacts_made_later(session):
    # the entry is added while block 'hi' does not exist yet; its contact with 'lo' is made afterwards
    session.command("block create brick 0 1 0 1 0 1 group 'lo'\nblock contact jmodel assign mohr\n"
                    "block contact material-table default prop stiffness-normal 1e9 stiffness-shear 1e9 friction 30\n"
                    "block contact material-table add jmodel mohr prop stiffness-normal 7e9 stiffness-shear 3e9 "
                    "range group-intersection 'lo' 'hi'\n"
                    "block create brick 0 1 0 1 1 2 group 'hi'\nblock create brick 1 2 0 1 0 1 group 'side'")
    props = _props_by_pair(session)
    assert set(props) == {(1, 2), (1, 3), (2, 3)}
    assert props[(1, 2)][[P_KN, P_KS]].tolist() == [7e9, 3e9]
    assert props[(1, 2)][P_TANF] == 0.0      # not given: the model's own default, not the material-table default
    assert props[(1, 3)][[P_KN, P_KS]].tolist() == [1e9, 1e9]


def test_material_table_survives_save_and_restore(session):
    session.command(STACK + "block contact material-table add prop stiffness-normal 5e9 stiffness-shear 2e9 "
                    "range group-intersection 'hi' 'top'\nmodel save 'mt'\nmodel new\nmodel restore 'mt'")
    tables = session.model.settings.mechanical["mtables"]
    assert tables == [{"id": 1, "jmodel": "mohr", "props": {"stiffness-normal": 5e9, "stiffness-shear": 2e9},
                       "groups": ["hi", "top"], "slot": None}]
    props = _props_by_pair(session)
    assert props[(2, 3)][[P_KN, P_KS]].tolist() == [5e9, 2e9]


@pytest.mark.parametrize("line, message", [
    ("block contact material-table add jmodel mohr prop frobnicate 1 range group-intersection 'lo' 'hi'",
     r"joint model 'mohr' has no property 'frobnicate'"),
    ("block contact material-table add jmodel nonlinear prop stiffness-normal 1e9",
     r"`nonlinear` is not supported yet"),
    ("block contact material-table add prop stiffness-normal -1 range group-intersection 'lo' 'hi'",
     r"stiffness-normal"),
])
def test_material_table_add_bad_input(session, line, message):
    session.command(STACK)
    with pytest.raises(Dec3dError, match=message):
        session.command(line)


# ----------------------------------------------------------------- gridpoint and zone histories
def test_gridpoint_and_zone_histories_read_their_nodes(session):
    session.command("block create brick 5 6 0 1 0 1\nblock create brick 0 1 0 1 0 1\n"
                    "block zone generate edgelength 0.5 range id 2")
    m = session.model
    v = m.vertices
    zs = m.store("zones")
    gp_row = int(np.flatnonzero(v["zoned"])[3])
    session.command(f"block history displacement-z gridpointid {gp_row + 1}\n"
                    f"block history name 'zv' velocity-x zone-id {int(zs['id'][2])}\n"
                    f"block history position-y gridpointid {gp_row + 1}")
    hs = histories(m)
    # a linear field: the value at the zone's centroid is the field at the mean of its corners
    v["velocity"][:] = 0.0
    v["velocity"][:, 0] = 2.0 * v["pos"][:, 0] - 3.0 * v["pos"][:, 2]
    v["disp"][gp_row] = [0.0, 0.0, -0.125]
    e = engine(m)
    corners = v["pos"][zs["gp"][2, :4]].mean(axis=0)
    assert hs.find(1).value(e) == -0.125
    assert hs.find("zv").value(e) == pytest.approx(2.0 * corners[0] - 3.0 * corners[2], abs=1e-12)
    assert hs.find(3).value(e) == v["pos"][gp_row, 1]
    # the first block is deleted: rows move, the histories follow their gridpoint and zone
    pos_before = v["pos"][gp_row].copy()
    session.command("block delete range id 1")
    assert hs.find(3).value(engine(m)) == pos_before[1]
    assert hs.find("zv").label == f"zone {int(zs['id'][2])} centroid velocity-x"


@pytest.mark.parametrize("line, message", [
    ("block history displacement-z gridpointid 1", r"there is no gridpoint 1"),
    ("block history displacement-z zone-id 1", r"there is no zone 1: no block is zoned"),
    ("block history rvelocity-x zone-id 1", r"`rvelocity-x` is not a zone quantity"),
    ("block history displacement-z zone-id 1 block-id 1", r"give no `position` or `block-id`"),
    ("block history displacement-z block-id 5", r"there is no block 5"),
])
def test_gridpoint_zone_block_history_errors(session, line, message):
    session.command("block create brick 0 1")
    with pytest.raises(Dec3dError, match=message):
        session.command(line)


def test_block_id_history_follows_that_block(session):
    session.command("block create brick 0 1 0 1 0 1\nblock create brick 3 4 0 1 0 1\n"
                    "block property density 100\nblock history velocity-x block-id 2\nblock initialize velocity-x 0.5 range id 2\n"
                    "history interval 1\nmodel cycle 3")
    assert histories(session.model).find(1).values == [0.5, 0.5, 0.5]


# ----------------------------------------------------------------------------- legacy .dec files
def _call_dec(tmp_path, content: bytes):
    import io

    from dec3d.session import Session

    (tmp_path / "Groningen.dec").write_bytes(content)
    (tmp_path / "main.dat").write_text("model new\ncall 'Groningen.dec'\nblock create brick 5 6\n", encoding="utf-8")
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.run_items(s.load_file(tmp_path / "main.dat"))
    return s


def test_a_dec_file_of_commands_is_read_as_a_deck(tmp_path):
    s = _call_dec(tmp_path, b"; geometry\nblock create brick 0 1 0 1 0 1 group 'S'\n")
    assert s.model.blocks.n == 2


@pytest.mark.parametrize("content, message", [
    (b"\x00\x01DEC\x00" + bytes(range(256)), r"`.*Groningen\.dec` is a binary file, not a deck: 3DEC's legacy \.dec"),
    (b"POLY 1 1 1\n  0.0 0.0 0.0  1.0 0.0 0.0\n", r"`.*Groningen\.dec` is not a deck of commands \(line 1: .*\): "
                                                  r"3DEC's legacy \.dec block-geometry files are not supported"),
])
def test_legacy_dec_geometry_is_refused_by_name(tmp_path, content, message):
    from dec3d.errors import NotSupportedError

    with pytest.raises(NotSupportedError, match=message) as ei:
        _call_dec(tmp_path, content)
    assert ei.value.location.line == 2        # the `call` line of the calling deck


def test_material_table_entry_with_another_range_applies_to_existing_contacts_only(session):
    session.command(STACK + "block contact material-table add prop stiffness-normal 5e9 stiffness-shear 2e9 "
                    "range group 'top'\nblock create brick 0 1 0 1 3 4 group 'top'")
    props = _props_by_pair(session)
    assert props[(2, 3)][[P_KN, P_KS]].tolist() == [5e9, 2e9]      # existed when the entry was added
    assert props[(3, 4)][[P_KN, P_KS]].tolist() == [1e9, 1e9]      # made later: the default
    assert "mtables" not in session.model.settings.mechanical or not session.model.settings.mechanical["mtables"]
