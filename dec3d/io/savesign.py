"""Who made a save file: an HMAC-SHA256 of its metadata with a key that belongs to the user.

A save holds the FISH functions and callbacks of the run that made it (``meta.json`` → ``extra.fish``),
and ``model restore`` would compile and install them: code that then runs at the next cycle. A save
file from someone else must not be able to do that. So each save carries ``signature.json``:

* ``meta_sha256``: the SHA-256 of the ``meta.json`` member (whose own checksum list covers every
  array): a damaged metadata member is caught like a damaged array;
* ``hmac_sha256``: HMAC-SHA256 of the ``meta.json`` bytes under this user's key (RFC 2104), or
  null when no key could be made.

The key is 32 random bytes in ``save-key`` in dec3d's configuration folder (``$DEC3D_CONFIG_DIR``,
else ``$XDG_CONFIG_HOME/dec3d``, else ``~/.config/dec3d``), made at the first save, readable by the
user only — kept outside any project, as Jupyter keeps the secret that marks notebooks as trusted.
A save whose HMAC checks under the key was made by this user on this machine: its FISH is restored.
Any other save (another user's, edited, from an older dec3d, made without a key) restores its model
and its FISH data (variables, tables) but not its functions or callbacks, unless the user says they
trust it (``model restore '<file>' trust``, ``dec3d run --trust-save``). docs/safety.md states it.
"""
from __future__ import annotations

import hashlib
import hmac
import os
import secrets
from pathlib import Path

KEY_FILE = "save-key"
MEMBER = "signature.json"


def config_dir() -> Path:
    """dec3d's configuration folder (not created here)."""
    env = os.environ.get("DEC3D_CONFIG_DIR")
    if env:
        return Path(env)
    xdg = os.environ.get("XDG_CONFIG_HOME")
    return (Path(xdg) if xdg else Path.home() / ".config") / "dec3d"


def _read_key(path: Path) -> bytes | None:
    try:
        text = path.read_text(encoding="ascii").strip()
        key = bytes.fromhex(text)
    except (OSError, ValueError, UnicodeDecodeError):
        return None
    return key if len(key) >= 32 else None


def signing_key(create: bool = True) -> bytes | None:
    """This user's key; made (mode 0600) when missing and ``create``; None when it cannot be had."""
    path = config_dir() / KEY_FILE
    key = _read_key(path)
    if key is not None or not create:
        return key
    try:
        path.parent.mkdir(parents=True, exist_ok=True, mode=0o700)
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    except FileExistsError:                  # made by another process just now
        return _read_key(path)
    except OSError:
        return None
    try:
        with os.fdopen(fd, "w", encoding="ascii") as fh:
            fh.write(secrets.token_hex(32) + "\n")
    except BaseException as exc:            # a full disk, Ctrl-C: no empty key file is left behind
        try:
            os.unlink(path)
        except OSError:
            pass
        if isinstance(exc, OSError):
            return None
        raise
    return _read_key(path)


def signature(meta_bytes: bytes) -> dict:
    """The ``signature.json`` content for a ``meta.json`` member."""
    key = signing_key(create=True)
    mac = hmac.new(key, meta_bytes, hashlib.sha256).hexdigest() if key is not None else None
    return {"meta_sha256": hashlib.sha256(meta_bytes).hexdigest(), "hmac_sha256": mac}


def signed_here(meta_bytes: bytes, sig: dict | None) -> bool:
    """True when ``sig`` holds a valid HMAC of ``meta_bytes`` under this user's key."""
    if not isinstance(sig, dict) or not isinstance(sig.get("hmac_sha256"), str):
        return False
    key = signing_key(create=False)
    if key is None:
        return False
    want = hmac.new(key, meta_bytes, hashlib.sha256).hexdigest()
    return hmac.compare_digest(want, sig["hmac_sha256"])
