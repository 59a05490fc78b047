"""Discrete fracture networks (DFNs): the store of disk fractures and the JSON side of templates.

``fractures``  one row per disk fracture
    id ()       int64  fracture id, from 1 (``range id``)
    dfn ()      int64  id of the DFN it belongs to (``settings.fractures["dfns"]`` names it)
    set ()      int64  set id (the template's set id when generated; the CSV/DFN file's set column)
    center (3,) m      centre of the disk
    normal (3,) -      unit normal, upward (n_z ≥ 0; a vertical disk has n_z = 0 and n_y ≥ 0 or n_y = 0 < n_x)
    radius ()   m      radius of the disk (3DEC's fracture "size" is the diameter: 2 × radius)
    cluster ()  int64  connected cluster (``fracture intersections compute``; −1 before), from 0
    group (1,)  int32  group code

``model.settings.fractures`` (JSON, saved with the model): ``templates`` {name: spec}, ``dfns``
{str(id): name}, ``next_fracture`` (next fracture id), ``next_dfn`` (next DFN id).

Orientation: the upward normal of a plane of dip δ and dip direction α (clockwise from +y, z up)
is (sin δ sin α, sin δ cos α, cos δ) (``dec3d.geometry.planes.dip_normal``); back from a normal:
δ = acos n_z, α = atan2(n_x, n_y) mod 360°.
"""
from __future__ import annotations

import numpy as np

from .groups import group_field
from .store import Field, Store

STORE = "fractures"
_F = np.float64
_I = np.int64


def _fields() -> dict[str, Field]:
    return {"id": Field((), _I, 0), "dfn": Field((), _I, 0), "set": Field((), _I, 0),
            "center": Field((3,), _F, 0.0), "normal": Field((3,), _F, 0.0), "radius": Field((), _F, 0.0),
            "cluster": Field((), _I, -1), "group": group_field()}


def fracture_store(model) -> Store:
    """The fracture store of ``model`` (made empty on first use)."""
    if STORE not in model.stores:
        model.add_store(Store(STORE, _fields()))
    return model.stores[STORE]


def has_fractures(model) -> bool:
    return STORE in model.stores and model.stores[STORE].n > 0


def dfn_state(model) -> dict:
    """The JSON part: templates, DFN names, next ids (created on first use)."""
    d = model.settings.fractures
    d.setdefault("templates", {})
    d.setdefault("dfns", {})
    d.setdefault("next_fracture", 1)
    d.setdefault("next_dfn", 1)
    return d


def upward(normals: np.ndarray) -> np.ndarray:
    """Unit normals flipped to point up (n_z > 0; on n_z = 0, n_y > 0; on both 0, n_x > 0)."""
    n = np.array(normals, dtype=_F, copy=True).reshape(-1, 3)
    n /= np.linalg.norm(n, axis=1)[:, None]
    z, y, x = n[:, 2], n[:, 1], n[:, 0]
    flip = (z < 0) | ((z == 0) & ((y < 0) | ((y == 0) & (x < 0))))
    n[flip] *= -1.0
    return n


def normals_from_dips(dip, ddir) -> np.ndarray:
    """Upward unit normals (N, 3) from dips and dip directions in radians."""
    dip, ddir = np.asarray(dip, _F), np.asarray(ddir, _F)
    sd = np.sin(dip)
    return np.column_stack([sd * np.sin(ddir), sd * np.cos(ddir), np.cos(dip)])


def dips_from_normals(normals) -> tuple[np.ndarray, np.ndarray]:
    """Dips and dip directions (radians, dip in [0, π/2], dip direction in [0, 2π)) of normals."""
    n = upward(normals)
    dip = np.arccos(np.clip(n[:, 2], -1.0, 1.0))
    ddir = np.mod(np.arctan2(n[:, 0], n[:, 1]), 2 * np.pi)
    return dip, ddir


def dfn_id(model, name: str | None, create: bool) -> int | None:
    """The id of the DFN called ``name`` (None: a new one named ``dfn<id>``); None when unknown."""
    st = dfn_state(model)
    if name is not None:
        for k, v in st["dfns"].items():
            if v == name:
                return int(k)
        if not create:
            return None
    i = int(st["next_dfn"])
    st["next_dfn"] = i + 1
    st["dfns"][str(i)] = name if name is not None else f"dfn{i}"
    return i


def dfn_name(model, i: int) -> str:
    return dfn_state(model)["dfns"].get(str(int(i)), f"dfn{int(i)}")


def add_fractures(model, dfn: int, center, normal, radius, set_id) -> np.ndarray:
    """Append fractures to ``model``; returns their rows. Normals are made unit and upward."""
    fs = fracture_store(model)
    center = np.asarray(center, _F).reshape(-1, 3)
    k = len(center)
    st = dfn_state(model)
    sl = fs.append(k)
    rows = np.arange(sl.start, sl.stop, dtype=_I)
    first = int(st["next_fracture"])
    fs["id"][rows] = np.arange(first, first + k, dtype=_I)
    st["next_fracture"] = first + k
    fs["dfn"][rows] = int(dfn)
    fs["set"][rows] = np.broadcast_to(np.asarray(set_id, _I), (k,))
    fs["center"][rows] = center
    fs["normal"][rows] = upward(normal) if k else np.zeros((0, 3))
    fs["radius"][rows] = np.asarray(radius, _F)
    return rows


def select(model, dfn: int | None = None, mask=None) -> np.ndarray:
    """Rows of the fractures of DFN ``dfn`` (all DFNs: None) within ``mask``."""
    if STORE not in model.stores:
        return np.zeros(0, _I)
    fs = model.stores[STORE]
    sel = np.ones(fs.n, bool) if mask is None else np.asarray(mask, bool).copy()
    if dfn is not None:
        sel &= fs["dfn"] == int(dfn)
    return np.flatnonzero(sel)


def delete(model, rows) -> None:
    fs = fracture_store(model)
    keep = np.ones(fs.n, bool)
    keep[np.asarray(rows, _I)] = False
    fs.compact(keep)


def ensure_face_fields(model) -> None:
    """The face fields ``block cut dfn`` writes: ``jointset`` and ``fracture`` (−1: none)."""
    f = model.faces
    for key in ("jointset", "fracture"):
        if key not in f:
            f.add_field(key, Field((), _I, -1))
