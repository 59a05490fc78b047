"""Histories: values sampled by the rigid engine's cycle every ``interval`` steps.

One ``HistorySet`` hangs on the model (``histories(model)``); it registers its ``sample``
as a step hook of the model's rigid engine (``RigidEngine.step_hooks``), so a history
created before or after the engine exists is sampled from the next step on. Each history
keeps the step and the total time of each sample beside the value.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from dec3d.model.kinematics import block_rotation, unwrap_rotation

_XYZ = (("", None), ("-x", 0), ("-y", 1), ("-z", 2))
#: block quantity -> (engine field, component or None for the magnitude)
BLOCK_QUANTITIES = {f"{q}{s}": (fld, comp)
                    for q, fld in (("displacement", "disp"), ("velocity", "velocity"), ("rvelocity", "spin"),
                                   ("position", "centroid"))
                    for s, comp in _XYZ}
#: the rotation of a block since it was made (``dec3d.model.kinematics``): components of the rotation
#: vector θ n [rad] and θ itself, followed continuously from sample to sample
ROTATION_QUANTITIES = ("rotation", "rotation-x", "rotation-y", "rotation-z")
#: quantities that `material-point x y z` can follow at a point fixed to the block instead of at its centroid
POINT_QUANTITIES = tuple(q for q in BLOCK_QUANTITIES if q.split("-")[0] in ("displacement", "velocity", "position"))
#: dec3d's own block quantities (not 3DEC variables), worked out from the vertices each sample:
#: angular momentum I(t) ω about the centroid, I(t) = R I₀ Rᵀ with R the best-fit rotation of the vertex
#: arms since the history was made (Kabsch), and the shape error max |r − R r₀| [m] of the vertex arms
RIGID_QUANTITIES = tuple(f"angular-momentum{s}" for s, _ in _XYZ) + ("shape-error",)
#: contact quantity -> (sub-contact field, how it is reduced); ``block contact history``
CONTACT_QUANTITIES = {"force-normal": ("fn", "sum"), "force-shear": ("fs", "norm"),
                      "force-shear-x": ("fs", 0), "force-shear-y": ("fs", 1), "force-shear-z": ("fs", 2),
                      "displacement-normal": ("un", "mean"), "displacement-shear": ("us", "norm-mean")}
MODEL_QUANTITIES = ("unbalanced-maximum", "ratio", "ratio-average", "ratio-local", "ratio-maximum", "time-total",
                    "kinetic-energy")


@dataclass
class History:
    id: int
    name: str
    label: str                                  # what is sampled, for the CSV header and the plot
    value: Callable[[object], float]            # value(engine) -> float
    steps: list[int] = field(default_factory=list)
    times: list[float] = field(default_factory=list)
    values: list[float] = field(default_factory=list)

    def sample(self, eng) -> None:
        self.steps.append(int(eng.step))
        self.times.append(float(eng.time))
        self.values.append(float(self.value(eng)))


class HistorySet:
    def __init__(self, model):
        self.model = model
        self.interval = 10
        self.items: list[History] = []

    def __call__(self, eng) -> None:
        """Step hook: sample every history when the step count is a multiple of the interval."""
        if self.items and eng.step % self.interval == 0:
            for h in self.items:
                h.sample(eng)

    def add(self, label: str, value: Callable, name: str | None = None) -> History:
        hid = (self.items[-1].id + 1) if self.items else 1
        h = History(hid, name or str(hid), label, value)
        self.items.append(h)
        return h

    def find(self, key) -> History | None:
        """A history by id (number) or by name."""
        for h in self.items:
            if (isinstance(key, (int, float)) and not isinstance(key, bool) and h.id == int(key)) or h.name == key:
                return h
        return None

    def add_block(self, quantity: str, block_id: int, name: str | None = None) -> History:
        fld, comp = BLOCK_QUANTITIES[quantity]
        model = self.model
        cache = {"row": -1}

        def value(eng) -> float:
            b = model.blocks
            r = cache["row"]
            if not (0 <= r < b.n and b["id"][r] == block_id):
                r = cache["row"] = int(np.flatnonzero(b["id"] == block_id)[0])
            v = b[fld][r]
            return float(np.linalg.norm(v)) if comp is None else float(v[comp])

        return self.add(f"block {block_id} {quantity}", value, name)

    def _row(self, block_id: int, cache: dict) -> int:
        b = self.model.blocks
        r = cache.get("row", -1)
        if not (0 <= r < b.n and b["id"][r] == block_id):
            r = cache["row"] = int(np.flatnonzero(b["id"] == block_id)[0])
        return r

    def add_rotation(self, quantity: str, block_id: int, name: str | None = None) -> History:
        """A component of the block's rotation vector since it was made, or its angle [rad]; each
        sample takes the equivalent vector (θ + 2πk) n nearest the previous one, so a block that keeps
        turning about one axis gives ω t past θ = π."""
        model = self.model
        state: dict = {"prev": None}
        comp = {"rotation": None, "rotation-x": 0, "rotation-y": 1, "rotation-z": 2}[quantity]

        def value(eng) -> float:
            r = self._row(block_id, state)
            rv = unwrap_rotation(block_rotation(model, [r])[0], state["prev"])
            state["prev"] = rv
            return float(np.linalg.norm(rv)) if comp is None else float(rv[comp])

        return self.add(f"block {block_id} {quantity}", value, name)

    def add_point(self, quantity: str, block_id: int, point, name: str | None = None) -> History:
        """Displacement (since the block was made), velocity or position of a point fixed to a block.

        The point is kept in the block's frame at its making: p_o = x̄_o + Rᵀ (p − x̄), with x̄ the mean of
        the block's vertices, x̄_o that of their origins and R the best-fit (Kabsch) rotation of the
        origin arms onto the vertex arms. Each sample carries it along: p(t) = x̄(t) + R(t) (p_o − x̄_o)
        (any set of the block's vertices will do, so a later cut does not lose it). The displacement
        is p(t) − p_o; the velocity v + ω × (p − c) of the block."""
        fld, comp = BLOCK_QUANTITIES[quantity]
        model = self.model
        cache: dict = {}
        p0 = np.asarray(point, dtype=float)

        def frame(r):
            b, v = model.blocks, model.vertices
            st, c = int(b["vert_start"][r]), int(b["vert_count"][r])
            pos, org = v["pos"][st:st + c], v["origin"][st:st + c]
            mp, mo = pos.mean(axis=0), org.mean(axis=0)
            return mp, mo, best_rotation(org - mo, pos - mp)

        mp, mo, rot = frame(self._row(block_id, cache))
        p_origin = mo + rot.T @ (p0 - mp)

        def value(eng) -> float:
            r = self._row(block_id, cache)
            mp, mo, rot = frame(r)
            p = mp + rot @ (p_origin - mo)
            if fld == "centroid":
                out = p
            elif fld == "disp":
                out = p - p_origin
            else:
                bb = model.blocks
                out = bb["velocity"][r] + np.cross(bb["spin"][r], p - bb["centroid"][r])
            return float(np.linalg.norm(out)) if comp is None else float(out[comp])

        return self.add(f"block {block_id} {quantity} at point ({p0[0]:g} {p0[1]:g} {p0[2]:g})", value, name)

    def add_rigid(self, quantity: str, block_id: int, name: str | None = None) -> History:
        """Angular momentum [kg·m²/s] or shape error [m] of one block (``RIGID_QUANTITIES``)."""
        model = self.model
        b = model.blocks
        r0 = int(np.flatnonzero(b["id"] == block_id)[0])
        s, c = int(b["vert_start"][r0]), int(b["vert_count"][r0])
        arms0 = model.vertices["pos"][s:s + c] - b["centroid"][r0]
        inertia0 = b["inertia"][r0].copy()
        comp = {"": None, "-x": 0, "-y": 1, "-z": 2}.get(quantity[len("angular-momentum"):], None)

        def value(eng) -> float:
            bb = model.blocks
            r = int(np.flatnonzero(bb["id"] == block_id)[0])
            st = int(bb["vert_start"][r])
            arms = model.vertices["pos"][st:st + c] - bb["centroid"][r]
            rot = best_rotation(arms0, arms)
            if quantity == "shape-error":
                return float(np.linalg.norm(arms - arms0 @ rot.T, axis=1).max())
            lm = rot @ inertia0 @ rot.T @ bb["spin"][r]
            return float(np.linalg.norm(lm)) if comp is None else float(lm[comp])

        return self.add(f"block {block_id} {quantity}", value, name)

    def add_contact(self, quantity: str, position, name: str | None = None) -> History:
        """A contact quantity summed (or averaged) over the sub-contacts of one contact: the contact whose
        centre is nearest ``position`` at the first sample, followed by its two blocks' ids afterwards
        (the ``contacts`` / ``subcontacts`` stores of the rigid engine)."""
        fld, how = CONTACT_QUANTITIES[quantity]
        model = self.model
        pos = np.asarray(position, dtype=float)
        pair: dict = {}

        def value(eng) -> float:
            c, sc = _contact_view(model, eng)
            if c is None or len(c["ida"]) == 0:
                return float("nan") if not pair else 0.0
            if not pair:
                k = int(np.argmin(np.linalg.norm(c["pos"] - pos, axis=1)))
                pair["ids"] = (int(c["ida"][k]), int(c["idb"][k]))
            ida, idb = pair["ids"]
            hit = np.flatnonzero((c["ida"] == ida) & (c["idb"] == idb))
            if len(hit) == 0:
                return 0.0                     # the two blocks are no longer in contact
            k = int(hit[0])
            s0, n = int(c["sub_start"][k]), int(c["sub_count"][k])
            v = sc[fld][s0:s0 + n]
            if how == "sum":
                return float(v.sum())
            if how == "mean":
                return float(v.mean()) if v.size else 0.0
            if how == "norm":
                return float(np.linalg.norm(v.sum(axis=0)))
            if how == "norm-mean":
                return float(np.linalg.norm(v.mean(axis=0))) if v.size else 0.0
            return float(v[:, how].sum())

        return self.add(f"contact near ({pos[0]:g} {pos[1]:g} {pos[2]:g}) {quantity}", value, name)

    def add_model(self, quantity: str, name: str | None = None) -> History:
        if quantity.startswith(("ratio", "unbalanced")):   # the measures of `model solve` (RigidEngine.criteria)
            return self.add(f"mechanical {quantity}", lambda eng: float(eng.criteria()[quantity]), name)
        attr = {"time-total": "time", "kinetic-energy": "kinetic"}[quantity]
        return self.add(f"mechanical {quantity}", lambda eng: float(getattr(eng, attr)), name)


def _contact_view(model, eng):
    """(contacts, subcontacts) stores of the rigid engine, or (None, None) before it has made them."""
    stores = model.stores
    if "contacts" in stores:
        return stores["contacts"], stores["subcontacts"]
    return None, None


def best_rotation(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The rotation R minimising Σ |b_i − R a_i|² (Kabsch; a, b (n, 3) centred point sets)."""
    u, _, vt = np.linalg.svd(b.T @ a)
    d = np.sign(np.linalg.det(u @ vt)) or 1.0
    return u @ np.diag([1.0, 1.0, d]) @ vt


def nearest_block_id(model, position) -> int:
    """Id of the visible block whose centroid is nearest ``position``."""
    b = model.blocks
    rows = np.flatnonzero(~b["hidden"])
    if rows.size == 0:
        raise ValueError("there are no blocks")
    d = np.linalg.norm(b["centroid"][rows] - np.asarray(position, dtype=float), axis=1)
    return int(b["id"][rows[int(np.argmin(d))]])


def histories(model) -> HistorySet:
    """The model's history set, made on first use and hooked to the model's rigid engine."""
    from .rigid import engine

    hs = getattr(model, "history_set", None)
    if hs is None:
        hs = HistorySet(model)
        model.history_set = hs
    eng = engine(model)
    if hs not in eng.step_hooks:
        eng.step_hooks.append(hs)
    return hs


def figures(times, values) -> dict[str, float]:
    """final, min, max and frequency (Hz, from the zero crossings of value − mean; 0 if fewer than two)."""
    v = np.asarray(values, dtype=float)
    t = np.asarray(times, dtype=float)
    if v.size == 0:
        return {"final": float("nan"), "min": float("nan"), "max": float("nan"), "frequency": 0.0}
    out = {"final": float(v[-1]), "min": float(v.min()), "max": float(v.max()), "frequency": 0.0}
    d = v - v.mean()
    k = np.flatnonzero((d[:-1] < 0) != (d[1:] < 0))      # a sign change between sample k and k + 1
    if k.size >= 2:
        tc = t[k] + (t[k + 1] - t[k]) * d[k] / (d[k] - d[k + 1])   # linear interpolation of the crossing
        if tc[-1] > tc[0]:
            out["frequency"] = float((k.size - 1) / (2.0 * (tc[-1] - tc[0])))
    return out
