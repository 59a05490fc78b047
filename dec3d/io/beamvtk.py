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

from dec3d.io.cablevtk import write_line_vtu
from dec3d.io.finite import require_finite


def write_beams_vtu(model, path: str | os.PathLike) -> str:
    from dec3d.model.beams import beam_stores

    path = os.fspath(path)
    nodes, els = beam_stores(model)
    pts = nodes["pos"]
    require_finite("beam node positions", pts)
    fl = els["fl"]
    cell = {"element_id": els["id"].astype(np.int64), "beam_id": els["beam"].astype(np.int64),
            "axial_force": fl[:, 6], "torsion": fl[:, 9], "shear_y": fl[:, 1], "shear_z": fl[:, 2],
            "moment_y_1": fl[:, 4], "moment_z_1": fl[:, 5], "moment_y_2": fl[:, 10], "moment_z_2": fl[:, 11]}
    point = {"node_id": nodes["id"].astype(np.int64), "displacement": nodes["disp"], "rotation": nodes["rot"],
             "velocity": nodes["vel"], "linked": (nodes["host"] >= 0).astype(np.uint8)}
    return write_line_vtu(path, pts, els["na"], els["nb"], point, cell)
