"""VTK output of the beams: one ``.vtu`` of line cells (VTK_LINE), one per beam element, written beside
each ``block vtk`` snapshot of a model with beams as ``<stem>_beams_<nnnn>.vtu``.

Cell data, per element (forces and moments in the element's axes, as the nodes put them on it,
``dec3d.kernels.beam``): ``element_id``, ``beam_id``, ``axial_force`` [N, tension positive],
``torsion`` [N·m], ``shear_y``/``shear_z`` [N, at end 1], ``moment_y_1``, ``moment_z_1``,
``moment_y_2``, ``moment_z_2`` [N·m]. Point data, per node: ``node_id``, ``displacement``,
``rotation``, ``velocity``, ``linked`` (0/1: linked to a block)."""
from __future__ import annotations

import os

import numpy as np

from dec3d.io.finite import require_finite
from dec3d.io.vtk import _data_array

VTK_LINE = 3


def write_beams_vtu(model, path: str | os.PathLike) -> str:
    from dec3d.model.beams import beam_stores

    path = os.fspath(path)
    nodes, els = beam_stores(model)
    pts = nodes["pos"]
    require_finite("beam node positions", pts)
    n, s = nodes.n, els.n
    fl = els["fl"]
    cell = {"element_id": els["id"].astype(np.int64), "beam_id": els["beam"].astype(np.int64),
            "axial_force": fl[:, 6], "torsion": fl[:, 9], "shear_y": fl[:, 1], "shear_z": fl[:, 2],
            "moment_y_1": fl[:, 4], "moment_z_1": fl[:, 5], "moment_y_2": fl[:, 10], "moment_z_2": fl[:, 11]}
    point = {"node_id": nodes["id"].astype(np.int64), "displacement": nodes["disp"], "rotation": nodes["rot"],
             "velocity": nodes["vel"], "linked": (nodes["host"] >= 0).astype(np.uint8)}
    ind = "        "
    parts = ['<?xml version="1.0"?>\n',
             '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">\n',
             '  <UnstructuredGrid>\n', f'    <Piece NumberOfPoints="{n}" NumberOfCells="{s}">\n',
             '      <PointData Vectors="displacement">\n']
    for key, arr in point.items():
        parts.append(_data_array(key, np.ascontiguousarray(arr), ind))
    parts.append('      </PointData>\n      <CellData Scalars="axial_force">\n')
    for key, arr in cell.items():
        parts.append(_data_array(key, np.ascontiguousarray(arr), ind))
    parts.append("      </CellData>\n      <Points>\n")
    parts.append(_data_array("Points", np.ascontiguousarray(pts, dtype=np.float64).reshape(n, 3), ind))
    parts.append("      </Points>\n      <Cells>\n")
    conn = np.column_stack([els["na"], els["nb"]]).astype(np.int64).ravel()
    parts.append(_data_array("connectivity", conn, ind))
    parts.append(_data_array("offsets", np.arange(2, 2 * s + 1, 2, dtype=np.int64), ind))
    parts.append(_data_array("types", np.full(s, VTK_LINE, dtype=np.uint8), ind))
    parts.append("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n")
    with open(path, "w", encoding="utf-8", newline="\n") as fh:
        fh.write("".join(parts))
    return path
