"""Save and restore the whole model (``model save`` / ``model restore``).

A state file is a zip archive (numpy's ``.npz`` layout) holding:

* ``meta.json``: format name and version (``dec3d.config.SAVE_FORMAT_VERSION``), units,
  settings (``Settings.to_dict``), tolerance, next block id, group and slot names, the
  store schema (rows, dtype and shape of every field), a SHA-256 per array, the caller's
  command record list and any extra JSON data the caller passes;
* ``<store>.<field>.npy``: the live rows of every field of every store.

Members are written in a fixed order with a fixed timestamp and compression level, so the
same model gives the same bytes: restore → save reproduces the file exactly. Arrays are
read with ``allow_pickle=False``. A file that is not a dec3d state, comes from a newer
format version, or fails any check raises ``StateFileError``; ``restore`` builds a new
``Model`` and never touches the caller's.
"""
from __future__ import annotations

import hashlib
import io
import json
import os
import tempfile
import zipfile

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
    text = json.dumps(meta, sort_keys=True, indent=1, allow_nan=False).encode("utf-8")
    folder = os.path.dirname(os.path.abspath(path))
    try:
        os.makedirs(folder, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=".dec3d-save-", dir=folder)
        with os.fdopen(fd, "wb") as fh, zipfile.ZipFile(fh, "w", compresslevel=6) as zf:
            zf.writestr(_member(_META), text)
            for name, b in blobs.items():
                zf.writestr(_member(name + ".npy"), b)
        os.replace(tmp, path)
    except OSError as exc:
        raise StateFileError(f"cannot write state file '{path}': {exc.strerror or exc}") from exc
    return path


def read_meta(path: str | os.PathLike) -> dict:
    """The JSON metadata of a state file (checked for format and version)."""
    path = os.fspath(path)
    try:
        with zipfile.ZipFile(path) as zf:
            return _check_meta(path, zf.read(_META))
    except KeyError:
        raise StateFileError(f"'{path}' is not a dec3d state file (no {_META})") from None
    except (zipfile.BadZipFile, OSError, EOFError) as exc:
        raise StateFileError(f"cannot read state file '{path}': {exc}") from exc


def _check_meta(path: str, raw: bytes) -> dict:
    try:
        meta = json.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise StateFileError(f"'{path}': the metadata is corrupted ({exc})") from exc
    if not isinstance(meta, dict) or meta.get("format") != FORMAT_NAME:
        raise StateFileError(f"'{path}' is not a dec3d state file")
    version = meta.get("version")
    if not isinstance(version, int):
        raise StateFileError(f"'{path}': the format version is missing")
    if version > SAVE_FORMAT_VERSION:
        raise StateFileError(
            f"'{path}' was saved in state format {version}, newer than this dec3d reads "
            f"({SAVE_FORMAT_VERSION}); use a newer dec3d")
    return meta


def restore_state(path: str | os.PathLike) -> tuple[Model, dict]:
    """Read a state file into a new ``Model``; returns it with the metadata dict
    (``meta['records']`` is the saved command record)."""
    path = os.fspath(path)
    try:
        with zipfile.ZipFile(path) as zf:
            if _META not in zf.namelist():
                raise StateFileError(f"'{path}' is not a dec3d state file (no {_META})")
            meta = _check_meta(path, zf.read(_META))
            members = set(zf.namelist())
            blobs = {}
            for name in sorted(meta.get("sha256", {})):
                if name + ".npy" not in members:
                    raise StateFileError(f"'{path}': array '{name}' is missing")
                blobs[name] = zf.read(name + ".npy")
    except StateFileError:
        raise
    except (zipfile.BadZipFile, OSError, EOFError, KeyError, ValueError) as exc:
        raise StateFileError(f"cannot read state file '{path}': {exc}") from exc
    try:
        return _build(path, meta, blobs), meta
    except StateFileError:
        raise
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise StateFileError(f"'{path}': the file is inconsistent ({exc})") from exc


def _build(path: str, meta: dict, blobs: dict[str, bytes]) -> Model:
    for name, b in blobs.items():
        if hashlib.sha256(b).hexdigest() != meta["sha256"][name]:
            raise StateFileError(f"'{path}': array '{name}' is corrupted (checksum mismatch)")
    model = Model()
    model.settings = Settings.from_dict(meta["settings"])
    model.tolerance = float(meta["tolerance"])
    model.next_block_id = int(meta["next_block_id"])
    model.time = float(meta.get("time", 0.0))
    model.step = int(meta.get("step", 0))
    model.groups = GroupTable.from_dict(meta["groups"])
    for sname, sdesc in meta["stores"].items():
        stores = model.stores
        if sname not in stores:
            model.add_store(Store(sname, {}))
        store = model.stores[sname]
        arrays = {}
        for key, fdesc in sdesc["fields"].items():
            name = f"{sname}.{key}"
            if name not in blobs:
                raise StateFileError(f"'{path}': array '{name}' is missing")
            arr = np.lib.format.read_array(io.BytesIO(blobs[name]), allow_pickle=False)
            shape = (int(sdesc["n"]), *fdesc["shape"])
            if arr.shape != shape or arr.dtype.str != fdesc["dtype"]:
                raise StateFileError(f"'{path}': array '{name}' has shape {arr.shape} "
                                     f"{arr.dtype.str}, expected {shape} {fdesc['dtype']}")
            if key not in store:
                store.add_field(key, Field(tuple(fdesc["shape"]), arr.dtype, fdesc["fill"]))
            arrays[key] = arr
        store.load_arrays(arrays)
    if "origin" not in meta["stores"].get("vertices", {}).get("fields", {"origin": 0}):
        # a file from before vertices had an origin: take each vertex as having moved with its block's centroid
        v = model.vertices
        v["origin"][:] = v["pos"] - model.blocks["disp"][np.clip(v["block"], 0, None)] if model.blocks.n else v["pos"]
    _check_geometry(path, model)
    return model


def _check_geometry(path: str, model: Model) -> None:
    """Indices between the geometry stores must point at live rows."""
    b, v, f, fv = model.blocks, model.vertices, model.faces, model.face_vertices

    def within(name, lo, hi, limit):
        if len(lo) and (lo.min() < 0 or hi.max() > limit):
            raise StateFileError(f"'{path}': {name} points outside its store")

    within("block vertex ranges", b["vert_start"], b["vert_start"] + b["vert_count"], v.n)
    within("block face ranges", b["face_start"], b["face_start"] + b["face_count"], f.n)
    within("face loops", f["vstart"], f["vstart"] + f["nvert"], fv.n)
    within("face vertices", fv["vertex"], fv["vertex"] + 1, v.n)
    within("block leaders", b["leader"], b["leader"] + 1, b.n)
    for store in (b, f):
        g = store["group"].ravel() + 1
        within(f"{store.name} group codes", g, g, len(model.groups.names))
