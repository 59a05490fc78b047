"""VTK output of the sub-contacts: one ``.vtu`` of points (``block vtk … contacts``).

Every sub-contact of every live contact is a VTK_VERTEX cell (type 1) at its point on the
contact plane (``subcontacts.pos``), in sub-contact row order, so one file serves rigid and
deformable contacts alike (on a deformable contact the points are its gridpoint sub-contacts).
Point data, per sub-contact:

- ``contact_id`` (the contact's row), ``block_a`` / ``block_b`` (the two blocks' ids), ``kind``
  (0 A-vertex/B-face, 1 B-vertex/A-face, 2 edge-edge, 3 point), ``area`` [m²];
- ``state`` (the joint law's bits: 1 failed in the past, 2 slipping now, 4 open/tension), and
  ``slip`` = 1 where the sub-contact has failed or slips now (0 otherwise);
- ``normal`` (the contact's unit normal, A → B), ``normal_force`` [N, compression positive],
  ``normal_stress`` [Pa, Fⁿ/area], ``shear_force`` (vector on B) and ``shear_force_magnitude``,
  ``normal_displacement`` [m], ``shear_displacement`` (accumulated vector) and
  ``shear_displacement_magnitude`` [m];
- ``jmodel`` (the joint model's code) and each joint model's history entries under the names its
  kernel gives them (``HIST_NAMES`` of ``kernels/joints``), 0 on the sub-contacts of other models; a
  name an array above already has gets ``_history`` after it (softening-mohr's ``slip_history``).

Arrays are written like ``dec3d.io.vtk``'s (inline base64, numeric only), so ParaView, PyVista
and meshio read them; a model with no sub-contacts gives a valid file with no points."""
from __future__ import annotations

import os

import numpy as np

from dec3d.io.finite import require_finite
from dec3d.io.vtk import _data_array

VTK_VERTEX = 1
#: joint-law state bits that mean the sub-contact has slipped (failed in the past, slipping now);
#: the values of ``dec3d.kernels.joints._common.ST_FAILED | ST_SLIP``
_SLIP_BITS = 1 | 2


def contact_point_data(model) -> tuple[np.ndarray, dict]:
    """(points (n, 3), name -> array) for the sub-contacts of the live contacts."""
    stores = model.stores
    if "subcontacts" not in stores or "contacts" not in stores:
        return np.zeros((0, 3)), {}
    c, s = model.store("contacts"), model.store("subcontacts")
    # each contact's sub-contacts, through its CSR range (sub_start, sub_count)
    start, count = c["sub_start"], c["sub_count"]
    ci = np.repeat(np.arange(c.n), count)
    rows = (np.repeat(start - np.cumsum(count) + count, count) + np.arange(int(count.sum()))).astype(np.int64)
    area = s["area"][rows]
    fn = s["fn"][rows]
    with np.errstate(divide="ignore", invalid="ignore"):
        sn = np.where(area > 0.0, fn / np.where(area > 0.0, area, 1.0), 0.0)
    state = s["state"][rows].astype(np.int32)
    data = {
        "contact_id": ci.astype(np.int64), "block_a": c["ida"][ci].astype(np.int64),
        "block_b": c["idb"][ci].astype(np.int64), "kind": s["kind"][rows].astype(np.int32),
        "area": area, "state": state, "slip": ((state & _SLIP_BITS) != 0).astype(np.uint8),
        "normal": c["normal"][ci], "normal_force": fn, "normal_stress": sn,
        "shear_force": s["fs"][rows], "shear_force_magnitude": np.linalg.norm(s["fs"][rows], axis=1),
        "normal_displacement": s["un"][rows], "shear_displacement": s["us"][rows],
        "shear_displacement_magnitude": np.linalg.norm(s["us"][rows], axis=1),
        "jmodel": c["jmodel"][ci].astype(np.int32),
    }
    if "pp" in s:           # pore pressure [Pa] and its force on the faces [N] (physics.water)
        data["pore_pressure"] = s["pp"][rows]
        data["pore_force"] = s["ppf"][rows]
    if "flowzones" in model.stores and model.store("flowzones").n:
        # flow in the joints (physics.flownet): each contact's mean knot pressure [Pa], hydraulic aperture [m]
        # and flow rate per unit width [m²/s], on each of its sub-contacts
        from dec3d.io.flowvalues import contact_values

        fp, fa, fq = contact_values(model)
        data["flow_pressure"], data["hydraulic_aperture"], data["flow_rate"] = fp[ci], fa[ci], fq[ci]
    if "hist" in s:
        # a history entry named as an array above (softening-mohr's `slip`, its slip displacement) keeps the
        # array and is written as `<name>_history`
        for name, col in _joint_history(c["jmodel"][ci], s["hist"][rows]).items():
            data[name if name not in data else f"{name}_history"] = col
    return s["pos"][rows], data


def _joint_history(codes, hist) -> dict:
    """The joint models' history entries, one array per name (a name two models share is one)."""
    from dec3d.kernels.joints import MODELS
    out: dict = {}
    for k in MODELS:
        mine = codes == k.CODE
        if not k.NHIST or not mine.any():
            continue
        for j, name in enumerate(k.HIST_NAMES):
            col = out.setdefault(name, np.zeros(len(codes)))
            col[mine] = hist[mine, j]
    return out


def write_contacts_vtu(model, path: str | os.PathLike) -> str:
    """Write the sub-contacts of ``model`` to ``path`` (a .vtu of vertex cells); returns the path."""
    path = os.fspath(path)
    pts, data = contact_point_data(model)
    require_finite("sub-contact positions", pts)
    n = len(pts)
    ind = "      "
    parts = ['<?xml version="1.0"?>\n',
             '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" '
             'header_type="UInt64">\n',
             '  <UnstructuredGrid>\n',
             f'    <Piece NumberOfPoints="{n}" NumberOfCells="{n}">\n',
             '      <PointData Scalars="state">\n']
    for key, arr in data.items():
        parts.append(_data_array(key, np.ascontiguousarray(arr), ind + "  "))
    parts.append("      </PointData>\n      <Points>\n")
    parts.append(_data_array("Points", np.ascontiguousarray(pts, dtype=np.float64).reshape(n, 3), ind + "  "))
    parts.append("      </Points>\n      <Cells>\n")
    parts.append(_data_array("connectivity", np.arange(n, dtype=np.int64), ind + "  "))
    parts.append(_data_array("offsets", np.arange(1, n + 1, dtype=np.int64), ind + "  "))
    parts.append(_data_array("types", np.full(n, VTK_VERTEX, dtype=np.uint8), ind + "  "))
    parts.append("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n")
    with open(path, "w", encoding="utf-8", newline="\n") as fh:
        fh.write("".join(parts))
    return path
