"""Histories: values sampled by the rigid engine's cycle every ``interval`` steps.

One ``HistorySet`` hangs on the model (``histories(model)``); it registers its ``sample``
as a step hook of the model's rigid engine (``RigidEngine.step_hooks``), so a history
created before or after the engine exists is sampled from the next step on. Each history
keeps the step and the total time of each sample beside the value.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from dec3d.errors import CommandError
from dec3d.io.state import register_known
from dec3d.model.kinematics import block_rotation, unwrap_rotation
from .flownet import FLOWKNOT_QUANTITIES, flowknot_history

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
                      "displacement-normal": ("un", "mean"), "displacement-shear": ("us", "norm-mean"),
                      "pore-pressure": ("ppf", "per-area")}
#: gridpoint quantity -> (vertex field, component or None for the magnitude); ``block history`` on a zoned block
GRIDPOINT_QUANTITIES = {q: ({"centroid": "pos"}.get(fld, fld), comp) for q, (fld, comp) in BLOCK_QUANTITIES.items()
                        if fld in ("disp", "velocity", "centroid")}
#: zone quantity -> column of ``zones.stress``; ``block zone history``
ZONE_QUANTITIES = {f"stress-{c}": i for i, c in enumerate(("xx", "yy", "zz", "xy", "xz", "yz"))}
#: a FISH name a `fish history` records (``HistorySet.add_fish``)
FISH_NAME = re.compile(r"[a-z_][a-z0-9_]{0,127}")
MODEL_QUANTITIES = ("unbalanced-maximum", "ratio", "ratio-average", "ratio-local", "ratio-maximum", "time-total",
                    "kinetic-energy")


@dataclass
class History:
    id: int
    name: str
    label: str                                  # what is sampled, for the CSV header and the plot
    value: Callable[[object], float]            # value(engine) -> float
    #: how to make it again (save files; ``HistorySet._make``): plain JSON. Every kind of history sets it
    spec: dict = field(default_factory=dict)
    steps: list[int] = field(default_factory=list)
    times: list[float] = field(default_factory=list)
    values: list[float] = field(default_factory=list)

    def sample(self, eng) -> None:
        self.steps.append(int(eng.step))
        self.times.append(float(eng.time))
        self.values.append(float(self.value(eng)))


class _BlockGone(LookupError):
    def __init__(self, block_id: int):
        super().__init__(block_id)
        self.block_id = int(block_id)


def _live_row(b, block_id: int) -> int:
    """Row of block ``block_id``; _BlockGone when it was deleted (reported by the sampler)."""
    rows = np.flatnonzero(b["id"] == block_id)
    if rows.size == 0:
        raise _BlockGone(block_id)
    return int(rows[0])


class HistorySet:
    def __init__(self, model):
        self.model = model
        self.interval = 10
        self.items: list[History] = []

    def __call__(self, eng) -> None:
        """Step hook: sample every history when the step count is a multiple of the interval."""
        if self.items and eng.step % self.interval == 0:
            # every value first: one that fails (a FISH history's function) leaves no history a sample ahead
            try:
                values = [float(h.value(eng)) for h in self.items]
            except _BlockGone as exc:
                h = next(h for h in self.items if h.spec.get("block_id") == exc.block_id)
                raise CommandError(f"history '{h.name}' ({h.label}) follows block {exc.block_id}, which was "
                                   "deleted: `history delete` it before deleting its block, or place it on a "
                                   "block that stays") from None
            step, time = int(eng.step), float(eng.time)
            for h, v in zip(self.items, values):
                h.steps.append(step)
                h.times.append(time)
                h.values.append(v)

    def add(self, label: str, value: Callable, name: str | None = None, spec: dict | None = None) -> History:
        hid = (self.items[-1].id + 1) if self.items else 1
        h = History(hid, name or str(hid), label, value, dict(spec or {}))
        self.items.append(h)
        return h

    # ------------------------------------------------------------ save files
    def to_state(self) -> tuple[dict, dict[str, np.ndarray]]:
        """(JSON description, arrays) of every history, for ``dec3d.io.state``."""
        items, arrays = [], {}
        for h in self.items:
            spec = dict(h.spec)
            if spec.get("kind") == "contact":
                ids = getattr(h, "follow", {}).get("ids")
                spec["pair"] = [int(i) for i in ids] if ids else None
            elif spec.get("kind") == "rotation":
                prev = h.state["prev"]
                spec["prev"] = None if prev is None else [float(x) for x in prev]
            items.append({"id": h.id, "name": h.name, "label": h.label, "spec": spec})
            arrays[f"{h.id}.steps"] = np.asarray(h.steps, dtype=np.int64)
            arrays[f"{h.id}.times"] = np.asarray(h.times, dtype=np.float64)
            arrays[f"{h.id}.values"] = np.asarray(h.values, dtype=np.float64)
        return {"interval": self.interval, "items": items}, arrays

    @classmethod
    def from_state(cls, model, desc: dict, arrays: dict[str, np.ndarray]) -> "HistorySet":
        """The inverse of ``to_state``; raises ValueError naming what is wrong (nothing is changed)."""
        hs = cls(model)
        interval = desc.get("interval")
        if not isinstance(interval, int) or isinstance(interval, bool) or interval < 1:
            raise ValueError(f"history interval {interval!r} is not a whole number ≥ 1")
        hs.interval = interval
        items = desc.get("items")
        if not isinstance(items, list):
            raise ValueError("the history list is not a list")
        seen = set()
        for it in items:
            if not isinstance(it, dict):
                raise ValueError("a history entry is not an object")
            hid, name, label, spec = it.get("id"), it.get("name"), it.get("label"), it.get("spec")
            if not isinstance(hid, int) or isinstance(hid, bool) or hid < 1 or hid in seen:
                raise ValueError(f"history id {hid!r} is not a new whole number ≥ 1")
            if hs.items and hid <= hs.items[-1].id:
                raise ValueError(f"history ids are not increasing at {hid}")
            seen.add(hid)
            if not isinstance(name, str) or not isinstance(label, str) or not isinstance(spec, dict):
                raise ValueError(f"history {hid}: name, label or spec has the wrong type")
            h = hs._make(hid, name, label, spec)
            steps, times, values = (arrays.get(f"{hid}.{k}") for k in ("steps", "times", "values"))
            if steps is None or times is None or values is None:
                raise ValueError(f"history {hid}: its samples are missing")
            if not (steps.ndim == times.ndim == values.ndim == 1 and len(steps) == len(times) == len(values)):
                raise ValueError(f"history {hid}: its sample arrays differ in length")
            if steps.dtype.kind not in "iu" or times.dtype.kind != "f" or values.dtype.kind != "f":
                raise ValueError(f"history {hid}: its sample arrays have the wrong types")
            if not np.isfinite(times).all() or np.isinf(values).any():
                raise ValueError(f"history {hid}: a sample time or value is not finite")
            h.steps, h.times, h.values = steps.tolist(), times.tolist(), values.tolist()
        return hs

    def _make(self, hid: int, name: str, label: str, spec: dict) -> History:
        kind = spec.get("kind")

        def num_list(key, n):
            v = spec.get(key)
            if not (isinstance(v, list) and len(v) == n and all(isinstance(x, (int, float)) and
                                                                not isinstance(x, bool) and np.isfinite(x)
                                                                for x in v)):
                raise ValueError(f"history {hid}: `{key}` is not {n} finite numbers")
            return v

        def block_id():
            v = spec.get("block_id")
            if not isinstance(v, int) or isinstance(v, bool) or v < 1:
                raise ValueError(f"history {hid}: block id {v!r} is not a whole number ≥ 1")
            return v

        q = spec.get("quantity")
        if kind == "block" and q in BLOCK_QUANTITIES:
            h = self.add_block(q, block_id(), name)
        elif kind == "rigid" and q in RIGID_QUANTITIES:
            arms = spec.get("arms0")
            if not (isinstance(arms, list) and arms and all(isinstance(a, list) for a in arms)):
                raise ValueError(f"history {hid}: `arms0` is not a list of vectors")
            for i, a in enumerate(arms):
                if not (len(a) == 3 and all(isinstance(x, (int, float)) and not isinstance(x, bool)
                                            and np.isfinite(x) for x in a)):
                    raise ValueError(f"history {hid}: vertex arm {i} is not 3 finite numbers")
            inertia = spec.get("inertia0")
            if not (isinstance(inertia, list) and len(inertia) == 3):
                raise ValueError(f"history {hid}: `inertia0` is not a 3 × 3 matrix")
            for row in inertia:
                if not (isinstance(row, list) and len(row) == 3 and all(
                        isinstance(x, (int, float)) and not isinstance(x, bool) and np.isfinite(x) for x in row)):
                    raise ValueError(f"history {hid}: `inertia0` is not a 3 × 3 matrix of finite numbers")
            h = self.add_rigid(q, block_id(), name, arms0=np.array(arms, float), inertia0=np.array(inertia, float))
        elif kind == "contact" and q in CONTACT_QUANTITIES:
            pos = num_list("position", 3)
            pair = spec.get("pair")
            if pair is not None and not (isinstance(pair, list) and len(pair) == 2 and all(
                    isinstance(x, int) and not isinstance(x, bool) for x in pair)):
                raise ValueError(f"history {hid}: `pair` is not two block ids")
            h = self.add_contact(q, pos, name, pair=tuple(pair) if pair else None)
        elif kind == "flowknot" and q in FLOWKNOT_QUANTITIES:
            label, value, fspec = flowknot_history(self.model, q, num_list("position", 3))
            h = self.add(label, value, name, fspec)
        elif kind == "rotation" and q in ROTATION_QUANTITIES:
            prev = None if spec.get("prev") is None else num_list("prev", 3)
            h = self.add_rotation(q, block_id(), name, prev=prev)
        elif kind == "point" and q in BLOCK_QUANTITIES and BLOCK_QUANTITIES[q][0] in ("centroid", "disp", "velocity"):
            h = self.add_point(q, block_id(), num_list("point", 3), name, p_origin=num_list("origin", 3))
        elif kind == "model" and (q in MODEL_QUANTITIES or q == "dynamic-time-total"):
            h = self.add_model(q, name)
        elif kind == "gridpoint" and q in GRIDPOINT_QUANTITIES:
            local = spec.get("local")
            if not isinstance(local, int) or isinstance(local, bool) or local < 0:
                raise ValueError(f"history {hid}: gridpoint index {local!r} is not a whole number ≥ 0")
            bid = block_id()
            b = self.model.blocks
            rows = np.flatnonzero(b["id"] == bid)
            if rows.size == 0 or local >= int(b["vert_count"][rows[0]]):
                raise ValueError(f"history {hid}: block {bid} has no gridpoint {local + 1}")
            h = self.add_gridpoint(q, bid, local, name)
        elif kind == "zone-centroid" and q in GRIDPOINT_QUANTITIES:
            zid = spec.get("zone_id")
            if not isinstance(zid, int) or isinstance(zid, bool) or zid < 1:
                raise ValueError(f"history {hid}: zone id {zid!r} is not a whole number ≥ 1")
            h = self.add_zone_centroid(q, zid, name)
        elif kind == "zone" and q in ZONE_QUANTITIES:
            zid = spec.get("zone_id")
            if not isinstance(zid, int) or isinstance(zid, bool) or zid < 1:
                raise ValueError(f"history {hid}: zone id {zid!r} is not a whole number ≥ 1")
            h = self.add_zone(q, zid, name)
        elif kind == "energy" and q in _energy_quantities():
            h = self.add_energy(q, name)
        elif kind == "fish" and isinstance(q, str) and FISH_NAME.fullmatch(q):
            h = self.add_fish(q, name)
        elif kind in ("cable", "cable-node") and isinstance(spec.get("id"), int) and spec["id"] >= 1:
            from .cable_history import add_cable_history     # (raises ValueError for a quantity it has not)
            h = add_cable_history(self, kind, q, spec["id"], name)
        elif kind == "liner" and isinstance(spec.get("id"), int) and spec["id"] >= 1 and spec.get("node") in (1, 2, 3):
            from .liner_history import add_liner_history     # (raises ValueError for a quantity it has not)
            h = add_liner_history(self, q, spec["id"], spec["node"], name)
        elif kind in ("beam", "dowel") and isinstance(spec.get("id"), int) and spec["id"] >= 1:
            from .beam_history import add_beam_history
            from .dowels import add_dowel_history
            h = (add_beam_history if kind == "beam" else add_dowel_history)(self, q, spec["id"], name)
        else:
            raise ValueError(f"history {hid}: unknown kind {kind!r} or quantity {q!r}")
        self.items.pop()
        h.id, h.label = hid, label
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
                r = cache["row"] = _live_row(b, block_id)
            v = b[fld][r]
            return float(np.linalg.norm(v)) if comp is None else float(v[comp])

        return self.add(f"block {block_id} {quantity}", value, name,
                        {"kind": "block", "quantity": quantity, "block_id": int(block_id)})

    def _row(self, block_id: int, cache: dict) -> int:
        b = self.model.blocks
        r = cache.get("row", -1)
        if not (0 <= r < b.n and b["id"][r] == block_id):
            r = cache["row"] = _live_row(b, block_id)
        return r

    def add_rotation(self, quantity: str, block_id: int, name: str | None = None, prev=None) -> History:
        """A component of the block's rotation vector since it was made, or its angle [rad]; each
        sample takes the equivalent vector (θ + 2πk) n nearest the previous one, so a block that keeps
        turning about one axis gives ω t past θ = π."""
        model = self.model
        state: dict = {"prev": None if prev is None else np.asarray(prev, dtype=float)}
        comp = {"rotation": None, "rotation-x": 0, "rotation-y": 1, "rotation-z": 2}[quantity]

        def value(eng) -> float:
            r = self._row(block_id, state)
            rv = unwrap_rotation(block_rotation(model, [r])[0], state["prev"])
            state["prev"] = rv
            return float(np.linalg.norm(rv)) if comp is None else float(rv[comp])

        h = self.add(f"block {block_id} {quantity}", value, name,
                     {"kind": "rotation", "quantity": quantity, "block_id": int(block_id)})
        h.state = state           # the last rotation vector (save files: unwrapping goes on after a restore)
        return h

    def add_point(self, quantity: str, block_id: int, point, name: str | None = None, p_origin=None) -> History:
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

        if p_origin is None:
            mp, mo, rot = frame(self._row(block_id, cache))
            p_origin = mo + rot.T @ (p0 - mp)
        p_origin = np.asarray(p_origin, dtype=float)

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

        return self.add(f"block {block_id} {quantity} at point ({p0[0]:g} {p0[1]:g} {p0[2]:g})", value, name,
                        {"kind": "point", "quantity": quantity, "block_id": int(block_id),
                         "point": [float(x) for x in p0], "origin": [float(x) for x in p_origin]})

    def add_rigid(self, quantity: str, block_id: int, name: str | None = None, arms0=None,
                  inertia0=None) -> History:
        """Angular momentum [kg·m²/s] or shape error [m] of one block (``RIGID_QUANTITIES``).
        ``arms0``, ``inertia0``: the reference state (a restored history's); default: the block now."""
        model = self.model
        b = model.blocks
        if arms0 is None:
            r0 = int(np.flatnonzero(b["id"] == block_id)[0])
            s, c = int(b["vert_start"][r0]), int(b["vert_count"][r0])
            arms0 = model.vertices["pos"][s:s + c] - b["centroid"][r0]
            inertia0 = b["inertia"][r0].copy()
        c = len(arms0)
        comp = {"": None, "-x": 0, "-y": 1, "-z": 2}.get(quantity[len("angular-momentum"):], None)

        def value(eng) -> float:
            bb = model.blocks
            r = _live_row(bb, block_id)
            st = int(bb["vert_start"][r])
            arms = model.vertices["pos"][st:st + c] - bb["centroid"][r]
            rot = best_rotation(arms0, arms)
            if quantity == "shape-error":
                return float(np.linalg.norm(arms - arms0 @ rot.T, axis=1).max())
            lm = rot @ inertia0 @ rot.T @ bb["spin"][r]
            return float(np.linalg.norm(lm)) if comp is None else float(lm[comp])

        return self.add(f"block {block_id} {quantity}", value, name,
                        {"kind": "rigid", "quantity": quantity, "block_id": int(block_id),
                         "arms0": np.asarray(arms0, float).tolist(), "inertia0": np.asarray(inertia0, float).tolist()})

    def add_contact(self, quantity: str, position, name: str | None = None, pair=None) -> History:
        """A contact quantity summed (or averaged) over the sub-contacts of one contact: the contact whose
        centre is nearest ``position`` at the first sample, followed by its two blocks' ids afterwards
        (the ``contacts`` / ``subcontacts`` stores of the rigid engine)."""
        fld, how = CONTACT_QUANTITIES[quantity]
        model = self.model
        pos = np.asarray(position, dtype=float)
        pair: dict = {"ids": tuple(pair)} if pair else {}

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
            if how == "per-area":               # the water force over the contact's area (physics.water)
                a = float(sc["area"][s0:s0 + n].sum())
                return float(sc[fld][s0:s0 + n].sum()) / a if fld in sc and a > 0.0 else 0.0
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

        h = self.add(f"contact near ({pos[0]:g} {pos[1]:g} {pos[2]:g}) {quantity}", value, name,
                     {"kind": "contact", "quantity": quantity, "position": [float(x) for x in pos]})
        h.follow = pair           # the two block ids followed (set at the first sample), for save files
        return h

    def add_gridpoint(self, quantity: str, block_id: int, local: int, name: str | None = None) -> History:
        """Displacement, velocity or position of one gridpoint of a zoned block: the ``local``-th row of
        the block's vertex range (kept by block id and index, so the history survives other blocks
        being zoned or deleted, which moves vertex rows). A gridpoint shared by joined blocks reads its
        master's motion."""
        fld, comp = GRIDPOINT_QUANTITIES[quantity]
        model = self.model
        cache: dict = {}

        def value(eng) -> float:
            r = self._row(block_id, cache)
            v = model.vertices
            row = int(model.blocks["vert_start"][r]) + local
            if v["link"][row] >= 0:
                row = int(v["link"][row])
            x = v[fld][row]
            return float(np.linalg.norm(x)) if comp is None else float(x[comp])

        return self.add(f"block {block_id} gridpoint {local + 1} {quantity}", value, name,
                        {"kind": "gridpoint", "quantity": quantity, "block_id": int(block_id), "local": int(local)})

    def add_zone(self, quantity: str, zone_id: int, name: str | None = None) -> History:
        """A stress component [Pa, tension positive] of the zone with id ``zone_id``."""
        col = ZONE_QUANTITIES[quantity]
        model = self.model
        row = _zone_row(model, zone_id)

        def value(eng) -> float:
            r = row()
            if r < 0:
                return float("nan")          # the zone has gone (its block deleted)
            return float(model.store("zones")["stress"][r, col])

        return self.add(f"zone {zone_id} {quantity}", value, name,
                        {"kind": "zone", "quantity": quantity, "zone_id": int(zone_id)})

    def add_zone_centroid(self, quantity: str, zone_id: int, name: str | None = None) -> History:
        """Displacement, velocity or position at the centroid of the zone ``zone_id``, interpolated from
        its nodes with the element's shape functions there (4-node tetrahedron: each corner 1/4; 10-node:
        corners -1/8, mid-edge nodes 1/4). NaN once the zone is gone."""
        fld, comp = GRIDPOINT_QUANTITIES[quantity]
        model = self.model
        row = _zone_row(model, zone_id)

        def value(eng) -> float:
            r = row()
            if r < 0:
                return float("nan")
            zs = model.store("zones")
            nn = int(zs["nnode"][r])
            gp = zs["gp"][r, :nn]
            w = np.full(nn, 0.25) if nn == 4 else np.concatenate([np.full(4, -0.125), np.full(6, 0.25)])
            x = w @ model.vertices[fld][gp]
            return float(np.linalg.norm(x)) if comp is None else float(x[comp])

        return self.add(f"zone {zone_id} centroid {quantity}", value, name,
                        {"kind": "zone-centroid", "quantity": quantity, "zone_id": int(zone_id)})

    def add_model(self, quantity: str, name: str | None = None) -> History:
        if quantity.startswith(("ratio", "unbalanced")):   # the measures of `model solve` (RigidEngine.criteria)
            value = lambda eng: float(eng.criteria()[quantity])   # noqa: E731
        elif quantity == "dynamic-time-total":               # `model history dynamic time-total`
            from .dynamic import dynamic_time

            value = lambda eng: dynamic_time(eng.model)           # noqa: E731
            return self.add("dynamic time-total", value, name, {"kind": "model", "quantity": quantity})
        else:
            attr = {"time-total": "time", "kinetic-energy": "kinetic"}[quantity]
            value = lambda eng: float(getattr(eng, attr))          # noqa: E731
        return self.add(f"mechanical {quantity}", value, name, {"kind": "model", "quantity": quantity})


    def add_energy(self, quantity: str, name: str | None = None) -> History:
        """`model history energy`: an energy component of ``physics.energy`` (its running sums)."""
        from .energy import value as energy_value

        model = self.model
        return self.add(f"energy {quantity}", lambda eng: energy_value(model, quantity), name,
                        {"kind": "energy", "quantity": quantity})

    def add_fish(self, var: str, name: str | None = None) -> History:
        """`fish history`: the value of a FISH global variable, or of a FISH function called at each
        sample. The FISH run time reaches the model as ``model.fish_probe(var)`` (set by the session's
        FISH commands; physics knows nothing of FISH)."""
        model = self.model

        def value(eng) -> float:
            probe = getattr(model, "fish_probe", None)
            if probe is None:
                raise ValueError(f"FISH history `{var}`: no FISH run time is attached to the model")
            return probe(var)

        return self.add(f"fish {var}", value, name, {"kind": "fish", "quantity": var})


def _energy_quantities() -> tuple:
    from .energy import QUANTITIES

    return QUANTITIES


def _zone_row(model, zone_id: int):
    """A function giving the zones-store row of the zone with id ``zone_id`` (kept between calls,
    looked up again when rows have moved), -1 once the zone is gone (its block deleted)."""
    cache = {"row": -1}

    def row() -> int:
        zs = model.store("zones")
        r = cache["row"]
        if not (0 <= r < zs.n and zs["id"][r] == zone_id):
            hit = np.flatnonzero(zs["id"] == zone_id)
            if hit.size == 0:
                return -1
            r = cache["row"] = int(hit[0])
        return r
    return row


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


def _restore_histories(model, desc: dict, arrays: dict) -> None:
    """``dec3d.io.state``'s loader of the histories in a save file (ValueError: nothing is changed)."""
    model.history_set = HistorySet.from_state(model, desc, arrays)
    histories(model)          # hooked to the restored model's engine: sampling goes on


register_known(histories=_restore_histories)


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
