"""FISH syntax tree -> Python closures (never eval/exec).

Every expression becomes a closure `ev(frame)` and every statement a closure `run(frame)`
returning None, or a signal for the enclosing construct: BREAK (`exit loop`), CONTINUE,
RETURN (`exit`), EXIT_SECTION. Locals are slots of the frame list, resolved when the
function is compiled; other names are looked up when they run (a FISH function first,
then a global variable, then an intrinsic), so functions may call functions defined
later. Intrinsics are resolved at compile time; an unknown one compiles and fails only
when it runs ("not supported yet", naming it).

Errors raised while a statement runs are located at the operator, call or statement
that failed (try/except costs nothing until an exception is raised in Python 3.11+).
"""
from __future__ import annotations

from ..errors import SourceLocation
from . import intrinsics as I
from .expressions import ExpressionCompiler, _truth
from .sections import CommandSections
from .runtime import STOP_CHECK, _STOP, FishError, FishFunction, check_stop
from .syntax import FishDef, FishSource
from .values import BINARY, COMPONENTS, FishValueError, Vec, iterate, set_index, type_name

BREAK, CONTINUE, RETURN, EXIT_SECTION = 1, 2, 3, 4


class Scope:
    def __init__(self, rt, src: FishSource, fdef: FishDef | None, bound=None):
        self.rt = rt
        self.src = src
        self.fdef = fdef
        self.own = fdef.name if fdef else None
        self.slots: dict[str, int] = {}
        if fdef is not None:
            for p in fdef.params:
                self.slots[p] = len(self.slots) + 1
            for name in sorted(fdef.locals):
                if name not in self.slots:
                    self.slots[name] = len(self.slots) + 1
        self.declared_globals = set(fdef.globals) if fdef else set()
        self.unsupported: set[str] = set()
        self.loops = 0
        self.sections = 0
        self.bound = bound or {}          # id(command node) -> bound items
        self.defer_closures: dict = {}    # id(Deferred) -> closure, for command sections

    @property
    def nslots(self) -> int:
        return len(self.slots) + 1


def compile_function(rt, fdef: FishDef, bound=None, location: SourceLocation | None = None) -> FishFunction:
    sc = Scope(rt, fdef.source, fdef, bound)
    c = Compiler(sc)
    if not rt.auto_create:
        c.check_names(fdef)
    body = c.block(fdef.body)
    src = fdef.source

    def run(f):
        r = body(f)
        if r == BREAK or r == CONTINUE or r == EXIT_SECTION:   # pragma: no cover - rejected when compiled
            raise FishError("a loop or section signal escaped its construct")
        return None

    return FishFunction(rt, fdef.name, fdef.params, sc.nslots, run, fdef, frozenset(sc.unsupported),
                        location or src.location(fdef.pos))


def compile_inline(rt, node, src: FishSource):
    """A `[ ]` statement: names are globals (there are no locals)."""
    sc = Scope(rt, src, None)
    c = Compiler(sc)
    if node[0] == "expr":
        ev = c.expr(node[1])

        def run(f):
            return ev(f)
        return run, sc
    st = c.stmt(node)
    if node[0] == "assign":
        target = node[1]
        getter = c.expr(target) if target[0] == "name" else None

        def run_assign(f):
            st(f)
            return getter(f) if getter is not None else 0
        return run_assign, sc

    def run_other(f):
        st(f)
        return 0
    return run_other, sc


class Compiler(CommandSections, ExpressionCompiler):
    """Statements (this class), `command … endcommand` sections (`sections.py`) and expressions
    (`expressions.py`)."""

    def check_names(self, fdef: FishDef) -> None:
        """`fish automatic-create off`: every name must be local, declared global, an existing
        global or function, or the function itself."""
        rt = self.rt
        known = set(self.sc.slots) | self.sc.declared_globals | {fdef.name}

        def walk(n):
            if not isinstance(n, tuple) or not n:
                return
            tag = n[0]
            if tag == "name":
                name = n[1]
                if "." in name or name in known or name in rt.functions or name in rt.globals:
                    return
                if I.lookup(name) is not None:
                    return
                raise self.err(f"undefined FISH name `{name}` (automatic-create is off)", n[2], len(name),
                               hint=f"declare it first: `global {name}` or `local {name}`")
            if tag == "call":
                name = n[1]
                if "." not in name and name not in known and name not in rt.functions and name not in rt.globals \
                        and I.lookup(name) is None:
                    raise self.err(f"undefined FISH name `{name}` (automatic-create is off)", n[3], len(name),
                                   hint="define the function before this one, or declare the variable")
                for a in n[2]:
                    walk(a)
                return
            for x in n[1:]:
                if isinstance(x, tuple):
                    if x and isinstance(x[0], str):
                        walk(x)
                    else:
                        for y in x:
                            walk(y)
                elif isinstance(x, list):
                    for y in x:
                        walk(y)

        for s in fdef.body:
            walk(s)


    # ------------------------------------------------------------ statements
    def block(self, stmts):
        fns = tuple(self.stmt(s) for s in stmts)
        if not fns:
            def empty(f):
                return None
            return empty
        if len(fns) == 1:
            return fns[0]
        if len(fns) == 2:
            s0, s1 = fns

            def run2(f):
                r = s0(f)
                if r is not None:
                    return r
                return s1(f)
            return run2

        def run(f):
            for s in fns:
                r = s(f)
                if r is not None:
                    return r
            return None
        return run

    def stmt(self, n):
        return getattr(self, "s_" + n[0])(n)

    def s_expr(self, n):
        ev = self.expr(n[1])

        def run(f):
            ev(f)
        return run

    def s_calls(self, n):
        evs = tuple(self.expr(x) for x in n[1])

        def run(f):
            for e in evs:
                e(f)
        return run

    def s_local(self, n):
        sets = []
        for name, value, pos in n[1]:
            slot = self.sc.slots[name]
            sets.append((slot, self.expr(value) if value is not None else None))
        sets = tuple(sets)

        def run(f):
            for slot, ev in sets:
                f[slot] = ev(f) if ev is not None else 0
        return run

    def s_global(self, n):
        rt = self.rt
        g = rt.globals
        sets = []
        for name, value, pos in n[1]:
            if name in self.sc.slots:
                raise self.err(f"`{name}` is declared both local and global", pos, len(name))
            sets.append((name, self.expr(value) if value is not None else None))
        sets = tuple(sets)

        def run(f):
            for name, ev in sets:
                if ev is not None:
                    g[name] = ev(f)
                elif name not in g:
                    g[name] = 0
        return run

    def store(self, target, pos):
        """A closure `set(frame, value)` for an assignment target."""
        rt, src = self.rt, self.src
        tag = target[0]
        if tag == "name":
            name = target[1]
            slot = self.sc.slots.get(name)
            if slot is None and name == self.sc.own:
                slot = 0
            if slot is not None:
                return ("slot", slot)
            if "." in name:
                base, _, last = name.rpartition(".")
                if last in COMPONENTS and "." not in base and (base in self.sc.slots or I.lookup_setter(name) is None):
                    get = self.e_name(("name", base, target[2]))
                    put = self.store(("name", base, target[2]), pos)
                    k = COMPONENTS[last]
                    return ("fn", _component_setter(get, put, k, last))
                st = I.resolve_setter(name)
                if st is None:
                    self.sc.unsupported.add(name)
                    return ("fn", _unsupported_setter(rt, src, target[2], name))
                fn = st.fn
                return ("fn", lambda f, v: fn(rt, v))
            g = rt.globals
            funcs = rt.functions

            def set_global(f, v):
                if name in funcs:
                    raise FishValueError(f"`{name}` is a FISH function; it can only set its own value inside itself")
                g[name] = v
            return ("fn", set_global)
        if tag == "call":
            name, argn = target[1], target[2]
            args, mapped = self.args(argn)
            if mapped is not None:
                raise self.err("`::` cannot be used on the left of `=`", argn[mapped][2], 2)
            slot = self.sc.slots.get(name)
            if slot is not None:
                def set_local_elem(f, v):
                    set_index(f[slot], [a(f) for a in args], v)
                return ("fn", set_local_elem)
            if "." in name or name in I.BUILTIN_CALLS:
                st = I.resolve_setter(name)
                if st is None:
                    self.sc.unsupported.add(name)
                    return ("fn", _unsupported_setter(rt, src, target[3], name))
                fn = st.fn
                return ("fn", lambda f, v: fn(rt, *[a(f) for a in args], v))
            g = rt.globals

            def set_global_elem(f, v):
                if name not in g:
                    raise FishValueError(f"`{name}` is not a list, array or map that could take an element")
                set_index(g[name], [a(f) for a in args], v)
            return ("fn", set_global_elem)
        if tag == "member":
            base = target[1]
            if base[0] != "name":
                raise self.err("only a variable's component can be assigned", pos)
            get = self.expr(base)
            put = self.store(base, pos)
            return ("fn", _component_setter(get, put, COMPONENTS[target[2]], target[2]))
        raise self.err("this cannot be assigned", pos)  # pragma: no cover - the parser allows no other targets

    def s_assign(self, n):
        target, op, value, pos = n[1], n[2], n[3], n[4]
        ev = self.expr(value)
        kind, st = self.store(target, pos)
        on_error = self.fail(pos, len(op))
        if op != "=":
            cur = self.expr(target)
            opfn = BINARY[op[0]]
            if kind == "slot":
                slot = st

                def run_aug_slot(f):
                    try:
                        f[slot] = opfn(cur(f), ev(f))
                    except Exception as e:
                        raise on_error(e) from None
                return run_aug_slot

            def run_aug(f):
                try:
                    st(f, opfn(cur(f), ev(f)))
                except Exception as e:
                    raise on_error(e) from None
            return run_aug
        if kind == "slot":
            slot = st

            def run_slot(f):
                f[slot] = ev(f)
            return run_slot

        def run_fn(f):
            v = ev(f)
            try:
                st(f, v)
            except Exception as e:
                raise on_error(e) from None
        return run_fn

    def s_if(self, n):
        branches = []
        for cond, body in n[1]:
            c = self.expr(cond)
            branches.append((c, self.block(body), self.fail(cond[-1])))
        other = self.block(n[2]) if n[2] is not None else None
        if len(branches) == 1:
            c, body, on_error = branches[0]

            def run1(f):
                v = c(f)
                if v is True or (v is not False and _truth(v, on_error)):
                    return body(f)
                if other is not None:
                    return other(f)
                return None
            return run1
        branches = tuple(branches)

        def run(f):
            for c, body, on_error in branches:
                v = c(f)
                if v is True or (v is not False and _truth(v, on_error)):
                    return body(f)
            if other is not None:
                return other(f)
            return None
        return run

    def _loop_body(self, stmts):
        self.sc.loops += 1
        try:
            return self.block(stmts)
        finally:
            self.sc.loops -= 1

    def s_loop_while(self, n):
        c = self.expr(n[1])
        body = self._loop_body(n[2])
        on_error = self.fail(n[1][-1])
        stop = _STOP

        def run(f):
            k = 0
            while True:
                v = c(f)
                if not (v is True or (v is not False and _truth(v, on_error))):
                    return None
                r = body(f)
                if r is not None and r != CONTINUE:
                    if r == BREAK:
                        return None
                    return r
                k += 1
                if k & STOP_CHECK == 0 and stop[0]:
                    check_stop()
        return run

    def s_loop_for(self, n):
        init = self.stmt(n[1])
        c = self.expr(n[2])
        self.sc.loops += 1
        try:
            step = self.stmt(n[3])
            body = self.block(n[4])
        finally:
            self.sc.loops -= 1
        on_error = self.fail(n[2][-1])
        stop = _STOP

        def run(f):
            init(f)
            k = 0
            while True:
                v = c(f)
                if not (v is True or (v is not False and _truth(v, on_error))):
                    return None
                r = body(f)
                if r is not None and r != CONTINUE:
                    if r == BREAK:
                        return None
                    return r
                step(f)
                k += 1
                if k & STOP_CHECK == 0 and stop[0]:
                    check_stop()
        return run

    def s_loop_foreach(self, n):
        var, seqn, pos = n[1], n[2], n[4]
        seq = self.expr(seqn)
        kind, st = self.store(("name", var, pos), pos)
        body = self._loop_body(n[3])
        on_error = self.fail(seqn[-1])
        stop = _STOP

        def run(f):
            try:
                items = iterate(seq(f))
            except Exception as e:
                raise on_error(e) from None
            k = 0
            for item in items:
                if kind == "slot":
                    f[st] = item
                else:
                    st(f, item)
                r = body(f)
                if r is not None and r != CONTINUE:
                    if r == BREAK:
                        return None
                    return r
                k += 1
                if k & STOP_CHECK == 0 and stop[0]:
                    check_stop()
            return None
        return run

    def s_loop_range(self, n):
        var, e1, e2, e3, stmts, pos = n[1], n[2], n[3], n[4], n[5], n[6]
        a, b = self.expr(e1), self.expr(e2)
        c = self.expr(e3) if e3 is not None else None
        kind, st = self.store(("name", var, pos), pos)
        get = self.expr(("name", var, pos))
        body = self._loop_body(stmts)
        on_error = self.fail(pos, 4)
        stop = _STOP
        add = BINARY["+"]

        def run(f):
            first, last = a(f), b(f)
            step = c(f) if c is not None else 1
            for v, what in ((first, "first"), (last, "last"), (step, "step")):
                if type(v) is not int and type(v) is not float:
                    raise on_error(FishValueError(f"the loop's {what} value must be a number, not a {type_name(v)}"))
            if step == 0:
                raise on_error(FishValueError("the loop step is zero: the loop would never end"))
            up = step > 0
            v = first
            k = 0
            # Itasca FISH: the counter is compared with the last value at the end of each pass, so the
            # body runs at least once ("FISH statements > loop", 3DEC/FLAC3D 7 manuals)
            while True:
                if kind == "slot":
                    f[st] = v
                else:
                    st(f, v)
                r = body(f)
                if r is not None and r != CONTINUE:
                    if r == BREAK:
                        return None
                    return r
                try:
                    v = add(get(f), step)
                except Exception as e:
                    raise on_error(e) from None
                if (v > last) if up else (v < last):
                    if kind == "slot":
                        f[st] = v
                    else:
                        st(f, v)
                    return None
                k += 1
                if k & STOP_CHECK == 0 and stop[0]:
                    check_stop()
        return run

    def s_break(self, n):
        if not self.sc.loops:
            raise self.err("`exit loop` outside a loop", n[1], 4)
        return _signal(BREAK)

    def s_continue(self, n):
        if not self.sc.loops:
            raise self.err("`continue` outside a loop", n[1], 8)
        return _signal(CONTINUE)

    def s_return(self, n):
        return _signal(RETURN)

    def s_exit_section(self, n):
        if not self.sc.sections:
            raise self.err("`exit section` outside a section", n[1], 4)
        return _signal(EXIT_SECTION)

    def s_section(self, n):
        self.sc.sections += 1
        loops = self.sc.loops
        self.sc.loops = 0           # `exit loop` cannot leave a section for a loop around it
        try:
            body = self.block(n[1])
        finally:
            self.sc.sections -= 1
            self.sc.loops = loops

        def run(f):
            r = body(f)
            if r == EXIT_SECTION:
                return None
            return r
        return run

    def s_case_of(self, n):
        sel = self.expr(n[1])
        cases = []
        for values, body, _pos in n[2]:
            cases.append((tuple(self.expr(v) for v in values), self.block(body)))
        cases = tuple(cases)
        from .values import equal

        def run(f):
            v = sel(f)
            for values, body in cases:
                for c in values:
                    if equal(v, c(f)):
                        return body(f)
            return None
        return run


def _signal(code):
    def run(f):
        return code
    return run


def _component_setter(get, put, k, comp):
    kind, st = put

    def set_comp(f, v):
        cur = get(f)
        if type(cur) is not Vec:
            raise FishValueError(f"`->{comp}` needs a vector, not a {type_name(cur)}")
        nv = cur.replace(k, v)
        if kind == "slot":
            f[st] = nv
        else:
            st(f, nv)
    return set_comp


def _unsupported_setter(rt, src, pos, name):
    def set_(f, v):
        from ..errors import NotSupportedError
        raise rt.error_at((src, pos), f"FISH intrinsic `{name}` cannot be set: not supported yet", NotSupportedError)
    return set_
