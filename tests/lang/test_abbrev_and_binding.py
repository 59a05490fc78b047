"""Abbreviation of command words and keywords; unknown, ambiguous and not-supported commands."""
import pytest

from dec3d.commands.binder import LegacySyntaxError
from dec3d.errors import BindError, NotSupportedError
from dec3d.lang.abbrev import matches


@pytest.mark.parametrize("word,cands,expected", [
    ("gen-sub", ["generate-subcontacts", "group", "generate"], ["generate-subcontacts"]),
    ("a-r", ["apply", "apply-remove", "attach"], ["apply-remove"]),
    ("v-y", ["velocity", "velocity-x", "velocity-y", "volume"], ["velocity-y"]),
    ("fric", ["friction", "friction-residual"], ["friction"]),
    ("stiffness-norm", ["stiffness-normal", "stiffness-shear"], ["stiffness-normal"]),
    ("disp", ["displacement", "displacement-x"], ["displacement"]),
    ("c", ["contact", "create", "cut"], ["contact", "create", "cut"]),
    ("zone", ["zone", "zone-x"], ["zone"]),
    ("xyz", ["contact"], []),
])
def test_prefix_rules(word, cands, expected):
    assert matches(word, cands) == expected


def test_abbreviated_commands_run(session):
    session.command("mod grav 0 0 -9.81\nmodel l-s on\nmodel conf high\nprog echo off")
    st = session.model.settings
    assert st.gravity == (0.0, 0.0, -9.81) and st.large_strain and st.configure == ["highorder"]


def test_ambiguous_word_lists_candidates(session):
    with pytest.raises(BindError) as e:
        session.command("model c 100")
    msg = e.value.message
    assert "ambiguous" in msg and all(c in msg for c in ("calm", "configure", "cycle"))
    assert (e.value.location.line, e.value.location.column) == (1, 7)


def test_unknown_command_suggests(session):
    with pytest.raises(BindError) as e:
        session.command("model gravty 0 0 -10")
    assert "unknown command `model gravty`" in e.value.message and "model gravity" in e.value.hint


def test_unknown_keyword_suggests(session):
    with pytest.raises(BindError) as e:
        session.command("program log-file 'x.log' apend")
    assert "unknown keyword `apend`" in e.value.message and "append" in e.value.hint


def test_known_but_unimplemented_command(session):
    with pytest.raises(NotSupportedError) as e:
        session.command("block copy id 1 translate 1 0 0")
    assert e.value.message == "`block copy` is not supported yet"


def test_legacy_syntax_is_named(session):
    with pytest.raises(LegacySyntaxError) as e:
        session.command("jset dip 0 dd 0 or 0,.5,0")
    assert "3DEC 5" in e.value.message and "block cut joint-set" in e.value.hint


def test_plot_of_a_plot_the_deck_did_not_make_is_drawn_with_a_notice(session, tmp_path):
    session.command("plot 'Blocks' export bitmap filename \"blocks-hex.png\"")
    assert "was not made in this deck" in session.output.getvalue()
    assert (tmp_path / "blocks-hex.png").stat().st_size > 0


def test_wrong_value_type_and_count(session):
    with pytest.raises(BindError) as e:
        session.command("model gravity 1 2")
    assert "1 or 3 numbers" in e.value.message
    with pytest.raises(BindError) as e:
        session.command("model large-strain 1.5")
    assert "on|off" in e.value.message
    with pytest.raises(BindError) as e:
        session.command("model configure warp-drive")
    assert "needs option" in e.value.message


def test_gravity_forms(session):
    session.command("model gravity 10")
    assert session.model.settings.gravity == (0.0, 0.0, -10.0)
    session.command("model gravity (0,-9.81,0)")
    assert session.model.settings.gravity == (0.0, -9.81, 0.0)


def test_bare_call_alias_and_log(tmp_path, session):
    (tmp_path / "sub.dat").write_text("model title 'from sub'\n")
    deck = tmp_path / "main.dat"
    deck.write_text("log-file 'run.log'\nlog on\ncall 'sub'\n[io.out('hello log')]\nlog off\n[io.out('not logged')]\n")
    session.call(deck)
    assert session.model.settings.title == "from sub"
    log = (tmp_path / "run.log").read_text()
    assert "hello log" in log and "not logged" not in log


def test_flag_keywords_take_no_value(session, tmp_path):
    session.command("model new force")
    session.command("program log-file 'a.log' append")
    assert (tmp_path / "a.log").exists()
