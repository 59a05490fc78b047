"""Value types of command keywords: how many tokens a value takes and how it is checked.

One declaration per keyword (see `Param`) drives binding, validation, unit
conversion (degrees -> radians at the boundary), error messages and the
`commands/` reference page. A value written as `[expr]` or `@name` is bound as a
`Deferred` and converted by the same type when the command runs.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

from ..config import DENSITY_LIMIT
from ..errors import BindError
from ..lang.abbrev import matches, suggest
from ..lang.deferred import Deferred  # noqa: F401  (commands and FISH share it)

NUMBERISH = ("NUMBER", "EXPR", "ATNAME")


class ValueType:
    """Base: takes one token. Subclasses say which tokens fit and how to convert."""

    label = "<value>"
    fits_types: tuple[str, ...] = NUMBERISH

    def fits(self, tok) -> bool:
        return tok.type in self.fits_types

    def take(self, toks, i: int, binder) -> tuple[Any, int]:
        tok = toks[i]
        if tok.type in ("EXPR", "ATNAME"):
            return binder.deferred(tok), i + 1
        try:
            return self.convert(self.literal(tok), None), i + 1
        except BindError as exc:      # the position is only worked out when there is an error
            raise exc.with_location(binder.where(tok)) from None

    def literal(self, tok):
        return str(tok)

    def convert(self, value, where) -> Any:
        return value

    def describe(self) -> str:
        return self.label


def _number_literal(tok):
    s = str(tok)
    if "." in s or "e" in s or "E" in s:
        return float(s)
    return int(s)


class ValueRangeError(BindError):
    """A value of the right kind outside what its keyword accepts.

    `detail` is the rule and the value ("must be in [0, 90) degrees, got 95"); the binder and
    the session put the keyword in front (`named`), so the message says which value is wrong."""

    def __init__(self, detail: str, location=None):
        super().__init__(f"value {detail}", location)
        self.detail = detail

    def named(self, name: str) -> "ValueRangeError":
        self.message = f"`{name}` {self.detail}"
        self.args = (self.message,)
        return self


#: largest coordinate or length dec3d accepts (m): beyond it float64 geometry loses every digit
#: of a block's size (1e12 m leaves 1e-4 m of resolution) and squares of lengths overflow sooner
COORD_LIMIT = 1e12
#: integers are 64-bit (as FISH integers); a larger count could not be held by any array
INT_LIMIT = 2**63 - 1


def _g(x) -> str:
    return f"{x:g}" if isinstance(x, float) else str(x)


@dataclass(frozen=True)
class Num(ValueType):
    """A real number. `angle=True`: given in degrees, stored in radians.

    Every number must be finite; `lo`/`hi` bound it (`lo_open`/`hi_open`: the bound itself
    excluded); an integer must fit 64 bits."""

    integer: bool = False
    angle: bool = False
    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False     # lo itself excluded (strictly positive, ...)
    hi_open: bool = False     # hi itself excluded (friction < 90°, damping < 1)

    @property
    def label(self):  # type: ignore[override]
        return "<i>" if self.integer else "<f>"

    def literal(self, tok):
        return _number_literal(tok)

    @cached_property
    def inline(self):
        """(lo, lo closed, hi, hi closed, angle) for ``Nums.take`` to convert a real number inline
        (±inf and open for no bound); None for integers."""
        if self.integer:
            return None
        lo = -math.inf if self.lo is None else self.lo
        hi = math.inf if self.hi is None else self.hi
        return lo, self.lo is not None and not self.lo_open, hi, self.hi is not None and not self.hi_open, self.angle

    def range_text(self) -> str:
        """The valid range in words: `in [0, 90) degrees`, `> 0`, `≥ 1`; "" when unbounded."""
        unit = " degrees" if self.angle else ""
        lo, hi = self.lo, self.hi
        if lo is not None and hi is not None:
            return f"in {'(' if self.lo_open else '['}{_g(lo)}, {_g(hi)}{')' if self.hi_open else ']'}{unit}"
        if lo is not None:
            return f"{'>' if self.lo_open else '≥'} {_g(lo)}{unit}"
        if hi is not None:
            return f"{'<' if self.hi_open else '≤'} {_g(hi)}{unit}"
        return ""

    def convert(self, value, where):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise BindError(f"expected a number, got {value!r}", where)
        if isinstance(value, float) and not math.isfinite(value):
            raise ValueRangeError(f"must be a finite number, got {value!r}", where)
        if self.integer:
            if isinstance(value, float):
                if value != int(value):
                    raise BindError(f"expected an integer, got {value!r}", where)
                value = int(value)
            if abs(value) > INT_LIMIT:
                raise ValueRangeError(f"must be an integer of at most 64 bits (|n| ≤ 2^63 - 1), got {_big(value)}",
                                      where)
        else:
            try:
                value = float(value)
            except OverflowError:
                raise ValueRangeError(f"must be a finite number, got {_big(value)}", where) from None
        lo, hi = self.lo, self.hi
        if ((lo is not None and (value < lo or (self.lo_open and value == lo)))
                or (hi is not None and (value > hi or (self.hi_open and value == hi)))):
            raise ValueRangeError(f"must be {self.range_text()}, got {_g(value)}", where)
        if self.angle:
            value = math.radians(value)
        return value

    def describe(self):
        rng = self.range_text()
        if rng:
            return f"{self.label} {rng}"
        return self.label + (" (degrees)" if self.angle else "")


def _big(n) -> str:
    """An integer too large to print whole (Python refuses str() beyond 4300 digits)."""
    if isinstance(n, int) and n.bit_length() > 64:
        return f"an integer of {n.bit_length()} bits"
    return _g(n)


@dataclass(frozen=True)
class Nums(ValueType):
    """Between `least` and `most` numbers in a row (a vector is Nums(3, 3))."""

    least: int = 3
    most: int = 3
    item: Num = field(default_factory=Num)
    multiple_of: int = 1
    counts: tuple[int, ...] = ()       # allowed counts when not every count in least..most is valid

    def take(self, toks, i, binder):
        out = []
        start = i
        n, most = len(toks), self.most
        literal, convert = self.item.literal, self.item.convert
        inline = self.item.inline
        if inline is not None:
            lo, lo_closed, hi, hi_closed, angle = inline
        # ``Num.take`` written out: a masonry deck's `block create polyhedron` line holds 72 numbers;
        # each turn takes one token or stops, so at most `most` turns
        stop = min(n, i + most)
        while i < stop:
            tok = toks[i]
            kind = tok.type
            if kind == "NUMBER":
                if inline is not None:    # Num.convert of _number_literal inline; what it refuses goes to it
                    s = tok.value
                    try:
                        v = float(s) if ("." in s or "e" in s or "E" in s) else float(int(s))
                    except OverflowError:
                        v = math.inf
                    if lo < v < hi or (v == lo and lo_closed) or (v == hi and hi_closed):
                        out.append(math.radians(v) if angle else v)
                        i += 1
                        continue
                try:
                    out.append(convert(literal(tok), None))
                except BindError as exc:
                    raise exc.with_location(binder.where(tok)) from None
            elif kind == "EXPR" or kind == "ATNAME":
                out.append(binder.deferred(tok))
            else:
                break
            i += 1
        if len(out) < self.least or len(out) % self.multiple_of or (self.counts and len(out) not in self.counts):
            want = str(self.least) if self.least == self.most else f"{self.least} to {self.most}"
            if self.counts:
                want = " or ".join(str(c) for c in self.counts)
            if self.multiple_of > 1:
                want = f"a multiple of {self.multiple_of}"
            where = binder.where(toks[min(i, len(toks) - 1)] if i > start else toks[start - 1 if start else 0])
            raise BindError(f"expected {want} numbers, got {len(out)}", where)
        return tuple(out), i

    def convert(self, value, where):
        return tuple(self.item.convert(v, where) for v in value)

    def describe(self):
        lab = self.item.label
        rng = self.item.range_text()
        each = f", each {rng}" if rng else ""
        if self.least == self.most == 3:
            return "<v>" + (" (degrees)" if self.item.angle and not rng else "") + each
        if self.least == self.most:
            return " ".join([lab] * self.least) + each
        return f"{lab} ×{self.least}..{self.most if self.most < 10**6 else 'n'}" + each


@dataclass(frozen=True)
class Text(ValueType):
    """A string, quoted or not."""

    label: str = "<s>"
    fits_types: tuple[str, ...] = ("STRING", "WORD", "EXPR", "ATNAME")

    def literal(self, tok):
        s = str(tok)
        return s[1:-1] if tok.type == "STRING" else s

    def convert(self, value, where):
        if isinstance(value, bool):
            value = "true" if value else "false"
        if isinstance(value, (int, float)):
            value = str(value)
        return value


_ON = {"on": True, "off": False, "true": True, "false": False, "yes": True, "no": False}


@dataclass(frozen=True)
class OnOff(ValueType):
    """on | off (also true/false, yes/no)."""

    label: str = "on|off"
    fits_types: tuple[str, ...] = ("WORD", "EXPR", "ATNAME")

    def fits(self, tok):
        if tok.type == "WORD":
            return len(matches(str(tok), _ON)) == 1
        return tok.type in ("EXPR", "ATNAME")

    def literal(self, tok):
        hit = matches(str(tok), _ON)
        return _ON[hit[0]] if len(hit) == 1 else str(tok)

    def convert(self, value, where):
        if isinstance(value, bool):
            return value
        if isinstance(value, (int, float)):
            return bool(value)
        raise BindError(f"expected on or off, got {value!r}", where)


@dataclass(frozen=True)
class Choice(ValueType):
    """One word among `options` (abbreviable)."""

    options: tuple[str, ...] = ()
    fits_types: tuple[str, ...] = ("WORD",)

    @property
    def label(self):  # type: ignore[override]
        return "|".join(self.options)

    def fits(self, tok):
        return tok.type == "WORD" and len(matches(str(tok), self.options)) == 1

    def literal(self, tok):
        return str(tok)

    def convert(self, value, where):
        hits = matches(str(value), self.options)
        if len(hits) != 1:
            what = "ambiguous" if hits else "not one of"
            close = [] if hits else suggest(str(value), self.options)
            raise BindError(f"`{value}` is {what} {', '.join(hits or self.options)}", where,
                            hint=f"did you mean {' or '.join(f'`{c}`' for c in close)}?" if close else None)
        return hits[0]


@dataclass(frozen=True)
class Flag(ValueType):
    """A keyword with no value: present means True."""

    label: str = ""
    fits_types: tuple[str, ...] = ()

    def take(self, toks, i, binder):
        return True, i


MISSING = object()


@dataclass(frozen=True)
class Param:
    """A keyword or positional argument of a command or range element.

    name: the keyword as written in full (`stiffness-normal`); value: its ValueType;
    default: value when absent; bare: value when the keyword is given without a value
    (MISSING: a value is required); repeat: may be given several times (a list is kept);
    supported: False for keywords of 3DEC that dec3d knows but does not implement yet.
    """

    name: str
    value: ValueType = field(default_factory=Num)
    doc: str = ""
    default: Any = None
    required: bool = False
    bare: Any = MISSING
    repeat: bool = False
    supported: bool = True
    units: str = ""

    @property
    def key(self) -> str:
        """The Python name of the argument: hyphens to underscores."""
        return self.name.replace("-", "_")


def P(name: str, value: ValueType | None = None, doc: str = "", **kw) -> Param:
    """Short constructor used in command declarations."""
    return Param(name, value if value is not None else Num(), doc, **kw)


FLOAT = Num()
#: a coordinate (m)
COORD = Num(lo=-COORD_LIMIT, hi=COORD_LIMIT)
DENSITY = Num(lo=0, lo_open=True, hi=DENSITY_LIMIT)
#: a length or distance (m), > 0
LENGTH = Num(lo=0, lo_open=True, hi=COORD_LIMIT)
INT = Num(integer=True)
POS_INT = Num(integer=True, lo=0)
ANGLE = Num(angle=True)
VEC3 = Nums(3, 3)
#: a point (m)
POINT = Nums(3, 3, item=COORD)
TEXT = Text()
ONOFF = OnOff()
FLAG = Flag()


@dataclass(frozen=True)
class OutPath(Text):
    """A file the command writes. The session checks a literal name when the deck is bound
    (``dec3d.io.paths.output_path``: under the output folder, a regular file) and again, with the
    value of an `[expr]`, when the command runs. `suffix`: added when the name has none
    (`model save`: .sav); `stem=True`: the name is a stem, `.vtu|.pvd|.vtk` dropped and `.pvd` checked."""

    label: str = "<file>"
    suffix: str = ""
    stem: bool = False

    def final(self, name: str) -> str:
        """The file name actually written for the name the deck gave."""
        import os

        if name.endswith(("/", os.sep)) or os.path.basename(name) in ("", ".", ".."):
            return name           # a folder: refused as such by dec3d.io.paths.output_path
        base, ext = os.path.splitext(name)
        if self.stem:
            return (base if ext.lower() in (".vtu", ".pvd", ".vtk") else name) + ".pvd"
        if self.suffix and not ext:
            return name + self.suffix
        return name


@dataclass(frozen=True)
class InPath(Text):
    """A file the command reads: looked for beside the calling deck, then in the output folder
    (``dec3d.io.paths.find_input``); `exts` are tried when the name has no extension."""

    label: str = "<file>"
    exts: tuple[str, ...] = ()


@dataclass(frozen=True)
class TableId(ValueType):
    """A table id: an integer or a name."""

    label = "<i|s>"
    fits_types = ("NUMBER", "STRING", "WORD", "EXPR", "ATNAME")

    def literal(self, tok):
        s = str(tok)
        if tok.type == "NUMBER":
            try:
                return int(s)
            except ValueError:
                raise BindError(f"a table id is an integer or a name, not {s}") from None
        return s[1:-1] if tok.type == "STRING" else s

    def convert(self, value, where):
        if isinstance(value, float) and value == int(value):
            value = int(value)
        if isinstance(value, bool) or not isinstance(value, (int, str)) or value == "":
            raise BindError(f"a table id is an integer or a name, not {value!r}", where)
        return value
