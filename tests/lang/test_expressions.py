"""Inline [expressions]: precedence, FISH arithmetic, variables across lines, hostile input."""
import math

import pytest

from dec3d.errors import BindError, DeckSyntaxError, ExpressionError, NotSupportedError
from dec3d.fish import compile_inline, inline_source, parse_inline
from dec3d.lang.expr import parse_expression
from dec3d.session import Session


def ev(text, variables=None):
    """Evaluate `[text]` as a deck's inline FISH is evaluated when its command runs; assignments
    land in ``variables``."""
    import io

    s = Session(stdout=io.StringIO())
    s.variables.update(variables or {})
    src = inline_source("<test>", 1, 2, text, f"[{text}]", ())
    node, _ = parse_inline(text, src)
    run, _ = compile_inline(s.fish_rt, node, src)
    value = run([0])
    if variables is not None:
        variables.update(s.variables)
    return value


@pytest.mark.parametrize("text,value", [
    ("1 + 2 * 3", 7), ("(1 + 2) * 3", 9), ("2 ^ 3 ^ 2", 512), ("-2 ^ 2", -4), ("2 * 3 ^ 2", 18),
    ("10 - 4 - 3", 3), ("12 / 3 / 2", 2), ("7 / 2", 3), ("-7 / 2", -3), ("7.0 / 2", 3.5), ("1e-3 * 2", 0.002),
    ("1 < 2 and 2 < 1", False), ("1 < 2 or 2 < 1", True), ("not 1 == 2", True), ("3 # 3", False),
    ("3 != 4", True), ("2 >= 2", True), ("'a' + 'b'", "ab"), ("string(3)", "3"),
])
def test_precedence_and_fish_arithmetic(text, value):
    assert ev(text) == value


def test_math_intrinsics():
    assert ev("math.sqrt(16)") == 4.0
    assert ev("math.atan2(1, 1)") == pytest.approx(math.pi / 4)
    assert ev("math.abs(-3)") == 3
    assert ev("math.sin(math.pi/2) + math.cos(0) + math.tan(0)") == pytest.approx(2.0)
    assert ev("math.exp(math.ln(5))") == pytest.approx(5.0)
    assert ev("math.log(1000)") == pytest.approx(3.0)      # FISH: math.log is base 10, math.ln natural
    assert ev("30 * math.degrad") == pytest.approx(math.pi / 6)
    assert ev("math.atan(0.42)*180/math.pi") == pytest.approx(22.7824057, rel=1e-8)


def test_string_build_as_in_hanze_decks():
    v = {"seqfact": 0.4, "rev": 1}
    v["specname"] = ev('string.build("SIN_O1_00_Gr_1_%1", seqFact*100)', v)
    assert ev('string.build("NUM/%1_rev%2", specName, rev)', v) == "NUM/SIN_O1_00_Gr_1_40.0_rev1"


def test_assignment_and_compound_assignment():
    v = {}
    assert ev("a = 2", v) == 2 and ev("a += 3", v) == 5 and v["a"] == 5


@pytest.mark.parametrize("text", ["__import__('os').system('x')", "a.b.('x')", "1 +", "(1", "a b", "x[0]",
                                  "lambda: 1", "open('f').read()"])
def test_hostile_or_malformed_input_is_a_syntax_error(text):
    with pytest.raises(DeckSyntaxError):
        parse_expression(text)


def test_hostile_call_in_a_deck_never_runs(session, tmp_path):
    marker = tmp_path / "pwned"
    for text in [f"[__import__('os').system('touch {marker}')]", "[__import__('os')]",
                 "model title [eval('1')]"]:
        with pytest.raises((DeckSyntaxError, NotSupportedError, BindError)):
            session.command(text)
    assert not marker.exists()


def test_runtime_errors_are_reported():
    with pytest.raises(ExpressionError, match="division by zero"):
        ev("1 / 0")
    with pytest.raises(ExpressionError, match="operator \\* cannot combine string and integer"):
        ev("'a' * 2")
    with pytest.raises(Exception) as e:
        ev("math.atan2(1)")
    assert "math.atan2" in str(e.value) and "argument" in str(e.value)


def test_variables_defined_on_earlier_lines(session):
    session.command("[g = 9.81]\n[k = 2]\nmodel gravity 0 0 [-g*k]")
    assert session.model.settings.gravity == (0.0, 0.0, pytest.approx(-19.62))
    session.command("model gravity 0 0 @g")   # @name substitution, in a later command
    assert session.model.settings.gravity == (0.0, 0.0, 9.81)
    session.command("[t = 'Case ' + string(k)]\nmodel title [t]")
    assert session.model.settings.title == "Case 2"


def test_undefined_variable_is_caught_before_anything_runs(session):
    with pytest.raises(BindError) as e:
        session.command("model title 'first'\nmodel gravity 0 0 [-gg]")
    assert e.value.location.column == 21 and "undefined FISH variable `gg`" in e.value.message
    assert session.model.settings.title == ""


def test_expression_type_checked_when_the_command_runs(session):
    with pytest.raises(BindError) as e:
        session.command("[s = 'down']\nmodel gravity 0 0 [s]")
    assert "expected a number" in e.value.message and e.value.location.line == 2


def test_io_out_writes_to_the_session(session):
    session.command("[x = 1.5]\n[io.out('x = ' + string(x))]")
    assert "x = 1.5" in session.output.getvalue()


def test_unsupported_intrinsic_is_named(session):
    with pytest.raises(NotSupportedError) as e:
        session.command("[io.out(block.gp.temperature/(3600*1000))]")
    assert "`block.gp.temperature`" in e.value.message and e.value.location.column == 9
