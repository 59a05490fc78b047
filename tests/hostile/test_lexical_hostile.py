"""Hostile deck text: byte-order marks, control characters (terminal escapes, NUL, bidirectional
overrides), invalid UTF-8, very long tokens. Each ends in a clean result or a clean error with
file:line:col; no raw control character ever reaches the console; no Python traceback."""
import subprocess
import sys

import pytest

from conftest import ROOT
from dec3d.errors import CommandError, DeckSyntaxError, printable

CLEAN = "\x00\x07\x1b\x9b\u202e"        # not one of these may appear in anything printed


def _dec3d(args, tmp_path):
    r = subprocess.run([sys.executable, "-m", "dec3d", *args], capture_output=True, text=True, cwd=ROOT,
                       timeout=120, errors="surrogateescape")
    assert "Traceback" not in r.stdout + r.stderr
    assert not any(c in r.stdout + r.stderr for c in CLEAN)
    return r


def test_a_utf8_byte_order_mark_is_accepted(session, tmp_path):
    deck = tmp_path / "bom.dat"
    deck.write_bytes(b"\xef\xbb\xbfmodel gravity 0 0 -9.81\r\nmodel title 'bom'\r\n\x1a")   # and a DOS EOF mark
    session.call(deck)
    assert session.model.settings.gravity == (0.0, 0.0, -9.81) and session.model.settings.title == "bom"


def test_columns_after_a_byte_order_mark_count_from_the_first_character(session, tmp_path):
    deck = tmp_path / "bom.dat"
    deck.write_bytes(b"\xef\xbb\xbfmodel gravity 0 0 'down'\n")
    with pytest.raises(Exception) as e:
        session.call(deck)
    assert (e.value.location.line, e.value.location.column) == (1, 19)


@pytest.mark.parametrize("text, message, column", [
    ("model title 'a\x1b[2Jb'\n", "control character \\x1b in a string", 15),
    ("model title \"\x1b]0;pwned\x07\"\n", "control character \\x1b in a string", 14),
    ("model save 'x\x00y'\n", "control character \\x00 in a string", 14),
    ("model title 'abc\u202edef'\n", "control character \\u202e in a string", 17),
    ("[s = 'a\x1bb']\n", "control character \\x1b in an inline expression", 8),
    ("model gravity 0 0 \x1b[31m\n", "unexpected character '\\x1b'", 19),
    ("model gravity 0 0 \x00\n", "unexpected character '\\x00'", 19),
])
def test_control_characters_are_refused_and_shown_escaped(session, tmp_path, text, message, column):
    deck = tmp_path / "ctl.dat"
    deck.write_text("model title 'first'\n" + text, encoding="utf-8")
    with pytest.raises(DeckSyntaxError) as e:
        session.call(deck)
    err = e.value
    assert err.message == message
    assert (err.location.line, err.location.column) == (2, column)
    report = err.format()
    assert not any(c in report for c in CLEAN)
    line, caret = report.splitlines()[1:3]
    # the caret stands under the offending character as shown (escapes widen the text before it)
    assert line == "    " + printable(text.rstrip("\n"))
    shown_col = len(printable(text[:column - 1]))
    assert caret == "    " + " " * shown_col + "^"
    assert session.model.settings.title == ""               # nothing ran


def test_a_comment_may_hold_anything_and_echo_shows_no_control_character(tmp_path):
    deck = tmp_path / "c.dat"
    deck.write_text("; a comment with \u202e and \x1b[2J in it\nmodel title 'ok' ; \x1b[31m\n", encoding="utf-8")
    r = _dec3d(["run", str(deck), "--out", str(tmp_path / "o")], tmp_path)
    assert r.returncode == 0
    assert r.stdout.splitlines() == ["dec3d> model title 'ok'"]


def test_console_output_escapes_control_characters(session):
    # every line the session prints goes through one place; deck text cannot bring a raw ESC to it
    session.write("a\x1b[2Jb\nline two\u202e")
    assert session.output.getvalue() == "a\\x1b[2Jb\nline two\\u202e\n"


def test_invalid_utf8_is_a_clean_error_with_its_position(session, tmp_path):
    deck = tmp_path / "latin1.dat"
    deck.write_bytes(b"model gravity 0 0 -9.81\nmodel title 'caf\xe9'\nmodel ti\xff\xfe 3\n")
    with pytest.raises(DeckSyntaxError) as e:
        session.call(deck)
    assert e.value.message == "bytes that are not UTF-8 text"
    assert (e.value.location.line, e.value.location.column) == (3, 9)
    assert e.value.hint == "save the deck as UTF-8 (or plain ASCII)"
    r = _dec3d(["run", str(deck), "--out", str(tmp_path / "o")], tmp_path)
    assert r.returncode == 2
    assert r.stderr.splitlines()[0] == f"{deck}:3:9: error: bytes that are not UTF-8 text"


def test_dec3d_check_on_hostile_text_reports_without_traceback(tmp_path):
    deck = tmp_path / "h.dat"
    deck.write_bytes(b"model title 'a\x1bb'\n\xff\xfe\n")
    r = _dec3d(["check", str(deck)], tmp_path)
    assert r.returncode == 1
    assert r.stdout.splitlines()[0] == f"{deck}:1:15: error: control character \\x1b in a string"


def test_a_300_character_token_is_cut_in_the_message_and_marked_whole(session):
    word = "a" * 300
    with pytest.raises(Exception) as e:
        session.command("model " + word)
    assert e.value.message == "unknown command `model " + "a" * 59 + "…`"
    assert e.value.location.length == 300 and e.value.location.column == 7
    with pytest.raises(Exception) as e:
        session.command("model cycle 1 " + "b" * 300)
    assert e.value.message == "unknown keyword `" + "b" * 59 + "…` for `model cycle`"


def test_a_300_digit_number_is_a_finite_real_or_a_refused_integer(session):
    session.command("model gravity 0 0 -" + "1" * 300)
    assert session.model.settings.gravity[2] == pytest.approx(-float("1" * 300))
    with pytest.raises(Exception) as e:
        session.command("model cycle " + "1" * 300)
    assert e.value.message == "`n` must be an integer of at most 64 bits (|n| ≤ 2^63 - 1), got an integer of " + str(int("1" * 300).bit_length()) + " bits"


def test_a_wrapped_error_says_error_once(session):
    # the engine's RunError is re-raised by `model cycle` as a CommandError of its message
    with pytest.raises(CommandError) as e:
        session.command("block create brick 0 1 0 1 0 1\nmodel cycle 1")
    first = e.value.format().splitlines()[0]
    assert first == "<command>:2:1: error: a block has no mass: set `block property density` before cycling"
    assert str(e.value) == "a block has no mass: set `block property density` before cycling"


def test_a_repeated_range_keyword_takes_expressions(session):
    # found by the fuzz test: `or [x]` in a range element reached the group lookup unevaluated
    session.command("block create brick 0 1 0 1 0 1 group 'g1'\nblock create brick 2 3 0 1 0 1 group 'g2'\n"
                    "[n = 'g2']\nblock hide range group 'none' or [n]")
    assert session.model.blocks["hidden"].tolist() == [False, True]


def test_a_non_ascii_vtk_name_is_written_and_read_back(session, tmp_path):
    """VTK files are UTF-8 XML: a non-ASCII file or group name is written, and every reader opens it."""
    import meshio
    import pyvista as pv

    session.command("block create brick 0 1 0 1 0 1 group 'ré'\nblock vtk filename 'café'")
    vtu = tmp_path / "café_0000.vtu"
    # (the group names also travel as text in `group_names`, dec3d.io.vtk)
    codes = [k for k in meshio.read(vtu).field_data if k.startswith("group_code:")]
    assert codes == ["group_code:ré"]
    from dec3d.io.vtk import read_text_array
    assert "ré" in read_text_array(pv.read(vtu).field_data["group_names"])
    assert [k for k in pv.read(vtu).field_data if k.startswith("group_code:")] == ["group_code:ré"]
    assert pv.read(tmp_path / "café.pvd").n_blocks == 1
