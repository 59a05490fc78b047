"""`block vtk`: VTK snapshots of the blocks, now and every N steps."""
from __future__ import annotations

from pathlib import Path

from ..io.vtk import request_vtk, stop_vtk
from .registry import command
from .values import FLAG, Num, P, Text


@command("block vtk", positional=[P("file", Text(), "file name stem (default 'blocks')")],
         keywords=[P("filename", Text(), "same as the positional file name"),
                   P("interval", Num(integer=True, lo=0), "also write every this many steps (0: only now)",
                     default=0),
                   P("off", FLAG, "stop writing snapshots every N steps", bare=True)],
         doc="Write the blocks to `<file>_<nnnn>.vtu` and list the snapshots in `<file>.pvd` (ParaView).",
         details="Each block is a polyhedron cell with its faces (cells ordered by vertex count, then block; "
                 "find a block by `block_id`). Cell data: block_id, group:<slot> (group codes; field data "
                 "`group_code:<name>` gives each name's code), density, volume, mass, hidden, leader_id, kind, "
                 "and the block's motion: displacement (of the centroid), velocity, spin, rotation (rotation "
                 "vector θn since the block was made, radians, from the best fit of its vertices) and "
                 "rotation_angle (θ). Point data: displacement (of each vertex since its block was made) and "
                 "velocity (v + ω × r of its block). The files open in ParaView, PyVista and meshio (meshio "
                 "reads no grid without cells). Relative names are written in the output folder. "
                 "With `interval n` a snapshot is also written every n steps while the model cycles.",
         examples=["block vtk", "block vtk 'jointed' interval 100", "block vtk filename 'out/blocks'",
                   "block vtk off"])
def block_vtk(session, call):
    a = call.args
    if a["off"]:
        stop_vtk(session.model)
        return
    name = a["filename"] or a["file"] or "blocks"
    p = session.out_path(name)
    if p.suffix.lower() in (".vtu", ".pvd", ".vtk"):
        p = p.with_suffix("")
    request_vtk(session.model, str(Path(p)), interval=a["interval"])
