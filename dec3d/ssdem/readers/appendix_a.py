"""The thesis's text input (Appendix A), read in its order, with each ambiguity settled.

Items, in order (numbers separated by spaces, tabs or commas, any line breaks):
  1  number of blocks n
  2  n block centroids: x y
  3  n blocks' vertices: x1 y1 x2 y2 x3 y3 x4 y4, counter-clockwise from the bottom-right
     corner, so side k joins vertex k and k+1: 0 right, 1 top, 2 left, 3 bottom
     (a triangle repeats a vertex: that side has zero length and no interface)
  4  n external forces: f_x f_y moment (at the centroid given in item 2)
  5  number of boundary (fixed) blocks nb
  6  nb centroids of the boundary blocks: x y
  7  c_peak phi_peak c_res phi_res (degrees; one set for the whole slope)
  8  n lines of spring constants per side: kn0 ks0 kn1 ks1 kn2 ks2 kn3 ks3
  9  n lines of side angles (degrees, normal from the x axis): a0 a1 a2 a3
  10 number of load increments ("iterations to full loading")
  11 displacement at peak strength (read and ignored: delta_peak = tau_p / k_s, ERRATA)
  12 displacement at the onset of residual strength delta_res
  13 pore pressure ratio r_u (applied as the listing did: sigma'_n = (1 - r_u) sigma_n)

Block numbers in messages count from 0, as the thesis's outputs do.  The resolutions
of the format's ambiguities are listed in docs/ssdem.md ("Appendix A").
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from .. import geometry
from ..model import Settings, Problem, find_interfaces, make_blocks
from ..units import factors
from . import DEFAULT_MAX_BLOCKS, read_text
from .errors import SsdemInputError
from .tomlspec import MAX_STEPS

SIDES = ("right", "top", "left", "bottom")
ANGLE_TOL = 2.0        # degrees: a side angle may differ this much from the geometry


class _Tokens:
    """Numbers of the file with their line and column."""

    def __init__(self, text: str, file: str):
        self.file, self.lines = file, text.splitlines()
        self.items: list[tuple[str, int, int]] = []
        for no, line in enumerate(self.lines, start=1):
            for m in re.finditer(r"[^\s,]+", line):
                self.items.append((m.group(0), no, m.start() + 1))
        self.pos = 0

    def error(self, message: str, field: str, at: int | None = None, hint: str | None = None):
        at = self.pos - 1 if at is None else at
        if 0 <= at < len(self.items):
            _, line, col = self.items[at]
        else:
            line, col = max(1, len(self.lines)), 1
        text = self.lines[line - 1] if 0 < line <= len(self.lines) else ""
        return SsdemInputError(message, self.file, line, field, text, col, hint)

    def number(self, field: str, integer: bool = False) -> float:
        if self.pos >= len(self.items):
            raise self.error("the file ends here, a value is missing", field, at=len(self.items),
                             hint="Appendix A lists 13 items in a fixed order; see docs/ssdem.md")
        tok = self.items[self.pos][0]
        self.pos += 1
        try:
            v = int(tok) if integer else float(tok)
        except ValueError:
            raise self.error(f"'{tok}' is not {'an integer' if integer else 'a number'}", field) from None
        if not np.isfinite(v):
            raise self.error(f"'{tok}' is not finite", field)
        return v

    def row(self, field: str, names: tuple[str, ...]) -> tuple[list[float], int]:
        start = self.pos
        return [self.number(f"{field}.{nm}") for nm in names], start


def read_appendix_a(path: str | Path, text: str | None = None, units: str = "kN-m",
                    tensile_strength: float | None = None, tol: float = 1e-3, max_iter: int = 200,
                    max_blocks: int = DEFAULT_MAX_BLOCKS):
    """Read an Appendix A file into a `Problem` (units: the file's force-length system).

    tensile_strength: None leaves the tension cut-off off, as the thesis program ran
    (its test is commented out); a value (file stress units) turns it on.
    """
    path = Path(path)
    text = read_text(path) if text is None else text
    tk = _Tokens(text, str(path))
    try:
        return _read(tk, path, units, tensile_strength, tol, max_iter, max_blocks)
    except SsdemInputError as exc:
        # in a file laid out one record per line, a value missing from (or added to) a
        # line shifts every later number, and the stream reading trips far below it:
        # name the line that does not hold its record instead
        defect = _layout_defect(tk)
        if defect is not None and defect.line <= exc.line:
            raise defect from None
        raise


def _records(n: int, nb_of):
    """(field, column names) of every record in the order of Appendix A, one per line."""
    yield "n_blocks", ("",)
    for i in range(n):
        yield f"centroid[{i}]", ("x", "y")
    for i in range(n):
        yield f"nodes[{i}]", ("x1", "y1", "x2", "y2", "x3", "y3", "x4", "y4")
    for i in range(n):
        yield f"force[{i}]", ("fx", "fy", "m")
    yield "n_boundary", ("",)
    for j in range(nb_of()):
        yield f"boundary[{j}]", ("x", "y")
    yield "strength", ("c_peak", "phi_peak", "c_res", "phi_res")
    names = tuple(f"{kind}_{s}" for s in SIDES for kind in ("kn", "ks"))
    for i in range(n):
        yield f"springs[{i}]", names
    for i in range(n):
        yield f"angles[{i}]", tuple(f"a_{s}" for s in SIDES)
    for name in ("iterations", "delta_peak", "delta_res", "ru"):
        yield name, ("",)


def _layout_defect(tk: _Tokens) -> SsdemInputError | None:
    """The line that holds more or fewer numbers than its record, when the file is laid
    out one record per line: either every other line holds exactly its record (a single
    defect, anywhere), or at least the first two lines did up to the first defect.
    None for a free layout or no defect."""
    lines: dict[int, list[int]] = {}
    for k, (_, line, _) in enumerate(tk.items):
        lines.setdefault(line, []).append(k)
    rows = sorted(lines.items())
    if len(rows) < 3:
        return None
    try:
        n = int(tk.items[0][0])
    except ValueError:
        return None
    if not 0 < n <= len(rows):
        return None
    nb: dict = {}
    try:
        at = 1 + 3 * n                                                   # the n_boundary line
        if at < len(rows) and len(rows[at][1]) == 1:
            nb["v"] = min(max(0, int(tk.items[rows[at][1][0]][0])), n)
    except ValueError:
        pass
    records = list(_records(n, lambda: nb.get("v", 0)))
    defects = [i for i, ((_, names), (_, idx)) in enumerate(zip(records, rows)) if len(idx) != len(names)]
    if not defects:
        return None
    first = defects[0]
    if not ((len(defects) == 1 and len(records) == len(rows)) or first >= 2):
        return None
    (field, names), (line, idx) = records[first], rows[first]
    text = tk.lines[line - 1]
    cols = "" if names == ("",) else f" ({' '.join(names)})"
    want = f"{len(names)} value{'s' if len(names) > 1 else ''}{cols}"
    hint = "each record of Appendix A is on a line of its own here"
    if len(idx) < len(names):
        last_tok, _, col = tk.items[idx[-1]]
        return SsdemInputError(f"line {line} holds {len(idx)} of the {want} of this record: "
                               f"{len(names) - len(idx)} missing", tk.file, line, field, text,
                               col + len(last_tok), hint)
    _, _, col = tk.items[idx[len(names)]]
    return SsdemInputError(f"line {line} holds {len(idx)} values, the record has {want}: "
                           f"{len(idx) - len(names)} extra", tk.file, line, field, text, col, hint)


def _read(tk: _Tokens, path: Path, units: str, tensile_strength, tol: float, max_iter: int, max_blocks: int):
    fac = factors(units)
    n = int(tk.number("n_blocks", integer=True))
    if n < 1:
        raise tk.error("must be at least 1", "n_blocks")
    if n > max_blocks:
        raise tk.error(f"{n} blocks is over the budget of {max_blocks} blocks "
                       f"(about {n * 31 / 1000 / 1024:.3g} GiB of memory)", "n_blocks",
                       hint="raise the budget with --max-blocks N if the machine can hold it")
    cen, cen_at = np.zeros((n, 2)), np.zeros(n, int)
    for i in range(n):
        vals, cen_at[i] = tk.row(f"centroid[{i}]", ("x", "y"))
        cen[i] = vals
    nodes, node_at = np.zeros((n, 4, 2)), np.zeros(n, int)
    for i in range(n):
        vals, node_at[i] = tk.row(f"nodes[{i}]", ("x1", "y1", "x2", "y2", "x3", "y3", "x4", "y4"))
        nodes[i] = np.reshape(vals, (4, 2))
    force = np.array([tk.row(f"force[{i}]", ("fx", "fy", "m"))[0] for i in range(n)])
    nb = int(tk.number("n_boundary", integer=True))
    if not 0 <= nb <= n:
        raise tk.error(f"must be between 0 and the number of blocks ({n})", "n_boundary")
    bcen = [tk.row(f"boundary[{j}]", ("x", "y")) for j in range(nb)]
    (c_p, phi_p, c_r, phi_r), st_at = tk.row("strength", ("c_peak", "phi_peak", "c_res", "phi_res"))
    for k, (nm, v) in enumerate(zip(("c_peak", "phi_peak", "c_res", "phi_res"), (c_p, phi_p, c_r, phi_r))):
        if v < 0 or (nm.startswith("phi") and v >= 90):
            raise tk.error("must be >= 0 (angles below 90 degrees)", f"strength.{nm}", at=st_at + k)
    spring_names = tuple(f"{kind}_{s}" for s in SIDES for kind in ("kn", "ks"))
    springs, spring_at = np.zeros((n, 4, 2)), np.zeros(n, int)
    for i in range(n):
        vals, spring_at[i] = tk.row(f"springs[{i}]", spring_names)
        for k, v in enumerate(vals):
            if v < 0:
                raise tk.error(f"negative stiffness {v}", f"springs[{i}].{spring_names[k]}", at=spring_at[i] + k)
        springs[i] = np.reshape(vals, (4, 2))
    angles, angle_at = np.zeros((n, 4)), np.zeros(n, int)
    for i in range(n):
        angles[i], angle_at[i] = tk.row(f"angles[{i}]", tuple(f"a_{s}" for s in SIDES))
    n_steps = int(tk.number("iterations", integer=True))
    if not 1 <= n_steps <= MAX_STEPS:
        raise tk.error(f"must be between 1 and {MAX_STEPS}, got {n_steps}", "iterations")
    tk.number("delta_peak")
    del_res = tk.number("delta_res")
    if del_res <= 0:
        raise tk.error("must be > 0", "delta_res")
    ru = tk.number("ru")
    if not 0 <= ru < 1:
        raise tk.error("must be in [0, 1)", "ru")
    if tk.pos < len(tk.items):
        raise tk.error("unexpected data after the last item (r_u)", "(end of file)", at=tk.pos)

    # geometry: drop repeated vertices, check orientation and convexity
    polys = []
    for i in range(n):
        p = nodes[i]
        d = np.roll(p, -1, axis=0) - p
        keep = np.hypot(d[:, 0], d[:, 1]) > 0
        if keep.sum() < 3:
            raise tk.error("a block needs at least three distinct vertices", f"nodes[{i}]", at=node_at[i])
        polys.append(p[keep])
    offsets = np.concatenate([[0], np.cumsum([len(p) for p in polys])])
    verts = np.concatenate(polys) * fac["length"]
    area, true_cen = geometry.polygon_area_centroid(verts, offsets)
    span = max(float(np.ptp(verts[:, 0])), float(np.ptp(verts[:, 1])), 1e-12)
    for i in np.flatnonzero(area <= 0):
        raise tk.error("vertices run clockwise or the block is degenerate (inverted block)", f"nodes[{i}]",
                       at=node_at[i], hint="list the corners counter-clockwise, starting at the bottom-right one")
    bad = geometry.convexity_defect(verts, offsets, 1e-9)
    for i in np.flatnonzero(bad):
        raise tk.error("the block is not convex (vertices out of order?)", f"nodes[{i}]", at=node_at[i])
    _check_angles(tk, nodes, angles, angle_at)
    ref = cen * fac["length"]
    notes = ["item 11 (displacement at peak) is ignored: delta_peak = tau_p / k_s per interface (ERRATA)"]
    for i in range(n):
        poly = verts[offsets[i]:offsets[i + 1]]
        if not _inside(poly, ref[i]):
            raise tk.error("the centroid lies outside its block", f"centroid[{i}]", at=cen_at[i])
        if np.hypot(*(ref[i] - true_cen[i])) > 0.01 * np.sqrt(area[i]):
            notes.append(f"block {i}: given centroid differs from the geometric one; loads and DOFs use the given point")
    for i, j in geometry.overlapping_pairs(verts, offsets, 1e-9 * span):
        raise tk.error(f"block {j} overlaps block {i}", f"nodes[{j}]", at=node_at[j])

    fixed = np.zeros(n, bool)
    for j, (xy, at) in enumerate(bcen):
        d = np.hypot(*(cen - np.asarray(xy)).T)
        k = int(np.argmin(d))
        if d[k] > 1e-3 * np.sqrt(area[k]) / fac["length"]:
            raise tk.error("matches no block centroid of item 2", f"boundary[{j}]", at=at)
        fixed[k] = True
    blocks = make_blocks(verts, offsets, fixed, force=force * np.array([fac["force"], fac["force"], fac["moment"]]), ref=ref)
    itf, same = find_interfaces(blocks)
    for i, j in same:
        raise tk.error(f"block {j} overlaps block {i} along an edge", f"nodes[{j}]", at=node_at[j])
    # side numbers refer to the vertices as typed; map compacted polygons back to them
    side_map = []
    for i in range(n):
        d = np.roll(nodes[i], -1, axis=0) - nodes[i]
        side_map.append(np.flatnonzero(np.hypot(d[:, 0], d[:, 1]) > 0))
    sa = np.array([side_map[a][s] for a, s in zip(itf.a, itf.side_a)], int)
    sb = np.array([side_map[b][s] for b, s in zip(itf.b, itf.side_b)], int)
    itf.side_a, itf.side_b = sa, sb
    kn_a, ks_a = springs[itf.a, sa, 0], springs[itf.a, sa, 1]
    kn_b, ks_b = springs[itf.b, sb, 0], springs[itf.b, sb, 1]
    # free-free: mean of the two sides' values; free-fixed: the free block's value (as the listing used)
    fa, fb = blocks.fixed[itf.a], blocks.fixed[itf.b]
    kn = np.where(fa, kn_b, np.where(fb, kn_a, 0.5 * (kn_a + kn_b)))
    ks = np.where(fa, ks_b, np.where(fb, ks_a, 0.5 * (ks_a + ks_b)))
    differ = ~fa & ~fb & ((np.abs(kn_a - kn_b) > 1e-9 * np.abs(kn_a + kn_b)) | (np.abs(ks_a - ks_b) > 1e-9 * np.abs(ks_a + ks_b)))
    if differ.any():
        notes.append(f"{int(differ.sum())} interfaces have different spring constants on their two sides; the mean is used")
    m = itf.m
    itf.kn, itf.ks = kn * fac["stiffness"], ks * fac["stiffness"]
    itf.c_p, itf.tan_p = np.full(m, c_p * fac["stress"]), np.full(m, np.tan(np.radians(phi_p)))
    itf.c_r, itf.tan_r = np.full(m, c_r * fac["stress"]), np.full(m, np.tan(np.radians(phi_r)))
    itf.del_res = np.full(m, del_res * fac["length"])
    itf.tensile = np.full(m, 0.0 if tensile_strength is None else tensile_strength * fac["stress"])
    itf.cutoff = np.full(m, tensile_strength is not None)
    itf.u_pore = np.zeros(m)
    itf.on_surface = np.zeros(m, bool)
    settings = Settings(n_steps=n_steps, tol=tol, max_iter=max_iter, ru=ru, ru_mode="listing")
    return Problem(title=path.name, blocks=blocks, interfaces=itf, settings=settings, source=str(path),
                   fmt="appendix-a", units=units, notes=notes)


def _inside(poly: np.ndarray, pt: np.ndarray) -> bool:
    e = np.roll(poly, -1, axis=0) - poly
    w = pt - poly
    cross = e[:, 0] * w[:, 1] - e[:, 1] * w[:, 0]
    return bool(np.all(cross >= -1e-12 * np.abs(e).max() * np.abs(w).max()))


def _check_angles(tk: _Tokens, nodes: np.ndarray, angles: np.ndarray, angle_at: np.ndarray) -> None:
    """Item 9 must agree with every side's outward normal (either sense) within ANGLE_TOL."""
    d = np.roll(nodes, -1, axis=1) - nodes                     # (n, 4, 2) side vectors as typed
    theta = np.degrees(np.arctan2(-d[..., 0], d[..., 1]))       # outward normal (d_y, -d_x)
    diff = np.abs((angles - theta + 90.0) % 180.0 - 90.0)       # modulo 180: n and -n are one axis
    bad = (diff > ANGLE_TOL) & (np.hypot(d[..., 0], d[..., 1]) > 0)
    for i, s in zip(*np.nonzero(bad)):
        raise tk.error(f"{angles[i, s]:g} deg, but the {SIDES[s]} side's normal is at {theta[i, s] % 360:.1f} deg",
                       f"angles[{i}].a_{SIDES[s]}", at=int(angle_at[i]) + int(s),
                       hint="the angle is between the x axis and the side's normal")
