"""FISH expressions -> closures `ev(frame)` (the statement compiler, `compiler.Compiler`, builds on
this class). Names, operators with their fast paths for numbers, comparisons, logic, member access
and calls of FISH functions and intrinsics; every failure is located at its operator or call.
"""
from __future__ import annotations

from ..errors import BindError
from . import intrinsics as I
from .values import BINARY, COMPONENTS, FishValueError, compare, component, index, neg, truth, type_name

INT_MAX = 2 ** 63 - 1


class CompileError(BindError):
    """A FISH function that parses but cannot be compiled (a name it may not use, `exit loop` outside a loop)."""


class ExpressionCompiler:
    def __init__(self, scope):          # a compiler.Scope
        self.sc = scope
        self.rt = scope.rt
        self.src = scope.src

    # ------------------------------------------------------------ helpers
    def err(self, msg, pos, length=1, hint=None):
        return CompileError(msg, self.src.location(pos, length), hint)

    def fail(self, pos, length=1):
        """A handler turning any exception at `pos` into a located one."""
        rt, src = self.rt, self.src

        def located(e):
            return rt.locate(e, src, pos, length)
        return located

    # ------------------------------------------------------------ expressions
    def expr(self, n):
        tag = n[0]
        return getattr(self, "e_" + tag)(n)

    def e_const(self, n):
        v = n[1]

        def ev(f):
            return v
        ev.const = v
        return ev

    def e_name(self, n):
        name, pos = n[1], n[2]
        slot = self.sc.slots.get(name)
        if slot is not None:
            def ev(f):
                return f[slot]
            ev.slot = slot
            return ev
        if name == self.sc.own:
            def own(f):
                return f[0]
            own.slot = 0
            return own
        if "." in name:
            return self.dotted_value(name, pos)
        return self.global_value(name, pos)

    def global_value(self, name, pos):
        rt, src = self.rt, self.src
        g = rt.globals
        funcs = rt.functions
        intr = I.lookup(name)
        site = (src, pos)

        def ev(f):
            fn = funcs.get(name)
            if fn is not None:
                return fn.invoke((), site)
            try:
                return g[name]
            except KeyError:
                pass
            if intr is not None and intr.lo == 0:
                try:
                    return intr.fn(rt)
                except Exception as e:
                    raise rt.locate(e, src, pos, len(name)) from None
            if rt.auto_create:
                g[name] = 0
                return 0
            raise rt.error_at(site, f"undefined FISH name `{name}`",
                              hint="automatic-create is off: declare it with `global` or `local` and assign it")
        return ev

    def dotted_value(self, name, pos):
        rt, src = self.rt, self.src
        base, _, last = name.rpartition(".")
        comp = COMPONENTS.get(last)
        if comp is not None and "." not in base and (base in self.sc.slots or base == self.sc.own or
                                                     I.lookup(name) is None):
            # `v.x` on a variable: component access, as `v->x`
            get = self.e_name(("name", base, pos))

            def ev(f):
                try:
                    return component(get(f), last)
                except Exception as e:
                    raise rt.locate(e, src, pos, len(name)) from None
            return ev
        intr = I.resolve(name)
        if intr is None:
            return self.unsupported(name, pos)
        if intr.lo > 0:
            want = intr.lo

            def need_args(f):
                raise rt.error_at((src, pos), f"FISH intrinsic `{intr.name}` needs {want} argument(s): "
                                  f"write `{intr.name}(...)`")
            return need_args
        fn = intr.fn

        def value(f):
            try:
                return fn(rt)
            except Exception as e:
                raise rt.locate(e, src, pos, len(name)) from None
        return value

    def unsupported(self, name, pos):
        rt, src = self.rt, self.src
        self.sc.unsupported.add(name)

        def ev(f):
            from ..errors import NotSupportedError
            raise rt.error_at((src, pos), f"FISH intrinsic `{name}` is not supported yet", NotSupportedError)
        return ev

    def e_neg(self, n):
        a = self.expr(n[1])
        on_error = self.fail(n[2])

        def ev(f):
            v = a(f)
            t = type(v)
            if t is float or t is int:
                return -v
            try:
                return neg(v)
            except Exception as e:
                raise on_error(e) from None
        return ev

    def e_not(self, n):
        a = self.expr(n[1])
        on_error = self.fail(n[2])

        def ev(f):
            v = a(f)
            if v is True:
                return False
            if v is False:
                return True
            try:
                return not truth(v)
            except Exception as e:
                raise on_error(e) from None
        return ev

    def e_and(self, n):
        a, b = self.expr(n[1]), self.expr(n[2])
        on_error = self.fail(n[3])

        def ev(f):
            try:
                return truth(a(f)) and truth(b(f))
            except Exception as e:
                raise on_error(e) from None
        return ev

    def e_or(self, n):
        a, b = self.expr(n[1]), self.expr(n[2])
        on_error = self.fail(n[3])

        def ev(f):
            try:
                return truth(a(f)) or truth(b(f))
            except Exception as e:
                raise on_error(e) from None
        return ev

    def e_cmp(self, n):
        op, a, b = n[1], self.expr(n[2]), self.expr(n[3])
        on_error = self.fail(n[4], len(op) if op != "==" else 1)
        sa = getattr(a, "slot", None)
        cb = getattr(b, "const", None) if hasattr(b, "const") else None
        if op == "<" and sa is not None and hasattr(b, "const") and type(cb) in (int, float):
            def lt_lc(f):
                x = f[sa]
                if type(x) is int or type(x) is float:
                    return x < cb
                try:
                    return compare("<", x, cb)
                except Exception as e:
                    raise on_error(e) from None
            return lt_lc

        def ev(f):
            x, y = a(f), b(f)
            tx, ty = type(x), type(y)
            if (tx is int or tx is float) and (ty is int or ty is float):
                if op == "<":
                    return x < y
                if op == ">":
                    return x > y
                if op == "==":
                    return x == y
                if op == "!=":
                    return x != y
                if op == "<=":
                    return x <= y
                return x >= y
            try:
                return compare(op, x, y)
            except Exception as e:
                raise on_error(e) from None
        return ev

    def e_bin(self, n):
        op, an, bn, pos = n[1], n[2], n[3], n[4]
        a, b = self.expr(an), self.expr(bn)
        if hasattr(a, "const") and hasattr(b, "const"):
            try:                                      # fold constants (errors wait until run time)
                v = BINARY[op](a.const, b.const)
                return self.e_const(("const", v, pos))
            except Exception:
                pass
        slow = BINARY[op]
        on_error = self.fail(pos)
        sa, sb = getattr(a, "slot", None), getattr(b, "slot", None)
        has_cb = hasattr(b, "const")
        cb = b.const if has_cb else None
        if op in ("+", "-", "*"):
            pyop = {"+": _py_add, "-": _py_sub, "*": _py_mul}[op]
            if sa is not None and has_cb and type(cb) in (int, float):
                if op == "+":
                    def add_lc(f):
                        x = f[sa]
                        if type(x) is float:
                            r = x + cb
                            if r - r:
                                raise on_error(FishValueError("numeric overflow: the result is not a finite number"))
                            return r
                        if type(x) is int and type(cb) is int:
                            r = x + cb
                            if -INT_MAX <= r <= INT_MAX:
                                return r
                        try:
                            return slow(x, cb)
                        except Exception as e:
                            raise on_error(e) from None
                    return add_lc
                if op == "*":
                    def mul_lc(f):
                        x = f[sa]
                        if type(x) is float:
                            r = x * cb
                            if r - r:
                                raise on_error(FishValueError("numeric overflow: the result is not a finite number"))
                            return r
                        try:
                            return slow(x, cb)
                        except Exception as e:
                            raise on_error(e) from None
                    return mul_lc
            if sa is not None and sb is not None:
                def bin_ll(f):
                    x = f[sa]
                    y = f[sb]
                    tx = type(x)
                    if tx is type(y):
                        if tx is float:
                            r = pyop(x, y)
                            if r - r:
                                raise on_error(FishValueError("numeric overflow: the result is not a finite number"))
                            return r
                        if tx is int:
                            r = pyop(x, y)
                            if -INT_MAX <= r <= INT_MAX:
                                return r
                    try:
                        return slow(x, y)
                    except Exception as e:
                        raise on_error(e) from None
                return bin_ll

            def bin_gg(f):
                x = a(f)
                y = b(f)
                tx = type(x)
                if tx is type(y):
                    if tx is float:
                        r = pyop(x, y)
                        if r - r:
                            raise on_error(FishValueError("numeric overflow: the result is not a finite number"))
                        return r
                    if tx is int:
                        r = pyop(x, y)
                        if -INT_MAX <= r <= INT_MAX:
                            return r
                try:
                    return slow(x, y)
                except Exception as e:
                    raise on_error(e) from None
            return bin_gg

        def bin_any(f):
            x = a(f)
            y = b(f)
            try:
                return slow(x, y)
            except Exception as e:
                raise on_error(e) from None
        return bin_any

    def e_member(self, n):
        base, comp, pos = self.expr(n[1]), n[2], n[3]
        on_error = self.fail(pos, len(comp))
        if comp not in COMPONENTS:
            raise self.err(f"a vector has components x, y, z, not `{comp}`", pos, len(comp))

        def ev(f):
            try:
                return component(base(f), comp)
            except Exception as e:
                raise on_error(e) from None
        return ev

    def e_map(self, n):
        raise self.err("`::` is written before an argument of a call", n[2], 2)

    def args(self, nodes):
        mapped = [i for i, a in enumerate(nodes) if a[0] == "map"]
        if len(mapped) > 1:
            raise self.err("only one argument of a call can be mapped with `::`", nodes[mapped[1]][2], 2)
        fns = tuple(self.expr(a[1] if a[0] == "map" else a) for a in nodes)
        return fns, (mapped[0] if mapped else None)

    def e_call(self, n):
        name, argn, pos = n[1], n[2], n[3]
        rt, src = self.rt, self.src
        args, mapped = self.args(argn)
        site = (src, pos)
        on_error = self.fail(pos, len(name))
        nargs = len(args)
        slot = self.sc.slots.get(name)
        if slot is not None or name == self.sc.own and False:
            def idx_local(f):
                try:
                    return index(f[slot], [a(f) for a in args])
                except Exception as e:
                    raise on_error(e) from None
            return idx_local
        intr = I.resolve(name) if ("." in name or name in I.BUILTIN_CALLS) else None
        if "." in name and intr is None:
            return self.unsupported(name, pos)
        if intr is not None:
            fn, lo, hi, iname = intr.fn, intr.lo, intr.hi, intr.name

            def call_intr(f):
                vals = [a(f) for a in args]
                try:
                    if mapped is not None:
                        seq = vals[mapped]
                        if type(seq) is not list:
                            raise FishValueError(f"`::` maps over a list, not a {type_name(seq)}")
                        out = []
                        for v in seq:
                            vals[mapped] = v
                            out.append(_call_checked(fn, lo, hi, iname, rt, vals))
                        return out
                    return _call_checked(fn, lo, hi, iname, rt, vals)
                except Exception as e:
                    raise on_error(e) from None
            return call_intr
        funcs, g = rt.functions, rt.globals

        def call_user(f):
            vals = [a(f) for a in args]
            fn = funcs.get(name)
            if fn is not None:
                if mapped is not None:
                    seq = vals[mapped]
                    if type(seq) is not list:
                        raise on_error(FishValueError(f"`::` maps over a list, not a {type_name(seq)}"))
                    out = []
                    for v in seq:
                        vals[mapped] = v
                        out.append(fn.invoke(tuple(vals), site))
                    return out
                return fn.invoke(tuple(vals), site)
            if name in g:
                try:
                    return index(g[name], vals)
                except Exception as e:
                    raise on_error(e) from None
            raise rt.error_at(site, f"`{name}` is neither a FISH function nor a variable"
                              + (" (automatic-create does not make functions)" if nargs else ""))
        return call_user


def _truth(v, on_error):
    try:
        return truth(v)
    except Exception as e:
        raise on_error(e) from None


def _py_add(x, y):
    return x + y


def _py_sub(x, y):
    return x - y


def _py_mul(x, y):
    return x * y


def _call_checked(fn, lo, hi, name, rt, vals):
    n = len(vals)
    if n < lo or (hi is not None and n > hi):
        want = str(lo) if lo == hi else (f"{lo} or more" if hi is None else f"{lo} to {hi}")
        raise FishValueError(f"FISH intrinsic `{name}` takes {want} argument(s), got {n}")
    return fn(rt, *vals)
