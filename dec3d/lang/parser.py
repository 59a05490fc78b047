"""Deck text -> raw lines of tokens, with positions (lark, grammar in deck.lark).

Nothing executes here. `parse_deck` returns a `ParsedDeck`: the source lines (for
error carets), the token lines in order and the lifted FISH blocks.

The grammar's rules say that a deck is lines of one or more tokens; every sequence of
tokens is such a line, so the LALR parser could never reject what the lexer accepts.
`parse_deck` therefore only lexes and cuts the token stream at the newline tokens (the
parser's per-token reductions were about 40 % of the time). The lexing itself is one
regular expression made of the grammar's own terminals, in the order lark tries them,
run with ``re.finditer`` (lark's lexer object costs about 5 µs a token, this about 1 µs:
a 70-number masonry `block create polyhedron` line is lexed in a tenth of a millisecond).
A physical line with the key (its ASCII digits as `0`) of lines lexed before is cut where they
were, without the regular expression (``_lex_fast``: generated decks repeat a few dozen keys).
Text it cannot lex goes through lark's lexer, which reports the bad character
(UnexpectedCharacters) with its line and column; tests/lang compares the two lexers'
tokens on every public deck.
"""
from __future__ import annotations

import gc
import re
from contextlib import contextmanager
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

from lark import Lark, Token
from lark.exceptions import UnexpectedCharacters, UnexpectedInput, UnexpectedToken

from ..errors import CONTROL_CHARS, DeckSyntaxError, SourceLocation, printable
from .prepass import FishBlock, lift_fish

_GRAMMAR_DIR = Path(__file__).parent
_new, _set = object.__new__, object.__setattr__
# the characters refused in strings and `[ ]`, but newlines: no token holds one
_CONTROL_NOT_NL = re.compile(CONTROL_CHARS.pattern.replace("\x0a-", "\x0b-", 1))
assert _CONTROL_NOT_NL.pattern != CONTROL_CHARS.pattern
#: the bytes of ASCII text that are none of those characters (deleted, what is left is the controls)
_NOT_CONTROL_ASCII = bytes(b for b in range(256) if b > 127 or _CONTROL_NOT_NL.match(chr(b)) is None)
# the numbers of a run (``NumRun``): NUMBER without its look-ahead (a run holds numbers and
# delimiters only); a run is split at its delimiters
_NUMBER_IN_RUN = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
_RUN_SPLIT = re.compile(r"[ \t\f\r,()=]+")


class NumRun:
    """Two or more numbers in a row on one physical line (only delimiters between them), lexed as one
    match: their texts (``nums``), not a token each. A `block create polyhedron` line of 72 numbers is
    one run; the binder converts a run's numbers in one pass (``bind_plan``) and asks for the tokens
    (``tokens()``, the ones lark's lexer gives) only when a line is bound the ordinary way or a
    location inside the run is resolved."""

    __slots__ = ("text", "nums", "start", "line", "line_start", "_tokens")
    type = "NUMRUN"

    def __init__(self, text: str, nums: list, start: int, line: int, line_start: int):
        self.text, self.nums, self.start, self.line, self.line_start = text, nums, start, line, line_start
        self._tokens = None

    def tokens(self) -> list:
        """The run's NUMBER tokens (type, text, line, column, end, offsets as lark's lexer makes them)."""
        toks = self._tokens
        if toks is None:
            toks = self._tokens = run_tokens(self.text, self.start, self.line, self.line_start)
            assert len(toks) == len(self.nums)
        return toks


def run_tokens(text: str, start: int, line: int, line_start: int) -> list:
    """The NUMBER tokens of the run of numbers ``text`` found at offset ``start`` of the deck, on
    ``line``, which starts at offset ``line_start``."""
    make = str.__new__
    toks = []
    for m in _NUMBER_IN_RUN.finditer(text):
        value = m.group()
        s, e = start + m.start(), start + m.end()
        tok = make(Token, value)
        tok.type, tok.value, tok.start_pos, tok.end_pos = "NUMBER", value, s, e
        tok.line = tok.end_line = line
        tok.column, tok.end_column = s - line_start + 1, e - line_start + 1
        toks.append(tok)
    return toks


class RawLine:
    """One command line: its tokens (lark Tokens: type, value, line, column). ``items`` is the same
    line as the lexer gave it, each run of numbers one ``NumRun``; ``tokens`` is made from it the
    first time it is asked for (the same Token objects, a run's numbers each a token). ``key``: the
    line's key (``_lex_fast``) when it was cut by its template and its words hold no digit — lines of
    one such key have one shape (the binder looks their plan up by it) — else None."""

    __slots__ = ("items", "_tokens", "key")

    def __init__(self, items: tuple, runs: bool = False, key: str | None = None):
        self.items = items
        self._tokens = None if runs else items
        self.key = key

    @property
    def tokens(self) -> tuple:
        toks = self._tokens
        if toks is None:
            out = []
            for it in self.items:
                if it.type == "NUMRUN":
                    out.extend(it.tokens())
                else:
                    out.append(it)
            toks = self._tokens = tuple(out)
        return toks

    @property
    def line(self) -> int:
        return self.items[0].line


class KeyLine(RawLine):
    """A line cut by the template of its key (``_lex_fast``): where it starts in the text (``pos``), its
    line number and the template ``tpl`` ((kind, start, end) per item, relative to ``pos``; the shape
    key or None; whether it holds runs of numbers). Its items are made the first time they are asked
    for: a binder that has the line's plan by its key reads its values from the text itself
    (``commands.bind_direct``) and most lines of a generated deck never make their tokens."""

    __slots__ = ("text", "pos", "line", "tpl", "_items")

    def __init__(self, text: str, pos: int, line: int, tpl: tuple):
        self.text, self.pos, self.line, self.tpl = text, pos, line, tpl
        self.key = tpl[1]
        self._items = self._tokens = None

    @property
    def items(self) -> tuple:
        items = self._items
        if items is None:
            items = self._items = _cut(self.text, self.pos, self.line, self.tpl[0])
            if not self.tpl[2]:
                self._tokens = items
        return items


def _cut(text: str, pos: int, line: int, tpl: tuple) -> tuple:
    """The items of the line at ``pos`` of ``text`` by the template of its key (kinds and places)."""
    make = str.__new__           # lark's Token._future_new written out (item_at, inline)
    items = []
    for kind, s, e in tpl:
        value = text[pos + s:pos + e]
        if kind == "NUMRUN":
            if "(" in value or ")" in value or "=" in value:
                nums = _RUN_SPLIT.split(value)
            else:
                nums = value.replace(",", " ").split()
            items.append(NumRun(value, nums, pos + s, line, pos))
        else:
            tok = make(Token, value)
            tok.type, tok.value, tok.start_pos, tok.end_pos = kind, value, pos + s, pos + e
            tok.line = tok.end_line = line
            tok.column, tok.end_column = s + 1, e + 1
            items.append(tok)
    return tuple(items)


def item_at(text: str, pos: int, line: int, kind: str, s: int, e: int):
    """The item of ``kind`` (a Token as lark's lexer makes it, or a ``NumRun``) at ``s:e`` of the line
    at ``pos`` of ``text``, line number ``line``."""
    value = text[pos + s:pos + e]
    if kind == "NUMRUN":
        if "(" in value or ")" in value or "=" in value:
            nums = _RUN_SPLIT.split(value)
        else:
            nums = value.replace(",", " ").split()
        return NumRun(value, nums, pos + s, line, pos)
    tok = str.__new__(Token, value)      # lark's Token._future_new written out
    tok.type, tok.value, tok.start_pos, tok.end_pos = kind, value, pos + s, pos + e
    tok.line = tok.end_line = line
    tok.column, tok.end_column = s + 1, e + 1
    return tok


@lru_cache(maxsize=None)
def deck_parser() -> Lark:
    return Lark.open(
        str(_GRAMMAR_DIR / "deck.lark"),
        parser="lalr",
        lexer="basic",
        maybe_placeholders=False,
        cache=False,
    )


@dataclass
class ParsedDeck:
    filename: str
    source_lines: list[str]
    lines: list[RawLine]
    fish: list[FishBlock]

    def location(self, tok: Token, stack=()) -> SourceLocation:
        line = tok.line
        lines = self.source_lines
        text = lines[line - 1] if 0 < line <= len(lines) else ""
        # errors.frozen_instance written out (a location per bound line)
        loc = _new(SourceLocation)
        _set(loc, "__dict__", {"file": self.filename, "line": line, "column": tok.column, "text": text,
                               "length": len(tok) or 1, "stack": stack if type(stack) is tuple else tuple(stack)})
        return loc


def normalise(text: str) -> str:
    """A leading UTF-8 byte-order mark and a trailing DOS end-of-file mark dropped, CRLF/CR to LF,
    a final newline, tabs kept (carets expand them)."""
    if text.startswith("\ufeff"):
        text = text[1:]
    if text.endswith("\x1a"):            # a DOS end-of-file mark (Ctrl-Z) after the last line
        text = text[:-1]
    if "\r" in text:
        text = text.replace("\r\n", "\n").replace("\r", "\n")
    if not text.endswith("\n"):
        text += "\n"
    return text


@contextmanager
def gc_paused():
    """Python's cycle collector off while a deck is read. Reading makes an object per token and
    frees none: every few hundred of them the collector scanned them all again (a 664 000-token
    masonry deck lexed in 3.9 s with it, 1.3 s without). Nothing made here forms cycles; the
    collector is turned back on (if it was on) when reading ends, by error or not.

    What was made meanwhile (tokens, bound commands: they live as long as the run) goes to the
    oldest generation without being scanned (``gc.freeze`` then ``gc.unfreeze``; skipped if the
    program froze objects of its own): left young, the first collection after reading would look at
    every one of them only to promote it — a fifth of reading a 100 000-line deck. Cycles among them
    are still found, by the next full collection."""
    was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was:
            if gc.get_freeze_count() == 0:
                gc.freeze()
                gc.unfreeze()
            gc.enable()


def parse_deck(text: str, filename: str = "<input>", stack=()) -> ParsedDeck:
    """Parse a whole deck; raise DeckSyntaxError with file:line:col on bad text."""
    text = normalise(text)
    source_lines = text.split("\n")
    lifted, fish = lift_fish(text, filename)
    def check(tok):
        _no_control(tok, filename, source_lines, stack)

    try:
        with gc_paused():
            lines = _lex_fast(lifted)
            if lines is None:                   # text the fast lexer cannot take: lark's reports it
                lines = _lex_lark(lifted, check)
    except UnexpectedInput as exc:
        raise _syntax_error(exc, filename, source_lines, stack) from None
    if _has_control(lifted):            # else no string or `[ ]` can hold one
        for line in lines:
            if type(line) is KeyLine:   # its strings only (its other items are not made for this)
                for kind, s, e in line.tpl[0]:
                    if kind == "STRING" or kind == "EXPR":
                        check(item_at(line.text, line.pos, line.line, kind, s, e))
                continue
            for tok in line.items:
                if tok.type in ("STRING", "EXPR"):
                    check(tok)
    return ParsedDeck(filename, source_lines, lines, fish)


def _has_control(text: str) -> bool:
    """Whether ``text`` holds a character of ``_CONTROL_NOT_NL`` (ASCII text by ``bytes.translate``,
    a quarter of the time of the regular expression's search)."""
    if text.isascii():
        return len(text.encode("ascii").translate(None, _NOT_CONTROL_ASCII)) > 0
    return _CONTROL_NOT_NL.search(text) is not None


def _lex_lark(text: str, check=None) -> list[RawLine]:
    """Token lines by lark's lexer (the reference ``_lex_fast`` is tested against). ``check(tok)``
    sees each string and inline expression as it is read, so that of two faults the first in the
    text is reported (a control character on line 1 before bytes that are not text on line 2)."""
    lines: list[RawLine] = []
    current: list[Token] = []
    for tok in deck_parser().lex(text):
        if tok.type == "_NL":
            if current:
                lines.append(RawLine(tuple(current)))
                current = []
        else:
            if check is not None and tok.type in ("STRING", "EXPR"):
                check(tok)
            current.append(tok)
    if current:
        lines.append(RawLine(tuple(current)))
    return lines


@lru_cache(maxsize=None)
def _fast_pattern() -> tuple[re.Pattern, frozenset]:
    """One alternation of the grammar's terminals, in lark's order for its basic lexer (priority,
    then widest, then longest pattern, then name), each a named group; the delimiters before a
    token are matched with it (half the matches). That is lark's lexing: no other terminal can
    start with a delimiter character (space, tab, form feed, `,()=`; carriage returns are gone
    after ``normalise``), so lark takes the whole run of them as one ignored token first."""
    lk = deck_parser()
    terms = sorted(lk.terminals, key=lambda t: (-t.priority, -t.pattern.max_width, -len(t.pattern.value), t.name))
    pattern = "|".join(f"(?P<{t.name}>{t.pattern.to_regexp()})" for t in terms)
    delim = lk.get_terminal("DELIMITERS").pattern.to_regexp()
    # a run of numbers (``NumRun``) before the rest: NUMBER is the first terminal tried, so lark
    # lexes this text as NUMBER, DELIMITERS, NUMBER, ... (a NUMBER never starts with a delimiter,
    # so the run ends exactly where the next token is not a number)
    number = lk.get_terminal("NUMBER").pattern.to_regexp()
    assert terms[0].name == "NUMBER"
    run = f"(?P<NUMRUN>{number}(?:(?:{delim}){number})+)"
    return re.compile(f"(?:{delim})?(?:{run}|{pattern})"), frozenset(lk.lexer_conf.ignore)


#: every ASCII digit as `0`: a physical line's *key*. No terminal of the grammar tells one ASCII digit
#: from another (``\\d``, ``[0-9]`` and classes holding all ten), so lines of one key are lexed alike:
#: the same token types at the same places, only the digits in their texts differ
_DIGITS_AS_0 = str.maketrans("123456789", "000000000")
_ASCII_DIGIT = re.compile("[0-9]").search
#: keys remembered per deck (a deck whose lines are each of their own key has no use for more)
MAX_TEMPLATES = 4096


def _lex_fast(text: str) -> list[RawLine] | None:
    """Token lines, the same tokens (type, text, line, column, end, offsets) lark's lexer gives;
    None when some text matches no terminal. A run of numbers is one ``NumRun`` item.

    Physical lines are lexed one by one. Of lines neither continued nor continuing one, the second
    of a key (``_DIGITS_AS_0``) leaves its *template* (each item's kind and place), and the later
    ones are cut by it without the regular expression: 8 000 `block create brick` lines have 29 keys,
    a generated deck of 100 000 lines a few hundred. (A key seen once costs a set entry: a deck of
    lines each of its own key is lexed as before.)"""
    pat, ignore = _fast_pattern()
    make = str.__new__           # lark's Token._future_new written out: a call less per token
    new_line = object.__new__
    lines: list[RawLine] = []
    current: list[Token] = []
    templates: dict[str, tuple] = {}
    seen: set[str] = set()       # keys of one line so far
    scan = None
    scan_at = -1                 # where ``scan`` matches next
    runs = False
    n_text = len(text)
    pos = 0                      # where the physical line starts
    line = 0
    for key in text.translate(_DIGITS_AS_0).split("\n"):
        line += 1
        stop = pos + len(key)    # the line's newline (or the end of the text)
        if pos >= n_text:
            break
        record = False
        if not current and stop < n_text:         # the line starts a command and ends at a newline
            tpl = templates.get(key)
            if tpl is not None:  # cut as the line of its key was (its items made when asked for)
                if tpl[0]:       # KeyLine(text, pos, line, tpl), written out
                    kl = new_line(KeyLine)
                    kl.text, kl.pos, kl.line, kl.tpl, kl.key = text, pos, line, tpl, tpl[1]
                    kl._items = kl._tokens = None
                    lines.append(kl)
                pos = stop + 1
                continue
            if key in seen:      # the second line of its key: the template is made from it
                record = len(templates) < MAX_TEMPLATES
            elif len(seen) < 4 * MAX_TEMPLATES:
                seen.add(key)
        if scan_at != pos:       # after lines cut by templates: the scanner goes on from here
            scan = pat.scanner(text, pos).match
        end = line_start = pos
        while True:              # the physical line's tokens, up to its newline
            m = scan()
            if m is None:        # text no terminal takes (or the end of a text without a final newline)
                if end != n_text:
                    return None
                break
            end = m.end()
            kind = m.lastgroup
            if kind in ignore:
                if kind == "CONTINUATION":
                    break        # the command goes on on the next physical line
                continue
            if kind == "_NL":
                if record:       # the template of the line's key
                    templates[key] = (tuple((it.type, it.start - pos, it.start - pos + len(it.text))
                                            if it.type == "NUMRUN" else (it.type, it.start_pos - pos, it.end_pos - pos)
                                            for it in current),
                                      None if any(it.type == "WORD" and _ASCII_DIGIT(it.value) is not None
                                                  for it in current) else key,
                                      runs)
                if current:
                    lines.append(RawLine(tuple(current), runs))
                    current = []
                    runs = False
                break
            if kind == "NUMRUN":
                value = m.group(kind)
                if "(" in value or ")" in value or "=" in value:
                    nums = _RUN_SPLIT.split(value)
                else:                   # blanks and commas only (str.split is a third of re.split)
                    nums = value.replace(",", " ").split()
                current.append(NumRun(value, nums, end - len(value), line, line_start))
                runs = True
            else:
                value = m.group(kind)
                start = end - len(value)
                tok = make(Token, value)
                tok.type, tok.value, tok.start_pos, tok.end_pos = kind, value, start, end
                tok.line = tok.end_line = line
                tok.column, tok.end_column = start - line_start + 1, end - line_start + 1
                current.append(tok)
        if end != stop + 1 and end != n_text:
            return None          # not reached: a physical line's tokens end at its newline
        pos = scan_at = end
    if current:
        lines.append(RawLine(tuple(current), runs))
    return lines


def _no_control(tok: Token, filename, source_lines, stack) -> None:
    """Quoted text and `[...]` may hold any printable character, but no control character: they
    would reach file names (a NUL) or the terminal (ESC sequences, bidirectional overrides)."""
    m = CONTROL_CHARS.search(str(tok))
    if m is None:
        return
    text = source_lines[tok.line - 1] if 0 < tok.line <= len(source_lines) else ""
    what = "a string" if tok.type == "STRING" else "an inline expression"
    raise DeckSyntaxError(f"control character {printable(m.group())} in {what}",
                          SourceLocation(filename, tok.line, tok.column + m.start(), text, 1, tuple(stack)),
                          "a deck is plain text: remove the character (or write it out in words)")


def _syntax_error(exc: UnexpectedInput, filename, source_lines, stack) -> DeckSyntaxError:
    line, col = exc.line, exc.column
    text = source_lines[line - 1] if 0 < line <= len(source_lines) else ""
    ch = text[col - 1] if 0 < col <= len(text) else ""
    if isinstance(exc, UnexpectedCharacters):
        if ch in "'\"":
            msg, hint = "unterminated string", f"close the string with {ch} on the same line"
        elif ch == "[":
            msg, hint = "unterminated inline expression", "close `[` with `]` on the same line"
        elif ch == "]":
            msg, hint = "`]` without a matching `[`", None
        elif ch == "\ufffd":
            msg, hint = "bytes that are not UTF-8 text", "save the deck as UTF-8 (or plain ASCII)"
        else:
            msg = f"unexpected character {ch!r}"
            hint = "delimiters are space , ( ) =; comments start with ;; continue a line with & or ..."
    elif isinstance(exc, UnexpectedToken):
        msg, hint = f"unexpected {exc.token.type.lower()} {str(exc.token)!r}", None
    else:
        msg, hint = "syntax error", None
    return DeckSyntaxError(msg, SourceLocation(filename, line, col, text, 1, tuple(stack)), hint)
