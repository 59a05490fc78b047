"""FISH language corpus: each construct runs in a Session and prints with io.out; the expected
output is worked out by hand from the FISH rules (Itasca FISH reference), not taken from the code."""
import pytest

from dec3d.errors import BindError, Dec3dError, DeckSyntaxError, ExpressionError, NotSupportedError


def run(session, text):
    session.command(text)
    return session.output.getvalue().splitlines()


CASES = [
    # arithmetic, precedence, integer division, power
    ("fish define f\n io.out(7/2)\n io.out(-7/2)\n io.out(7.0/2)\n io.out(-2^2)\n io.out(2^3^2)\n"
     " io.out(1+2*3)\nend\n@f", ["3", "-3", "3.5", "-4", "512", "7"]),
    # comparisons and logic: = and == are equality, # and != inequality, & | not
    ("fish define f\n io.out(3 = 3)\n io.out(3 # 3)\n io.out(2 != 3)\n io.out(1 < 2 & 2 < 1)\n"
     " io.out(1 < 2 | 2 < 1)\n io.out(not 1 == 2)\n io.out(2 >= 2 and 'a' == 'a')\nend\n@f",
     ["true", "false", "true", "false", "true", "true", "true"]),
    # case-insensitive names, function value by assignment to its name, arguments
    ("fish define Area(W, h)\n  AREA = w * H\nend\n[io.out(area(2, 3.5))]", ["7.0"]),
    # if / else if / else / endif and end_if; `then` optional
    ("fish define sign(x)\n if x > 0 then\n  sign = 'pos'\n else if x < 0\n  sign = 'neg'\n else\n"
     "  sign = 'zero'\n end_if\nend\n[io.out(sign(3))]\n[io.out(sign(-1))]\n[io.out(sign(0))]", ["pos", "neg", "zero"]),
    # counted loop (local counter, step), exit loop, continue
    ("fish define f\n local s = 0\n loop local i (1, 10)\n  if i = 3 then\n   continue\n  endif\n"
     "  if i > 6 then\n   exit loop\n  endif\n  s += i\n endloop\n io.out(s)\n local t = 0\n"
     " loop k (10, 1, -3)\n  t = t + k\n end_loop\n io.out(t)\nend\n@f", ["18", "22"]),
    # the body of a counted loop runs once even when first > last (Itasca: compared at the end of the pass)
    ("fish define f\n local n = 0\n loop i (5, 1)\n  n = n + 1\n endloop\n io.out(n)\nend\n@f", ["1"]),
    # loop while, loop for
    ("fish define f\n local i = 1\n loop while i < 100\n  i = i * 3\n endloop\n io.out(i)\n"
     " local s = 0\n loop for (j = 0, j < 4, j = j + 1)\n  s = s + j\n endloop\n io.out(s)\nend\n@f", ["243", "6"]),
    # lists: 1-based indexing, foreach, list.size, element assignment, boolean selection
    ("fish define f\n local a = list(10, 20, 30)\n io.out(a(2))\n a(2) = 5\n local s = 0\n"
     " loop foreach local x a\n  s = s + x\n endloop\n io.out(s)\n io.out(list.size(a))\n"
     " io.out(list.size(a(list(true, false, true))))\nend\n@f", ["20", "45", "3", "2"]),
    # vectors: components with -> and ., arithmetic
    ("fish define f\n v = vector(1, 2, 3)\n w = v * 2 + vector(0.5, 0, 0)\n io.out(w->x)\n io.out(w.z)\n"
     " w->y = 7\n io.out(w)\n io.out(math.mag(vector(3, 4, 0)))\nend\n@f", ["2.5", "6", "(2.5,7,6)", "5.0"]),
    # maps
    ("fish define f\n m = map('a', 1, 'b', 2)\n m('c') = 3\n io.out(m('b') + m('c'))\n io.out(map.size(m))\nend\n@f",
     ["5", "3"]),
    # case_of (legacy spelling caseof too), section with exit section
    ("fish define pick(k)\n case_of k\n  case 1\n   pick = 'one'\n  case 2, 3\n   pick = 'few'\n end_case\nend\n"
     "[io.out(pick(1))]\n[io.out(pick(3))]", ["one", "few"]),
    ("fish define f\n section\n  io.out('a')\n  exit section\n  io.out('b')\n end_section\n io.out('c')\nend\n@f",
     ["a", "c"]),
    # exit returns early; `...` continuation; ; comments; strings and string.build
    ("fish define f(x)\n f = 1 + ... ; first part\n     x\n if x > 5 then\n  exit\n endif\n f = 0\nend\n"
     "[io.out(f(9))]\n[io.out(string.build('%1-%2', 3, 'z'))]", ["10", "3-z"]),
    # globals and locals: a local does not leak, a global declaration does
    ("fish define f\n local hidden = 1\n global shown = 2\n plain = 3\nend\n@f\n[io.out(shown + plain)]", ["5"]),
    # several function names on one line call each in turn
    ("fish define a\n io.out('a')\nend\nfish define b\n io.out('b')\nend\nfish define both\n a b\nend\n@both", ["a", "b"]),
    # functions call functions defined later; recursion
    ("fish define fact(n)\n if n <= 1 then\n  fact = 1\n else\n  fact = n * fact(n - 1)\n endif\nend\n[io.out(fact(10))]",
     ["3628800"]),
    # math intrinsics (math.log is base 10, math.ln natural, per Itasca)
    ("fish define f\n io.out(math.log(1000))\n io.out(math.ln(math.exp(2)))\n io.out(math.sqrt(16))\n"
     " io.out(math.abs(-3))\n io.out(math.round(2.5))\nend\n@f", ["3.0", "2.0", "4.0", "3", "3"]),
    # `def` for `fish define`, keywords and names in any case
    ("DEF twice(X)\n  TWICE = x * 2\nEND\n[io.out(twice(21))]", ["42"]),
    # a deck value from a FISH function and a global it sets
    ("fish define props\n dens = 2650\nend\n@props\nfish define grav\n grav = -9.81\nend\n"
     "model gravity 0 0 [grav]\n[io.out(string(dens))]", ["2650"]),
]


@pytest.mark.parametrize("text,expected", CASES, ids=[f"case{i}" for i in range(len(CASES))])
def test_construct_prints_the_expected_lines(session, text, expected):
    assert run(session, text) == expected


def test_value_from_fish_reaches_a_command(session):
    session.command("fish define grav\n grav = -9.81\nend\nmodel gravity 0 0 @grav")
    assert session.model.settings.gravity == (0.0, 0.0, -9.81)


def test_command_section_runs_commands_with_locals(session):
    session.command("fish define setg(g)\n local gz = -g\n command\n  model gravity 0 0 [gz]\n"
                    "  model title [string.build('g=%1', g)]\n endcommand\nend\n[setg(9.5)]")
    assert session.model.settings.gravity == (0.0, 0.0, -9.5)
    assert session.model.settings.title == "g=9.5"


def test_fish_list_and_global_step(session):
    out = run(session, "fish define f(a)\n f = a\nend\n[x = 2]\nfish list\n[io.out(global.step)]")
    assert out == ["f(a)  (function)", "x = 2", "0"]


# ---------------------------------------------------------------- errors

def err(session, text, cls=Dec3dError):
    with pytest.raises(cls) as e:
        session.command(text)
    return e.value


def test_undefined_name_with_automatic_create_off(session):
    e = err(session, "fish automatic-create off\nfish define f\n global a = 1\n b = a + 1\nend", BindError)
    assert "undefined FISH name `b` (automatic-create is off)" in e.message
    assert (e.location.line, e.location.column) == (4, 2)
    assert "f" not in session.fish_rt.functions


def test_automatic_create_off_accepts_declared_and_existing_names(session):
    out = run(session, "fish automatic-create off\nfish define p\n global p1 = 30\nend\n"
                       "fish define q\n local r = p1 / 3\n io.out(r)\nend\n@p\n@q")
    assert out == ["10"]


def test_wrong_argument_count_names_the_call(session):
    e = err(session, "fish define f(a, b)\n f = a + b\nend\nfish define g\n g = f(1)\nend\n[x = g]", ExpressionError)
    assert "FISH function `f` takes 2 arguments (a, b), got 1" in e.message
    assert (e.location.line, e.location.column) == (5, 6)
    assert [str(s) for s in e.location.stack] == ["<command>:7:6"]   # called from the [x = g] line


def test_type_error_points_at_the_operator(session):
    e = err(session, "fish define f\n x = 'a' + 1\nend\n@f", ExpressionError)
    assert "operator + cannot combine string and integer" in e.message
    assert (e.location.line, e.location.column) == (2, 10)


def test_division_by_zero_inside_a_called_function(session, tmp_path):
    deck = tmp_path / "d.dat"
    deck.write_text("fish define inner(n)\n  inner = 10 / n\nend\nfish define outer\n  outer = inner(0)\nend\n@outer\n")
    with pytest.raises(ExpressionError) as e:
        session.call(deck)
    assert e.value.message.startswith("division by zero")
    loc = e.value.location
    assert (loc.file, loc.line, loc.column) == (str(deck), 2, 14)
    assert [(s.line, s.column) for s in loc.stack] == [(7, 2), (5, 11)]
    text = e.value.format()
    assert f"{deck}:2:14: error: division by zero" in text and f"called from {deck}:5:11" in text


def test_system_error_stops_the_deck_with_its_message(session, tmp_path):
    from dec3d.cli import main

    deck = tmp_path / "d.dat"
    deck.write_text("fish define check(e)\n if e > 1 then\n  system.error = 'error is ' + string(e)\n end_if\nend\n"
                    "[check(0.5)]\nmodel title 'reached'\n[check(2.5)]\nmodel title 'not reached'\n")
    with pytest.raises(ExpressionError) as e:
        session.call(deck)
    assert e.value.message == "error is 2.5" and e.value.location.line == 3
    assert session.model.settings.title == "reached"
    assert main(["run", "-q", str(deck)]) == 1


def test_runaway_recursion_is_a_clear_error(session):
    e = err(session, "fish define r(n)\n r = r(n + 1)\nend\n[r(1)]", ExpressionError)
    assert "FISH calls nested deeper than 200" in e.message and session.fish_rt.depth == 0


def test_huge_values_are_refused(session):
    e = err(session, "fish define f\n x = 2^80\nend\n@f", ExpressionError)
    assert "integer overflow" in e.message
    e = err(session, "fish define g\n s = 'x'\n loop while 1\n  s = s + s\n endloop\nend\n@g", ExpressionError)
    assert "string longer than" in e.message
    e = err(session, "fish define h\n x = 1e300 * 1e300\nend\n@h", ExpressionError)
    assert "not a finite number" in e.message


def test_unknown_intrinsic_compiles_and_fails_when_run(session):
    session.command("fish define f\n f = block.gp.temperature(1)\nend")     # compiles
    e = err(session, "@f", NotSupportedError)
    assert e.message == "FISH intrinsic `block.gp.temperature` is not supported yet" and e.location.line == 2


def test_syntax_errors_stop_the_deck_before_it_runs(session):
    e = err(session, "model title 'ran'\nfish define f\n if 1 then\n  x = (1 + \n endif\nend", DeckSyntaxError)
    assert e.location.line == 4 and session.model.settings.title == ""
    e = err(session, "fish define f\n loop i (1, 3)\n  x = i\nend", DeckSyntaxError)
    assert "`loop` is not closed" in e.message and e.location.line == 2
    e = err(session, "fish define f\n exit loop\nend", Dec3dError)
    assert "`exit loop` outside a loop" in e.message


def test_legacy_fish_is_named(session):
    from dec3d.commands.binder import LegacySyntaxError

    e = err(session, "def f\n array buf(10)\nend", LegacySyntaxError)
    assert "3DEC 5 (legacy) FISH" in e.message and "array.create" in e.hint


def test_keyboard_interrupt_leaves_the_runtime_consistent(session):
    session.command("fish define spin\n loop while 1\n  n = n + 1\n  if n = 5000 then\n   stop_me\n  endif\n endloop\nend")
    session.fish_rt.functions["stop_me"] = _StopNow(session.fish_rt)
    with pytest.raises(KeyboardInterrupt):
        session.command("[n = 0]\n@spin")
    assert session.fish_rt.depth == 0 and session.fish_rt.callstack == []
    assert 5000 <= session.variables["n"] <= 5000 + 1024


class _StopNow:
    """Stands for a Ctrl-C arriving while a loop runs: sets the stop flag."""

    def __init__(self, rt):
        self.rt = rt

    def invoke(self, args, site):
        from dec3d.fish import request_stop
        request_stop()
        return 0


def test_tables_as_the_elastic_hole_deck_fills_them(session):
    out = run(session, "fish define fill\n local t = table.get(1)\n table.label(t) = 'analytic'\n"
                       " table(t, 2.0) = 20\n table(t, 1.0) = 10\n table(t, 2.0) = 40\n"
                       " io.out(table.size(t))\n io.out(table(t, 1.5))\n io.out(table(1, 9))\n"
                       " io.out(table.label(1))\nend\n@fill")
    # points (1, 10) and (2, 40) after the replacement: halfway 25, beyond the end the last value
    assert out == ["2", "25.0", "40.0", "analytic"]
