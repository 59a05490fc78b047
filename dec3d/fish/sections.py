"""`command … endcommand` sections of FISH functions: their lines were bound like deck lines when
the deck was read; here their `[ ]`/`@` values and bare `[ … ]`/`@f` lines are compiled in the
function's scope (so they see its locals), and the lines run through the session.
"""
from __future__ import annotations

from .syntax import FishSource


class CommandSections:
    """Mixed into `compiler.Compiler` (which supplies `expr`, `stmt`, `sc`, `rt`, `src`)."""

    def s_command(self, n):
        """Command lines bound when the function was read; `[ ]`/`@` values see the function's locals."""
        items = self.sc.bound.get(id(n))
        rt, src = self.rt, self.src
        if items is None:
            def not_bound(f):
                raise rt.error_at((src, n[2]), "command sections run only inside a deck's FISH function")
            return not_bound
        closures = {}
        compiled = []
        for item in items:
            for d in _deferreds(item):
                closures[id(d)] = self.deferred(d)
            stmt = None
            if getattr(item, "node", None) is not None and not hasattr(item, "command"):
                stmt = self.inline_statement(item)
            compiled.append((item, stmt))
        session = rt.session
        compiled = tuple(compiled)

        def run(f):
            rt.command_scope.append((closures, f))
            try:
                for item, stmt in compiled:
                    if stmt is not None:
                        try:
                            stmt(f)
                        except Exception as e:
                            raise rt.locate(e, src, (item.location.line, item.location.column)) from None
                    else:
                        if rt.in_callback and _cycle_bound(item.command.path):
                            raise rt.error_at(item.location, f"`{' '.join(item.command.path)}` cannot run in a FISH "
                                              "callback: the cycle that calls it is still going on (cycling again, "
                                              "replacing the model or changing its blocks is refused there)")
                        session.run_fish_command(item, rt.stack())
            finally:
                rt.command_scope.pop()
        return run

    def deferred(self, d):
        """Compile a `[expr]` or `@name` value of a command line in this function's scope."""
        from .syntax import parse_inline
        tok = d.token
        if d.kind == "at":
            name = str(tok)[1:].lower()
            return self.expr(("name", name, (tok.line, tok.column + 1)))
        src = _token_source(self.src, tok)
        node, st = parse_inline(str(tok)[1:-1], src)
        inner = type(self)(Scope_like(self.sc, src))
        if node[0] == "expr":
            return inner.expr(node[1])
        s = inner.stmt(node)
        getter = inner.expr(node[1]) if node[0] == "assign" and node[1][0] == "name" else None

        def run(f):
            s(f)
            return getter(f) if getter is not None else 0
        return run

    def inline_statement(self, item):
        """A bare `[ ... ]` or `@f` line inside a command section."""
        text = item.source.strip()
        loc = item.location
        if text.startswith("@"):
            return self.expr(("name", text[1:].lower(), (loc.line, loc.column + 1)))
        from .syntax import parse_inline
        src = FishSource(self.src.filename, loc.line, [" " * loc.column + text[1:-1]], self.src.stack)
        src.display = {loc.line: loc.text}
        node, _ = parse_inline(text[1:-1], src)
        return type(self)(Scope_like(self.sc, src)).stmt(node)


def Scope_like(sc, src: FishSource):
    """The same names, another source (an inline fragment inside a command line)."""
    new = object.__new__(type(sc))
    new.__dict__.update(sc.__dict__)
    new.src = src
    return new


def _token_source(src: FishSource, tok) -> FishSource:
    text = src.text(tok.line)
    body = str(tok)[1:-1]
    s = FishSource(src.filename, tok.line, [" " * tok.column + body], src.stack)
    s.display = {tok.line: text}
    return s


def _deferreds(item):
    from ..lang.deferred import Deferred
    out = []

    def walk(v):
        if isinstance(v, Deferred):
            out.append(v)
        elif isinstance(v, (list, tuple)):
            for x in v:
                walk(x)
        elif isinstance(v, dict):
            for x in v.values():
                walk(x)
    args = getattr(item, "args", None)
    if args is not None:
        walk(args)
        walk(item.extra)
        if item.range is not None:
            for rc in item.range.elements:
                walk(rc.args)
    return out


#: commands a FISH callback may not run: they cycle, replace the model or change its blocks while the
#: engine's step loop holds the block set it started with
_NOT_IN_CALLBACK = (("model", "cycle"), ("model", "solve"), ("model", "step"), ("model", "new"),
                    ("model", "restore"), ("model", "factor-of-safety"), ("model", "fos"), ("program", "call"),
                    ("block", "create"), ("block", "delete"), ("block", "cut"), ("block", "join"),
                    ("block", "merge-start"), ("block", "merge-finish"), ("block", "generate"),
                    ("block", "excavate"), ("block", "fill"), ("block", "densify"), ("block", "fragment"),
                    ("block", "copy"), ("block", "zone", "generate"), ("block", "import"))


def _cycle_bound(path) -> bool:
    return any(tuple(path[:len(p)]) == p for p in _NOT_IN_CALLBACK)
