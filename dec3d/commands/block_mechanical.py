"""`block mechanical damping`, `block fix|free`, `block initialize`: motion settings and conditions."""
from __future__ import annotations

import numpy as np

from ..errors import CommandError
from ..physics.dynamic import MAXWELL_MAX
from ..physics.rigid import engine, mech
from .registry import command
from .values import FLAG, Choice, Deferred, Num, Nums, P, ValueRangeError


_RAYLEIGH_FORMS = ("mass", "stiffness")


def _check_damping(call):
    from ..errors import BindError

    mode = call.args["mode"]
    where = call.locations.get("alpha", call.location)
    if call.args["form"] is not None and mode != "rayleigh":
        raise BindError(f"`{call.args['form']}` belongs to rayleigh damping, not {mode}",
                        call.locations.get("form", call.location))
    if mode == "maxwell":
        vals = call.args["alpha"]
        if not vals or len(vals) % 2:
            raise BindError("maxwell damping takes pairs: <peak fraction of critical damping> <its frequency [Hz]> "
                            f"…, one to {MAXWELL_MAX} of them", where)
        if not any(isinstance(v, Deferred) for v in vals):
            _maxwell(vals, where)
        return
    if mode == "rayleigh":
        if len(call.args["alpha"]) != 2:
            raise BindError("rayleigh damping takes two values: <fraction of critical damping> <frequency [Hz]>",
                            where)
        vals = call.args["alpha"]
        if not any(isinstance(v, Deferred) for v in vals):
            _rayleigh(vals, where)
        return
    if len(call.args["alpha"]) > 1:
        raise BindError(f"{mode} damping takes one value", where)
    if mode == "none" and call.args["alpha"]:
        raise BindError("`damping none` takes no value", where)
    if call.args["alpha"] and not isinstance(call.args["alpha"][0], Deferred):
        _alpha(mode, call.args["alpha"][0], where)      # an [expr] is checked when the command runs


#: local and combined damping remove the fraction α of the unbalanced force's power: α = 1 would stop
#: every motion, α < 0 feed energy in (3DEC theory Eq. 79: 0 ≤ α < 1); the global servo's target
#: ratio is any positive number
_ALPHA = {"local": Num(lo=0, hi=1, hi_open=True), "combined": Num(lo=0, hi=1, hi_open=True),
          "global": Num(lo=0, lo_open=True)}


def _rayleigh(vals, where) -> tuple[float, float]:
    """(fraction, frequency) of rayleigh damping: the fraction in [0, 1), the frequency ≥ 0 and > 0 when
    the fraction is (3DEC decks write `rayleigh 0 0` for no damping)."""
    from ..errors import BindError

    try:
        xi = Num(lo=0, hi=1, hi_open=True).convert(vals[0], where)
    except ValueRangeError as exc:
        raise exc.named("the fraction of critical damping") from None
    try:
        f = Num(lo=0).convert(vals[1], where)
    except ValueRangeError as exc:
        raise exc.named("the rayleigh frequency") from None
    if xi > 0 and f <= 0:
        raise BindError(f"rayleigh damping with fraction {xi:g} needs a frequency > 0 Hz, got {f:g}", where)
    return float(xi), float(f)


def _maxwell(vals, where) -> list[list[float]]:
    """[[ξᵢ, fᵢ], …] of maxwell damping: each peak fraction in [0, 0.5), each frequency > 0."""
    out = []
    for i in range(0, len(vals), 2):
        try:
            xi = Num(lo=0, hi=0.5, hi_open=True).convert(vals[i], where)
        except ValueRangeError as exc:
            raise exc.named(f"the peak fraction of maxwell component {i // 2 + 1}") from None
        try:
            f = Num(lo=0, lo_open=True).convert(vals[i + 1], where)
        except ValueRangeError as exc:
            raise exc.named(f"the frequency of maxwell component {i // 2 + 1}") from None
        out.append([float(xi), float(f)])
    return out


def _alpha(mode, value, where) -> float:
    rule = _ALPHA.get(mode, Num())
    try:
        return rule.convert(value, where)
    except ValueRangeError as exc:
        raise exc.named(f"{mode} damping") from None


@command("block mechanical damping",
         positional=[P("mode", Choice(("local", "global", "combined", "none", "rayleigh", "maxwell")),
                       "damping form", required=True),
                     P("alpha", Nums(0, 2 * MAXWELL_MAX), "coefficient α of local and combined damping, in [0, 1); "
                       "target ratio of global, > 0; rayleigh: fraction of critical damping and frequency [Hz]; "
                       "maxwell: pairs of peak fraction and its frequency [Hz]", default=()),
                     P("form", Choice(_RAYLEIGH_FORMS), "rayleigh only: the mass- or stiffness-proportional term "
                       "alone")],
         check=_check_damping,
         doc="Set the mechanical damping (default: local, α = 0.8, with density scaling).",
         details="`local [α]` (3DEC theory Eq. 79), `combined [α]` (Eq. 83: local damping on the velocity and "
                 "on the force rate), `global [ratio]` (adaptive global viscous damping, Cundall 1982: a servo "
                 "keeps the ratio of damping power to the rate of change of kinetic energy at 0.5 or the value "
                 "given), `none` (dynamic runs: no damping, no density scaling, full inertia with Euler's "
                 "equations), `rayleigh <fraction> <frequency> [mass|stiffness]` (Rayleigh damping C = αM + βK "
                 "with the damping ratio `fraction` least at `frequency` Hz: α = ξω, β = ξ/ω, ω = 2π f; one "
                 "term alone is doubled so that the ratio at f stays ξ; the mass term damps body and gridpoint "
                 "velocities, the stiffness term every sub-contact (rigid, zoned and FE sides), the zones (4-node, "
                 "hexahedral, 10-node) and the FE elements (damping stress β D ε̇), and lowers the time step; "
                 "real masses and full inertia, as with `none`; see dec3d.physics.dynamic). In dynamic mode "
                 "(`model dynamic active on`) only rayleigh and maxwell damping are applied. `maxwell ξ₁ f₁ "
                 "[ξ₂ f₂ …]` (up to four pairs): Maxwell components, each a spring 4ξᵢ K in series with a dashpot "
                 "of relaxation time 1/(2π fᵢ), in parallel with the zones' and FE elements' stiffness K, so "
                 "component i damps most, ξᵢ, at fᵢ and the total ratio is Σ 2ξᵢ (f/fᵢ)/(1 + (f/fᵢ)²), nearly "
                 "flat between the frequencies (dec3d's reading of the pairs; see dec3d.physics.dynamic); "
                 "contacts and rigid blocks are not damped by it; real masses; the time step is lowered by "
                 "√(1 + Σ 4ξᵢ).",
         examples=["block mechanical damping local 0.8", "block mechanical damping combined",
                   "block mechanical damping global", "block mechanical damping none",
                   "block mechanical damping rayleigh 0.05 10", "block mech damp rayleigh 0.06 10.87 mass",
                   "block mechanical damping rayleigh 0 0",
                   "block mech damp maxwell 0.0233 0.9970 0.0195 7.1172 0.0278 50.0027"])
def damping(session, call):
    s = mech(session.model)
    mode = call.args["mode"]
    where = call.locations.get("alpha", call.location)
    if mode == "rayleigh":
        xi, f = _rayleigh(call.args["alpha"], where)
        s["damping"] = mode
        s["rayleigh"] = [xi, f, call.args["form"] or "both"]
        return
    if mode == "maxwell":
        s["maxwell"] = _maxwell(call.args["alpha"], where)
        s["damping"] = mode
        return
    alpha = _alpha(mode, call.args["alpha"][0], where) if call.args["alpha"] else None
    s["damping"] = mode
    if mode in ("local", "combined"):
        s["alpha"] = alpha if alpha is not None else 0.8
    if mode == "global":
        s["servo"] = []
        s["servo_ratio"] = alpha if alpha is not None else 0.5


@command("block mechanical mass-scale",
         positional=[P("mode", Choice(("on", "off", "automatic", "body")),
                       "on (Eq. 87, in any run), off, automatic (the default: on unless damping is none, "
                       "by body in static runs), or body (on, by body stiffness, masses raised or lowered)")],
         keywords=[P("timestep", Num(lo=0, lo_open=True), "time step the scaled masses must allow", units="s"),
                   P("safety", Num(lo=0, lo_open=True, hi=1, hi_open=True),
                     "with body or automatic: ω_max Δt ≤ 2 × safety (default 0.5 for the automatic scaling, "
                     "with body 0.7 with local or combined damping, 0.8 with global)")],
         doc="Density (mass) scaling of the rigid blocks for static runs (3DEC theory, \"Mass (Density) Scaling\").",
         details="Default (`automatic`): \"Density scaling is the default mode for static analysis with 3DEC\" "
                 "(3DEC theory text, \"Mass (Density) Scaling\"), so a static run (damping local, combined or "
                 "global) scales and a run with damping none or rayleigh, or in dynamic mode, keeps the real "
                 "masses. With local or combined damping the default scales by body with the masses only raised "
                 "(the text: \"inertial densities may be increased\"; scaling \"is only effective ... if the "
                 "natural timesteps differ for different parts of the model\"): each body's inertial mass and "
                 "inertia are raised to m_i = max(m, R_t (Δt / 2s)²), I_i = max(I, R_r (Δt / 2s)²), R the "
                 "Gershgorin "
                 "row sums of the contact stiffness around its six degrees of freedom, Δt the step at which the "
                 "body of median m / R_t keeps its mass, s = `safety` (default 0.5 here). This bounds the largest "
                 "natural frequency by ω_max Δt ≤ 2s and brings every stiff or light body to the same critical "
                 "step, "
                 "so stacks and walls settle in fewer steps (dec3d's measurements: a 10-layer cube stack 7090 → "
                 "2520 steps, a 20-block column 3520 → 1110, the masonry-wall example 640 → 180), and no block is "
                 "lighter than it is. Within a run the step never grows (a block sliding or tipping off its "
                 "contacts would get ever longer steps) and falls only below 0.8× (the joint law takes velocity × "
                 "the current step). With global damping, and in models with zoned or FE blocks, the default is "
                 "Eq. (87) (with `body` and global damping a block that friction holds on an incline, and a wedge "
                 "at FS 1.27, slid off). `on`: each body's inertial "
                 "mass is raised to the smallest value stable at the time step by Eq. (87) (m_i = max(m, K (Δt / 2 "
                 "frac)²), K the sum of its contact stiffnesses; the inertia by the same ratio), the step Eq. (87) "
                 "for a body of median mass and stiffness or the value given — the default before session 7, and "
                 "on in every run, dynamic ones too. `timestep` alone turns scaling on with Eq. (87) at that step "
                 "(the partial scaling of a dynamic run). `body` (dec3d): every body gets the same critical step, "
                 "lighter bodies lowered as well (a 10-layer cube stack: 1690 steps; 740 with `damping global`). "
                 "With `body` the default s is 0.7 with local or combined damping (their sign rule lags at larger "
                 "steps: a rocking column failed to settle at 0.8) and 0.8 with global damping. With "
                 "`damping global` a fresh adaptive servo starts at what it aims for on the fastest mode the scaling "
                 "lets through (α_v = 2 · ratio · ω / π, ω = 2s/Δt) instead of 0.02/Δt: from the weak start a "
                 "10 × 10 × 5 m block set down on a 40° slope (gravity tilted), φ = 45°, slid 15–180 mm before "
                 "friction held it (s = 0.5–0.9); it now moves 0.1 mm. (An earlier report of 1.2 m on a rotated "
                 "incline was not re-run.) With full inertia (Euler's equations) the scaling ratio comes from the "
                 "smallest principal moment, so ω_max Δt ≤ 2s holds for flat blocks too. Gravity always keeps "
                 "the real "
                 "mass. By body, the masses are worked out from the geometry at each detection that changes a "
                 "contact and kept in the block store (fields scaled_mass, scaled_inertia), so a run split into "
                 "several commands (or saved and restored between them) takes exactly the steps of one run.",
         examples=["block mechanical mass-scale on", "block mechanical mass-scale off",
                   "block mechanical mass-scale on timestep 1e-4", "block mechanical mass-scale body",
                   "block mechanical mass-scale body safety 0.7", "block mechanical mass-scale automatic safety 0.6"])
def mass_scale(session, call):
    s = mech(session.model)
    mode = call.args["mode"]
    scaling = s["scaling"] if mode is None else {"body": "body", "automatic": "auto"}.get(mode, "eq87")
    if call.args["safety"] is not None and scaling == "eq87":
        raise CommandError("`safety` goes with `mass-scale body` or `automatic` (Eq. 87 scaling uses its frac)",
                           call.locations.get("safety", call.location))
    if mode is not None:
        s["mass_scale"] = {"automatic": "auto", "body": "on"}.get(mode, mode)
        s["scaling"] = scaling
    if call.args["safety"] is not None:
        s["safety"] = float(call.args["safety"])
    if call.args["timestep"] is not None:
        s["mass_scale"] = "on"
        s["scale_timestep"] = float(call.args["timestep"])


_BITS = {"velocity": 0b000111, "velocity-x": 1, "velocity-y": 2, "velocity-z": 4,
         "rotation": 0b111000, "rotation-x": 8, "rotation-y": 16, "rotation-z": 32}
_FIXKW = [P(k, FLAG, f"the {k} component(s)", bare=True) for k in _BITS]


def _bits(call):
    bits = 0
    for k, v in _BITS.items():
        if call.args[k.replace("-", "_")]:
            bits |= v
    return bits or 0b111111


@command("block fix", keywords=_FIXKW, range="block",
         doc="Fix velocity and/or rotation components of the blocks in range (all six when none is named).",
         examples=["block fix", "block fix velocity-z rotation range position-z -1 0"])
def block_fix(session, call):
    mask = session.range_mask(call, "block")
    b = session.model.blocks
    engine(session.model)
    bits = _bits(call)
    b["fixity"][mask] |= np.uint8(bits)
    for i in range(3):
        if bits & (1 << i):
            b["velocity"][mask, i] = 0.0
        if bits & (8 << i):
            b["spin"][mask, i] = 0.0


@command("block free", keywords=_FIXKW, range="block",
         doc="Free velocity and/or rotation components of the blocks in range (all six when none is named).",
         examples=["block free", "block free rotation"])
def block_free(session, call):
    mask = session.range_mask(call, "block")
    b = session.model.blocks
    b["fixity"][mask] &= np.uint8(~_bits(call) & 0xFF)


@command("block initialize", keywords=[P(k, Num(), f"initial {k}", units="m/s" if k.startswith("v") else "rad/s")
                                       for k in ("velocity-x", "velocity-y", "velocity-z",
                                                 "rvelocity-x", "rvelocity-y", "rvelocity-z")], range="block",
         doc="Set the velocity or angular velocity of the blocks in range.",
         examples=["block initialize velocity-z -1", "block initialize rvelocity-z 2"])
def block_initialize(session, call):
    mask = session.range_mask(call, "block")
    b = session.model.blocks
    for i, ax in enumerate("xyz"):
        if call.args[f"velocity_{ax}"] is not None:
            b["velocity"][mask, i] = call.args[f"velocity_{ax}"]
        if call.args[f"rvelocity_{ax}"] is not None:
            b["spin"][mask, i] = call.args[f"rvelocity_{ax}"]


@command("block mechanical timestep", positional=[P("dt", Num(lo=0), "fixed time step; 0 returns to Eq. (87)",
                                                    required=True, units="s")],
         doc="Force the time step (0: automatic, Eq. 87 with frac 0.1).",
         examples=["block mechanical timestep 1e-4", "block mechanical timestep 0"])
def timestep(session, call):
    mech(session.model)["timestep"] = float(call.args["dt"]) or None
