"""Declared fields of the TOML slope input, and their binding with located errors.

Every section lists its keys with kind, default, unit kind, bounds and a one-line
doc; `bind` validates a parsed table against it and converts to SI.  Errors name
the file, the line of the key (found in the text, since tomllib keeps no
positions) and the dotted field name.  docs/ssdem.md documents the same table.
"""
from __future__ import annotations

import difflib
import math
import re
from dataclasses import dataclass
from typing import Any

from .errors import SsdemInputError

REQUIRED = object()
#: load steps and secant iterations per step at most (each is at least one linear solve)
MAX_STEPS = 10_000
MAX_ITERATIONS = 10_000
#: deepest nesting of arrays and inline tables the input may use (points need 2)
MAX_NESTING = 32
#: largest coordinate or length, in the input's units (beyond it the geometry loses all precision)
MAX_COORD = 1e9


@dataclass(frozen=True)
class Field:
    name: str
    kind: str                 # float, int, str, bool, points, pair
    default: Any = REQUIRED
    unit: str = "none"        # key of units.factors()
    lo: float | None = None   # inclusive lower bound
    hi: float | None = None   # inclusive upper bound
    choices: tuple = ()
    doc: str = ""
    positive: bool = False    # strictly > 0


SECTIONS: dict[str, tuple[Field, ...]] = {
    "": (
        Field("title", "str", "", doc="title of the analysis"),
        Field("units", "str", "kN-m", choices=("N-m", "kN-m", "lb-ft"), doc="force-length units of every number"),
    ),
    "profile": (
        Field("points", "points", doc="ground surface (x, y), x increasing, left to right"),
    ),
    "layer": (
        Field("name", "str", "", doc="label"),
        Field("top", "points", None, unit="length", doc="top boundary (x, y) of layers after the first"),
        Field("c", "float", unit="stress", lo=0.0, doc="peak effective cohesion c'_p"),
        Field("phi", "float", unit="angle", lo=0.0, hi=89.0, doc="peak effective friction angle, degrees"),
        Field("c_res", "float", None, unit="stress", lo=0.0, doc="residual cohesion (default: c)"),
        Field("phi_res", "float", None, unit="angle", lo=0.0, hi=89.0, doc="residual friction angle (default: phi)"),
        Field("gamma", "float", unit="unit_weight", positive=True, doc="total unit weight"),
        Field("kn", "float", unit="stiffness", positive=True, doc="normal Winkler spring constant (stress/length)"),
        Field("ks", "float", unit="stiffness", positive=True, doc="shear Winkler spring constant (stress/length)"),
        Field("delta_res", "float", None, unit="length", positive=True,
              doc="slip at the onset of residual strength (required when residual < peak)"),
        Field("tensile_strength", "float", 0.0, unit="stress", lo=0.0, doc="tensile strength of the interfaces"),
        Field("tension_cutoff", "bool", None, doc="crack interfaces in tension beyond the strength (default: c > 0)"),
    ),
    "water": (
        Field("ru", "float", 0.0, lo=0.0, hi=0.99, doc="pore pressure ratio r_u"),
        Field("ru_mode", "str", "standard", choices=("standard", "listing"),
              doc="standard: u = r_u*sigma_v; listing: sigma'_n = (1 - r_u) sigma_n (thesis program)"),
        Field("piezometric", "points", None, unit="length", doc="piezometric line (x, y); u = gamma_w (y_p - y)"),
        Field("gamma_w", "float", None, unit="unit_weight", positive=True, doc="unit weight of water (default 9.81 kN/m^3)"),
    ),
    "surcharge": (
        Field("from", "float", unit="length", doc="left end x of the loaded strip"),
        Field("to", "float", unit="length", doc="right end x"),
        Field("q", "float", unit="stress", lo=0.0, doc="vertical pressure on the horizontal projection"),
    ),
    "loads": (
        Field("kh", "float", 0.0, lo=0.0, hi=1.0, doc="pseudo-static horizontal coefficient, towards the face"),
    ),
    "mesh": (
        Field("size", "float", None, unit="length", positive=True, doc="block size of the grid mesh"),
        Field("bottom", "float", None, unit="length", doc="elevation of the fixed base of the grid mesh"),
        Field("slices", "int", 20, lo=2, doc="number of slices above a prescribed surface"),
        Field("rows", "int", None, lo=1, doc="blocks per slice (default: about square blocks)"),
    ),
    "surface": (
        Field("type", "str", choices=("circle", "polyline", "critical"), doc="prescribed slip surface"),
        Field("centre", "pair", None, unit="length", doc="circle centre (x, y)"),
        Field("radius", "float", None, unit="length", positive=True, doc="circle radius"),
        Field("points", "points", None, unit="length", doc="polyline (x, y), x increasing"),
        Field("bottom", "float", None, unit="length", doc="critical: lowest elevation a circle may reach"),
    ),
    "analysis": (
        Field("steps", "int", 10, lo=1, hi=MAX_STEPS, doc="load increments to full load"),
        Field("tolerance", "float", 1e-3, positive=True, doc="convergence: max |dk_s|/k_s (current secant) within a step"),
        Field("max_iterations", "int", 200, lo=1, hi=MAX_ITERATIONS, doc="secant iterations per step at most"),
        Field("strength_reduction", "bool", False,
              doc="also find the factor on c' and tan(phi') at which the static solution fails"),
        Field("interfaces", "str", "linear", choices=("linear", "no-tension"),
              doc="linear: springs carry tension (thesis); no-tension: they open, partly or fully, and close again"),
    ),
}
ARRAY_TABLES = {"layer", "surcharge"}

_HEADER = re.compile(r"^\s*(\[\[?)\s*([A-Za-z0-9_.\-]+)\s*\]\]?\s*(#.*)?$")
_KEY = re.compile(r"^\s*([A-Za-z0-9_\-]+)\s*=")


class Locator:
    """Line numbers of tables and keys in TOML text (tomllib keeps no positions)."""

    def __init__(self, text: str, file: str):
        self.file, self.lines = file, text.splitlines()
        self.tables: dict[tuple, int] = {("", 0): 1}
        self.keys: dict[tuple, tuple[int, int]] = {}
        counts: dict[str, int] = {}
        current, depth = ("", 0), 0
        for no, line in enumerate(self.lines, start=1):
            if depth == 0:
                m = _HEADER.match(line)
                if m:
                    name = m.group(2)
                    idx = counts.get(name, -1) + 1 if m.group(1) == "[[" else 0
                    counts[name] = idx
                    current = (name, idx)
                    self.tables[current] = no
                    continue
                k = _KEY.match(line)
                if k:
                    self.keys[current + (k.group(1),)] = (no, k.start(1) + 1)
            depth = max(0, depth + _bracket_balance(line))

    def where(self, table: str, index: int, key: str | None) -> tuple[int, int, str]:
        if key is not None and (table, index, key) in self.keys:
            line, col = self.keys[(table, index, key)]
        else:
            line, col = self.tables.get((table, index), 1), 1
        text = self.lines[line - 1] if 0 < line <= len(self.lines) else ""
        return line, col, text

    def error(self, table: str, index: int, key: str | None, message: str, hint: str | None = None):
        line, col, text = self.where(table, index, key)
        name = table if table else ""
        if table in ARRAY_TABLES:
            name = f"{table}[{index + 1}]"
        field = ".".join(p for p in (name, key or "") if p) or "(file)"
        return SsdemInputError(message, self.file, line, field, text, col, hint)


def _bracket_balance(line: str) -> int:
    """Net '[' minus ']' of a line outside strings and comments."""
    depth, quote = 0, None
    for ch in line:
        if quote:
            if ch == quote:
                quote = None
        elif ch in "\"'":
            quote = ch
        elif ch == "#":
            break
        elif ch == "[":
            depth += 1
        elif ch == "]":
            depth -= 1
    # a table header "[x]" opens no value; only brackets after "key =" or inside an array count
    if "=" not in line and _HEADER.match(line):
        return 0
    return depth


def bind(loc: Locator, table: str, index: int, data: dict, fac: dict) -> dict:
    """Check `data` against SECTIONS[table]; return values converted to SI (None = not given)."""
    spec = {f.name: f for f in SECTIONS[table]}
    for key in data:
        if key not in spec and not (table == "" and key in SECTIONS):
            close = difflib.get_close_matches(key, list(spec), n=1)
            raise loc.error(table, index, key, "unknown key",
                            f"did you mean '{close[0]}'?" if close else f"known keys: {', '.join(spec)}")
    out = {}
    for f in spec.values():
        if f.name not in data:
            if f.default is REQUIRED:
                raise loc.error(table, index, None, f"missing required key '{f.name}'", f.doc)
            out[f.name] = f.default
            continue
        out[f.name] = _convert(loc, table, index, f, data[f.name], fac)
    return out


def _convert(loc, table, index, f: Field, v, fac):
    def bad(msg):
        return loc.error(table, index, f.name, msg, f.doc)
    scale = fac.get(f.unit, 1.0)
    if f.kind == "str":
        if not isinstance(v, str):
            raise bad("expected a string")
        if f.choices and v not in f.choices:
            raise bad(f"'{v}' is not one of {', '.join(f.choices)}")
        return v
    if f.kind == "bool":
        if not isinstance(v, bool):
            raise bad("expected true or false")
        return v
    if f.kind == "int":
        if isinstance(v, bool) or not isinstance(v, int):
            raise bad("expected an integer")
        _bounds(bad, f, v)
        return v
    if f.kind == "float":
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise bad("expected a finite number")
        _bounds(bad, f, v)
        if f.unit == "length" and abs(v) > MAX_COORD:
            raise bad(f"must be between -{MAX_COORD:g} and {MAX_COORD:g}, got {v}")
        return float(v) * scale
    if f.kind == "pair":
        if not (isinstance(v, list) and len(v) == 2 and all(_num(x) for x in v)):
            raise bad("expected [x, y]")
        _coords(bad, v)
        return [float(x) * scale for x in v]
    if f.kind == "points":
        if not (isinstance(v, list) and len(v) >= 2 and all(isinstance(p, list) and len(p) == 2 and all(_num(x) for x in p) for p in v)):
            raise bad("expected a list of at least two [x, y] points")
        for p in v:
            _coords(bad, p)
        xs = [p[0] for p in v]
        if any(b <= a for a, b in zip(xs[:-1], xs[1:])):
            raise bad("x must increase strictly from point to point (left to right)")
        scale = fac["length"]
        return [[float(p[0]) * scale, float(p[1]) * scale] for p in v]
    raise AssertionError(f.kind)


def _coords(bad, p) -> None:
    for x in p:
        if abs(x) > MAX_COORD:
            raise bad(f"coordinates must be between -{MAX_COORD:g} and {MAX_COORD:g}, got {x}")


def _num(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def _bounds(bad, f: Field, v) -> None:
    if f.positive and not v > 0:
        raise bad(f"must be > 0, got {v}")
    if f.lo is not None and v < f.lo:
        raise bad(f"must be >= {f.lo:g}, got {v}")
    if f.hi is not None and v > f.hi:
        raise bad(f"must be <= {f.hi:g}, got {v}")
