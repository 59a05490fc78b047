"""Dynamic mode (`model dynamic`), Rayleigh damping and time functions of applied conditions.

Everything is kept in ``model.settings.mechanical`` (plain JSON, so `model save|restore` carries it):

- ``dynamic`` (bool) and ``dyn_time`` [s]: dynamic mode and the dynamic time, which runs on only while
  dynamic mode is on (Itasca, `model dynamic` command page: "time-total f: the accumulated dynamic time
  for the model. This can be reset to any value, and will continue to be accumulated during cycling").
  In dynamic mode the engine uses the real masses and full inertia (no density scaling of rigid blocks,
  zone gridpoints or FE nodes, unless `block mechanical mass-scale on` asks for it explicitly), the
  time step of the 3DEC theory text (Eqs. 84, 87, 88) without scaling, and only Rayleigh damping:
  the static forms (local, combined, adaptive global) are not applied in dynamic mode (dec3d follows
  the Itasca codes' rule that static damping is off in dynamic mode; `model dynamic list` says which
  damping is in effect).
- ``rayleigh``: [fraction ξ, frequency f [Hz], "both" | "mass" | "stiffness"] of `block mechanical
  damping rayleigh`. Rayleigh damping (Itasca 3DEC "Dynamic Analysis", Damping: C = α M + β K,
  Bathe and Wilson 1976) gives mode ω the damping ratio ξ(ω) = (α/ω + β ω)/2, least at
  ω_min = √(α/β) where it is ξ_min = √(αβ); with ξ_min = ξ and ω_min = 2π f:
  α = ξ ω_min [1/s], β = ξ / ω_min [s]. One term alone (`mass` or `stiffness`) is taken twice as
  large (α = 2ξω, or β = 2ξ/ω), so that the damping ratio at f is still ξ (dec3d's reading: the
  page could not be checked for this detail). The mass term is viscous damping of the body,
  gridpoint and node velocities (``kernels.motion`` mode 4, ``kernels.zonestep.gp_motion`` mode 4);
  the stiffness term acts on the sub-contacts (``kernels.rayleigh``: between rigid blocks, and
  where a zoned or FE block takes part, its share going to the gridpoints) and on the zones (4-node,
  hexahedral, 10-node) and FE elements as a damping stress β D ε̇ (``zone_stiffness_damping``). Stiffness damping lowers the stable step: Δt = Δt₀ (√(1 + λ²) − λ), λ = β / Δt₀ (the central-difference limit 2/ω (√(1 + ξ²) − ξ)
  for the highest mode Δt₀ allows, ω = 2/Δt₀, ξ = β ω / 2).
- ``maxwell``: [[ξ₁, f₁], [ξ₂, f₂], …] of `block mechanical damping maxwell ξ₁ f₁ ξ₂ f₂ …` (at most
  ``MAXWELL_MAX`` pairs). Maxwell damping (a generalized Maxwell body: springs in series with dashpots, in
  parallel with the elastic stiffness K) gives a damping ratio nearly constant over a band of
  frequencies. Component i is a spring α_i K in series with a dashpot of relaxation time τ_i; its force
  obeys dFᵢ/dt = αᵢ (−K v) − Fᵢ/τᵢ. For small αᵢ its damping ratio at frequency f is
  ξᵢ(f) = (αᵢ/2) r/(1 + r²), r = 2π f τᵢ, largest, αᵢ/4, at f = 1/(2π τᵢ). dec3d reads the pair (ξᵢ, fᵢ) as
  that peak ratio and its frequency: αᵢ = 4 ξᵢ, τᵢ = 1/(2π fᵢ), so the total ratio is about
  Σ 2ξᵢ (f/fᵢ)/(1 + (f/fᵢ)²); with the springs' stiffening of the storage part, half the loss factor
  (``maxwell_ratio``, within 2.5 % of the free-vibration root for the set below). (dec3d's reading, from
  the SAFEGO deck line `maxwell 0.0233 0.9970 0.0195 7.1172 0.0278 50.0027` commented "3 % Maxwell
  (1–50 Hz)": with it the ratio of a free vibration is 2.8–3.0 % over 1–50 Hz; Itasca's page on Maxwell
  damping was not within reach.) Applied to the zones (4-node,
  hexahedral, 10-node) and FE elements as nodal forces (``zone_maxwell_damping``: −K v is the same
  elastic-force rate the Rayleigh stiffness term uses, so for linear elastic material the forces equal
  those of Maxwell stresses σᵢ, dσᵢ/dt = αᵢ D ε̇ − σᵢ/τᵢ), integrated exactly over a step with v held:
  Fᵢ ← Fᵢ e^(−Δt/τᵢ) + αᵢ τᵢ (1 − e^(−Δt/τᵢ)) (−K v). The forces are state (``vertices.maxwell``,
  saved). Contacts and rigid blocks are not damped by it (the run warns). No mass term: real masses and
  full inertia. The spring stiffens the highest mode by at most (1 + Σ αᵢ): Δt = Δt₀ / √(1 + Σ αᵢ).
- ``timefns``: the time functions of `block apply … table|fish` and `block gridpoint apply … table|fish`
  (``TimeFunctions``).
"""
from __future__ import annotations

import math
from bisect import bisect_left

import numpy as np

from dec3d.errors import Dec3dError
from dec3d.io.state import register_known
from dec3d.units import suffix

#: the settings this module keeps, with their defaults (``rigid.MECH_DEFAULTS`` takes them over)
DYN_DEFAULTS = {"dynamic": False, "dyn_time": 0.0, "rayleigh": [], "maxwell": [], "timefns": []}
#: most components `block mechanical damping maxwell` takes (pairs ξ f)
MAXWELL_MAX = 4
RAYLEIGH_FORMS = ("both", "mass", "stiffness")


class TimeFunctionError(Dec3dError):
    """A time function cannot be evaluated while cycling (its table or FISH function is gone, or the
    value is not a finite number)."""


def _mech(model) -> dict:
    m = model.settings.mechanical
    for k, v in DYN_DEFAULTS.items():
        if k not in m:
            m[k] = list(v) if isinstance(v, list) else v
    return m


def is_dynamic(model) -> bool:
    return bool(_mech(model)["dynamic"])


def dynamic_time(model) -> float:
    return float(_mech(model)["dyn_time"])


def load_time(model) -> float:
    """The time of the time functions: the dynamic time in dynamic mode, else the model's time."""
    return dynamic_time(model) if is_dynamic(model) else float(model.time)


def rayleigh_coefficients(model) -> tuple[float, float]:
    """(α [1/s], β [s]) of the model's Rayleigh damping (0, 0 when it has none)."""
    r = _mech(model)["rayleigh"]
    if len(r) != 3:
        return 0.0, 0.0
    xi, f, form = float(r[0]), float(r[1]), r[2]
    if xi <= 0.0 or f <= 0.0:
        return 0.0, 0.0
    w = 2.0 * math.pi * f
    if form == "mass":
        return 2.0 * xi * w, 0.0
    if form == "stiffness":
        return 0.0, 2.0 * xi / w
    return xi * w, xi / w


def maxwell_components(model) -> list[tuple[float, float]]:
    """(αᵢ = 4 ξᵢ, τᵢ = 1/(2π fᵢ) [s]) of each Maxwell component in effect ([] unless the damping is
    maxwell; see the module text)."""
    m = _mech(model)
    if m["damping"] != "maxwell":
        return []
    return [(4.0 * float(xi), 1.0 / (2.0 * math.pi * float(f))) for xi, f in m.get("maxwell", []) if xi > 0]


def maxwell_timestep(dt0: float, comps) -> float:
    """Δt₀ lowered for the Maxwell springs: Δt₀ / √(1 + Σ αᵢ)."""
    return dt0 / math.sqrt(1.0 + sum(a for a, _ in comps)) if comps else dt0


def maxwell_ratio(comps, f: float) -> float:
    """The damping ratio of the Maxwell components at frequency f [Hz]: half the loss factor of the
    complex stiffness K (1 + Σ αᵢ i r/(1 + i r)), r = 2π f τᵢ, i.e. Σ αᵢ r/(1 + r²) over
    2 (1 + Σ αᵢ r²/(1 + r²)) (the springs stiffen the storage part; module text)."""
    rs = [(a, 2.0 * math.pi * f * t) for a, t in comps]
    loss = sum(a * r / (1.0 + r * r) for a, r in rs)
    storage = 1.0 + sum(a * r * r / (1.0 + r * r) for a, r in rs)
    return 0.5 * loss / storage


def zone_maxwell_damping(zst, comps, dt: float, pos, vel, facc) -> None:
    """Add the Maxwell components' forces on the gridpoints of the zones and FE elements to ``facc``,
    after moving each on by the step dt with the current velocities (module text). ``zst`` is the
    ``physics.zones.ZoneStepper``; the forces live in ``vertices.maxwell`` (MAXWELL_MAX, 3)."""
    from dec3d.model.store import Field

    v = zst.model.vertices
    if "maxwell" not in v:
        v.add_field("maxwell", Field((MAXWELL_MAX, 3), np.float64, 0.0))
    g = getattr(zst, "_maxwell_rate", None)
    if g is None or g.shape != facc.shape:
        g = zst._maxwell_rate = np.zeros_like(facc)
    rows = zst.rows
    g[rows] = 0.0
    zone_stiffness_damping(zst, 1.0, pos, vel, g)      # −K v: the rate of the elastic forces
    F = v["maxwell"]
    rate = g[rows]
    total = np.zeros_like(rate)
    for i, (a, tau) in enumerate(comps):
        e = math.exp(-dt / tau)
        Fi = F[rows, i] * e + (a * tau * (1.0 - e)) * rate
        F[rows, i] = Fi
        total += Fi
    facc[rows] += total


def stiffness_timestep(dt0: float, beta: float) -> float:
    """Δt₀ lowered for stiffness-proportional damping β [s] (see the module text)."""
    if beta <= 0.0 or not dt0 > 0.0:
        return dt0
    lam = beta / dt0
    return dt0 * (math.sqrt(1.0 + lam * lam) - lam)


def damping_text(model) -> str:
    """The damping in effect, in words (for `model dynamic list`)."""
    m = _mech(model)
    mode = m["damping"]
    if mode == "rayleigh":
        xi, f, form = m["rayleigh"]
        a, b = rayleigh_coefficients(model)
        what = {"both": "mass and stiffness", "mass": "mass only", "stiffness": "stiffness only"}[form]
        return (f"rayleigh, fraction {xi:g} at {f:g}{suffix(model, 'frequency')} ({what}: α = {a:.6g}"
                f"{suffix(model, 'rate')}, β = {b:.6g}{suffix(model, 'time')})"
                if a or b else "rayleigh with fraction or frequency 0: no damping")
    if mode == "maxwell":
        pairs = m.get("maxwell", [])
        hz = suffix(model, "frequency")
        return ("maxwell, " + ", ".join(f"{xi:g} at {f:g}{hz}" for xi, f in pairs) + " (peak ratio at frequency; "
                f"on zones and FE elements only)") if pairs else "maxwell with no component: no damping"
    if mode == "none":
        return "none"
    if m["dynamic"]:
        return f"none ({mode} damping is set and is not applied in dynamic mode)"
    return mode


def zone_stiffness_damping(zst, beta: float, pos, vel, facc) -> None:
    """Add the gridpoint forces of the damping stresses β D ε̇ of the zones and FE elements to ``facc``:
    each element kind's own step kernel, run on zero stresses with the strain increment of the current
    velocities over a unit time (so it returns −K v, the forces being linear in the stresses and the
    strains in the velocities), times β — the 4-node zones (``zone_step`` with each plastic model's zones
    taken as elastic: the damping stress is not limited by their strength; null zones stay null; the
    anisotropic elastic models keep theirs), the 10-node zones (``zones_ho.tet10_step``) and the FE
    elements with their hourglass control (``FeStepper.stiffness_damping``). ``zst`` is the
    ``physics.zones.ZoneStepper``."""
    from dec3d.kernels.zmodels import CODES, PLASTIC_CODES, model_mask
    from dec3d.kernels.zone_step import zone_step_for

    zs = zst.model.store("zones")
    sc = getattr(zst, "_rayleigh_scratch", None)
    if sc is None or sc[0].shape != zs["stress"].shape or sc[2].shape != facc.shape:
        plastic = np.isin(zs["cmodel"], sorted(PLASTIC_CODES))
        cm = np.where(plastic, CODES["elastic"], zs["cmodel"]).astype(zs["cmodel"].dtype)
        sc = zst._rayleigh_scratch = (np.zeros_like(zs["stress"]), np.zeros_like(zs["state"]), np.zeros_like(facc),
                                      np.zeros(facc.shape[0]), cm,
                                      np.zeros_like(zs["gstress"]) if len(zst.rows10) else None)
    stress, state, f, fm, cm, gstress = sc
    stress[:] = 0.0
    state[:] = 0
    f[:] = 0.0
    fm[:] = 0.0
    if zst.fast is not None:
        # (the anisotropic models' mean-stress correction is linear in the strain too: their zones
        # keep the step's averaging sweep, the plastic ones, taken as elastic, give it nothing)
        step = zone_step_for(model_mask(np.unique(cm[zst.rows4]), zst.plastic))
        step(pos, vel, zst.zmesh, zst.material(stress, state, cm), zst.zplan, zst.zscratch, 1.0, False, zst.nmd, f, fm)
    if gstress is not None:
        from dec3d.kernels.zones_ho import tet10_step
        gstress[zst.rows10] = 0.0
        tet10_step(pos, vel, zs["gp"], zst.rows10, zst.bulk, zst.shear, 1.0, gstress, stress, f)
    if zst.fe is not None:
        zst.fe.stiffness_damping(pos, vel, f)
    facc[zst.rows] += beta * f[zst.rows]


# ------------------------------------------------------------------ time functions

#: kinds of condition: (store, field, fixity bit base or None for forces)
KINDS = {("block", "velocity"): ("velocity", 1), ("block", "rvelocity"): ("spin", 8),
         ("block", "force"): ("fapp", None), ("block", "moment"): ("mapp", None),
         ("gridpoint", "velocity"): ("vapp", 1), ("gridpoint", "force"): ("fapp", None)}


def add_timefn(model, on: str, kind: str, comp: int, value: float, ids, table=None, fish=None,
               where: str = "") -> None:
    """Record a time function: the ``comp`` component of ``kind`` of the ``ids`` (block ids, or gridpoint
    vertex rows) is ``value`` × table(t) or × fish() while cycling. A velocity replaces the velocity time
    functions of that component on those ids; a force adds to what is there (as applied forces do)."""
    if KINDS[(on, kind)][1] is not None:
        remove_timefns(model, on, ids, {(kind, comp)})
    _mech(model)["timefns"].append({"on": on, "kind": kind, "comp": int(comp), "value": float(value),
                                    "table": table, "fish": fish, "ids": [int(i) for i in ids], "last": 0.0,
                                    "where": where})


def remove_timefns(model, on: str, ids, which) -> None:
    """Drop ``ids`` from the time functions of ``on`` whose (kind, comp) is in ``which``."""
    drop = set(int(i) for i in ids)
    keep = []
    for e in _mech(model)["timefns"]:
        if e["on"] == on and (e["kind"], e["comp"]) in which:
            e["ids"] = [i for i in e["ids"] if i not in drop]
            if not e["ids"]:
                continue
        keep.append(e)
    _mech(model)["timefns"][:] = keep


def has_timefns(model) -> bool:
    return bool(_mech(model)["timefns"])


def interpolate(xs, ys, x: float) -> float:
    """Linear interpolation in a table of increasing xs; the end values hold outside (as FISH `table`)."""
    if x <= xs[0]:
        return float(ys[0])
    if x >= xs[-1]:
        return float(ys[-1])
    k = bisect_left(xs, x)
    x0, x1, y0, y1 = xs[k - 1], xs[k], ys[k - 1], ys[k]
    return float(y0 + (y1 - y0) * (x - x0) / (x1 - x0))


def timefn_factor(model, e: dict, t: float) -> float:
    """table(t) or the FISH function's value now, for time function ``e``."""
    at = f"{e['where']}: " if e.get("where") else ""
    if e.get("table") is not None:
        get = getattr(model, "fish_table", None)
        tab = get(e["table"]) if get is not None else None
        if tab is None:
            raise TimeFunctionError(f"{at}there is no table {e['table']} any more (used by `{e['on']} apply "
                                    f"{e['kind']} … table {e['table']}`)")
        if not tab.xs:
            raise TimeFunctionError(f"{at}table {e['table']} has no points")
        return interpolate(tab.xs, tab.ys, t)
    probe = getattr(model, "fish_probe", None)
    if probe is None:
        raise TimeFunctionError(f"{at}no FISH run time for `fish {e['fish']}`")
    v = float(probe(e["fish"]))
    if not math.isfinite(v):
        raise TimeFunctionError(f"{at}FISH function `{e['fish']}` gave {v} at time {t:g} s")
    return v


class TimeFunctions:
    """A step of the cycle (first in ``steps._Run.steps`` when the model has time functions): before
    each step, every time-function condition is set for the time of that step, and the batch is cut to
    one step. A velocity is taken at the middle of the step (t + Δt/2: velocities live at half steps in
    the central-difference scheme), a force at its start t. The time is ``load_time``."""
    timing = "hooks"

    def __init__(self, run):
        self.run = run
        self.prepare()

    def prepare(self) -> None:
        m = self.run.m
        ids = m.blocks["id"]
        order = np.argsort(ids, kind="stable")
        self.rows = []
        for e in _mech(m)["timefns"]:
            want = np.asarray(e["ids"], np.int64)
            if e["on"] == "block":
                k = np.searchsorted(ids[order], want)
                k = np.minimum(k, max(len(order) - 1, 0))
                ok = (len(order) > 0) & (ids[order][k] == want) if len(order) else np.zeros(len(want), bool)
                self.rows.append(order[k[ok]])
            else:
                self.rows.append(want[(want >= 0) & (want < m.vertices.n)])

    def advance(self, n: int) -> int:
        r = self.run
        m = r.m
        t = load_time(m)
        for e, rows in zip(_mech(m)["timefns"], self.rows):
            field, bit = KINDS[(e["on"], e["kind"])]
            arr = (m.blocks if e["on"] == "block" else m.vertices)[field]
            i = e["comp"]
            if bit is not None:
                val = e["value"] * timefn_factor(m, e, t + 0.5 * r.dt)
                arr[rows, i] = val
                if e["on"] == "gridpoint" and r.zst is not None:
                    # the zone stepper holds its own copy of the held velocities, on the master rows
                    link = m.vertices["link"][rows]
                    r.zst.vapp[np.where(link >= 0, link, rows), i] = val
            else:
                new = e["value"] * timefn_factor(m, e, t)
                arr[rows, i] += new - e["last"]
                e["last"] = new
        return min(n, 1)

    def __repr__(self) -> str:
        return "TimeFunctions"


def timefns_state_problem(v) -> str | None:
    """Why a save file's ``timefns`` setting is not acceptable (None: it is)."""
    if not isinstance(v, list):
        return "is not a list"
    for e in v:
        if not isinstance(e, dict) or (e.get("on"), e.get("kind")) not in KINDS:
            return "has an entry that is not a known condition"
        if e.get("comp") not in (0, 1, 2) or not isinstance(e.get("ids"), list):
            return "has an entry with a bad component or id list"
        if not all(isinstance(i, int) and not isinstance(i, bool) for i in e["ids"]):
            return "has an entry whose ids are not whole numbers"
        for k in ("value", "last"):
            if not isinstance(e.get(k), (int, float)) or not math.isfinite(e[k]):
                return f"has an entry whose {k} is not a finite number"
        if (e.get("table") is None) == (e.get("fish") is None):
            return "has an entry that names neither (or both) a table and a FISH function"
        if not isinstance(e.get("fish") or "", str) or not isinstance(e.get("table") or 0, (int, str)):
            return "has an entry with a bad table id or FISH name"
    return None


register_known(timefns_problem=timefns_state_problem)
