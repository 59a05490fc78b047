"""FISH file input and output: file.open, file.read, file.write, file.close (Itasca's FISH names).

One file is open at a time, as in 3DEC. ``file.open(name, mode, type)``: mode 0 reads, 1 writes
(a new file), 2 appends; type 1 is ASCII (one line per array item). Itasca's FISH binary format
(type 0) is not readable outside Itasca's codes and is refused. Names follow the rules of every
file a deck names (dec3d.io.paths): a file written lands in the output folder, a file read is
found beside the deck, then in the output folder. ``file.read(a, n)`` puts the next n lines into
the list or array ``a`` (as strings, without the line end; ``a`` grows when shorter);
``file.write(a, n)`` writes the first n items of ``a``, one line each. Each returns 0 when it did
all it was asked, -1 when the file ended before n lines were read (the lines read are in ``a``).
"""
from __future__ import annotations

from ..errors import Dec3dError
from .intrinsics import MAX_LIST, intrinsic
from .values import FishValueError, to_string, type_name

_MODES = {0: "read", 1: "write", 2: "append"}


def _why(exc: OSError) -> str:
    return exc.strerror or type(exc).__name__


def _state(rt):
    st = getattr(rt, "_file", None)
    return st


def _where(rt):
    stack = rt.stack()
    return stack[0] if stack else None


@intrinsic("file.open", 3)
def _file_open(rt, name, mode, kind):
    if type(name) is not str or not name:
        raise FishValueError(f"`file.open` takes a file name (a string), not a {type_name(name)}")
    if mode not in _MODES or type(mode) is not int:
        raise FishValueError(f"`file.open`: the mode is 0 (read), 1 (write) or 2 (append), not {to_string(mode)}")
    if kind != 1 or type(kind) is not int:
        raise FishValueError("`file.open`: dec3d reads and writes ASCII files (type 1); Itasca's FISH binary "
                             f"format (type {to_string(kind)}) is not supported")
    if _state(rt) is not None:
        raise FishValueError(f"`file.open`: '{rt._file[1]}' is still open (FISH keeps one file open: "
                             "`file.close` it first)")
    where = _where(rt)
    try:
        if mode == 0:
            path = rt.session.in_path(name, where, what="file")
            handle = open(path, "r", encoding="utf-8", errors="replace")
        else:
            path = rt.session.out_path(name, where)
            path.parent.mkdir(parents=True, exist_ok=True)
            handle = open(path, "w" if mode == 1 else "a", encoding="utf-8", newline="\n")
    except Dec3dError as exc:          # a name the output-folder rules refuse (dec3d.io.paths)
        raise FishValueError(f"`file.open`: {exc.message}", hint=exc.hint) from None
    except OSError as exc:
        raise FishValueError(f"`file.open`: cannot open '{name}': {_why(exc)}") from None
    rt._file = (handle, name, mode)
    return 0


def _open_for(rt, name, modes):
    st = _state(rt)
    if st is None:
        raise FishValueError(f"`{name}`: no file is open (`file.open` one first)")
    if st[2] not in modes:
        raise FishValueError(f"`{name}`: '{st[1]}' is open for {_MODES[st[2]]}ing")
    return st[0]


def _count(name, a, n, need_items: bool):
    if type(a) is not list:
        raise FishValueError(f"`{name}` takes an array or a list, not a {type_name(a)}")
    if type(n) is not int or n < 0 or n > MAX_LIST:
        raise FishValueError(f"`{name}`: the number of lines is an integer from 0 to {MAX_LIST}, not {to_string(n)}")
    if need_items and n > len(a):
        raise FishValueError(f"`{name}`: asked for {n} lines of an array of {len(a)}")


@intrinsic("file.read", 2)
def _file_read(rt, a, n):
    _count("file.read", a, n, False)
    handle = _open_for(rt, "file.read", (0,))
    for i in range(n):
        line = handle.readline()
        if not line:
            return -1
        line = line.rstrip("\r\n")
        if i < len(a):
            a[i] = line
        else:
            a.append(line)
    return 0


@intrinsic("file.write", 2)
def _file_write(rt, a, n):
    _count("file.write", a, n, True)
    handle = _open_for(rt, "file.write", (1, 2))
    try:
        handle.write("".join(to_string(a[i]) + "\n" for i in range(n)))
        handle.flush()
    except OSError as exc:
        raise FishValueError(f"`file.write`: cannot write '{rt._file[1]}': {_why(exc)}") from None
    return 0


@intrinsic("file.close")
def _file_close(rt):
    st = _state(rt)
    if st is None:
        return 0
    rt._file = None
    try:
        st[0].close()
    except OSError as exc:
        raise FishValueError(f"`file.close`: '{st[1]}': {_why(exc)}") from None
    return 0
