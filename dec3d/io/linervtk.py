"""VTK output of the liners: one ``.vtu`` of triangle cells (VTK_TRIANGLE, type 5), one per liner
element, written beside each ``block vtk`` snapshot of a model with liners as ``<stem>_liners_<nnnn>.vtu``.

Cell data, per element (``model.liner_output``: in the element's axes, per unit length):
``element_id``, ``liner_id``, ``N_xx``, ``N_yy``, ``N_xy`` [N/m, tension positive], ``M_xx``, ``M_yy``,
``M_xy`` [N·m/m], ``normal`` (the element's z axis). Point data, per node: ``node_id``,
``displacement``, ``rotation``, ``velocity``, ``coupled`` (0/1: coupled to a block), ``coupling_state``
(bit 0 the normal spring broke, bit 1 the shear spring slipped)."""
from __future__ import annotations

import os

import numpy as np

from dec3d.io.finite import require_finite
from dec3d.io.vtk import _data_array

VTK_TRIANGLE = 5


def write_liners_vtu(model, path: str | os.PathLike) -> str:
    from dec3d.model.liners import liner_stores
    from dec3d.model.liner_output import element_resultants

    path = os.fspath(path)
    nodes, els = liner_stores(model)
    pts = nodes["pos"]
    require_finite("liner node positions", pts)
    r = element_resultants(model)
    cell = {"element_id": els["id"].astype(np.int64), "liner_id": els["liner"].astype(np.int64)}
    for k, name in enumerate(("N_xx", "N_yy", "N_xy", "M_xx", "M_yy", "M_xy")):
        cell[name] = r[:, k]
    cell["normal"] = els["axes"][:, 2]
    point = {"displacement": nodes["disp"], "node_id": nodes["id"].astype(np.int64), "rotation": nodes["rot"],
             "velocity": nodes["vel"], "coupled": (nodes["host"] >= 0).astype(np.uint8),
             "coupling_state": nodes["cstate"].astype(np.uint8)}
    n, s = len(pts), els.n
    ind = "        "
    parts = ['<?xml version="1.0"?>\n',
             '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">\n',
             '  <UnstructuredGrid>\n', f'    <Piece NumberOfPoints="{n}" NumberOfCells="{s}">\n',
             '      <PointData Vectors="displacement">\n']
    for key, arr in point.items():
        parts.append(_data_array(key, np.ascontiguousarray(arr), ind))
    parts.append('      </PointData>\n      <CellData Scalars="M_xx">\n')
    for key, arr in cell.items():
        parts.append(_data_array(key, np.ascontiguousarray(arr), ind))
    parts.append("      </CellData>\n      <Points>\n")
    parts.append(_data_array("Points", np.ascontiguousarray(pts, dtype=np.float64).reshape(n, 3), ind))
    parts.append("      </Points>\n      <Cells>\n")
    parts.append(_data_array("connectivity", np.ascontiguousarray(els["nodes"], dtype=np.int64).ravel(), ind))
    parts.append(_data_array("offsets", np.arange(3, 3 * s + 1, 3, dtype=np.int64), ind))
    parts.append(_data_array("types", np.full(s, VTK_TRIANGLE, dtype=np.uint8), ind))
    parts.append("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n")
    with open(path, "w", encoding="utf-8", newline="\n") as fh:
        fh.write("".join(parts))
    return path
