"""Value types of command keywords: how many tokens a value takes and how it is checked.

One declaration per keyword (see `Param`) drives binding, validation, unit
conversion (degrees -> radians at the boundary), error messages and the
`commands/` reference page. A value written as `[expr]` or `@name` is bound as a
`Deferred` and converted by the same type when the command runs.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from ..errors import BindError
from ..lang.abbrev import matches
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


@dataclass(frozen=True)
class Num(ValueType):
    """A real number. `angle=True`: given in degrees, stored in radians."""

    integer: bool = False
    angle: bool = False
    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False     # lo itself excluded (strictly positive, ...)

    @property
    def label(self):  # type: ignore[override]
        return "<i>" if self.integer else "<f>"

    def literal(self, tok):
        return _number_literal(tok)

    def convert(self, value, where):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise BindError(f"expected a number, got {value!r}", where)
        if self.integer:
            if isinstance(value, float):
                if value != int(value):
                    raise BindError(f"expected an integer, got {value!r}", where)
                value = int(value)
        else:
            value = float(value)
            if not math.isfinite(value):
                raise BindError(f"expected a finite number, got {value!r}", where)
        if self.lo is not None and (value < self.lo or (self.lo_open and value == self.lo)):
            rel = ">" if self.lo_open else "≥"
            raise BindError(f"value {value:g} out of range: must be {rel} {self.lo:g}", where)
        if self.hi is not None and value > self.hi:
            raise BindError(f"value {value:g} out of range: must be ≤ {self.hi:g}", where)
        if self.angle:
            value = math.radians(value)
        return value

    def describe(self):
        s = self.label
        if self.angle:
            s += " (degrees)"
        return s


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
        item = self.item
        while i < len(toks) and len(out) < self.most and toks[i].type in NUMBERISH:
            v, i = item.take(toks, i, binder)
            out.append(v)
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
        if self.least == self.most == 3:
            return "<v>" + (" (degrees)" if self.item.angle else "")
        if self.least == self.most:
            return " ".join([lab] * self.least)
        return f"{lab} ×{self.least}..{self.most if self.most < 10**6 else 'n'}"


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
            raise BindError(f"`{value}` is {what} {', '.join(hits or self.options)}", where)
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
INT = Num(integer=True)
POS_INT = Num(integer=True, lo=0)
ANGLE = Num(angle=True)
VEC3 = Nums(3, 3)
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
