"""The readable TOML slope input: profile, layers, water, surcharges, mesh, surface.

dec3d generates the block mesh from it (see mesh.py).  Field by field the format is
declared in tomlspec.SECTIONS and documented in docs/ssdem.md.  Every error names the
file, the line of the offending key and the field, e.g.

    slope.toml:14:1: error: field 'layer[2].kn': must be > 0, got -5.0
"""
from __future__ import annotations

import re
import tomllib
from pathlib import Path

import numpy as np

from .. import bishop
from ..build import from_slope
from ..mesh import MeshTooLarge
from ..model import Settings
from ..soil import Layer, Slope
from ..units import factors
from . import DEFAULT_MAX_BLOCKS, read_text
from .errors import SsdemInputError
from .tomlspec import MAX_NESTING, SECTIONS, Locator, bind


def _too_deep(text: str, path: Path) -> SsdemInputError | None:
    """Arrays or inline tables nested deeper than MAX_NESTING (tomllib would recurse
    without bound): an error at the line and column where the limit is passed.
    Brackets inside one-line strings and comments do not count."""
    depth = 0
    for no, line in enumerate(text.splitlines(), start=1):
        quote, escaped = None, False
        for i, ch in enumerate(line):
            if quote:
                if escaped:
                    escaped = False
                elif ch == "\\" and quote == '"':
                    escaped = True
                elif ch == quote:
                    quote = None
            elif ch in "'\"":
                quote = ch
            elif ch == "#":
                break
            elif ch in "[{":
                depth += 1
                if depth > MAX_NESTING:
                    return SsdemInputError(f"arrays or tables nested more than {MAX_NESTING} deep",
                                           str(path), no, "(syntax)", line, i + 1,
                                           "a slope input needs two levels: [[x, y], ...]")
            elif ch in "]}":
                depth = max(0, depth - 1)
    return None


def read_toml(path: str | Path, text: str | None = None, max_blocks: int = DEFAULT_MAX_BLOCKS, **_ignored):
    """Parse, validate and mesh a TOML slope file; returns a `Problem`.

    max_blocks: the block budget; a mesh estimated larger is refused before it is made.
    """
    path = Path(path)
    text = read_text(path) if text is None else text
    deep = _too_deep(text, path)
    if deep is not None:
        raise deep
    try:
        data = tomllib.loads(text)
    except RecursionError:
        raise SsdemInputError("arrays or tables nested too deeply", str(path), 1, "(syntax)") from None
    except tomllib.TOMLDecodeError as exc:
        m = re.search(r"line (\d+), column (\d+)", str(exc))
        line, col = (int(m.group(1)), int(m.group(2))) if m else (1, 1)
        lines = text.splitlines()
        src = lines[line - 1] if 0 < line <= len(lines) else ""
        raise SsdemInputError(f"TOML syntax: {exc}", path, line, "(syntax)", src, col) from None
    loc = Locator(text, str(path))
    top = bind(loc, "", 0, {k: v for k, v in data.items() if k not in SECTIONS or k == ""}, {})
    fac = factors(top["units"])
    sections = {}
    for name in SECTIONS:
        if not name:
            continue
        raw = data.get(name)
        if name in ("layer", "surcharge"):
            raw = [] if raw is None else raw
            if not isinstance(raw, list):
                raise loc.error(name, 0, None, f"use [[{name}]] (an array of tables)")
            sections[name] = [bind(loc, name, i, t, fac) for i, t in enumerate(raw)]
        else:
            if raw is not None and not isinstance(raw, dict):
                raise loc.error("", 0, name, f"'{name}' must be a table [{name}]")
            sections[name] = None if raw is None else bind(loc, name, 0, raw, fac)
    if sections["profile"] is None:
        raise loc.error("", 0, None, "missing table [profile]", "give the ground surface: [profile] points = [[x, y], ...]")
    if not sections["layer"]:
        raise loc.error("", 0, None, "no [[layer]] given", "at least one soil layer is needed")
    profile = np.array(sections["profile"]["points"])
    slope = Slope(profile=profile, layers=_layers(loc, sections["layer"], fac))
    _water(loc, slope, sections["water"], fac)
    for i, s in enumerate(sections["surcharge"]):
        if not s["to"] > s["from"]:
            raise loc.error("surcharge", i, "to", "must be larger than 'from'")
        slope.surcharges.append((s["from"], s["to"], s["q"]))
    if sections["loads"]:
        slope.kh = sections["loads"]["kh"]
    an = sections["analysis"] or bind(loc, "analysis", 0, {}, fac)
    settings = Settings(n_steps=an["steps"], tol=an["tolerance"], max_iter=an["max_iterations"],
                        ru=slope.ru, ru_mode=slope.ru_mode, strength_reduction=an["strength_reduction"],
                        interfaces=an["interfaces"])
    if an["interfaces"] == "no-tension":
        for i, lay in enumerate(slope.layers):
            if lay.tensile > 0:
                raise loc.error("layer", i, "tensile_strength", "no-tension interfaces carry no tension",
                                "give tensile_strength = 0, or interfaces = \"linear\" in [analysis]")
    mesh = sections["mesh"] or bind(loc, "mesh", 0, {}, fac)
    surface = _surface(loc, slope, sections["surface"], mesh)
    if surface is None:
        if mesh["size"] is None:
            raise loc.error("mesh", 0, None, "missing key 'size'", "a mesh without a prescribed [surface] needs a block size")
        if mesh["bottom"] is None:
            mesh["bottom"] = float(profile[:, 1].min() - np.ptp(profile[:, 1]))
    try:
        prob = from_slope(slope, mesh, surface, settings, title=top["title"], max_blocks=max_blocks)
    except MeshTooLarge as exc:
        raise loc.error("mesh", 0, exc.key, str(exc), "a coarser mesh, or raise the budget with --max-blocks N") from None
    except ValueError as exc:
        key = ("surface", "type") if surface is not None else ("mesh", "bottom")
        raise loc.error(key[0], 0, key[1], str(exc)) from None
    prob.source, prob.fmt, prob.units = str(path), "toml", top["units"]
    return prob


def _layers(loc: Locator, raw: list, fac: dict) -> list:
    layers = []
    for i, d in enumerate(raw):
        if i == 0 and d["top"] is not None:
            raise loc.error("layer", i, "top", "the first layer starts at the ground surface; give no 'top'")
        if i > 0 and d["top"] is None:
            raise loc.error("layer", i, None, "missing key 'top'", "layers after the first need their top boundary")
        c_res = d["c"] if d["c_res"] is None else d["c_res"]
        phi_res = d["phi"] if d["phi_res"] is None else d["phi_res"]
        if c_res > d["c"] or phi_res > d["phi"]:
            raise loc.error("layer", i, "c_res" if c_res > d["c"] else "phi_res", "residual strength above the peak")
        softens = c_res < d["c"] or phi_res < d["phi"]
        if softens and d["delta_res"] is None:
            raise loc.error("layer", i, None, "missing key 'delta_res'", "needed when the residual strength is below the peak")
        layers.append(Layer(
            name=d["name"] or f"layer{i + 1}", c=d["c"], phi=d["phi"], c_res=c_res, phi_res=phi_res,
            gamma=d["gamma"], kn=d["kn"], ks=d["ks"],
            delta_res=d["delta_res"] if d["delta_res"] is not None else np.inf,
            tensile=d["tensile_strength"],
            cutoff=(d["c"] > 0) if d["tension_cutoff"] is None else d["tension_cutoff"],
            top=None if d["top"] is None else np.array(d["top"])))
    return layers


def _water(loc: Locator, slope: Slope, w: dict | None, fac: dict) -> None:
    if not w:
        return
    if w["ru"] and w["piezometric"] is not None:
        raise loc.error("water", 0, "piezometric", "give either ru or a piezometric line, not both")
    if w["piezometric"] is not None and w["ru_mode"] != "standard":
        raise loc.error("water", 0, "ru_mode", "the listing's r_u mode does not apply to a piezometric line")
    slope.ru, slope.ru_mode = w["ru"], w["ru_mode"]
    if w["piezometric"] is not None:
        slope.piezometric = np.array(w["piezometric"])
    slope.gamma_w = w["gamma_w"] if w["gamma_w"] is not None else 9810.0


def _surface(loc: Locator, slope: Slope, s: dict | None, mesh: dict) -> dict | None:
    if s is None:
        return None
    kind = s["type"]
    if kind == "circle":
        for key in ("centre", "radius"):
            if s[key] is None:
                raise loc.error("surface", 0, None, f"missing key '{key}'", "a circle needs centre and radius")
        return dict(type="circle", centre=tuple(s["centre"]), radius=s["radius"])
    if kind == "polyline":
        if s["points"] is None:
            raise loc.error("surface", 0, None, "missing key 'points'", "a polyline surface needs its points")
        return dict(type="polyline", points=np.array(s["points"]))
    # critical: the minimum-FS circle of Bishop's simplified method
    found = bishop.search(slope, bottom=s["bottom"] if s["bottom"] is not None else mesh.get("bottom"))
    if found.get("centre") is None:
        raise loc.error("surface", 0, "type", "the circle search found no valid slip circle")
    return dict(type="circle", centre=tuple(found["centre"]), radius=found["radius"], search=found)
