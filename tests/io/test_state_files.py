"""Save / restore: exact round trip, refusal of newer or damaged files."""
import json
import math
import zipfile

import numpy as np
import pytest

from dec3d.config import SAVE_FORMAT_VERSION
from dec3d.errors import Dec3dError
from dec3d.geometry.cutting import cut_joint_set
from dec3d.geometry.polyhedron import brick
from dec3d.io.state import StateFileError, read_meta, restore_state, save_state
from dec3d.model.blocks import add_blocks, group_blocks, join_blocks
from dec3d.model.model import Model
from dec3d.model.store import Field, Store

RECORD = ["model new", "block create brick 0 2 0 2 0 2", "block cut joint-set dip 60 dip-direction 30"]


@pytest.fixture
def model():
    m = Model()
    add_blocks(m, [brick(0, 2, 0, 2, 0, 2)], density=2500.0, group="rock")
    cut_joint_set(m, math.radians(60), math.radians(30), spacing=0.7)
    group_blocks(m, m.blocks["centroid"][:, 2] > 1, "top", slot="level")
    join_blocks(m, m.blocks["id"] <= 2)
    m.settings.gravity = (0.0, 0.0, -9.81)
    m.settings.title = "round trip"
    m.tolerance = 1e-5
    extra = m.add_store(Store("contacts", {"gap": Field((), np.float64, 0.0)}))
    extra.append(3)
    extra["gap"][:] = [0.1, 0.2, 0.3]
    return m


def test_save_restore_save_is_byte_identical(model, tmp_path):
    a = save_state(model, tmp_path / "a.sav", records=RECORD)
    restored, meta = restore_state(a)
    b = save_state(restored, tmp_path / "b.sav", records=meta["records"])
    assert open(a, "rb").read() == open(b, "rb").read()
    assert meta["records"] == RECORD and meta["version"] == SAVE_FORMAT_VERSION
    assert restored is not model
    for name, store in model.stores.items():
        other = restored.store(name)
        assert other.n == store.n
        for key in store.fields:
            np.testing.assert_array_equal(other[key], store[key])
    assert restored.settings == model.settings
    assert restored.tolerance == 1e-5 and restored.next_block_id == model.next_block_id
    assert restored.groups.names == model.groups.names
    assert restored.groups.slot_names("blocks") == ["Default", "level"]


def test_arrays_are_loaded_without_pickle(model, tmp_path):
    path = save_state(model, tmp_path / "s.sav")
    with np.load(path, allow_pickle=False) as npz:
        assert "blocks.centroid" in npz.files
        np.testing.assert_array_equal(npz["blocks.centroid"], model.blocks["centroid"])


def rewrite(path, out, change):
    """A copy of a state file with ``change(name, bytes)`` applied to each member (None drops it). A
    changed meta.json gets a matching checksum in signature.json, as anyone editing the file can make:
    the deeper checks are what these tests reach (test_save_trust.py tests the checksum itself)."""
    import hashlib

    with zipfile.ZipFile(path) as zin:
        members = [(info, change(info.filename, zin.read(info.filename))) for info in zin.infolist()]
    meta = next((d for info, d in members if info.filename == "meta.json"), None)
    with zipfile.ZipFile(out, "w") as zout:
        for info, data in members:
            if info.filename == "signature.json" and data is not None and meta is not None:
                sig = json.loads(data)
                sig["meta_sha256"] = hashlib.sha256(meta).hexdigest()
                data = json.dumps(sig).encode()
            if data is not None:
                zout.writestr(info, data)
    return out


def test_newer_version_is_refused(model, tmp_path):
    path = save_state(model, tmp_path / "s.sav")

    def bump(name, data):
        if name != "meta.json":
            return data
        meta = json.loads(data)
        meta["version"] = SAVE_FORMAT_VERSION + 1
        return json.dumps(meta).encode()

    newer = rewrite(path, tmp_path / "newer.sav", bump)
    with pytest.raises(StateFileError, match="newer"):
        restore_state(newer)
    with pytest.raises(StateFileError, match="newer"):
        read_meta(newer)


def test_damaged_files_are_refused(model, tmp_path):
    path = save_state(model, tmp_path / "s.sav")

    def flip(name, data):
        if name == "blocks.volume.npy":
            data = bytearray(data)
            data[-1] ^= 0xFF
            return bytes(data)
        return data

    with pytest.raises(StateFileError, match="blocks.volume.*corrupted"):
        restore_state(rewrite(path, tmp_path / "flip.sav", flip))
    with pytest.raises(StateFileError, match="missing"):
        restore_state(rewrite(path, tmp_path / "gone.sav",
                              lambda n, d: None if n == "faces.area.npy" else d))
    raw = bytearray(open(path, "rb").read())
    raw[len(raw) // 2: len(raw) // 2 + 64] = b"\0" * 64
    (tmp_path / "zeroed.sav").write_bytes(bytes(raw))
    with pytest.raises(StateFileError):
        restore_state(tmp_path / "zeroed.sav")
    (tmp_path / "text.sav").write_text("model new\n")
    with pytest.raises(StateFileError, match="cannot read"):
        restore_state(tmp_path / "text.sav")
    with pytest.raises(StateFileError):
        restore_state(tmp_path / "absent.sav")
    other = tmp_path / "other.npz"
    np.savez(other, x=np.zeros(3))
    with pytest.raises(StateFileError, match="not a dec3d state file"):
        restore_state(other)
    assert issubclass(StateFileError, Dec3dError)


def test_inconsistent_indices_are_refused(model, tmp_path):
    import hashlib
    import io

    path = save_state(model, tmp_path / "s.sav")
    buf = io.BytesIO()
    leader = model.blocks["leader"].copy()
    leader[0] = 10_000
    np.lib.format.write_array(buf, leader)
    new = buf.getvalue()

    def break_leader(name, data):
        if name == "blocks.leader.npy":
            return new
        if name == "meta.json":       # a consistent checksum: only the index check can tell
            meta = json.loads(data)
            meta["sha256"]["blocks.leader"] = hashlib.sha256(new).hexdigest()
            return json.dumps(meta).encode()
        return data

    with pytest.raises(StateFileError, match="block leaders points outside"):
        restore_state(rewrite(path, tmp_path / "bad.sav", break_leader))
