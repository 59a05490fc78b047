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
from dec3d.io.cablevtk import write_cells_vtu

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
    return write_cells_vtu(path, pts, els["nodes"], VTK_TRIANGLE, point, cell, "M_xx")
