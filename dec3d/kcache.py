"""The guard of the numba kernels' on-disk cache (``dec3d/kernels``); run by ``dec3d/__init__``
before any kernel module is imported (the kernels themselves import only numpy, numba, math).

Numba's ``cache=True`` keys a cached kernel on its own source file only: a kernel compiled
into another (``cycle.run_steps`` holds ``jointlaw`` and ``motion``; ``contactmap.cp_batch``
holds ``commonplane``; ``subgeom`` holds ``polygon2d``) keeps the callee's old code after the
callee's file changes. So, at the import of ``dec3d`` (``guard``):

1. ``cache_dir()`` is where numba will write the caches of these files: ``NUMBA_CACHE_DIR``
   when the user set it, else ``__pycache__`` beside the sources when it is writable, else
   (a read-only install) ``NUMBA_CACHE_DIR`` is pointed at a per-user folder
   (``$XDG_CACHE_HOME`` or ``~/.cache``, ``dec3d/numba``), else at a fresh temporary folder
   (kernels then compile in every process, nothing is kept);
2. ``source_hash()`` is the SHA-256 of every ``*.py`` of this package and its sub-packages
   (``kernels/joints``: one joint law per file) (names and contents) with the numba and Python
   versions; it is kept in ``STAMP`` in each cache folder. When it differs, every cached
   kernel of the package (``*.nbi``, ``*.nbc``) there is deleted
   (``clear_stale``) and the new hash is written: one kernel edited → all recompile once.
3. Compiling: the first compilation of a dec3d kernel in the process prints one line on stderr
   (``NOTICE`` and the kernel's module) — on a cold cache (``is_cold``: no cached kernel index
   there) and whenever else numba compiles (a kernel edited, a new type signature); loads from
   the cache print nothing. ``compile_seconds()`` is the time spent compiling dec3d kernels so far
   (`dec3d run` reports it at the end).
4. A process that compiles after another process has stamped different sources (the files were
   edited or upgraded while it ran: its kernels are the old code) does not write them to the
   cache: the listener reads the stamp at each compilation's end and, when it no longer holds the
   digest this process started from, gives the kernel numba's ``NullCache`` before numba saves it
   (one line on stderr says so). Without this such a process wrote old code under the new stamp,
   where every later process loaded it.
"""
from __future__ import annotations

import hashlib
import os
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent / "kernels"
#: file in the cache folder holding the source hash the cached kernels were built from
STAMP = "dec3d-kernels.sha256"
NOTICE = "dec3d: compiling kernels"
#: the rest of the notice line, after "for <module>"
_NOTICE_TAIL = ("(first use: a few seconds to a minute, once; numba keeps them in its cache and later runs "
                "load them) …")
#: set by ``guard``: no cached kernel was found (``dec3d.warmup`` then compiles on the second core)
COLD = False


def source_hash(folder: Path = HERE) -> str:
    """SHA-256 over the names (relative to ``folder``) and contents of every ``*.py`` under
    ``folder`` (sorted), numba's and Python's versions."""
    import numba

    h = hashlib.sha256()
    h.update(f"numba {numba.__version__} python {sys.version_info[:2]}\n".encode())
    for p in sorted(folder.rglob("*.py")):
        h.update(p.relative_to(folder).as_posix().encode() + b"\0")
        h.update(p.read_bytes())
        h.update(b"\0")
    return h.hexdigest()


def _writable(d: Path) -> bool:
    try:
        d.mkdir(parents=True, exist_ok=True)
        tempfile.TemporaryFile(dir=d).close()
        return True
    except OSError:
        return False


def _subpath(folder: Path) -> str:
    """The folder numba uses under a cache root for sources in ``folder`` (numba's
    ``_CacheLocator.get_suitable_cache_subpath``: parent name + SHA-1 of the path)."""
    sub = os.path.abspath(folder)
    return "_".join([os.path.split(sub)[-1], hashlib.sha1(sub.encode()).hexdigest()])


def cache_dir(folder: Path = HERE, config=None) -> Path:
    """Where numba caches the kernels of ``folder``; points numba's ``CACHE_DIR`` at a
    per-user (else a temporary) folder when the sources' own ``__pycache__`` is read-only.
    ``config``: numba's config module (a stand-in in tests)."""
    if config is None:
        from numba.core import config
    if config.CACHE_DIR:
        return Path(config.CACHE_DIR) / _subpath(folder)
    tree = folder / "__pycache__"
    if _writable(tree):
        return tree
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "dec3d" / "numba"
    if not _writable(base / _subpath(folder)):
        base = Path(tempfile.mkdtemp(prefix="dec3d-numba-"))
    config.CACHE_DIR = str(base)
    return base / _subpath(folder)


def _module_names(folder: Path) -> set[str]:
    return {p.stem for p in folder.glob("*.py")}


def clear_stale(cdir: Path, digest: str, folder: Path = HERE) -> bool:
    """Delete the cached kernels of ``folder``'s modules in ``cdir`` unless ``cdir/STAMP``
    holds ``digest``; then write it. Returns True when something was stale (or no stamp).
    A folder that cannot be written is left alone (numba then finds no usable cache)."""
    stamp = cdir / STAMP
    try:
        if stamp.read_text().strip() == digest:
            return False
    except OSError:
        pass
    mods = _module_names(folder)
    try:
        cdir.mkdir(parents=True, exist_ok=True)
        for p in cdir.iterdir():
            if p.suffix in (".nbi", ".nbc") and p.name.split(".", 1)[0] in mods:
                p.unlink()
        tmp = cdir / f"{STAMP}.{os.getpid()}"
        tmp.write_text(digest + "\n")
        os.replace(tmp, stamp)
    except OSError:
        pass
    return True


def is_cold(cdir: Path, folder: Path = HERE) -> bool:
    """True when no kernel of ``folder`` has a cache index (``*.nbi``) in ``cdir``."""
    mods = _module_names(folder)
    try:
        return not any(p.suffix == ".nbi" and p.name.split(".", 1)[0] in mods for p in cdir.iterdir())
    except OSError:
        return True


def _notice_listener(stream=None, package="dec3d.kernels", stamp=None, digest=""):
    """A ``_ColdNotice`` that is a numba event ``Listener`` (numba imported only here)."""
    from numba.core.event import Listener

    cls = type("ColdNotice", (_ColdNotice, Listener), {})
    return cls(stream, package, stamp, digest)


#: the line printed (once) when a process stops caching because the sources moved on under it
MOVED = "dec3d: the kernel sources changed on disk since this process started: what it compiles now is not cached"


#: seconds spent compiling kernels of the guarded package in this process (``_ColdNotice``)
_COMPILE = [0.0]


def compile_seconds() -> float:
    """Wall seconds this process has spent compiling dec3d kernels (0 when all came from the cache)."""
    return _COMPILE[0]


class _ColdNotice:
    """numba "compile" event listener: prints the notice once, at the first compilation of a
    kernel of package ``package`` (compilations only: loads from the cache raise no event), and
    adds up the time spent compiling (outermost compilations only: a kernel compiles its callees
    inside its own compilation)."""

    def __init__(self, stream=None, package="dec3d.kernels", stamp=None, digest=""):
        self.stream = stream
        self.package = package
        self.shown = False
        self.depth = 0
        self.t0 = 0.0
        #: the cache folder's stamp file and the digest of this process's sources (``guard``)
        self.stamp = stamp
        self.digest = digest
        self.moved = False

    def _write(self, line: str):
        stream = self.stream or sys.stderr
        try:
            stream.write(line + "\n")
            stream.flush()
        except (OSError, ValueError):
            pass

    def _sources_moved(self) -> bool:
        """True when the stamp holds another digest than this process's (another process stamped
        other sources). No stamp to read (a cache folder that cannot be written) is not a move."""
        if self.stamp is None:
            return False
        try:
            return self.stamp.read_text().strip() != self.digest
        except OSError:
            return False

    def _ours(self, event) -> str:
        disp = (event.data or {}).get("dispatcher")
        mod = getattr(getattr(disp, "py_func", None), "__module__", "") or ""
        return mod if mod.startswith(self.package) else ""

    def on_start(self, event):
        mod = self._ours(event)
        if not mod:
            return
        if self.depth == 0:
            import time
            self.t0 = time.perf_counter()
        self.depth += 1
        if self.shown:
            return
        self.shown = True
        self._write(f"{NOTICE} for {mod} {_NOTICE_TAIL}")

    def on_end(self, event):
        if not self._ours(event) or self.depth == 0:
            return
        if self._sources_moved():            # numba saves after this event: let it save nothing
            from numba.core.caching import NullCache
            event.data["dispatcher"]._cache = NullCache()
            if not self.moved:
                self.moved = True
                self._write(MOVED)
        self.depth -= 1
        if self.depth == 0:
            import time
            _COMPILE[0] += time.perf_counter() - self.t0


def guard(folder: Path = HERE, package: str = "dec3d.kernels") -> None:
    """Clear stale cached kernels of ``folder`` (module ``package``) and arm the cold-start
    notice; nothing when numba's JIT is disabled."""
    from numba.core import config

    if config.DISABLE_JIT:
        return
    digest = source_hash(folder)
    # numba keeps each source folder's caches apart (the joint laws in kernels/joints): each is
    # cleared when anything under ``folder`` changed, since a kernel compiles its callees in
    for sub in sorted({p.parent for p in folder.rglob("*.py")} - {folder}):
        if "__pycache__" not in sub.parts:
            clear_stale(cache_dir(sub), digest, sub)
    cdir = cache_dir(folder)
    clear_stale(cdir, digest, folder)
    global COLD
    COLD = is_cold(cdir, folder)
    from numba.core import event as ev

    ev.register("numba:compile", _notice_listener(package=package, stamp=cdir / STAMP, digest=digest))
