"""Every lexical rule of the command language, on lines taken from real decks."""
import pytest

from dec3d.errors import BindError, DeckSyntaxError
from dec3d.lang.parser import parse_deck


def toks(text):
    d = parse_deck(text)
    return [[(t.type, str(t)) for t in line.tokens] for line in d.lines]


def test_comments_anywhere_and_banners():
    lines = toks(";;; Masonry mechanical properties\nmodel new ; start\n;-----\n  ; indented\n")
    assert lines == [[("WORD", "model"), ("WORD", "new")]]


def test_continuation_ampersand_and_dots_mixed():
    # H:04 mixes both markers inside one command; positions stay those of the physical lines
    text = "block create tunnel dip 0 dip-direction 0 radius 1 length 0 1 ...\n" \
           "    blocks-axial 1 blocks-radial 4 &\n    boundary 9 radius-ratio 1.4\nmodel new\n"
    d = parse_deck(text)
    assert len(d.lines) == 2
    first = d.lines[0].tokens
    assert [str(t) for t in first][-4:] == ["boundary", "9", "radius-ratio", "1.4"]
    assert (first[-1].line, first[-1].column) == (3, 29)
    assert d.lines[1].tokens[0].line == 4


def test_continuation_followed_by_comment():
    d = parse_deck("model gravity 0 0 & ; the z part follows\n -9.81\n")
    assert [str(t) for t in d.lines[0].tokens] == ["model", "gravity", "0", "0", "-9.81"]


def test_delimiters_equals_comma_parentheses():
    # S: `stiffness-norm=1e9`, H: `p 0.0,0.4,3.464`, Python decks `(15,3,2)`
    assert toks("block contact prop stiffness-norm=1e9 fric=0\n")[0][3:] == [
        ("WORD", "stiffness-norm"), ("NUMBER", "1e9"), ("WORD", "fric"), ("NUMBER", "0")]
    assert toks('b his name "ACC6" v-y  p 0.0,0.4,3.464\n')[0][-3:] == [
        ("NUMBER", "0.0"), ("NUMBER", "0.4"), ("NUMBER", "3.464")]
    assert [v for _, v in toks("block cut joint-set origin (15,3,2)\n")[0][-3:]] == ["15", "3", "2"]


def test_strings_single_and_double_quotes():
    line = toks("block group \"Masonry\" range group 'S' or \"T_B\" not\n")[0]
    assert ("STRING", '"Masonry"') in line and ("STRING", "'S'") in line and ("STRING", '"T_B"') in line


def test_semicolon_inside_string_is_not_a_comment():
    assert toks("model title 'a;b'\n")[0][-1] == ("STRING", "'a;b'")


def test_numbers_signs_and_exponents():
    vals = [v for _, v in toks("block face apply stress -30e6 -30e6 -15e6 0 0 0 +1.5E-3 .5\n")[0][3:]]
    assert vals == ["stress", "-30e6", "-30e6", "-15e6", "0", "0", "0", "+1.5E-3", ".5"]


def test_case_insensitive_words(session):
    session.command("MODEL GRAVITY 0 0 -10\nModel Large-Strain ON")
    assert session.model.settings.gravity == (0.0, 0.0, -10.0)
    assert session.model.settings.large_strain is True


def test_inline_expression_and_at_name_tokens():
    line = toks("block zone property density [dens] young [Eb] pois [v]\n")[0]
    assert ("EXPR", "[dens]") in line and ("EXPR", "[Eb]") in line
    line = toks("block contact prop stiffness-normal @knj stiffness-shear @ksj\n")[0]
    assert ("ATNAME", "@knj") in line


def test_unquoted_file_name_starting_with_digits():
    assert toks("call 03_Fish\n")[0] == [("WORD", "call"), ("WORD", "03_Fish")]


def test_crlf_line_endings():
    d = parse_deck("model new\r\nmodel large-strain on\r\n")
    assert len(d.lines) == 2 and d.lines[1].tokens[0].line == 2


def test_fish_blocks_are_lifted_raw_and_lines_keep_numbers():
    text = ("fish def joint_prop\n    dens = 1835  ; comment\n    Gt = 0.025*((2*tensj*1e-6)^0.7)*1000\nend\n"
            "@joint_prop\nmodel new\n")
    d = parse_deck(text)
    assert len(d.fish) == 1
    f = d.fish[0]
    assert (f.name, f.line, f.end_line) == ("joint_prop", 1, 4)
    assert "Gt = 0.025" in f.body and {"dens", "gt", "joint_prop"} <= f.variables
    assert [ln.tokens[0].line for ln in d.lines] == [5, 6]


def test_fish_define_without_end_is_an_error():
    with pytest.raises(DeckSyntaxError) as e:
        parse_deck("model new\nfish define f\n  a = 1\n", "x.dat")
    assert e.value.location.line == 2 and "no matching `end`" in e.value.message


@pytest.mark.parametrize("text,col,what", [
    ("model title 'unterminated\n", 13, "unterminated string"),
    ("model gravity [1+2\n", 15, "unterminated inline expression"),
    ("model gravity 0 0 # 1\n", 19, "unexpected character '#'"),
])
def test_syntax_errors_point_at_the_character(text, col, what):
    with pytest.raises(DeckSyntaxError) as e:
        parse_deck(text, "deck.dat")
    assert e.value.location.column == col and what in e.value.message


def test_optional_range_word(session):
    """`block hide group 'x'` and `block hide pos-x 0 0.32`: range elements without `range`."""
    from dec3d.commands.registry import Command, Registry, RangeElement
    from dec3d.commands.binder import BindContext, Binder
    from dec3d.commands.values import P, Nums, Text, Num

    reg = Registry()
    reg.add(Command(("block", "hide"), lambda s, c: None, positional=(P("mode", __import__(
        "dec3d.commands.values", fromlist=["ONOFF"]).ONOFF),), range="block"))
    reg.add_range_element(RangeElement("group", None, (P("name", Text(), required=True),),
                                       (P("slot", Text()), P("or", Text(), repeat=True))))
    reg.add_range_element(RangeElement("position-x", None, (P("bounds", Nums(1, 2), required=True),)))
    for text, n in [("block hide group 'x'\n", 1), ("block hide pos-x 0 0.32\n", 1),
                    ("block hide range group 'S' or 'T_B' not\n", 1),
                    ("block hide off range pos-x 0 1 group 'a' slot 'b'\n", 2)]:
        d = parse_deck(text)
        call = Binder(d, BindContext(), registry=reg).bind(d.lines[0])
        assert call.range is not None and len(call.range.elements) == n, text
    d = parse_deck("block hide range group 'S' or 'T_B' not\n")
    call = Binder(d, BindContext(), registry=reg).bind(d.lines[0])
    el = call.range.elements[0]
    assert el.negate and el.args["name"] == "S" and el.args["or"] == ["T_B"]
    d = parse_deck("block hide pos-x 0 0.32\n")
    assert Binder(d, BindContext(), registry=reg).bind(d.lines[0]).range.elements[0].args["bounds"] == (0, 0.32)
    d = parse_deck("block hide range positoin-x 0 1\n")
    with pytest.raises(BindError) as e:
        Binder(d, BindContext(), registry=reg).bind(d.lines[0])
    assert "unknown range element `positoin-x`" in e.value.message
