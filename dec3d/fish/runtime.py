"""The FISH run time: global variables, compiled functions, the call stack, limits.

One `FishRuntime` per Session. Globals live in `session.variables` (the same mapping
inline `[ ]` expressions and `@name` read); functions in `functions`. A function call
makes a frame (a Python list: slot 0 the function's value, then parameters, then
locals) and runs the closures the compiler made. Errors raised inside carry the
location in the FISH body and the FISH call stack (outermost caller first).
"""
from __future__ import annotations

import sys

from ..errors import Dec3dError, ExpressionError, NotSupportedError, SourceLocation
from .values import FishValueError, index, type_name

MAX_DEPTH = 200            # nested FISH calls
STOP_CHECK = 1023          # loops look at the stop flag every STOP_CHECK + 1 iterations

_STOP = [False]

#: Python frames FISH may need: each FISH call is a few frames deep, MAX_DEPTH calls at most
RECURSION_LIMIT = 20000


def _deep_enough() -> None:
    """Raise Python's recursion limit to what FISH needs, when a FISH run time is made (a session),
    not when the module is imported: importing dec3d changes no process-wide setting."""
    if sys.getrecursionlimit() < RECURSION_LIMIT:
        sys.setrecursionlimit(RECURSION_LIMIT)


def request_stop() -> None:
    """Ask running FISH loops to stop (they raise KeyboardInterrupt at their next check)."""
    _STOP[0] = True


def clear_stop() -> None:
    _STOP[0] = False


def check_stop() -> None:
    if _STOP[0]:
        _STOP[0] = False
        raise KeyboardInterrupt


class FishError(ExpressionError):
    """A FISH statement failed while running."""


class SystemErrorRaised(FishError):
    """`system.error = '...'`: the deck stops with the message."""


class FishFunction:
    __slots__ = ("name", "params", "nparams", "nslots", "body", "fdef", "unsupported", "rt", "location")

    def __init__(self, rt, name, params, nslots, body, fdef, unsupported, location):
        self.rt = rt
        self.name = name
        self.params = params
        self.nparams = len(params)
        self.nslots = nslots
        self.body = body
        self.fdef = fdef
        self.unsupported = unsupported
        self.location = location

    def invoke(self, args, site):
        """Run with `args`; `site` is (FishSource, pos) or a SourceLocation of the caller."""
        rt = self.rt
        if args and not self.nparams:
            # `f(1)` on a function of no arguments: 3DEC runs it and indexes its value (a list, an
            # array, a map: `local cx1 = auditContacts(1)` in SAFEGO's energy_audit_freerock.dat)
            value = self.invoke((), site)
            try:
                return index(value, list(args))
            except FishValueError as exc:
                raise rt.error_at(site, f"`{self.name}(…)`: FISH function `{self.name}` takes no arguments, so "
                                        f"its value is indexed: {exc}") from None
        if len(args) != self.nparams:
            want = f"{self.nparams} argument{'s' if self.nparams != 1 else ''}"
            if self.nparams:
                want += f" ({', '.join(self.params)})"
            raise rt.error_at(site, f"FISH function `{self.name}` takes {want}, got {len(args)}")
        if rt.depth >= MAX_DEPTH:
            raise rt.error_at(site, f"FISH calls nested deeper than {MAX_DEPTH} (runaway recursion in `{self.name}`?)")
        f = [0] * self.nslots
        if args:
            f[1:1 + self.nparams] = args
        rt.depth += 1
        rt.callstack.append(site)
        try:
            self.body(f)
        finally:
            rt.depth -= 1
            rt.callstack.pop()
        return f[0]


class FishRuntime:
    def __init__(self, session):
        _deep_enough()
        self.session = session
        self.functions: dict[str, FishFunction] = {}
        self.auto_create = True
        self.depth = 0
        self.callstack: list = []
        self.inline_cache: dict = {}
        self.command_scope: list = []        # (closures by id(deferred), frame) while a command section runs
        self.tables: dict = {}               # FISH tables by id (table_intrinsics)
        #: `fish callback add`: (position, name, interval, site), kept sorted by position (then order added)
        self.callbacks: list = []
        #: `fish history`: FISH name -> where the command was (errors of a sample point there)
        self.history_sites: dict = {}
        self.in_callback = 0                 # > 0 while a callback runs (sections refuse cycling commands)

    @property
    def globals(self) -> dict:
        return self.session.variables

    def write(self, text: str) -> None:
        self.session.write(text)

    # ------------------------------------------------------------ errors
    def _site_location(self, site) -> SourceLocation | None:
        if site is None:
            return None
        if isinstance(site, SourceLocation):
            return site
        src, pos = site
        return src.location(pos)

    def stack(self) -> tuple:
        out = []
        for s in self.callstack:
            loc = self._site_location(s)
            if loc is None:
                continue
            if isinstance(s, SourceLocation) and not out:
                out.extend(loc.stack)        # the deck's include stack comes first
                loc = SourceLocation(loc.file, loc.line, loc.column, loc.text, loc.length, ())
            out.append(loc)
        return tuple(out)

    def error_at(self, site, msg, cls=FishError, hint=None):
        """An error located at `site`, with the FISH call stack up to (not including) it."""
        loc = self._site_location(site)
        if loc is not None:
            stack = self.stack()
            if stack and stack[-1] == loc:
                stack = stack[:-1]
            loc = SourceLocation(loc.file, loc.line, loc.column, loc.text, loc.length, stack)
        return cls(msg, loc, hint)

    def locate(self, exc: BaseException, src, pos, length: int = 1):
        """Turn an exception raised while running the statement at `pos` into a located Dec3dError."""
        if isinstance(exc, Dec3dError):
            if exc.location is None:
                exc.location = self.error_at((src, pos), "").location
                if length > 1 and exc.location is not None:
                    loc = exc.location
                    exc.location = SourceLocation(loc.file, loc.line, loc.column, loc.text, length, loc.stack)
            return exc
        if isinstance(exc, ZeroDivisionError):
            return self.error_at((src, pos), "division by zero")
        if isinstance(exc, OverflowError):
            return self.error_at((src, pos), "numeric overflow: the result is not a finite number")
        if isinstance(exc, RecursionError):
            return self.error_at((src, pos), "FISH calls nested too deep (runaway recursion?)")
        if isinstance(exc, (ValueError, TypeError)):
            return self.error_at((src, pos), f"bad value: {exc}")
        return exc

    # ------------------------------------------------------------ names
    def define(self, fn: FishFunction) -> None:
        self.functions[fn.name] = fn
        self.globals.pop(fn.name, None)   # a function and a variable cannot share a name

    def clear(self) -> None:
        self.functions.clear()
        self.inline_cache.clear()
        self.tables.clear()
        self.callbacks.clear()
        self.history_sites.clear()
        self.auto_create = True

    # ------------------------------------------------------------ sampling (fish history)
    def probe(self, name: str) -> float:
        """The value `fish history <name>` records: a FISH function is called (no arguments) and its
        value taken; a global variable is read. Numbers and booleans (1/0) only."""
        site = self.history_sites.get(name)
        fn = self.functions.get(name)
        if fn is not None:
            self.in_callback += 1            # sampled while the cycle goes on, as a callback is
            try:
                v = fn.invoke([], site)
            finally:
                self.in_callback -= 1
        elif name in self.globals:
            v = self.globals[name]
        else:
            raise self.error_at(site, f"`fish history {name}`: there is no FISH variable or function `{name}` "
                                      "any more")
        t = type(v)
        if t is bool:
            return 1.0 if v else 0.0
        if t is int or t is float:
            return float(v)
        raise self.error_at(site, f"`fish history {name}`: the value is a {type_name(v)}, not a number")

    # ------------------------------------------------------------ callbacks
    def run_callbacks(self, step: int, before: bool | None = None) -> None:
        """Call every `fish callback` function whose interval divides `step` (in position order);
        ``before``: only those at negative positions (True, before the step's forces) or at positions
        ≥ 0 (False, after its motion); None: all."""
        for pos, name, interval, site in list(self.callbacks):
            if step % interval or (before is not None and (pos < 0) != before):
                continue
            fn = self.functions.get(name)
            if fn is None:
                raise self.error_at(site, f"FISH callback `{name}` is not a FISH function any more")
            self.in_callback += 1
            try:
                fn.invoke([], site)
            finally:
                self.in_callback -= 1


def not_supported(name: str) -> NotSupportedError:
    return NotSupportedError(f"FISH intrinsic `{name}` is not supported yet")


__all__ = ["FishRuntime", "FishFunction", "FishError", "SystemErrorRaised", "FishValueError", "request_stop",
           "clear_stop", "check_stop", "not_supported", "MAX_DEPTH"]
