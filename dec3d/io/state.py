"""Save and restore the whole model (``model save`` / ``model restore``).

A state file is a zip archive (numpy's ``.npz`` layout) holding:

* ``meta.json``: format name and version (``dec3d.config.SAVE_FORMAT_VERSION``), units,
  settings (``Settings.to_dict``), tolerance, next block id, group and slot names, the
  store schema (rows, dtype and shape of every field), a SHA-256 per array, the caller's
  command record list and any extra JSON data the caller passes;
* ``<store>.<field>.npy``: the live rows of every field of every store;
* ``@history.<id>.steps|times|values.npy``: the samples of each history (``meta['histories']``
  says how to make each history again: ``HistorySet.to_state``);
* ``signature.json``: the SHA-256 of ``meta.json`` and its HMAC under the user's key
  (``dec3d.io.savesign``): ``restore_state`` refuses a metadata member that fails its checksum and
  says in ``meta['signed_here']`` whether this user's key made the file.

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
import zipfile
import zlib

import numpy as np

from dec3d.config import SAVE_FORMAT_VERSION
from dec3d.errors import Dec3dError
from dec3d.io.finite import NAN_MARKERS, require_finite
from dec3d.io.savesign import MEMBER as _SIGNATURE, signature, signed_here
from dec3d.kernels.zmodels import NZPROP
from dec3d.io.state_meta import (UNSET, _HIST, _NPY_HEADER_MAX, _expected_arrays, _known, _meta_problem,
                                  _settings_problem, register_known)
from dec3d.model.groups import GroupTable
from dec3d.model.model import Model
from dec3d.model.settings import Settings
from dec3d.model.store import Field, Store

# (register_known and _settings_problem are imported from here by other modules and tests)
__all__ = ["FORMAT_NAME", "MAX_STATE_BYTES", "StateFileError", "save_state", "read_meta", "restore_state",
           "register_known", "_settings_problem"]

FORMAT_NAME = "dec3d-state"
UNITS = "SI: m, kg, s, N, Pa; angles in radians"
_META = "meta.json"
_STAMP = (1980, 1, 1, 0, 0, 0)
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
    nan_masks: dict[str, str] = {}
    for sname, store in model.stores.items():
        fields = {}
        for key, arr in store.to_arrays().items():
            name = f"{sname}.{key}"
            require_finite(name, arr)
            if name in NAN_MARKERS and np.isnan(arr).any():
                # NaN "not set" markers leave the file as 0 and a mask (no NaN in any file written)
                unset = np.isnan(arr)
                arrays[name + UNSET] = unset
                nan_masks[name] = name + UNSET
                arr = np.where(unset, 0.0, arr)
            arrays[name] = arr
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
    if nan_masks:
        meta["nan_masks"] = nan_masks
    text = json.dumps(meta, sort_keys=True, indent=1, allow_nan=False).encode("utf-8")
    from .paths import os_error_text, replace_via_temp

    def write(fh):
        with zipfile.ZipFile(fh, "w", compresslevel=6) as zf:
            zf.writestr(_member(_META), text)
            zf.writestr(_member(_SIGNATURE), json.dumps(signature(text), sort_keys=True).encode("ascii"))
            for name, b in blobs.items():
                zf.writestr(_member(name + ".npy"), b)

    try:
        # the temporary file is removed on every way out (Ctrl-C included): the old file stays whole
        replace_via_temp(path, write, ".dec3d-save-")
    except OSError as exc:
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


def _read_signature(path: str, zf: zipfile.ZipFile, meta_raw: bytes) -> dict | None:
    """The ``signature.json`` member (None in a file from before it), with the metadata's checksum
    checked."""
    try:
        info = zf.getinfo(_SIGNATURE)
    except KeyError:
        return None
    if info.file_size > 4096:
        raise StateFileError(f"'{path}': {_SIGNATURE} declares {info.file_size} bytes, more than a signature")
    try:
        sig = json.loads(zf.read(info).decode("ascii"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise StateFileError(f"'{path}': {_SIGNATURE} is corrupted ({type(exc).__name__})") from None
    if not isinstance(sig, dict) or not isinstance(sig.get("meta_sha256"), str):
        raise StateFileError(f"'{path}': {_SIGNATURE} is corrupted")
    if hashlib.sha256(meta_raw).hexdigest() != sig["meta_sha256"]:
        raise StateFileError(f"'{path}': {_META} is corrupted (checksum mismatch)")
    return sig


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
            raw = _read_meta_member(path, zf)
            sig = _read_signature(path, zf, raw)
            meta = _check_meta(path, raw)
            meta["signed_here"] = signed_here(raw, sig)
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
            mask = meta.get("nan_masks", {}).get(name)
            if arr.dtype.kind == "f":
                # NaN "not set" markers: a mask beside the array (older files: NaN in the array itself)
                finite = np.isfinite(arr) if (name not in NAN_MARKERS or mask) else ~np.isinf(arr)
                if not finite.all():
                    raise StateFileError(f"'{path}': array '{name}' holds a value that is not finite")
            if mask and arr.dtype.kind == "f":
                arr = np.where(_read_npy(path, mask, blobs[mask], shape, "|b1"), np.nan, arr)
            if key not in store:
                store.add_field(key, Field(tuple(fdesc["shape"]), arr.dtype, fdesc["fill"]))
            elif np.dtype(store.fields[key].dtype) != arr.dtype:
                raise StateFileError(f"'{path}': array '{name}' has dtype {arr.dtype.str}; this dec3d keeps "
                                     f"{np.dtype(store.fields[key].dtype).str}")
            arrays[key] = arr
        store.load_arrays(arrays)
        if sname in ("zones", "feblocks") and "prop" in store and store.fields["prop"].shape[0] < NZPROP:
            # a file from before the zone-model library (8 property columns): the models' own
            # columns are added empty
            store.resize_field("prop", (NZPROP,))
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
    need(np.isin(zs["cmodel"], [0] + sorted(_known()["zone_model_codes"])).all(),
         "a zone has an unknown constitutive model code")


def _check_feblocks(path: str, model: Model) -> None:
    """The ``feblocks`` store (dec3d.model.feblocks): node and slave rows within the vertices,
    block rows within the blocks, Gauss rule 2 or 3, known constitutive codes."""
    from dec3d.model.zones import ZMODEL_ELASTIC, ZMODEL_NULL

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
    need(np.isin(es["cmodel"], (ZMODEL_NULL, ZMODEL_ELASTIC)).all(),
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
