"""VTK output of the blocks: ``.vtu`` snapshots and a ``.pvd`` time series.

Written by hand (XML UnstructuredGrid, inline base64 binary, UInt64 headers): small,
exact (floats go out bit for bit) and deterministic (the same model gives the same
bytes). Every live block is one VTK_POLYHEDRON cell (type 42) whose polygonal faces are
given in the classic ``faces`` / ``faceoffsets`` layout that VTK 8-9 and ParaView read.
Points are the vertex store's rows, in order; cells go by vertex count, then block row
(``cell_order``; find a block by the ``block_id`` cell array).

Cell data: ``block_id``, ``group:<slot>`` (group code per slot, -1 none), ``density``,
``volume``, ``mass``, ``hidden``, ``leader_id``, ``kind``, and the motion of each block:
``displacement`` (of its centroid), ``velocity``, ``spin``, ``rotation`` (rotation vector
since the block was made, radians) and ``rotation_angle`` (its length), as defined in
``dec3d.model.kinematics``. Point data: ``displacement`` (pos − origin of each vertex) and
``velocity`` (v + ω × r of its block). Field data: one ``group_code:<name>`` array per group
name holding its code. Scalar arrays carry no ``NumberOfComponents`` (VTK's default 1) and
every array is a numeric ``DataArray``, so VTK/ParaView, PyVista and meshio all read the files.

Zoned (deformable) blocks are written as their zones instead: VTK_TETRA cells (type 10), or
VTK_QUADRATIC_TETRA (24) for 10-node zones, whose node order (corners, then mid-edge nodes of
edges 01 12 20 03 13 23) is the zones store's. Zone cells follow the polyhedra, 4-node ones first,
each by zone row; they carry their block's cell data and ``zone_id`` (0 on polyhedra), ``overlay``
(0 or 1: which 5-tetrahedron set of a mixed-discretization hexahedron; -1 otherwise), ``stress``
(six components in VTK's symmetric-tensor order XX YY ZZ XY YZ XZ, tension positive),
``mean_stress``, ``principal_stress`` (ascending: most compressive first) and ``von_mises`` (zero on
polyhedra). Gridpoints' point data are their own displacement and velocity. meshio reads no file
mixing polyhedra with other cells, so a series snapshot of a model with both rigid blocks and zones
is two files: ``<stem>_<nnnn>.vtu`` (rigid blocks) and ``<stem>_zones_<nnnn>.vtu`` (zones), parts 0
and 1 of the same time in the .pvd. FE blocks are polyhedra of their triangulated surface here;
their 20-node elements go to ``<stem>_fe_<nnnn>.vtu`` (``dec3d.io.fevtk``), part 2.
"""
from __future__ import annotations

import base64
import os
from xml.sax.saxutils import quoteattr

import numpy as np

from dec3d.geometry.mass import range_index
from dec3d.io.finite import require_finite
from dec3d.model.kinematics import block_rotation, vertex_displacement, vertex_velocity
from dec3d.units import field_lines

VTK_POLYHEDRON = 42
VTK_TETRA = 10
VTK_QUADRATIC_TETRA = 24          # corners, then mid-edge nodes of edges 01 12 20 03 13 23 (the zones' order)
#: VTK's order of a symmetric tensor's six components (XX YY ZZ XY YZ XZ) as columns of ``zones.stress``
#: (xx yy zz xy xz yz)
VTK_TENSOR_ORDER = np.array([0, 1, 2, 3, 5, 4])
_TYPES = {np.dtype(np.float64): "Float64", np.dtype(np.float32): "Float32",
          np.dtype(np.int64): "Int64", np.dtype(np.int32): "Int32",
          np.dtype(np.uint8): "UInt8", np.dtype(np.int8): "Int8"}


#: component names written with the six-component stress arrays (VTK's ``ComponentName<i>`` attributes)
STRESS_NAMES = ("XX", "YY", "ZZ", "XY", "YZ", "XZ")
#: names of the plastic-state categories: ``plastic_label`` (= state & 15) indexes this list
PLASTIC_LABELS = tuple(" ".join(w for b, w in ((1, "shear-n"), (2, "tension-n"), (4, "shear-p"), (8, "tension-p"))
                                if code & b) or "none" for code in range(16))


def text_array(items) -> np.ndarray:
    """Strings as one UInt8 field array (UTF-8, one per line): meshio reads no String arrays, and
    ``bytes(a).decode().split("\\n")`` gives them back (``read_text_array``)."""
    return np.frombuffer("\n".join(items).encode("utf-8"), dtype=np.uint8).copy()


def read_text_array(arr) -> list[str]:
    """The strings of a ``text_array`` (as read back by meshio or PyVista)."""
    raw = bytes(np.asarray(arr, dtype=np.uint8).ravel())
    return raw.decode("utf-8").split("\n") if raw else []


def _data_array(name: str, arr: np.ndarray, indent: str, tuples: bool = False, components=None) -> str:
    require_finite(name, arr)
    arr = np.ascontiguousarray(arr)
    if arr.dtype == np.bool_:
        arr = arr.astype(np.uint8)
    # one component is VTK's default; meshio turns an explicit "1" into (n, 1) arrays that its
    # polyhedron reader cannot regroup
    comps = "" if arr.ndim == 1 else f'NumberOfComponents="{arr.shape[1]}" '
    if tuples:                          # field data arrays must say their length
        comps += f'NumberOfTuples="{arr.shape[0]}" '
    for i, cname in enumerate(components or ()):      # ParaView shows these in its component menu
        comps += f'ComponentName{i}="{cname}" '
    raw = arr.astype(arr.dtype.newbyteorder("<"), copy=False).tobytes()
    payload = base64.b64encode(np.uint64(len(raw)).astype("<u8").tobytes() + raw).decode("ascii")
    return (f'{indent}<DataArray type="{_TYPES[arr.dtype]}" Name={quoteattr(name)} '
            f'{comps}format="binary">\n{indent}  {payload}\n'
            f"{indent}</DataArray>\n")


def cell_order(model) -> np.ndarray:
    """Block rows in the order their cells are written: by vertex count, then by row.

    meshio's polyhedron reader gathers cells of equal vertex count into blocks in the order the
    counts first appear but hands out the cell data in ascending count order; cells already
    sorted by count keep both in step (and every reader sees the same cell order)."""
    return np.argsort(model.blocks["vert_count"], kind="stable")


def block_cells(model, rows=None):
    """Connectivity, offsets, faces and faceoffsets arrays (int64) of the blocks ``rows``
    (every live block, in row order, by default), one cell per block in that order.

    The face stream of a cell is: number of faces, then per face its number of points
    and the point ids.
    """
    b, f = model.blocks, model.faces
    rows = np.arange(b.n) if rows is None else np.asarray(rows, dtype=np.int64)
    ncell = rows.size
    vcount = b["vert_count"][rows]
    connectivity = range_index(b["vert_start"][rows], vcount)
    offsets = np.cumsum(vcount)
    fcount = b["face_count"][rows]
    frows = range_index(b["face_start"][rows], fcount)
    nvert = f["nvert"][frows]
    loops = model.face_vertices["vertex"][range_index(f["vstart"][frows], nvert)]
    cell_of_face = np.repeat(np.arange(ncell), fcount)
    chunk = 1 + nvert
    before = np.cumsum(chunk) - chunk                  # stream length of earlier faces
    face_pos = before + cell_of_face + 1               # +1 per cell count entry so far
    stream = np.empty(int(chunk.sum()) + ncell, dtype=np.int64)
    first_face = np.cumsum(fcount) - fcount
    stream[face_pos[first_face] - 1] = fcount
    stream[face_pos] = nvert
    stream[range_index(face_pos + 1, nvert)] = loops
    faceoffsets = np.append(face_pos[first_face[1:]] - 1, stream.size) if ncell else np.zeros(0, np.int64)
    return connectivity, offsets, stream, faceoffsets.astype(np.int64)


def mixed(model) -> bool:
    """True when the model has both zones and rigid (unzoned) blocks: meshio reads no file mixing
    polyhedron cells with others, so a snapshot of such a model is two files (``VtkSeries``)."""
    from dec3d.model.zones import has_zones
    if not has_zones(model):
        return False
    return bool(np.setdiff1d(np.arange(model.blocks.n), model.store("zones")["block"]).size)


def _zone_cells(model, cells: str):
    """Cells of a model with zones (``dec3d.model.zones``): the block rows written as polyhedra (the
    rigid ones, by ``cell_order``; none when ``cells`` is "zones"), the zone rows written (4-node
    zones, then 10-node ones, each by row; none when ``cells`` is "blocks"), their connectivity and
    VTK cell types."""
    b = model.blocks
    zs = model.store("zones")
    zoned = np.zeros(b.n, dtype=bool)
    zoned[zs["block"]] = True
    rigid = np.flatnonzero(~zoned) if cells != "zones" else np.zeros(0, np.int64)
    poly = rigid[np.argsort(b["vert_count"][rigid], kind="stable")]
    nn = zs["nnode"].astype(np.int64)
    zrows = (np.concatenate([np.flatnonzero(nn == 4), np.flatnonzero(nn == 10)]) if cells != "blocks"
             else np.zeros(0, np.int64))
    nz = nn[zrows]
    conn = zs["gp"][zrows][np.arange(10)[None, :] < nz[:, None]]      # row by row, the first nnode of each
    types = np.where(nz == 10, VTK_QUADRATIC_TETRA, VTK_TETRA).astype(np.uint8)
    return poly, zrows, conn, np.cumsum(nz), types


def _zone_cell_data(model, zrows, npoly: int) -> dict:
    """Cell arrays of the zones (zero on the polyhedron cells of rigid blocks): zone_id, overlay, the stress
    tensor in VTK's symmetric-tensor order, mean stress, principal stresses, von Mises stress and the
    plastic state bits (``zones.state``: 1 shear now, 2 tension now, 4 shear past, 8 tension past)."""
    from dec3d.model.zone_quality import mean_stress, principal_stresses, von_mises
    zs = model.store("zones")
    st = zs["stress"][zrows]

    def pad(a):
        out = np.zeros((npoly + len(zrows),) + a.shape[1:], dtype=a.dtype)
        out[npoly:] = a
        return out

    overlay = np.full(npoly + len(zrows), -1, dtype=np.int8)
    overlay[npoly:] = zs["overlay"][zrows]
    out = {"zone_id": pad(zs["id"][zrows]), "overlay": overlay, "stress": pad(st[:, VTK_TENSOR_ORDER]),
           "mean_stress": pad(mean_stress(st)), "principal_stress": pad(principal_stresses(st)),
           "von_mises": pad(von_mises(st)), "plastic_state": pad(zs["state"][zrows]),
           "cmodel": pad(zs["cmodel"][zrows])}
    state = zs["state"][zrows]
    # the plastic state as categories (3DEC's legend): one 0/1 array per bit, and the label code
    for bit, key in ((1, "shear_now"), (2, "tension_now"), (4, "shear_past"), (8, "tension_past")):
        out[key] = pad(((state & bit) != 0).astype(np.uint8))
    out["plastic_label"] = pad((state & 15).astype(np.uint8))
    out.update(_zone_history(zs, zrows, pad))
    return out


def gridpoint_stress(model, zrows) -> np.ndarray:
    """(number of vertices, 6) zone stress averaged to the gridpoints, xx yy zz xy xz yz (the zones
    store's order), each zone weighted by its volume over the zones ``zrows`` that use the point
    (every node of a 10-node zone); 0 at points of no zone."""
    zs = model.store("zones")
    nn = zs["nnode"][zrows].astype(np.int64)
    used = np.arange(10)[None, :] < nn[:, None]
    gp = zs["gp"][zrows][used]
    w = np.repeat(np.abs(zs["volume"][zrows]), nn)
    st = np.repeat(zs["stress"][zrows], nn, axis=0)
    n = model.vertices.n
    num = np.zeros((n, 6))
    np.add.at(num, gp, st * w[:, None])
    den = np.bincount(gp, weights=w, minlength=n)
    return np.where(den[:, None] > 0, num / np.where(den > 0, den, 1.0)[:, None], 0.0)


def _zone_history(zs, zrows, pad) -> dict:
    """The zone models' history entries as cell arrays named as each model names them
    (``HIST_NAMES`` of ``kernels/zmodels``), 0 on the cells of other models; a name two models
    share is one array."""
    from dec3d.kernels.zmodels import MODELS
    cm = zs["cmodel"][zrows]
    hist = zs["hist"][zrows]
    out: dict = {}
    for k in MODELS:
        mine = cm == k.CODE
        if not k.NHIST or not mine.any():
            continue
        for j, name in enumerate(k.HIST_NAMES):
            col = out.get(name)
            if col is None:
                col = out[name] = np.zeros(len(zrows))
            col[mine] = hist[mine, j]
    return {name: pad(col) for name, col in out.items()}


def write_vtu(model, path: str | os.PathLike, cells: str = "all", point_data: dict | None = None,
              field_data: dict | None = None) -> str:
    """Write one snapshot of every live block; returns the path written. ``point_data`` and
    ``field_data`` (name -> array) are extra arrays after the standard ones (eigenmode shapes).

    In a model with zones, ``cells`` picks what is written: "all" (rigid blocks as polyhedra and
    zones), "blocks" (the rigid blocks only) or "zones" (the zones only)."""
    path = os.fspath(path)
    text = vtu_text(model, cells, point_data, field_data)
    with open(path, "w", encoding="utf-8", newline="\n") as fh:
        fh.write(text)
    return path


def vtu_text(model, cells: str = "all", point_data: dict | None = None, field_data: dict | None = None) -> str:
    """The text of ``write_vtu``'s file (the pictures of ``dec3d.plot`` read it from memory)."""
    from dec3d.model.zones import has_zones
    b, v = model.blocks, model.vertices
    require_finite("Points", v["pos"])      # the fields below derive from it: name the source
    zoned = has_zones(model)
    if zoned:
        order, zrows, zconn, zoffs, ztypes = _zone_cells(model, cells)
        cell_rows = np.concatenate([order, model.store("zones")["block"][zrows]])
    else:
        order = cell_order(model)
        cell_rows = order
    conn, offs, faces, faceoffs = block_cells(model, order)
    types = np.full(len(order), VTK_POLYHEDRON, dtype=np.uint8)
    if zoned:
        conn = np.concatenate([conn, zconn])
        offs = np.concatenate([offs, (offs[-1] if len(offs) else 0) + zoffs])
        types = np.concatenate([types, ztypes])
        faceoffs = np.concatenate([faceoffs, np.full(len(zrows), -1, dtype=np.int64)])
    ncell = len(cell_rows)
    ind = "      "
    parts = ['<?xml version="1.0"?>\n',
             '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" '
             'header_type="UInt64">\n',
             '  <UnstructuredGrid>\n']
    names = list(model.groups.names)
    zones_here = zoned and len(zrows) > 0
    units = field_lines(model, ("displacement", "velocity", "density", "volume", "mass", "spin")
                        + (("stress_gp", "stress") if zones_here else ()))
    if names or field_data or zones_here or units:
        # a numeric array per name (code = its index): meshio reads no String arrays; the names again as
        # text (UTF-8 bytes, one per line, line i = code i) for labels
        parts.append("    <FieldData>\n")
        for code, gname in enumerate(names):
            parts.append(_data_array(f"group_code:{gname}", np.array([code], dtype=np.int32), ind,
                                     tuples=True))
        if names:
            parts.append(_data_array("group_names", text_array(names), ind, tuples=True))
        if zones_here:
            parts.append(_data_array("plastic_labels", text_array(PLASTIC_LABELS), ind, tuples=True))
        if units:           # only when the deck declares its units (`model configure units si`)
            parts.append(_data_array("units", text_array(units), ind, tuples=True))
        for key, arr in (field_data or {}).items():
            parts.append(_data_array(key, np.atleast_1d(np.asarray(arr)), ind, tuples=True))
        parts.append("    </FieldData>\n")
    parts.append(f'    <Piece NumberOfPoints="{v.n}" NumberOfCells="{ncell}">\n')
    parts.append('      <PointData Vectors="displacement">\n')
    disp, vel = vertex_displacement(model), vertex_velocity(model)
    if zoned or "feslave" in v:
        # gridpoints (zones, FE nodes) move on their own: their displacement and velocity are the vertex store's
        gp = v["zoned"]
        disp[gp], vel[gp] = v["disp"][gp], v["velocity"][gp]
    parts.append(_data_array("displacement", disp, ind + "  "))
    parts.append(_data_array("velocity", vel, ind + "  "))
    if zones_here:
        # zone stress averaged to the gridpoints (volume-weighted): smooth contours
        parts.append(_data_array("stress_gp", gridpoint_stress(model, zrows)[:, VTK_TENSOR_ORDER], ind + "  ",
                                 components=STRESS_NAMES))
    for key, arr in (point_data or {}).items():
        parts.append(_data_array(key, np.asarray(arr), ind + "  "))
    parts.append("      </PointData>\n")
    parts.append('      <CellData Scalars="block_id">\n')
    leader = b["leader"]
    rot = block_rotation(model)
    cell = {"block_id": b["id"], "density": b["density"], "volume": b["volume"],
            "mass": b["mass"], "hidden": b["hidden"],
            "leader_id": b["id"][leader] if b.n else b["id"], "kind": b["kind"],
            "displacement": b["disp"], "velocity": b["velocity"], "spin": b["spin"],
            "rotation": rot, "rotation_angle": np.linalg.norm(rot, axis=1)}
    for key, arr in cell.items():
        parts.append(_data_array(key, arr[cell_rows], ind + "  "))
    slots = model.groups.slot_names("blocks")
    g = b["group"][cell_rows]
    for col, slot in enumerate(slots):
        parts.append(_data_array(f"group:{slot}", g[:, col], ind + "  "))
    if zoned and len(zrows):
        for key, arr in _zone_cell_data(model, zrows, len(order)).items():
            parts.append(_data_array(key, arr, ind + "  ", components=STRESS_NAMES if key == "stress" else None))
    parts.append("      </CellData>\n")
    parts.append("      <Points>\n")
    parts.append(_data_array("Points", v["pos"], ind + "  "))
    parts.append("      </Points>\n      <Cells>\n")
    parts.append(_data_array("connectivity", conn, ind + "  "))
    parts.append(_data_array("offsets", offs, ind + "  "))
    parts.append(_data_array("types", types, ind + "  "))
    if len(order):
        parts.append(_data_array("faces", faces, ind + "  "))
        parts.append(_data_array("faceoffsets", faceoffs, ind + "  "))
    parts.append("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n")
    return "".join(parts)


def write_pvd(path: str | os.PathLike, entries: list[tuple]) -> str:
    """Write a ParaView collection: ``entries`` of (time [s], .vtu file[, part]) in order (part 0 by
    default; the zones of a mixed model are part 1 of the same time).

    File names are written relative to the .pvd's folder when they lie under it.
    """
    path = os.fspath(path)
    base = os.path.dirname(os.path.abspath(path))
    lines = ['<?xml version="1.0"?>\n',
             '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n',
             "  <Collection>\n"]
    for t, f, *part in entries:
        rel = os.path.relpath(os.path.abspath(f), base)
        lines.append(f'    <DataSet timestep="{float(t)!r}" group="" part="{int(part[0]) if part else 0}" '
                     f'file={quoteattr(rel)}/>\n')
    lines.append("  </Collection>\n</VTKFile>\n")
    with open(path, "w", encoding="utf-8", newline="\n") as fh:
        fh.write("".join(lines))
    return path


class VtkSeries:
    """A time series of snapshots ``<stem>_<nnnn>.vtu`` listed in ``<stem>.pvd``.

    ``write(model, time)`` adds one snapshot and rewrites the .pvd, so a run stopped at
    any point leaves a readable collection.
    """

    def __init__(self, stem: str | os.PathLike, guard=None):
        self.stem = os.fspath(stem)
        self.entries: list[tuple] = []
        self.count = 0                  # snapshots written
        #: also write the sub-contacts (``<stem>_contacts_<nnnn>.vtu``, the last part of each time)
        self.contacts = False
        #: guard(file) -> file: checks each file before it is written (``Session.out_path``)
        self.guard = guard or (lambda f: f)

    @property
    def pvd_path(self) -> str:
        return self.stem + ".pvd"

    def write(self, model, time: float = 0.0) -> str:
        folder = os.path.dirname(self.stem)
        if folder:
            os.makedirs(folder, exist_ok=True)
        k = self.count
        first = len(self.entries)          # this snapshot's entries start here
        vtu = self.guard(f"{self.stem}_{k:04d}.vtu")
        if mixed(model):
            # meshio reads no file mixing polyhedra with other cells: the zones go beside, as part 1
            zvtu = self.guard(f"{self.stem}_zones_{k:04d}.vtu")
            write_vtu(model, vtu, cells="blocks")
            write_vtu(model, zvtu, cells="zones")
            self.entries += [(float(time), vtu, 0), (float(time), zvtu, 1)]
        else:
            write_vtu(model, vtu)
            self.entries.append((float(time), vtu))
        if "feblocks" in model.stores and model.store("feblocks").n:
            # FE elements as quadratic hexahedra (VTK 25) beside, as part 2 (``dec3d.io.fevtk``)
            from dec3d.io.fevtk import write_feblocks_vtu
            fvtu = self.guard(f"{self.stem}_fe_{k:04d}.vtu")
            write_feblocks_vtu(model, fvtu)
            self.entries.append((float(time), fvtu, 2))
        if "cable_segments" in model.stores and model.store("cable_segments").n:
            # the cables as lines (``dec3d.io.cablevtk``): the part after the others of this time
            from dec3d.io.cablevtk import write_cables_vtu
            lvtu = self.guard(f"{self.stem}_cables_{k:04d}.vtu")
            write_cables_vtu(model, lvtu)
            part = 1 + max((e[2] if len(e) > 2 else 0) for e in self.entries[first:])
            self.entries.append((float(time), lvtu, part))
        if "beam_elements" in model.stores and model.store("beam_elements").n:
            # the beams as lines (``dec3d.io.beamvtk``)
            from dec3d.io.beamvtk import write_beams_vtu
            bvtu = self.guard(f"{self.stem}_beams_{k:04d}.vtu")
            write_beams_vtu(model, bvtu)
            part = 1 + max((e[2] if len(e) > 2 else 0) for e in self.entries[first:])
            self.entries.append((float(time), bvtu, part))
        if "liner_elements" in model.stores and model.store("liner_elements").n:
            # the liners as triangles (``dec3d.io.linervtk``)
            from dec3d.io.linervtk import write_liners_vtu
            nvtu = self.guard(f"{self.stem}_liners_{k:04d}.vtu")
            write_liners_vtu(model, nvtu)
            part = 1 + max((e[2] if len(e) > 2 else 0) for e in self.entries[first:])
            self.entries.append((float(time), nvtu, part))
        if self.contacts:
            # the sub-contacts as points (``dec3d.io.contactvtk``): the part after the others of this time
            from dec3d.io.contactvtk import write_contacts_vtu
            cvtu = self.guard(f"{self.stem}_contacts_{k:04d}.vtu")
            write_contacts_vtu(model, cvtu)
            part = 1 + max((e[2] if len(e) > 2 else 0) for e in self.entries[first:])
            self.entries.append((float(time), cvtu, part))
        from dec3d.io.jointvtk import has_joints, write_joints_vtu
        if has_joints(model):
            # the joints as planes (``dec3d.io.jointvtk``), always when there are contacts; the last part
            jvtu = self.guard(f"{self.stem}_joints_{k:04d}.vtu")
            write_joints_vtu(model, jvtu)
            part = 1 + max((e[2] if len(e) > 2 else 0) for e in self.entries[first:])
            self.entries.append((float(time), jvtu, part))
        self.count += 1
        write_pvd(self.guard(self.pvd_path), self.entries)
        return vtu


def request_vtk(model, stem: str, interval: int = 0, guard=None, contacts: bool = False) -> None:
    """Ask for snapshots of ``model`` into the series ``stem`` (``<stem>_<nnnn>.vtu`` and
    ``<stem>.pvd``): one now, and every ``interval`` steps afterwards when interval > 0.
    Requests for the same stem continue its series. ``guard(file)`` checks each file before
    it is written (the session's output-folder rule). ``contacts``: each snapshot also writes the
    sub-contacts (``dec3d.io.contactvtk``)."""
    req = model.outputs.get("vtk")
    if req is None or req["series"].stem != stem:
        req = {"series": VtkSeries(stem, guard), "interval": 0, "last_step": None}
        model.outputs["vtk"] = req
    req["interval"] = int(interval)
    req["series"].contacts = bool(contacts)
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
