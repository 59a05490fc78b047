"""VTK output of the joints as planes: one quadrilateral per sub-contact on its contact's plane.

3DEC draws the joints as the contact areas, coloured by normal or shear stress. dec3d keeps for
each sub-contact its point on the common plane, the plane's normal and its area (``subcontacts``);
the cell written for it is its share of the contact polygon when the contact's sub-contacts are the
corners of a convex polygon (rigid face-to-face contacts: the sub-contact, the midpoints of its two
edges and the centroid; these tile the contact area), else the square of its area on that plane,
centred at its point, with one side along the first in-plane axis (``plane_axes``).

Written beside each ``block vtk`` snapshot of a model that has sub-contacts as
``<stem>_joints_<nnnn>.vtu`` (VTK_QUAD cells, type 9). Cell data: every array of
``dec3d.io.contactvtk`` (contact_id, block_a, block_b, kind, area [m²], state, slip, normal,
normal_force [N], normal_stress [Pa, compression positive], shear_force [N], shear_force_magnitude,
normal_displacement [m], shear_displacement [m], shear_displacement_magnitude, jmodel and the joint
models' history entries), plus ``shear_stress`` [Pa, |Fˢ| / area], ``opening`` [m, the normal
displacement where it is positive (open), else 0] and, when the joints carry water,
``pressure`` [Pa]. Point data: none (the corners belong to one cell each)."""
from __future__ import annotations

import os

import numpy as np

from dec3d.io.contactvtk import contact_point_data
from dec3d.io.finite import require_finite
from dec3d.io.vtk import _data_array, text_array
from dec3d.units import field_lines

VTK_QUAD = 9


def plane_axes(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit in-plane axes (t1, t2) per unit normal, t1 ⟂ n from the global axis least along n,
    t2 = n × t1."""
    n = np.asarray(normal, dtype=np.float64).reshape(-1, 3)
    e = np.zeros_like(n)
    e[np.arange(len(n)), np.argmin(np.abs(n), axis=1)] = 1.0
    t1 = np.cross(n, e)
    ln = np.linalg.norm(t1, axis=1)
    t1 = t1 / np.where(ln > 0, ln, 1.0)[:, None]
    return t1, np.cross(n, t1)


def joint_polygons(model) -> tuple[np.ndarray, dict]:
    """(corners (4n, 3), cell arrays) for the n sub-contacts of the live contacts."""
    pts, data = contact_point_data(model)
    if not len(pts):
        return np.zeros((0, 3)), data
    area = data["area"]
    t1, t2 = plane_axes(data["normal"])
    h = 0.5 * np.sqrt(np.maximum(area, 0.0))[:, None]
    corners = np.stack([pts - h * t1 - h * t2, pts + h * t1 - h * t2, pts + h * t1 + h * t2,
                        pts - h * t1 + h * t2], axis=1)
    _tributary(pts, data["contact_id"], t1, t2, corners)
    corners = corners.reshape(-1, 3)
    with np.errstate(divide="ignore", invalid="ignore"):
        data["shear_stress"] = np.where(area > 0, data["shear_force_magnitude"] / np.where(area > 0, area, 1.0), 0.0)
    data["opening"] = np.maximum(data["normal_displacement"], 0.0)
    s = model.store("subcontacts")
    if "pp" in s:                             # water in the joints (physics.water): the pore pressure [Pa]
        data["pressure"] = _rows_of(model, s["pp"])
    return corners, data


def _tributary(pts, cid, t1, t2, corners) -> None:
    """Where the sub-contacts of a contact sit at the corners of a convex polygon on its plane (a face-to-face
    contact of rigid blocks), each gets its share of the polygon instead of a square: itself, the midpoint
    of the edge to the next corner, the polygon's centroid and the midpoint of the edge from the previous
    corner (the quadrilaterals tile the polygon). Two sub-contacts at one corner (a vertex of each block
    there) split that share along the corner-centroid diagonal. ``corners`` (n, 4, 3) is changed in place."""
    bounds = np.flatnonzero(np.diff(cid)) + 1
    for rows in np.split(np.arange(len(cid)), bounds):
        if len(rows) < 3:
            continue
        p = pts[rows]
        size = np.ptp(p, axis=0).max()
        if size <= 0:
            continue
        key = np.round((p - p.min(axis=0)) / (1e-7 * size)).astype(np.int64)
        uniq, first, which = np.unique(key, axis=0, return_index=True, return_inverse=True)
        which = which.ravel()
        if len(first) < 3 or np.bincount(which).max() > 2:
            continue
        q = p[first]
        c = q.mean(axis=0)
        u, v = (q - c) @ t1[rows[0]], (q - c) @ t2[rows[0]]
        order = np.argsort(np.arctan2(v, u))
        uv = np.column_stack([u, v])[order]
        nxt, prv = np.roll(uv, -1, axis=0), np.roll(uv, 1, axis=0)
        # convex with every point a corner: each turn goes the same way and is not straight
        cross = (uv[:, 0] - prv[:, 0]) * (nxt[:, 1] - uv[:, 1]) - (uv[:, 1] - prv[:, 1]) * (nxt[:, 0] - uv[:, 0])
        if not (cross > 1e-9 * size * size).all():
            continue
        qo = q[order]
        nxt_mid, prv_mid = 0.5 * (qo + np.roll(qo, -1, axis=0)), 0.5 * (qo + np.roll(qo, 1, axis=0))
        cc = np.broadcast_to(c, qo.shape)
        rank = np.empty(len(order), np.int64)
        rank[order] = np.arange(len(order))
        seen = np.zeros(len(first), np.int64)
        for k, r in enumerate(rows):
            j = rank[which[k]]
            if np.sum(which == which[k]) == 1:
                corners[r] = [qo[j], nxt_mid[j], cc[j], prv_mid[j]]
            elif seen[which[k]] == 0:
                corners[r] = [qo[j], nxt_mid[j], cc[j], cc[j]]
                seen[which[k]] = 1
            else:
                corners[r] = [qo[j], cc[j], prv_mid[j], prv_mid[j]]


def _rows_of(model, column: np.ndarray) -> np.ndarray:
    """A sub-contact column in the order of ``contact_point_data`` (each contact's CSR range)."""
    c = model.store("contacts")
    start, count = c["sub_start"], c["sub_count"]
    rows = (np.repeat(start - np.cumsum(count) + count, count) + np.arange(int(count.sum()))).astype(np.int64)
    return np.asarray(column)[rows]


def joints_vtu_text(model) -> str:
    corners, data = joint_polygons(model)
    require_finite("joint corners", corners)
    n = len(corners) // 4
    ind = "        "
    parts = ['<?xml version="1.0"?>\n',
             '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">\n',
             '  <UnstructuredGrid>\n']
    units = field_lines(model, data)
    if units:               # only when the deck declares its units (`model configure units si`)
        parts += ["    <FieldData>\n", _data_array("units", text_array(units), "      ", tuples=True),
                  "    </FieldData>\n"]
    parts += [f'    <Piece NumberOfPoints="{4 * n}" NumberOfCells="{n}">\n', '      <CellData Scalars="normal_stress">\n']
    for key, arr in data.items():
        parts.append(_data_array(key, np.ascontiguousarray(arr), ind))
    parts.append("      </CellData>\n      <Points>\n")
    parts.append(_data_array("Points", np.ascontiguousarray(corners, dtype=np.float64).reshape(-1, 3), ind))
    parts.append("      </Points>\n      <Cells>\n")
    parts.append(_data_array("connectivity", np.arange(4 * n, dtype=np.int64), ind))
    parts.append(_data_array("offsets", np.arange(4, 4 * n + 1, 4, dtype=np.int64), ind))
    parts.append(_data_array("types", np.full(n, VTK_QUAD, dtype=np.uint8), ind))
    parts.append("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n")
    return "".join(parts)


def has_joints(model) -> bool:
    return "contacts" in model.stores and "subcontacts" in model.stores and model.store("contacts").n > 0 \
        and int(model.store("contacts")["sub_count"].sum()) > 0


def write_joints_vtu(model, path: str | os.PathLike) -> str:
    """Write the joint planes of ``model`` to ``path``; returns the path."""
    path = os.fspath(path)
    text = joints_vtu_text(model)
    with open(path, "w", encoding="utf-8", newline="\n") as fh:
        fh.write(text)
    return path
