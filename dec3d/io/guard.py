"""No deck destroys its own inputs or a file it did not write (docs/safety.md, "Files a run replaces").

A ``FileRecord`` keeps, for one run, the files it has read (the deck, every deck it calls, every
save it restores, every table or geometry file it imports) and the files it has written. Every
write goes through ``claim`` (``Session.out_path``), which refuses

- a file this run has read and did not write first (compared by resolved path and by device and
  inode, so a symbolic link, a hard link or another spelling of the name leads to the same file);
- the record of dec3d's own outputs (``MANIFEST``);
- an existing file this run did not write, unless it is one of dec3d's own outputs — listed in the
  output folder's ``MANIFEST`` with the size and SHA-256 of what dec3d wrote (nobody changed it
  since), or a dec3d save (a zip holding ``meta.json``) or a VTK XML file — or the user lets the
  run replace any file (``dec3d run --allow-overwrite``, ``Session(allow_overwrite=True)``).

``dec3d.commands._file_check.bind_check`` applies the same rules, in deck order, to the literal
names of a bound deck before anything runs. ``finish`` writes the manifest of the files the run
wrote.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

from .paths import PathError, printable, replace_via_temp

#: the output folder's record of the files dec3d wrote there (name -> [size, SHA-256])
MANIFEST = ".dec3d-outputs.json"
OVERWRITE_HINT = ("delete or rename it, write another name, or let the run replace existing files with "
                  "`dec3d run --allow-overwrite` (Session(allow_overwrite=True))")
_VTK = (".vtu", ".pvd", ".vtk", ".vtp")


def _digest(p: Path):
    """[size, SHA-256] of a file (None when it cannot be read): how the manifest knows a file unchanged."""
    import hashlib

    h = hashlib.sha256()
    try:
        with open(p, "rb") as fh:
            for chunk in iter(lambda: fh.read(1 << 20), b""):
                h.update(chunk)
            return [fh.tell(), h.hexdigest()]
    except OSError:
        return None


def file_key(p: Path):
    """(device, inode) of a file, None when it cannot be reached: the same file under any name."""
    try:
        st = os.stat(p)
    except OSError:
        return None
    return (st.st_dev, st.st_ino)


class FileRecord:
    """The files one run has read and written (resolved paths)."""

    def __init__(self, out_dir, allow_overwrite: bool = False):
        self.out_dir = Path(out_dir)
        self.allow_overwrite = bool(allow_overwrite)
        self.inputs: dict[Path, str] = {}       # resolved path -> what it was read as
        self.input_keys: dict[tuple, Path] = {}  # (device, inode) -> resolved path
        self.created: set[Path] = set()
        self.dirty: set[Path] = set()            # written since the manifest was last written
        self._manifest: dict | None = None

    # ---------------------------------------------------------------- reads
    def read(self, path, what: str) -> Path:
        """Note a file the run reads (a file it wrote itself before is not an input); returns ``path``."""
        real = Path(path).resolve()
        if real in self.created or real in self.inputs:
            return path
        what = printable(what)
        self.inputs[real] = what
        k = file_key(real)
        if k is not None:
            self.input_keys[k] = real
        return path

    def input_of(self, real: Path, inputs=None, keys=None) -> str | None:
        inputs = self.inputs if inputs is None else inputs
        if real in inputs:
            return inputs[real]
        k = file_key(real)
        keys = self.input_keys if keys is None else keys
        return inputs.get(keys[k]) if k is not None and k in keys else None

    # ---------------------------------------------------------------- writes
    def refusal(self, real: Path, name: str, created=None, inputs=None, keys=None) -> PathError | None:
        """Why the run may not write ``real`` (named ``name`` in the deck), or None."""
        created = self.created if created is None else created
        shown = printable(str(name))
        what = self.input_of(real, inputs, keys)
        if what is not None:
            return PathError(f"`{shown}` would replace {what} ({real}), which this run reads: a run never "
                             "writes over its own inputs", hint="write the output under another name")
        if real.name == MANIFEST and real.parent == self._root():
            return PathError(f"`{shown}` is dec3d's record of the files it wrote in the output folder; "
                             "a deck cannot write it")
        if real in created or self.allow_overwrite or not real.exists():
            return None
        if self._own(real):
            return None
        return PathError(f"`{shown}` would replace the existing file {real}, which dec3d did not write "
                         "(or which was changed since)", hint=OVERWRITE_HINT)

    def claim(self, real: Path, name: str, where=None) -> Path:
        """Run time: check the write of ``real`` and note it as written by this run."""
        exc = self.refusal(real, name)
        if exc is not None:
            raise exc.with_location(where) if where is not None else exc
        self.created.add(real)
        self.dirty.add(real)
        return real

    def _root(self) -> Path:
        try:
            return self.out_dir.resolve()
        except OSError:
            return self.out_dir

    def _own(self, real: Path) -> bool:
        """Whether an existing file is one of dec3d's outputs: a dec3d save or VTK XML file (a look at
        its start), else one the manifest lists with its size and SHA-256 (unchanged since)."""
        ext = real.suffix.lower()
        try:
            with open(real, "rb") as fh:
                head = fh.read(512)
        except OSError:
            return False
        if ext == ".sav" and head.startswith(b"PK\x03\x04"):
            import zipfile

            try:
                with zipfile.ZipFile(real) as zf:
                    if "meta.json" in zf.namelist():
                        return True
            except (OSError, zipfile.BadZipFile, ValueError):
                pass
        if ext in _VTK and b"<VTKFile" in head:
            return True
        entry = self._entries().get(self._rel(real) or "")
        try:
            size = real.stat().st_size
        except OSError:
            return False
        return entry is not None and entry[0] == size and entry == _digest(real)

    # ---------------------------------------------------------------- manifest
    def _rel(self, real: Path) -> str | None:
        root = self._root()
        try:
            return real.relative_to(root).as_posix()
        except ValueError:
            return None

    def _entries(self) -> dict:
        if self._manifest is None:
            self._manifest = {}
            try:
                data = json.loads((self._root() / MANIFEST).read_text(encoding="utf-8"))
                files = data.get("files") if isinstance(data, dict) else None
                self._manifest = {k: v for k, v in (files if isinstance(files, dict) else {}).items()
                                  if isinstance(v, list) and len(v) == 2 and ".." not in Path(k).parts
                                  and not Path(k).is_absolute()}
            except (OSError, ValueError, UnicodeError):
                pass
        return self._manifest

    def finish(self, still_writing=()) -> None:
        """Write the manifest: the files written since it was last written (as they are now; also the
        files in ``still_writing``, such as an open log, which may grow after this) and earlier
        entries still true. Cheap when nothing was written: it runs at the end of every top-level
        ``Session.run_items``."""
        todo = self.dirty | {Path(p).resolve() for p in still_writing if p is not None}
        if not todo:
            return
        root = self._root()
        entries = {}
        for rel, v in self._entries().items():
            if (root / rel).is_file():
                entries[rel] = v          # an earlier output (checked again before it is replaced)
        for real in todo:
            rel = self._rel(real)
            if rel is not None and real.is_file() and rel != MANIFEST:
                v = _digest(real)
                if v is not None:
                    entries[rel] = v
        self.dirty.clear()
        if not entries or not root.is_dir():
            return
        text = json.dumps({"version": 1, "files": dict(sorted(entries.items()))}, indent=0)
        try:
            replace_via_temp(root / MANIFEST, lambda fh: fh.write(text.encode("utf-8")), ".dec3d-outputs-")
        except OSError:
            pass                         # a read-only or full folder: the next run asks before replacing
        self._manifest = entries
