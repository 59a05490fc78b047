"""Save and restore the whole model (``model save`` / ``model restore``).

A state file is a zip archive (numpy's ``.npz`` layout) holding:

* ``meta.json``: format name and version (``dec3d.config.SAVE_FORMAT_VERSION``), units,
  settings (``Settings.to_dict``), tolerance, next block id, group and slot names, the
  store schema (rows, dtype and shape of every field), a SHA-256 per array, the caller's
  command record list and any extra JSON data the caller passes;
* ``<store>.<field>.npy``: the live rows of every field of every store;
* ``@history.<id>.steps|times|values.npy``: the samples of each history (``meta['histories']``
  says how to make each history again: ``HistorySet.to_state``).

Members are written in a fixed order with a fixed timestamp and compression level, so the
same model gives the same bytes: restore → save reproduces the file exactly. Arrays are
read with ``allow_pickle=False``. ``restore_state`` checks everything before it builds
anything: the metadata's types, enumerations and finite numbers, each member's declared size
against the size its schema implies (and ``MAX_STATE_BYTES`` in all) before it is
decompressed, checksums, shapes and dtypes, index ranges between stores, finite floats. A file
that is not a dec3d state, comes from a newer format version, or fails any check raises
``StateFileError``; ``restore`` builds a new ``Model`` and never touches the caller's.
"""
from __future__ import annotations

import hashlib
import io
import json
import os
import math
import re
import tempfile
import zipfile
import zlib

import numpy as np

from dec3d.config import SAVE_FORMAT_VERSION
from dec3d.errors import Dec3dError
from dec3d.io.finite import require_finite
from dec3d.model.groups import GroupTable
from dec3d.model.model import Model
from dec3d.model.settings import Settings
from dec3d.model.store import Field, Store

FORMAT_NAME = "dec3d-state"
UNITS = "SI: m, kg, s, N, Pa; angles in radians"
_META = "meta.json"
_STAMP = (1980, 1, 1, 0, 0, 0)
_HIST = "@history."
#: largest state file read, in decompressed bytes (arrays and metadata together)
MAX_STATE_BYTES = 8 * 2**30
#: largest metadata member
MAX_META_BYTES = 256 * 2**20


class StateFileError(Dec3dError):
    """A state file cannot be written or read; the model in memory is unchanged."""


def _member(name: str) -> zipfile.ZipInfo:
    zi = zipfile.ZipInfo(name, date_time=_STAMP)
    zi.compress_type = zipfile.ZIP_DEFLATED
    zi.create_system = 3
    zi.external_attr = 0o644 << 16
    return zi


def _npy_bytes(arr: np.ndarray) -> bytes:
    buf = io.BytesIO()
    np.lib.format.write_array(buf, np.ascontiguousarray(arr), version=(1, 0), allow_pickle=False)
    return buf.getvalue()


def save_state(model: Model, path: str | os.PathLike, records: list[str] | None = None,
               extra: dict | None = None) -> str:
    """Write ``model`` to ``path`` (atomically: a temporary file is renamed at the end)."""
    path = os.fspath(path)
    arrays: dict[str, np.ndarray] = {}
    schema: dict[str, dict] = {}
    for sname, store in model.stores.items():
        fields = {}
        for key, arr in store.to_arrays().items():
            require_finite(f"{sname}.{key}", arr)
            arrays[f"{sname}.{key}"] = arr
            spec = store.fields[key]
            fields[key] = {"dtype": arr.dtype.str, "shape": list(arr.shape[1:]),
                           "fill": np.asarray(spec.fill).item()}
        schema[sname] = {"n": store.n, "fields": fields}
    require_finite("time", model.time)
    hs = getattr(model, "history_set", None)
    hdesc = None
    if hs is not None:
        hdesc, harrays = hs.to_state()
        arrays.update({_HIST + k: v for k, v in harrays.items()})
    blobs = {name: _npy_bytes(arr) for name, arr in sorted(arrays.items())}
    meta = {
        "format": FORMAT_NAME,
        "version": SAVE_FORMAT_VERSION,
        "units": UNITS,
        "settings": model.settings.to_dict(),
        "tolerance": model.tolerance,
        "next_block_id": model.next_block_id,
        "time": model.time,
        "step": model.step,
        "groups": model.groups.to_dict(),
        "stores": schema,
        "sha256": {name: hashlib.sha256(b).hexdigest() for name, b in blobs.items()},
        "records": list(records or []),
        "extra": extra or {},
    }
    if hdesc is not None:
        meta["histories"] = hdesc
    text = json.dumps(meta, sort_keys=True, indent=1, allow_nan=False).encode("utf-8")
    folder = os.path.dirname(os.path.abspath(path))
    try:
        os.makedirs(folder, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=".dec3d-save-", dir=folder)
        with os.fdopen(fd, "wb") as fh, zipfile.ZipFile(fh, "w", compresslevel=6) as zf:
            zf.writestr(_member(_META), text)
            for name, b in blobs.items():
                zf.writestr(_member(name + ".npy"), b)
        from .paths import chmod_like_outputs

        chmod_like_outputs(tmp)             # mkstemp makes 0600; other outputs get 0666 less the umask
        os.replace(tmp, path)
    except OSError as exc:
        try:
            os.unlink(tmp)
        except (OSError, NameError):
            pass
        from .paths import os_error_text

        raise StateFileError(f"cannot write state file '{path}': {os_error_text(exc)}") from None
    return path


def read_meta(path: str | os.PathLike) -> dict:
    """The JSON metadata of a state file (checked for format and version)."""
    path = os.fspath(path)
    try:
        with zipfile.ZipFile(path) as zf:
            return _check_meta(path, _read_meta_member(path, zf))
    except StateFileError:
        raise
    except _READ_ERRORS as exc:
        raise StateFileError(f"cannot read state file '{path}': {_why(exc)}") from None


def _read_meta_member(path: str, zf: zipfile.ZipFile) -> bytes:
    try:
        info = zf.getinfo(_META)
    except KeyError:
        raise StateFileError(f"'{path}' is not a dec3d state file (no {_META})") from None
    if info.file_size > MAX_META_BYTES:
        raise StateFileError(f"'{path}': {_META} declares {info.file_size} bytes, more than a state file's "
                             f"metadata ({MAX_META_BYTES} at most)")
    return zf.read(info)


#: what reading a damaged zip can raise (zlib.error: corrupt compressed data; NotImplementedError:
#: an unknown compression method; RuntimeError: an encrypted member)
_READ_ERRORS = (zipfile.BadZipFile, zipfile.LargeZipFile, OSError, EOFError, zlib.error, NotImplementedError,
                RuntimeError, ValueError, KeyError, OverflowError, MemoryError)


def _why(exc: BaseException) -> str:
    if isinstance(exc, zlib.error):
        return "its compressed data is corrupted"
    if isinstance(exc, MemoryError):
        return "not enough memory"
    return getattr(exc, "strerror", None) or str(exc) or type(exc).__name__


def _check_meta(path: str, raw: bytes) -> dict:
    try:
        meta = json.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError, RecursionError) as exc:
        raise StateFileError(f"'{path}': the metadata is corrupted ({type(exc).__name__})") from None
    if not isinstance(meta, dict) or meta.get("format") != FORMAT_NAME:
        raise StateFileError(f"'{path}' is not a dec3d state file")
    version = meta.get("version")
    if not isinstance(version, int) or isinstance(version, bool):
        raise StateFileError(f"'{path}': the format version is missing")
    if version > SAVE_FORMAT_VERSION:
        raise StateFileError(
            f"'{path}' was saved in state format {version}, newer than this dec3d reads "
            f"({SAVE_FORMAT_VERSION}); use a newer dec3d")
    return meta


def restore_state(path: str | os.PathLike) -> tuple[Model, dict]:
    """Read a state file into a new ``Model``; returns it with the metadata dict
    (``meta['records']`` is the saved command record). Everything is checked first; any
    problem raises ``StateFileError`` and nothing of the caller's is touched."""
    path = os.fspath(path)
    try:
        with zipfile.ZipFile(path) as zf:
            meta = _check_meta(path, _read_meta_member(path, zf))
            bad = _meta_problem(meta)
            if bad:
                raise StateFileError(f"'{path}': the file is inconsistent: {bad}")
            names = _expected_arrays(meta)
            if set(meta["sha256"]) != set(names):
                extra = sorted(set(meta["sha256"]) ^ set(names))[:3]
                raise StateFileError(f"'{path}': the checksum list does not match the arrays ({', '.join(extra)})")
            infos = {}
            total = 0
            for name, nbytes in sorted(names.items()):
                try:
                    info = zf.getinfo(name + ".npy")
                except KeyError:
                    raise StateFileError(f"'{path}': array '{name}' is missing") from None
                # the declared size is checked before anything is decompressed (a zip bomb is refused here;
                # zipfile stops reading a member at its declared size)
                if info.file_size > nbytes + _NPY_HEADER_MAX:
                    raise StateFileError(f"'{path}': array '{name}' declares {info.file_size} bytes, its schema "
                                         f"allows {nbytes + _NPY_HEADER_MAX}")
                total += info.file_size
                infos[name] = info
            if total > MAX_STATE_BYTES:
                raise StateFileError(f"'{path}': the arrays hold {total} bytes, more than dec3d reads "
                                     f"({MAX_STATE_BYTES} at most)")
            blobs = {}
            for name, info in infos.items():
                b = zf.read(info)
                if hashlib.sha256(b).hexdigest() != meta["sha256"][name]:
                    raise StateFileError(f"'{path}': array '{name}' is corrupted (checksum mismatch)")
                blobs[name] = b
    except StateFileError:
        raise
    except _READ_ERRORS as exc:
        raise StateFileError(f"cannot read state file '{path}': {_why(exc)}") from None
    try:
        return _build(path, meta, blobs), meta
    except StateFileError:
        raise
    except (KeyError, TypeError, ValueError, IndexError, OverflowError) as exc:
        raise StateFileError(f"'{path}': the file is inconsistent ({exc})") from None


#: room for the .npy header (format 1.0 pads it to a multiple of 64 bytes; dtype and shape are short)
_NPY_HEADER_MAX = 4096
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,63}\Z")
_DTYPE_KINDS = "fiub"


def _is_int(v) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def _is_num(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _expected_arrays(meta: dict) -> dict[str, int]:
    """Array name -> the data bytes its schema implies (``_meta_problem`` has passed)."""
    out = {}
    for sname, sdesc in meta["stores"].items():
        for key, fdesc in sdesc["fields"].items():
            n = int(sdesc["n"])
            for d in fdesc["shape"]:
                n *= int(d)
            out[f"{sname}.{key}"] = n * np.dtype(fdesc["dtype"]).itemsize
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
    if not {"joint_models", "joint_model_codes", "histories", "energy_problem"} <= KNOWN.keys():
        # a restore called before anything imported the physics layer (e.g. ``dec3d.io.state``
        # used on its own): load the registering modules by name, which keeps the import arrows
        # of the layers (physics -> io) as they are
        import importlib
        for name in ("dec3d.physics.jmodels", "dec3d.physics.history", "dec3d.physics.energy"):
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
    choices = {"damping": ("local", "combined", "global", "none", "rayleigh"), "mass_scale": ("on", "off", "auto"),
               "scaling": ("eq87", "body", "raised", "auto"),
               "inertia": ("full", "scalar", "auto"), "jmodel": tuple(sorted(_known()["joint_models"]))}
    for k, options in choices.items():
        if k in m and m[k] not in options:
            return f"mechanical setting `{k}` is {m[k]!r}, not one of {', '.join(options)}"
    checks = {"alpha": lambda v: _is_num(v) and 0 <= v < 1,
              "frac": lambda v: _is_num(v) and v > 0,
              "servo_ratio": lambda v: _is_num(v) and v > 0,
              "dynamic": lambda v: isinstance(v, bool),
              "dt_mode": lambda v: isinstance(v, list) and len(v) == 2 and isinstance(v[0], bool) and _is_num(v[1]),
              "dyn_time": lambda v: _is_num(v) and v >= 0,
              "rayleigh": lambda v: isinstance(v, list) and (v == [] or (
                  len(v) == 3 and _is_num(v[0]) and 0 <= v[0] < 1 and _is_num(v[1]) and v[1] >= 0
                  and v[2] in ("both", "mass", "stiffness"))),
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


def _build(path: str, meta: dict, blobs: dict[str, bytes]) -> Model:
    model = Model()
    model.settings = Settings.from_dict(meta["settings"])
    model.tolerance = float(meta["tolerance"])
    model.next_block_id = int(meta["next_block_id"])
    model.time = float(meta["time"])
    model.step = int(meta["step"])
    model.groups = GroupTable.from_dict(meta["groups"])
    for sname, sdesc in meta["stores"].items():
        stores = model.stores
        if sname not in stores:
            model.add_store(Store(sname, {}))
        store = model.stores[sname]
        arrays = {}
        for key, fdesc in sdesc["fields"].items():
            name = f"{sname}.{key}"
            shape = (int(sdesc["n"]), *fdesc["shape"])
            arr = _read_npy(path, name, blobs[name], shape, fdesc["dtype"])
            if arr.dtype.kind == "f":
                finite = np.isfinite(arr) if name != "contacts.prop" else ~np.isinf(arr)  # NaN: "not set"
                if not finite.all():
                    raise StateFileError(f"'{path}': array '{name}' holds a value that is not finite")
            if key not in store:
                store.add_field(key, Field(tuple(fdesc["shape"]), arr.dtype, fdesc["fill"]))
            elif np.dtype(store.fields[key].dtype) != arr.dtype:
                raise StateFileError(f"'{path}': array '{name}' has dtype {arr.dtype.str}; this dec3d keeps "
                                     f"{np.dtype(store.fields[key].dtype).str}")
            arrays[key] = arr
        store.load_arrays(arrays)
    if "origin" not in meta["stores"].get("vertices", {}).get("fields", {"origin": 0}):
        # a file from before vertices had an origin: take each vertex as having moved with its block's centroid
        v = model.vertices
        v["origin"][:] = v["pos"] - model.blocks["disp"][np.clip(v["block"], 0, None)] if model.blocks.n else v["pos"]
    _check_geometry(path, model)
    _check_contacts(path, model)
    _check_zones(path, model)
    _check_feblocks(path, model)
    h = meta.get("histories")
    if h is not None:
        harrays = {}
        for it in h["items"]:
            for k in ("steps", "times", "values"):
                name = f"{_HIST}{it['id']}.{k}"
                harrays[f"{it['id']}.{k}"] = _read_npy(path, name, blobs[name], None,
                                                       "<i8" if k == "steps" else "<f8")
        try:
            _known()["histories"](model, h, harrays)    # hooked to the restored engine: sampling goes on
        except ValueError as exc:
            raise StateFileError(f"'{path}': {exc}") from None
    return model


def _read_npy(path: str, name: str, blob: bytes, shape, dtype: str) -> np.ndarray:
    """One ``.npy`` member, its header checked against the schema before any array is made
    (``shape`` None: any 1-D length the member's bytes can hold)."""
    f = io.BytesIO(blob)
    fmt = np.lib.format
    try:
        version = fmt.read_magic(f)
        if version == (1, 0):
            got, fortran, dt = fmt.read_array_header_1_0(f)
        elif version == (2, 0):
            got, fortran, dt = fmt.read_array_header_2_0(f)
        else:
            raise ValueError(f"npy format {version}")
    except (ValueError, SyntaxError, TypeError, EOFError) as exc:
        raise StateFileError(f"'{path}': array '{name}' has a malformed header ({exc})") from None
    fits = (got == tuple(shape)) if shape is not None else (len(got) == 1 and got[0] * 8 <= len(blob))
    if not fits or dt.str != dtype or fortran:
        raise StateFileError(f"'{path}': array '{name}' has shape {got} {dt.str}, expected "
                             f"{tuple(shape) if shape is not None else '(n,)'} {dtype}")
    f.seek(0)
    return fmt.read_array(f, allow_pickle=False)


def _check_geometry(path: str, model: Model) -> None:
    """Indices between the geometry stores must point at live rows."""
    b, v, f, fv = model.blocks, model.vertices, model.faces, model.face_vertices

    def within(name, lo, hi, limit):
        if len(lo) and (lo.min() < 0 or hi.max() > limit or (hi < lo).any()):
            raise StateFileError(f"'{path}': {name} points outside its store")

    within("block vertex ranges", b["vert_start"], b["vert_start"] + b["vert_count"], v.n)
    within("block face ranges", b["face_start"], b["face_start"] + b["face_count"], f.n)
    within("face loops", f["vstart"], f["vstart"] + f["nvert"], fv.n)
    within("face vertices", fv["vertex"], fv["vertex"] + 1, v.n)
    within("block leaders", b["leader"], b["leader"] + 1, b.n)
    within("vertex owners", v["block"], v["block"] + 1, b.n)
    within("face owners", f["block"], f["block"] + 1, b.n)
    for store in (b, f):
        g = store["group"].ravel() + 1
        within(f"{store.name} group codes", g, g, len(model.groups.names))


def _check_zones(path: str, model: Model) -> None:
    """The ``zones`` store (dec3d.model.zones): gridpoint rows within the vertices, block rows
    within the blocks, gridpoint links valid, 4- or 10-node zones, known constitutive codes."""
    from dec3d.model.zones import ZMODEL_ELASTIC, ZMODEL_MOHR, ZMODEL_NULL

    v, nb = model.vertices, model.blocks.n

    def need(ok, what):
        if not ok:
            raise StateFileError(f"'{path}': {what}")

    if "link" in v and v.n:
        link = v["link"]
        need(((link == -1) | ((link >= 0) & (link < v.n))).all(), "a gridpoint link points outside the vertices")
    if "zones" not in model.stores:
        return
    zs = model.store("zones")
    if not zs.n:
        return
    for key in ("block", "gp", "nnode", "cmodel"):
        need(key in zs, f"the zones store lacks its '{key}' field")
    need(zs["block"].min() >= 0 and zs["block"].max() < nb, "zone block rows point outside the blocks")
    nn = zs["nnode"]
    need(np.isin(nn, (4, 10)).all(), "a zone has a node count other than 4 or 10")
    gp = zs["gp"]
    used = np.arange(10)[None, :] < nn[:, None].astype(np.int64)
    need(((gp[used] >= 0) & (gp[used] < v.n)).all(), "zone gridpoint rows point outside the vertices")
    need((gp[~used] == -1).all(), "a zone has gridpoint rows past its node count")
    need(np.isin(zs["cmodel"], (ZMODEL_NULL, ZMODEL_ELASTIC, ZMODEL_MOHR)).all(),
         "a zone has an unknown constitutive model code")


def _check_feblocks(path: str, model: Model) -> None:
    """The ``feblocks`` store (dec3d.model.feblocks): node and slave rows within the vertices,
    block rows within the blocks, Gauss rule 2 or 3, known constitutive codes."""
    from dec3d.model.zones import ZMODEL_ELASTIC, ZMODEL_MOHR, ZMODEL_NULL

    if "feblocks" not in model.stores or not model.store("feblocks").n:
        return
    es, nv = model.store("feblocks"), model.vertices.n

    def need(ok, what):
        if not ok:
            raise StateFileError(f"'{path}': {what}")

    for key in ("block", "nodes", "slaves", "nq", "cmodel"):
        need(key in es, f"the feblocks store lacks its '{key}' field")
    need(es["block"].min() >= 0 and es["block"].max() < model.blocks.n, "FE element block rows point outside the blocks")
    need(es["nodes"].min() >= 0 and es["nodes"].max() < nv, "FE element node rows point outside the vertices")
    s = es["slaves"]
    need(((s == -1) | ((s >= 0) & (s < nv))).all(), "FE element slave rows point outside the vertices")
    need(np.isin(es["nq"], (2, 3)).all(), "an FE element has a Gauss rule other than 2 or 3")
    need(np.isin(es["cmodel"], (ZMODEL_NULL, ZMODEL_ELASTIC, ZMODEL_MOHR)).all(),
         "an FE element has an unknown constitutive model code")


def _check_contacts(path: str, model: Model) -> None:
    """Indices of the rigid engine's contact stores must point at live rows; codes must be known."""
    stores = model.stores
    if "contacts" not in stores:
        return
    c = stores["contacts"]
    sc = stores.get("subcontacts")
    nb = model.blocks.n
    nsc = sc.n if sc is not None else 0

    def need(ok, what):
        if not ok:
            raise StateFileError(f"'{path}': {what}")

    if c.n:
        for key in ("a", "b"):
            if key in c:
                need(c[key].min() >= 0 and c[key].max() < nb, f"contact block rows ({key}) point outside the blocks")
        if "sub_start" in c and "sub_count" in c:
            s0, k = c["sub_start"], c["sub_count"]
            need(s0.min() >= 0 and k.min() >= 0 and (s0 + k).max() <= nsc,
                 "contact sub-contact ranges point outside the sub-contacts")
        if "jmodel" in c:
            need(np.isin(c["jmodel"], sorted(_known()["joint_model_codes"])).all(), "a contact has an unknown joint model code")
        if "type" in c:
            need(c["type"].min() >= 0 and c["type"].max() <= 6, "a contact has an unknown contact type")
    if sc is not None and sc.n:
        if "contact" in sc:
            need(sc["contact"].min() >= 0 and sc["contact"].max() < c.n,
                 "sub-contact owners point outside the contacts")
        if "kind" in sc:
            need(sc["kind"].min() >= 0 and sc["kind"].max() <= 3, "a sub-contact has an unknown kind")
    nv = model.vertices.n
    for st, what in ((c, "contact"), (sc, "sub-contact")):
        if st is None or not st.n:
            continue
        for key in ("gp_a", "gp_b"):
            if key in st:
                g = st[key]
                need(((g == -1) | ((g >= 0) & (g < nv))).all(),
                     f"{what} surface gridpoints ({key}) point outside the vertices")
