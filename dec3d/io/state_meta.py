"""Checks of a state file's metadata before anything is built (``io.state.restore_state``): types,
enumerations and finite numbers of every setting, the arrays the schema implies, and the registry
of setting values other modules add (``register_known``)."""
from __future__ import annotations

import json
import math
import re

import numpy as np

_HIST = "@history."          # prefix of the history members (io.state)

_NPY_HEADER_MAX = 4096
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,63}\Z")
_DTYPE_KINDS = "fiub"


def _is_int(v) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def _is_num(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


#: suffix of the mask array saved beside an array holding NaN "not set" markers (io.finite.NAN_MARKERS)
UNSET = "~unset"


def _expected_arrays(meta: dict) -> dict[str, int]:
    """Array name -> the data bytes its schema implies (``_meta_problem`` has passed)."""
    out = {}
    for sname, sdesc in meta["stores"].items():
        for key, fdesc in sdesc["fields"].items():
            n = int(sdesc["n"])
            for d in fdesc["shape"]:
                n *= int(d)
            out[f"{sname}.{key}"] = n * np.dtype(fdesc["dtype"]).itemsize
    for name, mask in meta.get("nan_masks", {}).items():
        out[mask] = out[name] // 8           # one byte per float64 of the array it masks
    h = meta.get("histories")
    if h is not None:
        for it in h["items"]:
            for k in ("steps", "times", "values"):
                # samples are taken at batch ends, at most one per step and per interval change: a generous
                # bound that still refuses an absurd declared size
                out[f"{_HIST}{it['id']}.{k}"] = 16 * (int(meta["step"]) + 2)
    return out


def _meta_problem(meta: dict) -> str | None:
    """What is wrong with the metadata's shape, types, enumerations and numbers (None: nothing)."""
    need = {"settings": dict, "groups": dict, "stores": dict, "sha256": dict, "records": list}
    for k, t in need.items():
        if not isinstance(meta.get(k), t):
            return f"`{k}` is missing or not a{'n object' if t is dict else ' list'}"
    if not all(isinstance(r, str) for r in meta["records"]):
        return "the command record holds something other than text"
    if not isinstance(meta.get("extra", {}), dict):
        return "`extra` is not an object"
    masks = meta.get("nan_masks", {})
    known = {f"{s}.{k}" for s, d in meta["stores"].items() if isinstance(d, dict)
             for k in (d.get("fields") if isinstance(d.get("fields"), dict) else {})}
    if not (isinstance(masks, dict) and all(isinstance(k, str) and k in known and v == k + UNSET
                                            for k, v in masks.items())):
        return "`nan_masks` does not name arrays of the file"
    tol = meta.get("tolerance")
    if not (_is_num(tol) and tol > 0):
        return f"the tolerance {tol!r} is not a finite number > 0"
    nb = meta.get("next_block_id")
    if not (_is_int(nb) and nb >= 1):
        return f"the next block id {nb!r} is not a whole number ≥ 1"
    t = meta.get("time", 0.0)
    if not (_is_num(t) and t >= 0):
        return f"the time {t!r} is not a finite number ≥ 0"
    st = meta.get("step", 0)
    if not (_is_int(st) and st >= 0):
        return f"the step {st!r} is not a whole number ≥ 0"
    meta.setdefault("time", 0.0)
    meta.setdefault("step", 0)
    g = meta["groups"]
    if not (isinstance(g.get("names", []), list) and all(isinstance(x, str) for x in g.get("names", []))):
        return "the group names are not a list of text"
    slots = g.get("slots", {})
    if not (isinstance(slots, dict) and all(isinstance(v, list) and all(isinstance(x, str) for x in v)
                                            for v in slots.values())):
        return "the group slots are not lists of text"
    for sname, sdesc in meta["stores"].items():
        if not _NAME.match(sname):
            return f"store name {sname!r} is not a plain name"
        if not (isinstance(sdesc, dict) and _is_int(sdesc.get("n")) and sdesc["n"] >= 0
                and isinstance(sdesc.get("fields"), dict)):
            return f"store '{sname}': its row count or field list is malformed"
        for key, fdesc in sdesc["fields"].items():
            if not _NAME.match(key) or not isinstance(fdesc, dict):
                return f"store '{sname}': field {key!r} is malformed"
            try:
                dt = np.dtype(fdesc.get("dtype"))
            except (TypeError, ValueError, SyntaxError):
                return f"store '{sname}': field '{key}' has an unknown dtype"
            if dt.kind not in _DTYPE_KINDS or dt.itemsize > 8 or dt.str != fdesc["dtype"]:
                return f"store '{sname}': field '{key}' has dtype {fdesc['dtype']!r} (plain numbers only)"
            shape = fdesc.get("shape")
            if not (isinstance(shape, list) and len(shape) <= 3 and all(_is_int(d) and 0 <= d <= 2**20
                                                                         for d in shape)):
                return f"store '{sname}': field '{key}' has shape {shape!r}"
            fill = fdesc.get("fill")
            if not (isinstance(fill, (int, float, bool)) and (isinstance(fill, bool) or math.isfinite(fill))):
                return f"store '{sname}': field '{key}' has fill {fill!r}"
        if sdesc["n"] > 2**40:
            return f"store '{sname}': {sdesc['n']} rows"
    for name, digest in meta["sha256"].items():
        if not (isinstance(digest, str) and re.fullmatch(r"[0-9a-f]{64}", digest)):
            return f"the checksum of '{name}' is malformed"
    h = meta.get("histories")
    if h is not None:
        if not (isinstance(h, dict) and _is_int(h.get("interval")) and h["interval"] >= 1
                and isinstance(h.get("items"), list)
                and all(isinstance(it, dict) and _is_int(it.get("id")) and it["id"] >= 1 for it in h["items"])):
            return "the history list is malformed"
    return _settings_problem(meta["settings"])


#: What a save file may name that a higher layer defines (the import arrows run physics -> io, so
#: physics registers it here when imported: ``physics.jmodels`` the joint models' names and codes,
#: ``physics.history`` how histories are made again from their description).
KNOWN: dict = {}


def register_known(**entries) -> None:
    """Called by the physics layer at import: ``joint_models`` (names), ``joint_model_codes``,
    ``histories`` (``load(model, desc, arrays)``, raising ValueError naming what is wrong)."""
    for k, v in entries.items():
        if isinstance(v, (set, frozenset)):
            KNOWN.setdefault(k, set()).update(v)
        else:
            KNOWN[k] = v


def _known() -> dict:
    if not {"joint_models", "joint_model_codes", "zone_model_codes", "histories", "energy_problem"} <= KNOWN.keys():
        # a restore called before anything imported the physics layer (e.g. ``dec3d.io.state``
        # used on its own): load the registering modules by name, which keeps the import arrows
        # of the layers (physics -> io) as they are
        import importlib
        for name in ("dec3d.physics.jmodels", "dec3d.physics.cmodels", "dec3d.physics.history",
                     "dec3d.physics.energy"):
            importlib.import_module(name)
    return KNOWN


def _settings_problem(d: dict) -> str | None:
    if not isinstance(d.get("title", ""), str):
        return "the title is not text"
    g = d.get("gravity", [0, 0, 0])
    if not (isinstance(g, list) and len(g) == 3 and all(_is_num(x) for x in g)):
        return f"gravity {g!r} is not 3 finite numbers"
    if not isinstance(d.get("large_strain", False), bool):
        return "large-strain is not true or false"
    c = d.get("configure", [])
    if not (isinstance(c, list) and all(isinstance(x, str) for x in c)):
        return "the configure list is not a list of text"
    ui = d.get("update_interval", 10)
    if not (_is_int(ui) and ui >= 1):
        return f"the update interval {ui!r} is not a whole number ≥ 1"
    m = d.get("mechanical", {})
    if not isinstance(m, dict):
        return "the mechanical settings are not an object"
    choices = {"damping": ("local", "combined", "global", "none", "rayleigh", "maxwell"), "mass_scale": ("on", "off", "auto"),
               "scaling": ("eq87", "body", "raised", "auto"),
               "inertia": ("full", "scalar", "auto"), "jmodel": tuple(sorted(_known()["joint_models"]))}
    for k, options in choices.items():
        if k in m and m[k] not in options:
            return f"mechanical setting `{k}` is {m[k]!r}, not one of {', '.join(options)}"
    checks = {"alpha": lambda v: _is_num(v) and 0 <= v < 1,
              "frac": lambda v: _is_num(v) and v > 0,
              "servo_ratio": lambda v: _is_num(v) and v > 0,
              "dynamic": lambda v: isinstance(v, bool),
              "dt_mode": lambda v: (isinstance(v, list) and len(v) in (2, 3) and isinstance(v[0], bool)
                                    and all(_is_num(x) for x in v[1:])),
              "dyn_time": lambda v: _is_num(v) and v >= 0,
              "rayleigh": lambda v: isinstance(v, list) and (v == [] or (
                  len(v) == 3 and _is_num(v[0]) and 0 <= v[0] < 1 and _is_num(v[1]) and v[1] >= 0
                  and v[2] in ("both", "mass", "stiffness"))),
              "maxwell": lambda v: isinstance(v, list) and len(v) <= 4 and all(
                  isinstance(p, list) and len(p) == 2 and _is_num(p[0]) and 0 <= p[0] < 0.5 and _is_num(p[1])
                  and p[1] > 0 for p in v),
              "timefns": _timefns_ok,
              "safety": lambda v: v is None or (_is_num(v) and 0 < v < 1),
              "ctol": lambda v: v is None or (_is_num(v) and v > 0),
              "timestep": lambda v: v is None or (_is_num(v) and v >= 0),
              "scale_timestep": lambda v: v is None or (_is_num(v) and v > 0),
              "servo": lambda v: isinstance(v, list) and len(v) <= 2**20 and all(_is_num(x) for x in v),
              "dt_run": lambda v: isinstance(v, list) and (v == [] or (len(v) == 2 and _is_num(v[0]) and v[0] > 0
                                                                        and _is_int(v[1]) and v[1] >= 0)),
              "props": lambda v: isinstance(v, dict) and all(isinstance(k, str) and _is_num(x) for k, x in v.items()),
              "signature": lambda v: isinstance(v, list) and all(_is_int(x) for x in v),
              "mtables": lambda v: isinstance(v, list) and all(_mtable_ok(t) for t in v),
              "face_tables": lambda v: isinstance(v, list) and all(_face_table_ok(t) for t in v),
              "grid": lambda v: (isinstance(v, list) and len(v) == 3 and isinstance(v[0], list) and len(v[0]) == 3
                                 and all(_is_num(x) for x in v[0]) and _is_num(v[1]) and v[1] > 0
                                 and isinstance(v[2], list) and len(v[2]) == 3
                                 and all(_is_int(x) and 1 <= x <= 2**21 for x in v[2]))}
    for k, ok in checks.items():
        if k in m and not ok(m[k]):
            return f"mechanical setting `{k}` has the value {_short(m[k])}, which is not allowed"
    if "energy" in m:
        why = _known()["energy_problem"](m["energy"])
        if why:
            return f"the energy record {why}"
    return None


def _timefns_ok(v) -> bool:
    """The time functions of applied conditions (checked by ``physics.dynamic``, registered at import)."""
    if "timefns_problem" not in KNOWN:
        import importlib
        importlib.import_module("dec3d.physics.dynamic")
    return KNOWN["timefns_problem"](v) is None


def _mtable_ok(t) -> bool:
    """One `block contact material-table add` entry of the mechanical settings."""
    return (isinstance(t, dict) and _is_int(t.get("id")) and t.get("jmodel") in _known()["joint_models"]
            and isinstance(t.get("props"), dict)
            and all(isinstance(k, str) and _is_num(x) for k, x in t["props"].items())
            and (t.get("groups") is None or (isinstance(t["groups"], list) and len(t["groups"]) == 2
                                             and all(isinstance(g, str) for g in t["groups"])))
            and (t.get("slot") is None or isinstance(t["slot"], str)))


def _face_table_ok(t) -> bool:
    """One table of `block face apply … table` (``dec3d.model.quiet``): id, x increasing, as many y."""
    return (isinstance(t, dict) and (_is_int(t.get("id")) or isinstance(t.get("id"), str))
            and isinstance(t.get("x"), list) and isinstance(t.get("y"), list) and 1 <= len(t["x"]) == len(t["y"])
            and all(_is_num(x) for x in t["x"] + t["y"]) and all(a < b for a, b in zip(t["x"], t["x"][1:])))


def _short(v) -> str:
    s = json.dumps(v)
    return s if len(s) <= 60 else s[:59] + "…"
