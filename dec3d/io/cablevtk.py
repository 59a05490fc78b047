"""VTK output of the cables: one ``.vtu`` of line cells (VTK_LINE, type 3), one per cable element,
between the cable nodes (``dec3d.model.cables``). Written beside each ``block vtk`` snapshot of a model
with cables as ``<stem>_cables_<nnnn>.vtu`` (``dec3d.io.vtk.VtkSeries.write``), colour by
``axial_force`` in ParaView.

Cell data, per element: ``element_id``, ``cable_id``, ``axial_force`` [N, tension positive],
``axial_stress`` [Pa, force / cross-sectional area], ``grout_force_a``/``grout_force_b`` [N, on the
cable at each end, along the element a → b], ``state`` (bits: 1 yields in tension now, 2 in compression
now, 4 grout slips now, 8 yielded in the past, 16 grout slipped in the past, 32 ruptured), ``yield`` and
``slip`` (0/1, now), ``ruptured`` (0/1: broken at its ``tensile-failure-strain``, carries nothing). Point data, per node: ``node_id``, ``displacement``, ``velocity``, ``grouted`` (0/1: has a
host block). Arrays are written as ``dec3d.io.vtk``'s (inline base64)."""
from __future__ import annotations

import os

import numpy as np

from dec3d.io.finite import require_finite
from dec3d.io.vtk import _data_array

VTK_LINE = 3


def write_cables_vtu(model, path: str | os.PathLike) -> str:
    """Write the cables of ``model`` to ``path``; returns the path."""
    from dec3d.model.cables import cable_stores

    path = os.fspath(path)
    nodes, segs = cable_stores(model)
    pts = nodes["pos"]
    require_finite("cable node positions", pts)
    area = segs["prop"][:, 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        stress = np.where(area > 0, segs["fa"] / np.where(area > 0, area, 1.0), 0.0)
    state = segs["state"].astype(np.int32)
    cell = {"element_id": segs["id"].astype(np.int64), "cable_id": segs["cable"].astype(np.int64),
            "axial_force": segs["fa"], "axial_stress": stress, "grout_force_a": segs["gf"][:, 0],
            "grout_force_b": segs["gf"][:, 1], "state": state, "yield": ((state & 3) != 0).astype(np.uint8),
            "slip": ((state & 4) != 0).astype(np.uint8), "ruptured": ((state & 32) != 0).astype(np.uint8)}
    point = {"node_id": nodes["id"].astype(np.int64), "displacement": nodes["disp"], "velocity": nodes["vel"],
             "grouted": (nodes["host"] >= 0).astype(np.uint8)}
    return write_line_vtu(path, pts, segs["na"], segs["nb"], point, cell)


def write_line_vtu(path: str, pts, na, nb, point: dict, cell: dict) -> str:
    """A ``.vtu`` of line cells between points ``pts`` (rows ``na[i]`` – ``nb[i]``), with point and cell
    data arrays (the first of each is what ParaView colours by: displacement, axial force); cables and
    beams (``io.beamvtk``) write theirs with it."""
    return write_cells_vtu(path, pts, np.column_stack([na, nb]), VTK_LINE, point, cell, "axial_force")


def write_cells_vtu(path: str, pts, conn, vtk_type: int, point: dict, cell: dict, scalars: str) -> str:
    """A ``.vtu`` of cells of one VTK type, each of the points ``pts`` in a row of ``conn`` (s, k), with
    point and cell data arrays (displacement and ``scalars`` the ones ParaView colours by): the line
    cells of cables and beams, the triangles of liners (``io.linervtk``)."""
    conn = np.asarray(conn)
    n, s, k = len(pts), len(conn), conn.shape[1]
    ind = "        "
    parts = ['<?xml version="1.0"?>\n',
             '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">\n',
             '  <UnstructuredGrid>\n', f'    <Piece NumberOfPoints="{n}" NumberOfCells="{s}">\n',
             '      <PointData Vectors="displacement">\n']
    for key, arr in point.items():
        parts.append(_data_array(key, np.ascontiguousarray(arr), ind))
    parts.append(f'      </PointData>\n      <CellData Scalars="{scalars}">\n')
    for key, arr in cell.items():
        parts.append(_data_array(key, np.ascontiguousarray(arr), ind))
    parts.append("      </CellData>\n      <Points>\n")
    parts.append(_data_array("Points", np.ascontiguousarray(pts, dtype=np.float64).reshape(n, 3), ind))
    parts.append("      </Points>\n      <Cells>\n")
    parts.append(_data_array("connectivity", np.ascontiguousarray(conn, dtype=np.int64).ravel(), ind))
    parts.append(_data_array("offsets", np.arange(k, k * s + 1, k, dtype=np.int64), ind))
    parts.append(_data_array("types", np.full(s, vtk_type, dtype=np.uint8), ind))
    parts.append("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n")
    with open(path, "w", encoding="utf-8", newline="\n") as fh:
        fh.write("".join(parts))
    return path
