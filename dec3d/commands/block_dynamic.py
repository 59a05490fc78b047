"""`block dynamic eigen modes <n>`: natural frequencies and mode shapes of rigid-block systems."""
from __future__ import annotations

from ..errors import CommandError
from ..io.vtk import write_vtu
from ..physics.eigen import EigenError, eigenmodes, vertex_mode_displacement
from ..units import paren
from .registry import command
from .values import Num, OutPath, P

MODES_FILE = OutPath(suffix=".vtu")


@command("block dynamic eigen modes",
         positional=[P("n", Num(integer=True, lo=1, hi=10000), "number of modes (lowest frequencies first)",
                       required=True)],
         keywords=[P("file", MODES_FILE, "VTK file of the mode shapes, in the output folder (dec3d; default "
                     "'eigen_modes.vtu')", default="eigen_modes.vtu")],
         doc="Work out the n lowest natural frequencies and mode shapes of the rigid blocks about their "
             "current state, list them and write the shapes to VTK.",
         details="Each body (a block, or joined blocks) has 6 degrees of freedom at its centroid; every closed "
                 "sub-contact (normal displacement at most the model tolerance) adds springs kn·area along the "
                 "contact normal and ks·area across it at the sub-contact's point, the mass matrix holds each "
                 "body's mass and full inertia tensor, and fixed velocity components are removed "
                 "(dec3d.physics.eigen). The generalised problem K φ = ω² M φ is solved with scipy (dense for up "
                 "to 600 free degrees of freedom, else sparse shift-invert). The frequencies f = ω/2π [Hz] and "
                 "periods are listed and go into the results as `eigen.f<i>` and `<file stem>.f<i>`; the VTK "
                 "file holds the blocks "
                 "with point arrays `mode_<i>` (vertex displacement u + θ × r, largest 1) and field arrays "
                 "`frequency` and `omega2`. The model is not changed. Zoned blocks are refused.",
         examples=["block dynamic eigen modes 8", "block dynamic eigen modes 3 file 'arch_modes.vtu'"])
def eigen_modes(session, call):
    n = int(call.args["n"])
    where = call.locations.get("file", call.location)
    path = session.out_path(MODES_FILE.final(call.args["file"]), where)
    try:
        modes = eigenmodes(session.model, n)
    except EigenError as exc:
        raise CommandError(str(exc.args[0]), call.location) from None
    session.write(f"eigenmodes of {len(modes.bodies)} bodies, {modes.ndof} free degrees of freedom")
    session.write(f"  mode  {'frequency' + paren(session, 'frequency'):>14}  {'period' + paren(session, 'time'):>14}")
    for i, f in enumerate(modes.frequencies, start=1):
        period = f"{1.0 / f:14.6g}" if f > 0 else "           inf"
        session.write(f"  {i:4d}  {f:14.6g}  {period}")
        session.results[f"eigen.f{i}"] = float(f)
        session.results[f"{path.stem}.f{i}"] = float(f)
    shapes = {f"mode_{i + 1}": vertex_mode_displacement(session.model, modes, i) for i in range(n)}
    write_vtu(session.model, path, point_data=shapes,
              field_data={"frequency": modes.frequencies, "omega2": modes.omega2})
    session.written.add(path)
    session.model.eigen_modes = modes


@command("block dynamic eigen setmode", accepts_anything=True,
         doc="Display-only in dec3d: 3DEC shows a mode shape; here every mode is in the VTK file of "
             "`block dynamic eigen modes` (point arrays `mode_<i>`). Accepted and skipped.",
         examples=["block dynamic eigen setmode", "block dyn eigen setm 2"])
def eigen_setmode(session, call):
    if getattr(session.model, "eigen_modes", None) is None:
        raise CommandError("no modes yet: run `block dynamic eigen modes <n>` first", call.location)
    session.write("notice: `block dynamic eigen setmode` is display-only: open the mode shapes "
                  "(point arrays mode_<i>) of the VTK file written by `block dynamic eigen modes`")


