"""`model new|title|configure|large-strain|gravity`: model-wide settings."""
from __future__ import annotations

from ..errors import BindError
from ..units import NAMES as UNIT_SYSTEMS
from .registry import command
from .values import FLAG, ONOFF, Choice, Num, Nums, P, Text


@command("model new", keywords=[P("force", FLAG, "accepted for 3DEC compatibility (no prompt is ever shown)")],
         doc="Start a new model: every block, contact, setting, FISH variable and function is cleared.",
         examples=["model new"])
def model_new(session, call):
    session.new_model()


@command("model title", positional=[P("text", Text(), "the title; omitted clears it", default="")],
         doc="Set the model title (written into save files and VTK output).",
         examples=["model title 'Sliding wedge'", "model title"])
def model_title(session, call):
    session.model.settings.title = call.args["text"]


CONFIGURE_OPTIONS = ("dynamic", "fluid", "thermal", "highorder", "feblock", "creep")


def _check_configure(call):
    opt = call.args["option"]
    if opt != "threads" and call.args["n"] is not None:
        raise BindError(f"`model configure {opt}` takes no value",
                        call.locations.get("n", call.location))
    if (opt == "units") != (call.args["system"] is not None):
        raise BindError("`model configure units` needs the system: si or none" if opt == "units" else
                        f"`model configure {opt}` takes no unit system",
                        call.locations.get("system", call.locations.get("option", call.location)))


@command("model configure",
         positional=[P("option", Choice(CONFIGURE_OPTIONS + ("threads", "units")),
                       "process to enable, or `threads`, or `units`",
                       required=True),
                     P("n", Num(integer=True, lo=1), "with `threads`: the number of threads of the parallel kernels"),
                     P("system", Choice(UNIT_SYSTEMS), "with `units`: si (reports and VTK name SI units) or none "
                       "(no units shown, the default)")],
         check=_check_configure,
         doc="Enable an optional process or element type for the rest of the model's life; or set the number "
             "of threads the calculation uses.",
         details="Options: " + ", ".join(CONFIGURE_OPTIONS) + ". Each is recorded once, in the order given; "
                 "the engine reads them (dynamic: recorded only, dynamic mode is `model dynamic active on`; highorder: 10-node "
                 "tetrahedra; feblock: 20-node brick FE blocks; fluid: flow in the joints, every contact a flow "
                 "plane, on until `model fluid active off` — see `block fluid property`, `flowplane property`, "
                 "`flowknot apply`). `threads n` sets how many threads the parallel "
                 "kernels (contact forces, motion, point updates) use from now on, at most the number of cores "
                 "(numba's NUMBA_NUM_THREADS); `threads` alone prints the count. The environment variable "
                 "DEC3D_THREADS sets it when dec3d starts. It is a setting of the program, not of the model "
                 "(`model new` keeps it, save files do not hold it), and the results are bit-identical whatever "
                 "the count: every sum is taken in a fixed order. `units si` declares that the deck is in SI units "
                 "(m, kg, s, N, Pa): reports then name units (`axial (N)`, `Δt = 2e-05 s`) and VTK files carry a "
                 "`units` field-data array; without it (or after `units none`) quantities print without units, "
                 "since a deck may use any consistent system (kN, kPa, t/m³). A dec3d setting (3DEC has none), "
                 "saved with the model.",
         examples=["model configure dynamic", "model config dyn", "model configure highorder",
                   "model configure threads 2", "model configure threads",
                   "model configure units si"])
def model_configure(session, call):
    if call.args["option"] == "threads":
        from ..config import set_threads, thread_report
        from ..errors import CommandError

        n = call.args["n"]
        if n is not None:
            try:
                set_threads(int(n))
            except ValueError as exc:
                raise CommandError(str(exc), call.locations.get("n", call.location)) from None
        session.write(thread_report() + "\n")
        return
    if call.args["option"] == "units":
        sysname = call.args["system"]
        session.model.settings.units = "" if sysname == "none" else sysname
        return
    opts = session.model.settings.configure
    if call.args["option"] not in opts:
        opts.append(call.args["option"])


@command("model large-strain", positional=[P("mode", ONOFF, "on: update geometry as blocks move; off: small strain",
                                              required=True)],
         doc="Switch large-strain mode (geometry updated and new contacts detected as blocks move).",
         details="Rigid blocks in dec3d always move in large strain: their vertices, contacts and sub-contacts "
                 "are updated as they move whatever this setting says. For deformable (zoned) blocks and FE "
                 "blocks it matters: with `on` the gridpoints move with their displacements, zone strain rates "
                 "are taken on the current geometry, zone stresses turn with the material's spin, zone volumes "
                 "are updated after each run, and contacts are detected again as blocks move; with `off` (the "
                 "default) gridpoint positions stay where the zones were made (displacements are still "
                 "accumulated) and, in a model of deformable blocks only, contacts are not detected again while "
                 "cycling (nothing moves that could make one).",
         examples=["model large-strain on", "model large-strain off"])
def model_large_strain(session, call):
    session.model.settings.large_strain = call.args["mode"]


@command("model gravity", positional=[P("g", Nums(1, 3, counts=(1, 3)), "magnitude (acting in -z) or three components gx gy gz, m/s²",
                                        required=True, units="m/s²")],
         doc="Set the gravitational acceleration.",
         details="One value is a magnitude acting along -z (z is up in 3DEC 7+); three values are the components.",
         examples=["model gravity 0 0 -9.81", "model gravity 9.81", "model gravity (0,-9.81,0)"])
def model_gravity(session, call):
    g = call.args["g"]
    session.model.settings.gravity = (0.0, 0.0, -abs(g[0])) if len(g) == 1 else tuple(float(x) for x in g)
