"""Save files cannot carry code that runs (issue 35, item 2): a save's FISH functions and callbacks are
installed by `model restore` only when the save was signed by this user's key (dec3d.io.savesign) or
the user says they trust it; the metadata is covered by a checksum like the arrays."""
import hashlib
import io
import json
import subprocess
import sys
import zipfile

import pytest

from conftest import ROOT
from dec3d.errors import Dec3dError
from dec3d.session import Session

# a FISH function called every step by a callback: it counts, and writes a file when it runs
DECK = ("model new\nblock create brick 0 1 0 1 0 1\nblock property density 1000\nmodel gravity 0 0 -10\n"
        "[n = 0]\n[tag = 'kept']\n"
        "fish define count\n  global n = n + 1\nend\n"
        "fish callback add count 1.0\nmodel cycle 3\nmodel save 'a'\n")


def _session(tmp_path):
    out = io.StringIO()
    s = Session(out_dir=tmp_path, stdout=out)
    s.output = out
    return s


def _saved(tmp_path):
    s = _session(tmp_path)
    s.command(DECK)
    assert s.variables["n"] == 3
    return tmp_path / "a.sav"


def _rewrite(path, edit):
    """Rewrite a save with ``edit(meta) -> meta`` applied to its metadata, as someone with a zip tool
    would: the signature member's metadata checksum is made again (anyone can), its HMAC cannot be."""
    with zipfile.ZipFile(path) as zf:
        members = {i.filename: zf.read(i) for i in zf.infolist()}
    meta = edit(json.loads(members["meta.json"]))
    raw = json.dumps(meta, sort_keys=True, indent=1).encode()
    sig = json.loads(members["signature.json"])
    sig["meta_sha256"] = hashlib.sha256(raw).hexdigest()
    members["meta.json"], members["signature.json"] = raw, json.dumps(sig).encode()
    with zipfile.ZipFile(path, "w") as zf:
        for name, b in members.items():
            zf.writestr(name, b)


def test_own_save_restores_its_functions_and_callbacks(tmp_path):
    path = _saved(tmp_path)
    s = _session(tmp_path)
    s.command("model restore 'a'\nmodel cycle 2")
    assert s.variables["n"] == 5                         # the callback ran twice more
    assert "not restored" not in s.output.getvalue()


def test_edited_save_restores_the_model_and_data_but_not_the_code(tmp_path):
    path = _saved(tmp_path)

    def evil(meta):
        for f in meta["extra"]["fish"]["functions"]:
            f["lines"] = ["  global n = n + 1000"]
        return meta

    _rewrite(path, evil)
    s = _session(tmp_path)
    s.command("model restore 'a'")
    out = s.output.getvalue()
    assert ("'a' was not saved by this user on this machine: its FISH function `count` and 1 callback not "
            "restored") in out
    assert s.model.blocks.n == 1 and s.model.step == 3          # the model came back
    assert s.variables["n"] == 3 and s.variables["tag"] == "kept"   # and the FISH data
    s.command("model cycle 2")
    assert s.variables["n"] == 3                                  # no callback ran
    with pytest.raises(Dec3dError):
        s.command("[count]")                                      # no function installed


def test_trust_keyword_and_flag_install_the_code_of_a_save_from_elsewhere(tmp_path, monkeypatch):
    path = _saved(tmp_path)
    monkeypatch.setenv("DEC3D_CONFIG_DIR", str(tmp_path / "another-user"))
    s = _session(tmp_path)
    s.command("model restore 'a'")
    assert "not restored" in s.output.getvalue()                 # another user's key: not signed here
    s.command("model restore 'a' trust\nmodel cycle 1")
    assert s.variables["n"] == 4
    t = _session(tmp_path)
    t.trust_saves = True                                          # `dec3d run --trust-save`
    t.command("model restore 'a'\nmodel cycle 1")
    assert t.variables["n"] == 4 and "not restored" not in t.output.getvalue()


def test_metadata_damage_is_refused_like_array_damage(tmp_path):
    path = _saved(tmp_path)
    with zipfile.ZipFile(path) as zf:
        members = {i.filename: zf.read(i) for i in zf.infolist()}
    members["meta.json"] = members["meta.json"].replace(b'"step": 3', b'"step": 4')
    with zipfile.ZipFile(path, "w") as zf:
        for name, b in members.items():
            zf.writestr(name, b)
    s = _session(tmp_path)
    with pytest.raises(Dec3dError, match="meta.json is corrupted"):
        s.command("model restore 'a'")
    assert s.model.blocks.n == 0                                  # nothing of the file was taken


def test_a_save_without_a_signature_is_not_trusted(tmp_path):
    """A save from before signatures (or with its signature member removed): the code stays out."""
    path = _saved(tmp_path)
    with zipfile.ZipFile(path) as zf:
        members = {i.filename: zf.read(i) for i in zf.infolist() if i.filename != "signature.json"}
    with zipfile.ZipFile(path, "w") as zf:
        for name, b in members.items():
            zf.writestr(name, b)
    s = _session(tmp_path)
    s.command("model restore 'a'\nmodel cycle 1")
    assert "function `count` and 1 callback not restored" in s.output.getvalue()
    assert s.variables["n"] == 3


def test_the_key_is_private_and_the_same_model_saves_to_the_same_bytes(tmp_path, monkeypatch):
    monkeypatch.setenv("DEC3D_CONFIG_DIR", str(tmp_path / "cfg"))
    path = _saved(tmp_path)
    key = tmp_path / "cfg" / "save-key"
    assert key.is_file() and (key.stat().st_mode & 0o077) == 0
    first = path.read_bytes()
    s = _session(tmp_path)
    s.command("model restore 'a'\nmodel save 'b'")
    assert (tmp_path / "b.sav").read_bytes() == first


def test_dec3d_run_trust_save_flag(tmp_path):
    _saved(tmp_path)
    deck = tmp_path / "r.dat"
    deck.write_text("model restore 'a'\nmodel cycle 1\n")
    import os

    env = {**os.environ, "DEC3D_CONFIG_DIR": str(tmp_path / "elsewhere"), "PYTHONPATH": str(ROOT)}
    for flags, words in (([], "not restored"), (["--trust-save"], None)):
        r = subprocess.run([sys.executable, "-m", "dec3d", "run", str(deck), *flags], capture_output=True,
                           text=True, env=env, cwd=tmp_path, timeout=300)
        assert r.returncode == 0, r.stderr
        assert (words in r.stdout) if words else ("not restored" not in r.stdout)
