"""`model restore` refuses hostile or damaged save files before it changes anything, carries the
histories, and restore → save gives the same bytes.

Each hostile file is a real save file with one thing changed (the checksums of changed arrays are
made right again, so the check under test is the one that must catch it). Every case asserts the
exact message and that the session's model, record and files are as before.
"""
import io
import json
import math
import os
import shutil
import zipfile

import numpy as np
import pytest

from dec3d.errors import Dec3dError
from dec3d.io import state
from dec3d.physics.jmodels import JOINT_MODELS
from dec3d.session import Session

DECK = """model new
block create brick 0 1 0 1 -1 0
block create brick 0 1 0 1 0 1
block property density 2000
model gravity 0 0 -10
block contact jmodel assign mohr
block contact property stiffness-normal 1e8 stiffness-shear 1e8 friction 30
block fix range position-z -1 0
block history displacement-z position 0.5 0.5 0.5
block history name 'am' angular-momentum position 0.5 0.5 0.5
block contact history force-normal position 0.5 0.5 0
model history mechanical ratio
model cycle 40
model save 'good'
"""


@pytest.fixture(scope="module")
def good(tmp_path_factory):
    """A save file with blocks, contacts, sub-contacts and four kinds of histories."""
    d = tmp_path_factory.mktemp("good")
    s = Session(out_dir=d, stdout=io.StringIO())
    s.run_items(s.load_text(DECK))
    return d / "good.sav"


def _members(path):
    with zipfile.ZipFile(path) as zf:
        return {n: zf.read(n) for n in zf.namelist()}


def _rewrite(src, dst, meta_fn=None, arrays=None):
    """Copy save file `src` to `dst`, with meta_fn(meta) applied and arrays replaced (checksums made right,
    the metadata's in signature.json too)."""
    members = _members(src)
    meta = json.loads(members.pop("meta.json"))
    for name, arr in (arrays or {}).items():
        blob = state._npy_bytes(arr)
        members[name + ".npy"] = blob
        meta["sha256"][name] = __import__("hashlib").sha256(blob).hexdigest()
    if meta_fn:
        meta_fn(meta)
    raw = json.dumps(meta, sort_keys=True, indent=1).encode()
    if "signature.json" in members:             # the metadata's checksum made right too
        sig = json.loads(members["signature.json"])
        sig["meta_sha256"] = __import__("hashlib").sha256(raw).hexdigest()
        members["signature.json"] = json.dumps(sig).encode()
    with zipfile.ZipFile(dst, "w") as zf:
        zf.writestr(state._member("meta.json"), raw)
        for n, b in sorted(members.items()):
            zf.writestr(state._member(n), b)
    return dst


def _array(path, name):
    return np.lib.format.read_array(io.BytesIO(_members(path)[name + ".npy"]))


@pytest.fixture
def victim(tmp_path):
    """A session holding its own small model and record: what a failed restore must leave alone."""
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.run_items(s.load_text("block create brick 0 2 0 2 0 2\nblock property density 1234\n"))
    return s


def _restore_fails(victim, bad_file, message):
    before_model, before_record = victim.model, list(victim.record)
    before = state.save_state(victim.model, victim.out_dir / "before.sav", records=victim.record)
    files = sorted(os.listdir(victim.out_dir))
    with pytest.raises(Dec3dError) as e:
        victim.run_items(victim.load_text(f"model restore '{bad_file.name}'\n"))
    assert e.value.message == message
    assert e.value.location.line == 1 and e.value.location.column == 15
    assert victim.model is before_model and victim.record == before_record
    after = state.save_state(victim.model, victim.out_dir / "after.sav", records=victim.record)
    assert open(before, "rb").read() == open(after, "rb").read()
    assert sorted(os.listdir(victim.out_dir)) == sorted(files + ["after.sav"])


def _set(path, value):
    def fn(meta):
        d = meta
        for k in path[:-1]:
            d = d[k]
        d[path[-1]] = value
    return fn


META_CASES = [
    (("settings", "mechanical", "damping"), "bogus",
     "mechanical setting `damping` is 'bogus', not one of local, combined, global, none, rayleigh, maxwell"),
    (("settings", "mechanical", "jmodel"), "magic",
     "mechanical setting `jmodel` is 'magic', not one of " + ", ".join(sorted(JOINT_MODELS))),
    (("settings", "mechanical", "frac"), "abc",
     'mechanical setting `frac` has the value "abc", which is not allowed'),
    (("settings", "mechanical", "alpha"), 1.5,
     "mechanical setting `alpha` has the value 1.5, which is not allowed"),
    (("settings", "mechanical", "dyn_time"), -2.0,
     "mechanical setting `dyn_time` has the value -2.0, which is not allowed"),
    (("settings", "mechanical", "rayleigh"), [0.05, 10, "both", 1],
     "mechanical setting `rayleigh` has the value [0.05, 10, \"both\", 1], which is not allowed"),
    (("settings", "mechanical", "timefns"), [{"on": "block", "kind": "velocity", "comp": 5, "ids": [1],
                                              "value": 1.0, "last": 0.0, "table": 1, "fish": None}],
     'mechanical setting `timefns` has the value [{"comp": 5, "fish": null, "ids": [1], "kind": "velocity", …, '
     'which is not allowed'),
    (("settings", "gravity"), [0, 0, "down"], "gravity [0, 0, 'down'] is not 3 finite numbers"),
    (("time",), math.nan, "the time nan is not a finite number ≥ 0"),
    (("tolerance",), -1.0, "the tolerance -1.0 is not a finite number > 0"),
    (("records",), 5, "`records` is missing or not a list"),
    (("records",), ["model new", 7], "the command record holds something other than text"),
    (("step",), "many", "the step 'many' is not a whole number ≥ 0"),
    (("stores", "blocks", "n"), -3, "store 'blocks': its row count or field list is malformed"),
    (("stores", "blocks", "fields", "mass", "dtype"), "|O",
     "store 'blocks': field 'mass' has dtype '|O' (plain numbers only)"),
    (("histories", "interval"), 0, "the history list is malformed"),
]


@pytest.mark.parametrize("where,value,why", META_CASES, ids=["/".join(c[0]) + "=" + str(c[1]) for c in META_CASES])
def test_bad_metadata_is_refused_and_nothing_changes(good, victim, where, value, why):
    bad = _rewrite(good, victim.out_dir / "bad.sav", meta_fn=_set(where, value))
    _restore_fails(victim, bad, f"'{bad}': the file is inconsistent: {why}")


def test_out_of_range_contact_rows_are_refused(good, victim):
    a = _array(good, "contacts.a")
    assert len(a) > 0
    bad = _rewrite(good, victim.out_dir / "bad.sav", arrays={"contacts.a": np.full_like(a, 99)})
    _restore_fails(victim, bad, f"'{bad}': contact block rows (a) point outside the blocks")


def test_out_of_range_subcontact_owner_is_refused(good, victim):
    c = _array(good, "subcontacts.contact")
    bad = _rewrite(good, victim.out_dir / "bad.sav", arrays={"subcontacts.contact": c + 1000})
    _restore_fails(victim, bad, f"'{bad}': sub-contact owners point outside the contacts")


def test_unknown_joint_model_code_is_refused(good, victim):
    c = _array(good, "contacts.jmodel")
    bad = _rewrite(good, victim.out_dir / "bad.sav", arrays={"contacts.jmodel": c + 40})
    _restore_fails(victim, bad, f"'{bad}': a contact has an unknown joint model code")


def test_nan_in_an_array_is_refused(good, victim):
    pos = _array(good, "vertices.pos").copy()
    pos[3, 1] = np.nan
    bad = _rewrite(good, victim.out_dir / "bad.sav", arrays={"vertices.pos": pos})
    _restore_fails(victim, bad, f"'{bad}': array 'vertices.pos' holds a value that is not finite")


def test_a_history_of_unknown_kind_is_refused(good, victim):
    def fn(meta):
        meta["histories"]["items"][0]["spec"]["kind"] = "telepathy"
    bad = _rewrite(good, victim.out_dir / "bad.sav", meta_fn=fn)
    _restore_fails(victim, bad, f"'{bad}': history 1: unknown kind 'telepathy' or quantity 'displacement-z'")


def test_a_member_larger_than_its_schema_is_refused_before_it_is_read(good, victim):
    """The row count says 2 blocks; the member really holds 10 MB (compressed to a few kB)."""
    big = np.zeros((1_250_000,), dtype=np.float64)
    bad = _rewrite(good, victim.out_dir / "bad.sav", arrays={"blocks.mass": big})
    size = len(state._npy_bytes(big))
    _restore_fails(victim, bad, f"'{bad}': array 'blocks.mass' declares {size} bytes, its schema allows "
                                f"{2 * 8 + 4096}")


def _patch_declared_size(path, member, size):
    """Write `size` as the uncompressed size of `member` in the zip's central directory."""
    raw = bytearray(path.read_bytes())
    name = member.encode()
    i = 0
    while True:
        i = raw.index(b"PK\x01\x02", i)
        n = int.from_bytes(raw[i + 28:i + 30], "little")
        if raw[i + 46:i + 46 + n] == name:
            raw[i + 24:i + 28] = size.to_bytes(4, "little")
            break
        i += 4
    path.write_bytes(bytes(raw))


def test_an_absurd_declared_size_is_refused_before_decompressing(good, victim):
    bad = _rewrite(good, victim.out_dir / "bad.sav")
    _patch_declared_size(bad, "vertices.pos.npy", 0xFFFFFFF0)
    n_vert = len(_array(good, "vertices.pos"))
    _restore_fails(victim, bad, f"'{bad}': array 'vertices.pos' declares {0xFFFFFFF0} bytes, its schema "
                                f"allows {n_vert * 3 * 8 + 4096}")


def test_corrupt_compressed_data_is_a_clean_error(good, victim):
    bad = _rewrite(good, victim.out_dir / "bad.sav")
    with zipfile.ZipFile(bad) as zf:
        info = zf.getinfo("vertices.pos.npy")
    raw = bytearray(bad.read_bytes())
    start = info.header_offset + 30 + len(info.filename.encode()) + len(info.extra)
    raw[start:start + 8] = b"\xff" * 8          # a deflate block of the reserved type 3
    bad.write_bytes(bytes(raw))
    _restore_fails(victim, bad, f"cannot read state file '{bad}': its compressed data is corrupted")


def test_missing_file_says_where_it_looked(victim):
    with pytest.raises(Dec3dError) as e:
        victim.run_items(victim.load_text("model restore 'nothing'\n"))
    here = os.getcwd()
    assert e.value.message == (f"cannot read state file `nothing`: no such file (looked for {here}/nothing.sav, "
                               f"{here}/nothing, {victim.out_dir}/nothing.sav, {victim.out_dir}/nothing)")


def test_restore_then_save_is_byte_identical_with_histories(good, tmp_path):
    shutil.copy(good, tmp_path / "good.sav")
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.run_items(s.load_text("model restore 'good'\nmodel save 'again'\n"))
    assert (tmp_path / "again.sav").read_bytes() == good.read_bytes()
    meta = state.read_meta(good)
    assert [h["spec"]["kind"] for h in meta["histories"]["items"]] == ["block", "rigid", "contact", "model"]
    assert len(_array(good, "@history.1.values")) == 4          # samples at steps 10, 20, 30, 40


def test_histories_continue_after_a_restore_as_without_it(good, tmp_path):
    """40 + 30 cycles in one go and 40, save, restore, 30: the exported histories are the same file."""
    a = Session(out_dir=tmp_path / "a", stdout=io.StringIO())
    a.run_items(a.load_text(DECK + "model cycle 30\nhistory export 1 2 3 4 file 'h.csv'\n"))
    (tmp_path / "b").mkdir()
    shutil.copy(good, tmp_path / "b" / "good.sav")
    b = Session(out_dir=tmp_path / "b", stdout=io.StringIO())
    b.run_items(b.load_text("model restore 'good'\nmodel cycle 30\nhistory export 1 'am' 3 4 file 'h.csv'\n"))
    ha, hb = (tmp_path / "a" / "h.csv").read_text(), (tmp_path / "b" / "h.csv").read_text()
    assert ha == hb and len(ha.splitlines()) == 1 + 7


def test_save_files_get_the_permissions_of_other_outputs(good, tmp_path):
    shutil.copy(good, tmp_path / "good.sav")
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.run_items(s.load_text("model restore 'good'\nmodel save 'x'\nhistory export 1 file 'h.csv'\n"))
    mode = lambda p: os.stat(p).st_mode & 0o777
    umask = os.umask(0)
    os.umask(umask)
    assert mode(tmp_path / "x.sav") == mode(tmp_path / "h.csv") == 0o666 & ~umask


def test_an_array_header_larger_than_its_schema_is_refused_before_allocating(good, victim):
    """The .npy header claims 10¹² rows: refused from the header, no array of that size is made."""
    members = _members(good)
    blob = members["blocks.mass.npy"]
    hdr_end = blob.index(b"\n") + 1
    header = blob[:hdr_end].replace(b"(2,)", b"(1000000000000,)")
    pad = (64 - len(header) % 64) % 64
    header = header[:-1] + b" " * pad + b"\n"
    header = header[:8] + (len(header) - 10).to_bytes(2, "little") + header[10:]
    forged = header + blob[hdr_end:]
    victim_file = victim.out_dir / "bad.sav"

    def fn(meta):
        meta["sha256"]["blocks.mass"] = __import__("hashlib").sha256(forged).hexdigest()
    _rewrite(good, victim_file, meta_fn=fn)
    raw = _members(victim_file)
    raw["blocks.mass.npy"] = forged
    with zipfile.ZipFile(victim_file, "w") as zf:
        for n, b in sorted(raw.items()):
            zf.writestr(state._member(n), b)
    _restore_fails(victim, victim_file, f"'{victim_file}': array 'blocks.mass' has shape (1000000000000,) <f8, "
                                        "expected (2,) <f8")
