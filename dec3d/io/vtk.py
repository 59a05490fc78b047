"""VTK output of the blocks: ``.vtu`` snapshots and a ``.pvd`` time series.

Written by hand (XML UnstructuredGrid, inline base64 binary, UInt64 headers): small,
exact (floats go out bit for bit) and deterministic (the same model gives the same
bytes). Every live block is one VTK_POLYHEDRON cell (type 42) whose polygonal faces are
given in the classic ``faces`` / ``faceoffsets`` layout that VTK 8-9 and ParaView read.
Points are the vertex store's rows, in order.

Cell data: ``block_id``, ``group:<slot>`` (group code per slot, -1 none; names in the
field data array ``group_names``, index = code), ``density``, ``volume``, ``mass``,
``hidden``, ``leader_id``, ``kind``. Point data: ``displacement``, ``velocity``.
"""
from __future__ import annotations

import base64
import os
from xml.sax.saxutils import quoteattr

import numpy as np

from dec3d.geometry.mass import range_index

VTK_POLYHEDRON = 42
_TYPES = {np.dtype(np.float64): "Float64", np.dtype(np.float32): "Float32",
          np.dtype(np.int64): "Int64", np.dtype(np.int32): "Int32",
          np.dtype(np.uint8): "UInt8", np.dtype(np.int8): "Int8"}


def _data_array(name: str, arr: np.ndarray, indent: str) -> str:
    arr = np.ascontiguousarray(arr)
    if arr.dtype == np.bool_:
        arr = arr.astype(np.uint8)
    comps = 1 if arr.ndim == 1 else arr.shape[1]
    raw = arr.astype(arr.dtype.newbyteorder("<"), copy=False).tobytes()
    payload = base64.b64encode(np.uint64(len(raw)).astype("<u8").tobytes() + raw).decode("ascii")
    return (f'{indent}<DataArray type="{_TYPES[arr.dtype]}" Name={quoteattr(name)} '
            f'NumberOfComponents="{comps}" format="binary">\n{indent}  {payload}\n'
            f"{indent}</DataArray>\n")


def _string_array(name: str, values: list[str], indent: str) -> str:
    # VTK stores strings as NUL-terminated chars, one tuple per string
    raw = b"".join(v.encode("utf-8") + b"\0" for v in values)
    payload = base64.b64encode(np.uint64(len(raw)).astype("<u8").tobytes() + raw).decode("ascii")
    return (f'{indent}<Array type="String" Name={quoteattr(name)} '
            f'NumberOfTuples="{len(values)}" format="binary">\n{indent}  {payload}\n'
            f"{indent}</Array>\n")


def block_cells(model):
    """Connectivity, offsets, faces and faceoffsets arrays (int64) of every live block.

    The face stream of a cell is: number of faces, then per face its number of points
    and the point ids.
    """
    b, f = model.blocks, model.faces
    vcount = b["vert_count"]
    connectivity = range_index(b["vert_start"], vcount)
    offsets = np.cumsum(vcount)
    fcount = b["face_count"]
    frows = range_index(b["face_start"], fcount)
    nvert = f["nvert"][frows]
    loops = model.face_vertices["vertex"][range_index(f["vstart"][frows], nvert)]
    cell_of_face = np.repeat(np.arange(b.n), fcount)
    chunk = 1 + nvert
    before = np.cumsum(chunk) - chunk                  # stream length of earlier faces
    face_pos = before + cell_of_face + 1               # +1 per cell count entry so far
    stream = np.empty(int(chunk.sum()) + b.n, dtype=np.int64)
    first_face = np.cumsum(fcount) - fcount
    stream[face_pos[first_face] - 1] = fcount
    stream[face_pos] = nvert
    stream[range_index(face_pos + 1, nvert)] = loops
    faceoffsets = np.append(face_pos[first_face[1:]] - 1, stream.size) if b.n else np.zeros(0, np.int64)
    return connectivity, offsets, stream, faceoffsets.astype(np.int64)


def write_vtu(model, path: str | os.PathLike) -> str:
    """Write one snapshot of every live block; returns the path written."""
    path = os.fspath(path)
    b, v = model.blocks, model.vertices
    conn, offs, faces, faceoffs = block_cells(model)
    ind = "      "
    parts = ['<?xml version="1.0"?>\n',
             '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" '
             'header_type="UInt64">\n',
             '  <UnstructuredGrid>\n']
    names = list(model.groups.names)
    if names:
        parts += ["    <FieldData>\n", _string_array("group_names", names, ind), "    </FieldData>\n"]
    parts.append(f'    <Piece NumberOfPoints="{v.n}" NumberOfCells="{b.n}">\n')
    parts.append('      <PointData Vectors="displacement">\n')
    parts.append(_data_array("displacement", v["disp"], ind + "  "))
    parts.append(_data_array("velocity", v["velocity"], ind + "  "))
    parts.append("      </PointData>\n")
    parts.append('      <CellData Scalars="block_id">\n')
    leader = b["leader"]
    cell = {"block_id": b["id"], "density": b["density"], "volume": b["volume"],
            "mass": b["mass"], "hidden": b["hidden"],
            "leader_id": b["id"][leader] if b.n else b["id"], "kind": b["kind"]}
    for key, arr in cell.items():
        parts.append(_data_array(key, arr, ind + "  "))
    slots = model.groups.slot_names("blocks")
    g = b["group"]
    for col, slot in enumerate(slots):
        parts.append(_data_array(f"group:{slot}", g[:, col], ind + "  "))
    parts.append("      </CellData>\n")
    parts.append("      <Points>\n")
    parts.append(_data_array("Points", v["pos"], ind + "  "))
    parts.append("      </Points>\n      <Cells>\n")
    parts.append(_data_array("connectivity", conn, ind + "  "))
    parts.append(_data_array("offsets", offs, ind + "  "))
    parts.append(_data_array("types", np.full(b.n, VTK_POLYHEDRON, dtype=np.uint8), ind + "  "))
    parts.append(_data_array("faces", faces, ind + "  "))
    parts.append(_data_array("faceoffsets", faceoffs, ind + "  "))
    parts.append("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n")
    with open(path, "w", encoding="ascii", newline="\n") as fh:
        fh.write("".join(parts))
    return path


def write_pvd(path: str | os.PathLike, entries: list[tuple[float, str]]) -> str:
    """Write a ParaView collection: ``entries`` of (time [s], .vtu file) in order.

    File names are written relative to the .pvd's folder when they lie under it.
    """
    path = os.fspath(path)
    base = os.path.dirname(os.path.abspath(path))
    lines = ['<?xml version="1.0"?>\n',
             '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n',
             "  <Collection>\n"]
    for t, f in entries:
        rel = os.path.relpath(os.path.abspath(f), base)
        lines.append(f'    <DataSet timestep="{float(t)!r}" group="" part="0" file={quoteattr(rel)}/>\n')
    lines.append("  </Collection>\n</VTKFile>\n")
    with open(path, "w", encoding="ascii", newline="\n") as fh:
        fh.write("".join(lines))
    return path


class VtkSeries:
    """A time series of snapshots ``<stem>_<nnnn>.vtu`` listed in ``<stem>.pvd``.

    ``write(model, time)`` adds one snapshot and rewrites the .pvd, so a run stopped at
    any point leaves a readable collection.
    """

    def __init__(self, stem: str | os.PathLike, guard=None):
        self.stem = os.fspath(stem)
        self.entries: list[tuple[float, str]] = []
        #: guard(file) -> file: checks each file before it is written (``Session.out_path``)
        self.guard = guard or (lambda f: f)

    @property
    def pvd_path(self) -> str:
        return self.stem + ".pvd"

    def write(self, model, time: float = 0.0) -> str:
        folder = os.path.dirname(self.stem)
        if folder:
            os.makedirs(folder, exist_ok=True)
        vtu = self.guard(f"{self.stem}_{len(self.entries):04d}.vtu")
        write_vtu(model, vtu)
        self.entries.append((float(time), vtu))
        write_pvd(self.guard(self.pvd_path), self.entries)
        return vtu


def request_vtk(model, stem: str, interval: int = 0, guard=None) -> None:
    """Ask for snapshots of ``model`` into the series ``stem`` (``<stem>_<nnnn>.vtu`` and
    ``<stem>.pvd``): one now, and every ``interval`` steps afterwards when interval > 0.
    Requests for the same stem continue its series. ``guard(file)`` checks each file before
    it is written (the session's output-folder rule)."""
    req = model.outputs.get("vtk")
    if req is None or req["series"].stem != stem:
        req = {"series": VtkSeries(stem, guard), "interval": 0, "last_step": None}
        model.outputs["vtk"] = req
    req["interval"] = int(interval)
    req["series"].write(model, model.time)
    req["last_step"] = model.step


def periodic_vtk(model) -> str | None:
    """For the engine, after each batch of steps: write a snapshot if ``interval`` steps
    have passed since the last one. Returns the file written, if any."""
    req = model.outputs.get("vtk")
    if not req or req["interval"] <= 0:
        return None
    if req["last_step"] is not None and model.step - req["last_step"] < req["interval"]:
        return None
    req["last_step"] = model.step
    return req["series"].write(model, model.time)


def stop_vtk(model) -> None:
    """``block vtk off``: no more periodic snapshots."""
    model.outputs.pop("vtk", None)
