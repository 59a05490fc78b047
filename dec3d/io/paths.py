"""Where a deck may write and read files: one place for every writer and reader.

Writes (``model save``, ``block vtk``, ``history export``, ``program log-file``, the log) go
under the output folder and nowhere else: ``output_path`` refuses a name that is absolute
outside it, climbs out with ``..``, goes through a symlink that points out, or names a folder,
a device or another file that is not a regular file. Reads (``program call``,
``model restore``) look beside the calling deck first, then in the output folder
(``find_input``); what they find must be a regular file under the folder of the deck the run
started from or under the output folder. ``allow_outside=True`` (``dec3d run
--allow-outside-paths``, ``Session(allow_outside_paths=True)``) lifts the folder rule for a
deck the user trusts; folders, devices and other non-regular files stay refused. See
``docs/safety.md``.

Every refusal is a ``PathError`` whose message names the file as the deck wrote it and never
shows anything read from a file.
"""
from __future__ import annotations

from contextlib import contextmanager

import os
from pathlib import Path

from dec3d.errors import Dec3dError

#: longest name of one path component most file systems take (bytes, UTF-8)
NAME_MAX = 255
#: longest path accepted
PATH_MAX = 4096
FLAG_HINT = "a deck you trust may do so with `dec3d run --allow-outside-paths` (Session(allow_outside_paths=True))"


class PathError(Dec3dError):
    """A file name a deck gave is refused (outside the allowed folders, not a regular file, malformed)."""


def _checked_name(name) -> Path:
    text = os.fspath(name) if not isinstance(name, str) else name
    if not isinstance(text, str) or text.strip() == "":
        raise PathError("the file name is empty")
    if "\x00" in text:
        raise PathError("a file name may not contain a NUL character")
    if len(text.encode("utf-8", "surrogateescape")) > PATH_MAX:
        raise PathError(f"the file name is longer than {PATH_MAX} bytes")
    p = Path(text)
    for part in p.parts:
        if len(part.encode("utf-8", "surrogateescape")) > NAME_MAX:
            raise PathError(f"`{_short(part)}` is longer than {NAME_MAX} bytes, too long for a file name")
    return p


def _short(s: str, n: int = 160) -> str:
    """A name fit for a message: control characters as '?', at most n characters."""
    s = "".join(ch if ch.isprintable() else "?" for ch in s)
    return s if len(s) <= n else s[:n - 1] + "…"


def _resolve(p: Path, name: str) -> Path:
    try:
        return p.resolve()
    except (OSError, RuntimeError) as exc:      # a symlink loop, a permission problem
        raise PathError(f"`{_short(name)}` cannot be resolved ({getattr(exc, 'strerror', None) or exc})") from None


def within(p: Path, root: Path) -> bool:
    """Whether the resolved path ``p`` is ``root`` or lies under it."""
    return p == root or root in p.parents


def file_kind(p: Path) -> str | None:
    """None for a regular file or a missing one; else what it is."""
    try:
        st = p.stat()
    except FileNotFoundError:
        return None
    except OSError:
        return None
    import stat

    if stat.S_ISREG(st.st_mode):
        return None
    if stat.S_ISDIR(st.st_mode):
        return "a folder"
    if stat.S_ISCHR(st.st_mode) or stat.S_ISBLK(st.st_mode):
        return "a device"
    if stat.S_ISFIFO(st.st_mode):
        return "a pipe"
    if stat.S_ISSOCK(st.st_mode):
        return "a socket"
    return "not a regular file"


def output_path(name, out_dir: str | os.PathLike, allow_outside: bool = False) -> Path:
    """The resolved file a deck's name ``name`` writes (relative names: under ``out_dir``).

    Raises ``PathError`` when it leaves ``out_dir`` (unless ``allow_outside``), names a
    folder, or is an existing non-regular file."""
    text = os.fspath(name)
    p = _checked_name(text)
    if p.name in ("", ".", "..") or text.endswith(("/", os.sep)):
        raise PathError(f"`{_short(text)}` names a folder, not a file")
    out = Path(out_dir)
    target = p if p.is_absolute() else out / p
    real = _resolve(target, text)
    root = _resolve(out, os.fspath(out))
    if not allow_outside and not within(real, root):
        raise PathError(f"`{_short(text)}` is outside the output folder {root}: a deck writes only there",
                        hint=FLAG_HINT)
    if real == root:
        raise PathError(f"`{_short(text)}` names the output folder, not a file")
    kind = file_kind(real)
    if kind is not None:
        raise PathError(f"`{_short(text)}` is {kind}, not a regular file: dec3d writes only regular files")
    return real


def input_candidates(name, bases, exts: tuple[str, ...] = ()) -> list[Path]:
    """The files a read of ``name`` tries, in order: each base folder, each with the name as given and
    then (when it has no extension) with each of ``exts``."""
    p = _checked_name(name)
    out: list[Path] = []
    for b in ([None] if p.is_absolute() else bases):
        c = p if b is None else Path(b) / p
        # 3DEC adds the default extension to a bare name: those come first, the bare name last
        for cand in ([c.with_name(c.name + e) for e in exts] if not c.suffix and c.name else []) + [c]:
            if cand not in out:
                out.append(cand)
    return out


def check_input_name(name, bases, roots, allow_outside: bool = False) -> None:
    """Bind time: refuse a name every candidate of which lies outside ``roots`` (no file is opened)."""
    if allow_outside:
        _checked_name(name)
        return
    cands = input_candidates(name, bases)
    real_roots = [_resolve(Path(r), os.fspath(r)) for r in roots]
    if not any(within(_resolve(c, os.fspath(name)), r) for c in cands for r in real_roots):
        raise PathError(f"`{_short(os.fspath(name))}` is outside the deck's folder and the output folder: "
                        "a deck reads only there", hint=FLAG_HINT)


def find_input(name, bases, roots, allow_outside: bool = False, exts: tuple[str, ...] = (),
               what: str = "file", prefer=()) -> Path:
    """The resolved file a read of ``name`` opens: the first candidate (``input_candidates``) that exists;
    a candidate in ``prefer`` (resolved paths: files this run wrote) comes before the others.

    Raises ``PathError`` when none exists (saying where it looked), when the one found is not a
    regular file, or when it lies outside every folder of ``roots`` (unless ``allow_outside``)."""
    text = os.fspath(name)
    cands = input_candidates(text, bases, exts)
    if prefer:
        mine = [c for c in cands if _resolve(c, text) in prefer]
        cands = mine + [c for c in cands if c not in mine]
    real_roots = [_resolve(Path(r), os.fspath(r)) for r in roots]
    odd = None
    for c in cands:
        try:
            exists = c.exists()
        except OSError:
            exists = False
        if not exists:
            continue
        real = _resolve(c, text)
        kind = file_kind(real)
        if kind is not None:
            odd = odd or (c, kind)         # a folder of that name: a later candidate may be the file
            continue
        if not allow_outside and not any(within(real, r) for r in real_roots):
            raise PathError(f"`{_short(text)}` ({real}) is outside the deck's folder and the output folder: "
                            "a deck reads only there", hint=FLAG_HINT)
        return real
    if odd is not None:
        raise PathError(f"`{_short(text)}` ({odd[0]}) is {odd[1]}, not a regular file: dec3d reads only "
                        "regular files")
    looked = ", ".join(_short(str(c)) for c in cands)
    raise PathError(f"cannot read {what} `{_short(text)}`: no such file (looked for {looked})",
                    hint=MISSING_HINT[0])


#: a hint for files not found, set where the reason is known: a `dec3d batch --dask` worker has only the
#: files the deck names literally (``dec3d.batch``), not those a run names by an expression
MISSING_HINT: list = [None]


@contextmanager
def missing_hint(text: str):
    """While in the block, a file not found says ``text`` as its hint."""
    old, MISSING_HINT[0] = MISSING_HINT[0], text
    try:
        yield
    finally:
        MISSING_HINT[0] = old


DASK_MISSING = ("a `dec3d batch --dask` worker has only the files the deck names literally (and those they "
                "call): name this one literally, or run the batch on the process pool (without --dask)")


def os_error_text(exc: OSError) -> str:
    """A one-line reason for a failed file operation (no traceback, no file contents)."""
    import errno

    if exc.errno in (errno.EEXIST, errno.ENOTDIR):
        return "a file stands where a folder is needed"
    if exc.errno == errno.ENOSPC:
        return "no space left on the device"
    if exc.errno == errno.ENAMETOOLONG:
        return "the file name is too long"
    return exc.strerror or str(exc) or type(exc).__name__


def chmod_like_outputs(path: str | os.PathLike) -> None:
    """Give a file made by ``tempfile.mkstemp`` (mode 0600) the mode an ordinary ``open`` gives
    (0666 less the umask), so every output has the same permissions."""
    mask = os.umask(0)
    os.umask(mask)
    os.chmod(path, 0o666 & ~mask)


printable = _short


def replace_via_temp(path, write, prefix: str = ".dec3d-") -> None:
    """Write a file whole or not at all: ``write(binary file)`` fills a temporary file beside ``path``,
    which then replaces ``path`` in one step. The temporary file is removed on every other way out
    (an OS error, Ctrl-C, any exception), so a stopped write leaves the old file as it was and no
    half-written file behind."""
    import tempfile

    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=prefix, dir=folder)
    try:
        with os.fdopen(fd, "wb") as fh:
            write(fh)
        chmod_like_outputs(tmp)             # mkstemp makes 0600; other outputs get 0666 less the umask
        os.replace(tmp, path)
        tmp = None
    finally:
        if tmp is not None:
            try:
                os.unlink(tmp)
            except OSError:
                pass
