"""Lines dec3d knows by name and does not implement yet, and `.dec` files.

A deck line naming a 3DEC command, keyword, range element or FISH intrinsic that dec3d does not
implement (``UnimplementedError`` from the binder) does not stop the whole deck from binding: it
becomes an ``Unsupported`` item in its place, the lines after it (and the files they call) are
bound as usual, and the run goes on up to it. There it stops with the line's location, or, with
``dec3d run --skip-unsupported`` (``Session.skip_unsupported``), prints the line as skipped and
goes on. A real deck error (a misspelt keyword, a bad value) still stops the deck before anything
runs.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..errors import Dec3dError, NotSupportedError, SourceLocation, UnimplementedError


@dataclass(frozen=True)
class Unsupported:
    """A line bound as "not supported yet": ``error`` is raised when the run reaches it."""

    location: SourceLocation
    source: str
    error: UnimplementedError

    def run(self, session) -> None:
        if getattr(session, "skip_unsupported", False):
            session.write(f"skipped (not supported yet): {self.location.file}:{self.location.line}: {self.source} "
                          f"({self.error.message})")
            session.warnings.append(f"{self.location.file}:{self.location.line}: skipped `{self.source}`: "
                                    f"{self.error.message}")
            return
        err = self.error
        hint = err.hint or ("`dec3d run --skip-unsupported` skips such lines (printing each) and goes on; "
                            "the lines before this one have run")
        raise UnimplementedError(err.message, err.location, hint)


def bind_or_defer(session, binder, raw):
    """``binder.bind_line(raw)``, or an ``Unsupported`` item for a line dec3d does not implement."""
    try:
        return binder.bind_line(raw)
    except UnimplementedError as exc:
        return unsupported(exc)


def unsupported(exc: UnimplementedError) -> Unsupported:
    """The ``Unsupported`` item of a line whose binding raised ``exc`` (raised again without a location)."""
    loc = exc.location
    text = loc.text.strip() if loc is not None and loc.text else ""
    if loc is None:
        raise exc
    line = SourceLocation(loc.file, loc.line, 1, loc.text, len(loc.text.rstrip()), loc.stack)
    return Unsupported(line, text, exc)


def empty_range(session, call, store: str, n: int) -> None:
    """A range that selects nothing: a warning naming the line (once per line), an error with
    ``dec3d run --strict`` (``Session.strict``). Not for the lines of a FISH function's command
    sections: a loop that scans positions or groups meets empty ones as a matter of course."""
    rt = getattr(session, "fish_rt", None)
    if rt is not None and rt.depth > 0:
        return
    loc = call.range.elements[0].location if call.range.elements else call.location
    text = f"the range selects no {store} (of {n})"
    if getattr(session, "strict", False):
        from ..errors import CommandError
        raise CommandError(text + " (--strict)", loc)
    where = loc.resolve() if hasattr(loc, "resolve") else loc
    at = f"{where.file}:{where.line}:{where.column}" if where is not None else "<input>"
    # once per bound line: a FISH loop running one command line many times warns once (the calls are
    # kept, so that their ids are not reused)
    seen = session.__dict__.setdefault("_empty_ranges", {})
    if id(call) in seen:
        return
    seen[id(call)] = call
    session.write(f"warning: {at}: {text}")
    session.warnings.append(f"{at}: {text}")


def load_dec(session, raw: bytes, path: Path, shown: str, where, stack) -> list:
    """A `.dec` file: read as a deck when it holds 3DEC commands; 3DEC's legacy binary/tabular
    block-geometry format (not documented) is refused by name."""
    why = ("3DEC's legacy .dec block-geometry files are not supported (their format is not documented); "
           "a .dec file that holds 3DEC commands is read as a deck")
    if b"\x00" in raw[:4096]:
        raise NotSupportedError(f"`{shown}` is a binary file, not a deck: {why}", where)
    try:
        items = session.load_text(raw.decode("utf-8", errors="replace"), str(path), path.parent, stack)
    except NotSupportedError:
        raise
    except Dec3dError as exc:
        loc = exc.location
        if loc is not None and loc.file == str(path):
            raise NotSupportedError(f"`{shown}` is not a deck of commands (line {loc.line}: {exc.message}): "
                                    f"{why}", where) from None
        raise
    return items
