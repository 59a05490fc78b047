"""DFN files: the Itasca-style text format, plain CSV, bootstrapped orientation lists, and VTK of disks.

Itasca text format (``fracture export``/``fracture import``, any extension but .csv). The Itasca
"DFN-Related File Formats" page specifies the data file; only its bootstrapped-distribution and
template parts could be read (docs corpus), so the disk line below is dec3d's reading and is NOT
confirmed against Itasca's own files. Its values follow the order of Itasca's FISH
``fracture.create(dfn, arr)`` disk format (confirmed): "disk", centre, diameter, dip, dip direction:

    ; header line (any text)
    disk <id> <x> <y> <z> <diameter> <dip> <dip-direction> [<set>]

Angles in degrees, the diameter in m (3DEC's fracture size). Separators may be spaces, tabs, commas
or semicolons; lines starting with ``;`` or ``#`` are comments; an empty line ends the data (as in
Itasca's bootstrapped file). ``fracture`` is accepted for ``disk``.

CSV (``.csv``): a header ``id,x,y,z,nx,ny,nz,radius,set`` (column order free; ``set`` optional);
the normal need not be unit nor upward (it is made so).

Bootstrapped orientation list (Itasca's format: one header line, then per line an id, the values of
the distribution and an optional last column, the quantity; an empty line ends it): dec3d reads
``id dip dip-direction [quantity]``, the quantity weighting the line (1 when absent). Itasca's own
example on that page has five columns and a "dip" of 242 under the header "id dip dipdir quant", which
matches neither its header nor its text, so lines of another shape are refused rather than guessed.

Every reader raises ``DfnFileError(line, message)``; the command adds the deck's file:line:column.
"""
from __future__ import annotations

import math
import os
import re

import numpy as np

from dec3d.io.finite import require_finite

_SPLIT = re.compile(r"[\s,;]+")
#: sides of the polygon a disk is written as in VTK
NGON = 24


class DfnFileError(ValueError):
    def __init__(self, line: int, message: str):
        super().__init__(f"line {line}: {message}" if line else message)
        self.line = line


def _num(tok: str, line: int, what: str) -> float:
    try:
        v = float(tok)
    except ValueError:
        raise DfnFileError(line, f"{what} `{tok[:40]}` is not a number") from None
    if not math.isfinite(v):
        raise DfnFileError(line, f"{what} is not finite")
    return v


def _rows(text: str, skip_header: bool):
    lines = text.splitlines()
    start = 1 if skip_header else 0
    for i in range(start, len(lines)):
        s = lines[i].strip()
        if not s:
            if i > start:
                return
            continue
        if s[0] in ";#":
            continue
        yield i + 1, [t for t in _SPLIT.split(s) if t]


def read_itasca(text: str):
    """(ids, centres, normals, radii, sets) of the disks of an Itasca-style text file."""
    ids, cen, dip, ddir, rad, sets = [], [], [], [], [], []
    for ln, t in _rows(text, skip_header=False):
        if t[0].lower() not in ("disk", "fracture"):
            raise DfnFileError(ln, f"expected `disk id x y z diameter dip dip-direction [set]`, got `{t[0][:40]}`")
        if len(t) not in (8, 9):
            raise DfnFileError(ln, f"a disk line has 7 or 8 values after the word, got {len(t) - 1}")
        v = [_num(x, ln, w) for x, w in zip(t[1:], ("id", "x", "y", "z", "diameter", "dip", "dip direction", "set"))]
        if not v[4] > 0:
            raise DfnFileError(ln, f"the diameter must be positive, got {v[4]:g}")
        if not 0 <= v[5] <= 90:
            raise DfnFileError(ln, f"the dip must be in [0, 90] degrees, got {v[5]:g}")
        ids.append(int(v[0]))
        cen.append(v[1:4])
        dip.append(math.radians(v[5]))
        ddir.append(math.radians(v[6]))
        rad.append(v[4] / 2)
        sets.append(int(v[7]) if len(v) > 7 else 1)
    if not ids:
        raise DfnFileError(0, "the file holds no disk")
    d, a = np.asarray(dip), np.asarray(ddir)
    n = np.column_stack([np.sin(d) * np.sin(a), np.sin(d) * np.cos(a), np.cos(d)])
    return np.asarray(ids), np.asarray(cen, float), n, np.asarray(rad), np.asarray(sets)


def write_itasca(path, ids, c, dip_deg, ddir_deg, radius, sets) -> str:
    path = os.fspath(path)
    require_finite("fracture centres", c)
    with open(path, "w", encoding="utf-8", newline="\n") as fh:
        fh.write("; dec3d DFN: disk id x y z diameter dip dip-direction set\n")
        for i in range(len(ids)):
            x, y, z = (float(v) for v in c[i])
            fh.write(f"disk {int(ids[i])} {x!r} {y!r} {z!r} {2 * float(radius[i])!r} "
                     f"{float(dip_deg[i])!r} {float(ddir_deg[i])!r} {int(sets[i])}\n")
    return path


_CSV_COLS = ("id", "x", "y", "z", "nx", "ny", "nz", "radius")


def read_csv(text: str):
    lines = text.splitlines()
    if not lines:
        raise DfnFileError(1, "the file is empty")
    head = [h.strip().lower() for h in lines[0].split(",")]
    missing = [c for c in _CSV_COLS if c not in head]
    if missing:
        raise DfnFileError(1, f"the header lacks the column(s) {', '.join(missing)} "
                              "(id,x,y,z,nx,ny,nz,radius[,set])")
    col = {h: i for i, h in enumerate(head)}
    out = {k: [] for k in (*_CSV_COLS, "set")}
    for i, s in enumerate(lines[1:], start=2):
        if not s.strip():
            continue
        t = [x.strip() for x in s.split(",")]
        if len(t) != len(head):
            raise DfnFileError(i, f"{len(t)} values for {len(head)} columns")
        for k in _CSV_COLS:
            out[k].append(_num(t[col[k]], i, k))
        out["set"].append(_num(t[col["set"]], i, "set") if "set" in col else 1)
        if not out["radius"][-1] > 0:
            raise DfnFileError(i, f"the radius must be positive, got {out['radius'][-1]:g}")
        if out["nx"][-1] ** 2 + out["ny"][-1] ** 2 + out["nz"][-1] ** 2 <= 0:
            raise DfnFileError(i, "the normal is zero")
    if not out["id"]:
        raise DfnFileError(0, "the file holds no fracture")
    c = np.column_stack([out["x"], out["y"], out["z"]])
    n = np.column_stack([out["nx"], out["ny"], out["nz"]])
    return (np.asarray(out["id"]).astype(np.int64), c, n, np.asarray(out["radius"]),
            np.asarray(out["set"]).astype(np.int64))


def write_csv(path, ids, c, n, radius, sets) -> str:
    path = os.fspath(path)
    require_finite("fracture centres", c)
    with open(path, "w", encoding="utf-8", newline="\n") as fh:
        fh.write("id,x,y,z,nx,ny,nz,radius,set\n")
        for i in range(len(ids)):
            vals = [*(float(v) for v in c[i]), *(float(v) for v in n[i]), float(radius[i])]
            fh.write(f"{int(ids[i])}," + ",".join(repr(v) for v in vals) + f",{int(sets[i])}\n")
    return path


def read_bootstrapped(text: str):
    """(dips, dip directions [rad], weights) of an Itasca bootstrapped orientation file."""
    dip, ddir, w = [], [], []
    for ln, t in _rows(text, skip_header=True):
        if len(t) not in (3, 4):
            raise DfnFileError(ln, f"expected `id dip dip-direction [quantity]`, got {len(t)} values")
        v = [_num(x, ln, k) for x, k in zip(t, ("id", "dip", "dip direction", "quantity"))]
        if not 0 <= v[1] <= 90:
            raise DfnFileError(ln, f"the dip must be in [0, 90] degrees, got {v[1]:g}")
        q = v[3] if len(v) > 3 else 1.0
        if not q > 0:
            raise DfnFileError(ln, f"the quantity must be positive, got {q:g}")
        dip.append(math.radians(v[1]))
        ddir.append(math.radians(v[2]))
        w.append(q)
    if not dip:
        raise DfnFileError(0, "the file holds no orientation")
    return dip, ddir, w


def write_vtu(path, ids, dfn, sets, c, n, radius, dip_deg, ddir_deg, sides: int = NGON, cluster=None) -> str:
    """Disks as ``sides``-gons (VTK_POLYGON), cell data fracture_id, dfn_id, set, radius, dip,
    dip_direction, cluster (−1: not computed), normal."""
    from dec3d.io.vtk import _data_array

    path = os.fspath(path)
    k = len(radius)
    require_finite("fracture centres", c)
    a = np.cross(np.where(np.abs(n[:, 2:3]) < 0.9, [[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]]), n)
    u = a / np.linalg.norm(a, axis=1)[:, None] if k else a
    w = np.cross(n, u)
    phi = 2 * np.pi * np.arange(sides) / sides
    pts = (c[:, None, :] + radius[:, None, None] * (np.cos(phi)[None, :, None] * u[:, None, :]
                                                    + np.sin(phi)[None, :, None] * w[:, None, :])).reshape(-1, 3)
    cell = {"fracture_id": np.asarray(ids, np.int64), "dfn_id": np.asarray(dfn, np.int64),
            "set": np.asarray(sets, np.int64), "radius": np.asarray(radius, float),
            "dip": np.asarray(dip_deg, float), "dip_direction": np.asarray(ddir_deg, float),
            "cluster": np.full(k, -1, np.int64) if cluster is None else np.asarray(cluster, np.int64)}
    ind = "        "
    parts = ['<?xml version="1.0"?>\n',
             '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">\n',
             '  <UnstructuredGrid>\n', f'    <Piece NumberOfPoints="{k * sides}" NumberOfCells="{k}">\n',
             '      <CellData Scalars="set">\n']
    for key, arr in cell.items():
        parts.append(_data_array(key, np.ascontiguousarray(arr), ind))
    parts.append(_data_array("normal", np.ascontiguousarray(n, float).reshape(k, 3), ind))
    parts.append("      </CellData>\n      <Points>\n")
    parts.append(_data_array("Points", np.ascontiguousarray(pts, dtype=np.float64).reshape(k * sides, 3), ind))
    parts.append("      </Points>\n      <Cells>\n")
    parts.append(_data_array("connectivity", np.arange(k * sides, dtype=np.int64), ind))
    parts.append(_data_array("offsets", np.arange(sides, sides * k + 1, sides, dtype=np.int64), ind))
    parts.append(_data_array("types", np.full(k, 7, dtype=np.uint8), ind))
    parts.append("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n")
    with open(path, "w", encoding="utf-8", newline="\n") as fh:
        fh.write("".join(parts))
    return path
