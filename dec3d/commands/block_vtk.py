"""`block vtk`: VTK snapshots of the blocks, now and every N steps."""
from __future__ import annotations

from ..io.vtk import request_vtk, stop_vtk
from .registry import command
from .values import FLAG, Num, OutPath, P

STEM = OutPath(stem=True)


@command("block vtk", positional=[P("file", STEM, "file name stem in the output folder (default 'blocks')")],
         keywords=[P("filename", STEM, "same as the positional file name"),
                   P("interval", Num(integer=True, lo=0), "also write every this many steps (0: only now)",
                     default=0),
                   P("off", FLAG, "stop writing snapshots every N steps", bare=True),
                   P("contacts", FLAG, "also write the sub-contacts to `<file>_contacts_<nnnn>.vtu`", bare=True)],
         doc="Write the blocks to `<file>_<nnnn>.vtu` and list the snapshots in `<file>.pvd` (ParaView).",
         details="Each block is a polyhedron cell with its faces (cells ordered by vertex count, then block; "
                 "find a block by `block_id`). Cell data: block_id, group:<slot> (group codes; field data "
                 "`group_code:<name>` gives each name's code), density, volume, mass, hidden, leader_id, kind, "
                 "and the block's motion: displacement (of the centroid), velocity, spin, rotation (rotation "
                 "vector θn since the block was made, radians, from the best fit of its vertices) and "
                 "rotation_angle (θ). Point data: displacement (of each vertex since its block was made) and "
                 "velocity (v + ω × r of its block). The files open in ParaView, PyVista and meshio (meshio "
                 "reads no grid without cells). Relative names are written in the output folder. "
                 "With `interval n` a snapshot is also written every n steps while the model cycles. "
                 "Zoned blocks are written as their zones (tetra cells; quadratic tetra for 10-node zones) with "
                 "cell data zone_id, overlay (0/1: the two overlaid 5-tetrahedron sets of a hexahedral zone, -1 otherwise; "
                 "threshold on it to see one set), stress (XX YY ZZ XY YZ XZ, ParaView's tensor order), mean_stress, "
                 "principal_stress and von_mises, and gridpoint displacement and velocity as point data. When the "
                 "model has rigid blocks too, the zones go to `<file>_zones_<nnnn>.vtu` (part 1 of the same "
                 "time in the .pvd), since meshio reads no file mixing polyhedra with other cells. The elements of FE "
                 "blocks go to `<file>_fe_<nnnn>.vtu` (part 2): quadratic hexahedra (VTK 25) with point data "
                 "displacement, velocity and vertex_row, and cell data element_id, block_id, gauss, volume, "
                 "cmodel, stress (the element's volume-weighted mean of its Gauss-point stresses, XX YY ZZ XY "
                 "YZ XZ) and stress_gauss_mean. With `contacts`, each "
                 "snapshot also writes the sub-contacts (rigid and deformable contacts) as points to "
                 "`<file>_contacts_<nnnn>.vtu`, the last part of the same time in the .pvd, with point data "
                 "contact_id, block_a, block_b, kind, area, state (joint-law bits: 1 failed, 2 slipping now, 4 open), "
                 "slip (1 where failed or slipping), normal, normal_force, normal_stress, shear_force, "
                 "shear_force_magnitude, normal_displacement, shear_displacement and shear_displacement_magnitude. "
                 "A model with cables (`structure cable create`) also gets `<file>_cables_<nnnn>.vtu` per snapshot: "
                 "one line cell per cable element with cell data element_id, cable_id, axial_force (N, tension "
                 "positive; colour by it), axial_stress, grout_force_a, grout_force_b, state, yield and slip, and "
                 "point data node_id, displacement, velocity and grouted (dec3d/io/cablevtk.py). "
                 "Zones also carry the plastic state as categories (cell data shear_now, tension_now, "
                 "shear_past, tension_past: 0/1; plastic_label: the state's code 0-15 whose text is line "
                 "`code` of field data plastic_labels, e.g. 'shear-n shear-p') and their stress averaged to "
                 "the gridpoints (point data stress_gp, volume-weighted, XX YY ZZ XY YZ XZ). Group names are "
                 "field data group_names (UTF-8 text, line i = code i). A model with contacts also gets "
                 "`<file>_joints_<nnnn>.vtu`, the joint planes: one quadrilateral per sub-contact on its "
                 "contact plane with the contact arrays above plus shear_stress, opening and (water) pressure "
                 "(dec3d/io/jointvtk.py). Every array: docs/outputs.md.",
         examples=["block vtk", "block vtk 'jointed' interval 100", "block vtk filename 'out/blocks'",
                   "block vtk 'stage1' contacts",
                   "block vtk off"])
def block_vtk(session, call):
    a = call.args
    if a["off"]:
        stop_vtk(session.model)
        return
    key = "filename" if a["filename"] else "file"
    name = a[key] or "blocks"
    where = call.locations.get(key, call.location)
    pvd = session.out_path(STEM.final(name), where)       # <stem>.pvd, checked; the stem is beside it
    # every snapshot file is checked too when it is written (a symlink may appear later)
    request_vtk(session.model, str(pvd.with_suffix("")), interval=a["interval"],
                guard=lambda f: str(session.out_path(f, where)), contacts=bool(a["contacts"]))
