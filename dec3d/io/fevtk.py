"""VTK output of FE-block elements: one VTK_QUADRATIC_HEXAHEDRON cell (type 25) per 20-node
element (issue 12, "Output").

The element node order of ``feblocks.nodes`` (the corrected Table 1 of the FE-block text,
shared/seeds/ERRATA.md) is VTK's order for type 25, so the connectivity is written as it is.
Points are the element (master) nodes, each once, in ascending vertex row. Point data:
``displacement`` (the node's own, ``vertices.disp``: FE nodes are gridpoints, and in small strain
their positions stay put), ``velocity``, ``vertex_row``. Cell data: ``element_id``, ``block_id``,
``gauss`` (2 or 3 per direction), ``volume``, ``cmodel``, ``stress`` (tension positive, in VTK's
symmetric-tensor order XX YY ZZ XY YZ XZ like the zones of ``dec3d.io.vtk``: the volume-weighted
mean of the Gauss-point stresses, ``feblocks.stress``) and ``stress_gauss_mean`` (their plain
mean, same order; the hourglass rows of 2 x 2 x 2 elements are not stresses and are left out).
Same XML writer as ``dec3d.io.vtk`` (inline base64, deterministic bytes); meshio reads the cells
as ``hexahedron20``. ``block vtk`` writes this file beside its snapshot (``VtkSeries``).
"""
from __future__ import annotations

import os

import numpy as np

from dec3d.io.finite import require_finite
from dec3d.io.vtk import VTK_TENSOR_ORDER, _data_array

VTK_QUADRATIC_HEXAHEDRON = 25


def write_feblocks_vtu(model, path: str | os.PathLike) -> str:
    """Write the FE elements of the model (none: an empty grid); returns the path written."""
    path = os.fspath(path)
    v, b = model.vertices, model.blocks
    if "feblocks" in model.stores:
        es = model.store("feblocks")
        ne = es.n
        nodes = es["nodes"][:ne]
    else:
        es, ne, nodes = None, 0, np.zeros((0, 20), np.int64)
    used = np.unique(nodes.ravel())
    remap = np.full(v.n, -1, np.int64)
    remap[used] = np.arange(len(used))
    conn = remap[nodes].ravel() if ne else np.zeros(0, np.int64)
    pos = v["pos"][used]
    require_finite("Points", pos)
    disp = v["disp"][used]
    ind = "      "
    parts = ['<?xml version="1.0"?>\n',
             '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">\n',
             "  <UnstructuredGrid>\n",
             f'    <Piece NumberOfPoints="{len(used)}" NumberOfCells="{ne}">\n',
             '      <PointData Vectors="displacement">\n',
             _data_array("displacement", disp.reshape(-1, 3), ind + "  "),
             _data_array("velocity", v["velocity"][used].reshape(-1, 3), ind + "  "),
             _data_array("vertex_row", used.astype(np.int64), ind + "  "),
             "      </PointData>\n",
             '      <CellData Scalars="element_id">\n']
    if ne:
        nq = es["nq"][:ne].astype(np.int64)
        ng = nq ** 3
        gmean = np.array([es["gstress"][e, : ng[e]].mean(axis=0) for e in range(ne)])
        cell = {"element_id": es["id"][:ne], "block_id": b["id"][es["block"][:ne]], "gauss": es["nq"][:ne],
                "volume": es["volume"][:ne], "cmodel": es["cmodel"][:ne],
                "stress": es["stress"][:ne][:, VTK_TENSOR_ORDER], "stress_gauss_mean": gmean[:, VTK_TENSOR_ORDER]}
    else:
        cell = {"element_id": np.zeros(0, np.int64)}
    for key, arr in cell.items():
        parts.append(_data_array(key, arr, ind + "  "))
    parts += ["      </CellData>\n", "      <Points>\n",
              _data_array("Points", pos.reshape(-1, 3), ind + "  "),
              "      </Points>\n      <Cells>\n",
              _data_array("connectivity", conn.astype(np.int64), ind + "  "),
              _data_array("offsets", (20 * np.arange(1, ne + 1)).astype(np.int64), ind + "  "),
              _data_array("types", np.full(ne, VTK_QUADRATIC_HEXAHEDRON, np.uint8), ind + "  "),
              "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n"]
    with open(path, "w", encoding="utf-8", newline="\n") as fh:
        fh.write("".join(parts))
    return path
