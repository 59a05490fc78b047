"""FISH intrinsics: the registry and the ones dec3d implements.

`@intrinsic(name, lo, hi)` registers `fn(rt, *args)`; `@setter(name)` registers what
`name(args) = value` (or `name = value`) does. Dotted names may be abbreviated part by
part when the result is unambiguous (Itasca: "FISH built-in library functions may use
abbreviations if the name contains a '.' and the result is unambiguous"). Names are the
3DEC 7+ ones (Itasca FISH reference: math, string, io, system, time, global, mech,
list, vector, block).
"""
from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass
from typing import Callable

from .runtime import SystemErrorRaised
from .values import MAX_LIST, MAX_STRING, FishValueError, Vec, to_string, type_name


@dataclass(frozen=True)
class Intrinsic:
    name: str
    fn: Callable
    lo: int
    hi: int | None
    doc: str = ""


INTRINSICS: dict[str, Intrinsic] = {}
SETTERS: dict[str, Intrinsic] = {}
#: undotted names that are intrinsics only when called: `list(...)`, `vector(...)`, `string(x)` ...
BUILTIN_CALLS: set[str] = set()


def intrinsic(name: str, lo: int = 0, hi: int | None = -1, doc: str = ""):
    def deco(fn):
        INTRINSICS[name] = Intrinsic(name, fn, lo, lo if hi == -1 else hi, doc)
        if "." not in name:
            BUILTIN_CALLS.add(name)
        return fn
    return deco


def setter(name: str, doc: str = ""):
    def deco(fn):
        SETTERS[name] = Intrinsic(name, fn, 0, None, doc)
        if "." not in name:
            BUILTIN_CALLS.add(name)
        return fn
    return deco


def lookup(name: str) -> Intrinsic | None:
    return INTRINSICS.get(name)


def lookup_setter(name: str) -> Intrinsic | None:
    return SETTERS.get(name)


def _abbrev(name: str, table: dict) -> Intrinsic | None:
    hit = table.get(name)
    if hit is not None or "." not in name:
        return hit
    parts = name.split(".")
    cands = [k for k in table if len(k.split(".")) == len(parts)
             and all(full.startswith(p) for full, p in zip(k.split("."), parts))]
    return table[cands[0]] if len(cands) == 1 else None


def resolve(name: str) -> Intrinsic | None:
    return _abbrev(name, INTRINSICS)


def resolve_setter(name: str) -> Intrinsic | None:
    return _abbrev(name, SETTERS)


# ---------------------------------------------------------------- helpers

def _number(v, what="argument"):
    if type(v) is not int and type(v) is not float:
        raise FishValueError(f"{what} must be a number, not a {type_name(v)}")
    return v


def _finite(r):
    if r - r:
        raise FishValueError("numeric overflow: the result is not a finite number")
    return r


def _math1(name, f, domain=None):
    def fn(rt, x):
        _number(x, f"`{name}`: the argument")
        try:
            return _finite(f(x))
        except OverflowError:
            raise FishValueError(f"`{name}`: numeric overflow: the result for {to_string(x)} is too large") from None
        except ValueError:
            raise FishValueError(f"`{name}`: {to_string(x)} is outside its domain{domain or ''}") from None
    intrinsic(name, 1)(fn)


for _n, _f, _d in [("math.sqrt", math.sqrt, " (x >= 0)"), ("math.sin", math.sin, None),
                   ("math.cos", math.cos, None), ("math.tan", math.tan, None),
                   ("math.asin", math.asin, " (-1 <= x <= 1)"), ("math.acos", math.acos, " (-1 <= x <= 1)"),
                   ("math.atan", math.atan, None), ("math.exp", math.exp, None),
                   ("math.ln", math.log, " (x > 0)"), ("math.log", math.log10, " (x > 0)"),
                   ("math.sinh", math.sinh, None), ("math.cosh", math.cosh, None), ("math.tanh", math.tanh, None)]:
    _math1(_n, _f, _d)
# Itasca: math.log is the base-10 logarithm and math.ln the natural one.


@intrinsic("math.abs", 1)
def _abs(rt, x):
    if type(x) is Vec:
        return math.sqrt(x.x * x.x + x.y * x.y + x.z * x.z)
    return abs(_number(x))


@intrinsic("math.atan2", 2)
def _atan2(rt, y, x):
    return math.atan2(_number(y), _number(x))


@intrinsic("math.sgn", 1)
def _sgn(rt, x):
    _number(x)
    return 1 if x >= 0 else -1


@intrinsic("math.floor", 1)
def _floor(rt, x):
    return int(math.floor(_number(x)))


@intrinsic("math.ceiling", 1)
def _ceiling(rt, x):
    return int(math.ceil(_number(x)))


@intrinsic("math.round", 1)
def _round(rt, x):
    return int(math.floor(_number(x) + 0.5))


@intrinsic("math.min", 1, None)
def _min(rt, *xs):
    return min(_number(x) for x in xs)


@intrinsic("math.max", 1, None)
def _max(rt, *xs):
    return max(_number(x) for x in xs)


@intrinsic("math.pi")
def _pi(rt):
    return math.pi


@intrinsic("math.e")
def _e(rt):
    return math.e


@intrinsic("math.degrad")
def _degrad(rt):
    return math.pi / 180.0


@intrinsic("float", 1)
def _float(rt, x):
    if type(x) is str:
        try:
            return float(x)
        except ValueError:
            raise FishValueError(f"float(): {x!r} is not a number") from None
    return float(_number(x))


@intrinsic("int", 1)
def _int(rt, x):
    if type(x) is str:
        try:
            return int(float(x))
        except ValueError:
            raise FishValueError(f"int(): {x!r} is not a number") from None
    x = _number(x)
    if x - x:
        raise FishValueError("int(): the value is not finite")
    return int(x)


@intrinsic("boolean", 1)
def _boolean(rt, x):
    from .values import truth
    return truth(x)


# ---------------------------------------------------------------- strings

@intrinsic("string", 1)
def _string(rt, v):
    return to_string(v)


@intrinsic("string.build", 1, None)
def _string_build(rt, fmt, *args):
    """`%1` ... `%n` are replaced by the arguments (`%10` before `%1`)."""
    if type(fmt) is not str:
        raise FishValueError("string.build: the first argument must be a string")
    out = fmt
    for k in range(len(args), 0, -1):
        out = out.replace(f"%{k}", to_string(args[k - 1]))
    if len(out) > MAX_STRING:
        raise FishValueError(f"string longer than {MAX_STRING} characters")
    return out


@intrinsic("string.len", 1)
def _string_len(rt, s):
    if type(s) is not str:
        raise FishValueError(f"string.len needs a string, not a {type_name(s)}")
    return len(s)


@intrinsic("string.upper", 1)
def _upper(rt, s):
    if type(s) is not str:
        raise FishValueError(f"string.upper needs a string, not a {type_name(s)}")
    return s.upper()


@intrinsic("string.lower", 1)
def _lower(rt, s):
    if type(s) is not str:
        raise FishValueError(f"string.lower needs a string, not a {type_name(s)}")
    return s.lower()


@intrinsic("string.sub", 2, 3)
def _sub(rt, s, start, length=None):
    """1-based start; the rest of the string when no length is given."""
    if type(s) is not str or type(start) is not int or (length is not None and type(length) is not int):
        raise FishValueError("string.sub takes (string, start, [length]) with integer positions")
    i = max(start - 1, 0)
    return s[i:] if length is None else s[i:i + max(length, 0)]


# ---------------------------------------------------------------- io, system, time

@intrinsic("io.out", 1, None)
def _io_out(rt, *vs):
    rt.write(" ".join(to_string(v) for v in vs))
    return 0


@setter("system.error")
def _system_error(rt, message):
    raise SystemErrorRaised(to_string(message))


@intrinsic("system.command", 1)
def _system_command(rt, text):
    """Run a command given as a string (`system.command('exit')`), bound and run at once, as a line of a
    `command … endcommand` section: in a FISH callback, commands that cycle or change the blocks are refused."""
    if type(text) is not str:
        raise FishValueError(f"`system.command` takes a command (a string), not a {type_name(text)}")
    from .sections import _cycle_bound

    def refuse(path):
        if rt.in_callback and _cycle_bound(path):
            return (f"`{' '.join(path)}` cannot run in a FISH callback: the cycle that calls it is still going "
                    "on (cycling again, replacing the model or changing its blocks is refused there)")
        return None
    rt.session.system_command(text, rt.stack(), refuse)
    return 0


@intrinsic("system.directory.create", 1)
def _directory_create(rt, name):
    """Make a folder (and its parents) under the output folder; 0 when it exists afterwards. A name that
    leaves the output folder is refused as every file a deck writes (dec3d.io.paths)."""
    if type(name) is not str:
        raise FishValueError(f"`system.directory.create` takes a folder name (a string), not a {type_name(name)}")
    # checked as a file inside the folder: the folder itself may exist already
    path = rt.session.out_path((name.rstrip("/\\") or name) + "/.dec3d-folder").parent
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise FishValueError(f"`system.directory.create`: cannot make '{name}': {exc.strerror or exc}") from None
    return 0


@intrinsic("time.kernel")
def _time_kernel(rt):
    """Milliseconds of processor time spent by dec3d (Itasca: time in calculations, ms)."""
    return _time.process_time() * 1000.0


@intrinsic("time.clock")
def _time_clock(rt):
    """Hundredths of a second of wall-clock time since the program started."""
    return int((_time.perf_counter() - _START) * 100)


_START = _time.perf_counter()


# ---------------------------------------------------------------- types, lists, vectors

@intrinsic("type", 1)
def _type(rt, v):
    """Itasca's type codes: 1 integer, 2 float, 3 string, 4 pointer/index, 5 vector (2-D), 6 vector (3-D),
    7 boolean, ... 10 list, 11 map; dec3d returns the ones it has."""
    code = {int: 1, float: 2, str: 3, Vec: 6, bool: 7, list: 10, dict: 11}.get(type(v))
    return code if code is not None else (4 if hasattr(v, "kind") and hasattr(v, "key") else 0)


@intrinsic("list", 0, None)
def _list(rt, *items):
    if len(items) == 1 and type(items[0]) in (list, Vec):
        return list(items[0])
    return list(items)


@intrinsic("list.size", 1)
def _list_size(rt, v):
    if type(v) not in (list, dict):
        raise FishValueError(f"list.size needs a list, not a {type_name(v)}")
    return len(v)


@intrinsic("list.sequence", 1, 3)
def _list_sequence(rt, n, start=1, step=1):
    """n values from start (default 1) by step (default 1)."""
    if type(n) is not int or n < 0:
        raise FishValueError("list.sequence: the count must be a non-negative integer")
    if n > MAX_LIST:
        raise FishValueError(f"a list longer than {MAX_LIST} items")
    return [start + k * step for k in range(n)]


@intrinsic("list.append", 2)
def _list_append(rt, lst, v):
    if type(lst) is not list:
        raise FishValueError(f"list.append needs a list, not a {type_name(lst)}")
    if len(lst) >= MAX_LIST:
        raise FishValueError(f"a list longer than {MAX_LIST} items")
    return lst + [v]


@intrinsic("list.sum", 1)
def _list_sum(rt, lst):
    if type(lst) is not list:
        raise FishValueError(f"list.sum needs a list, not a {type_name(lst)}")
    from .values import add
    total = 0
    for v in lst:
        total = add(total, v)
    return total


@intrinsic("array.create", 1)
def _array_create(rt, n):
    if type(n) is not int or n < 0:
        raise FishValueError("array.create: the size must be a non-negative integer")
    if n > MAX_LIST:
        raise FishValueError(f"an array longer than {MAX_LIST} items")
    return [0] * n


@intrinsic("map", 0, None)
def _map(rt, *kv):
    if len(kv) % 2:
        raise FishValueError("map() takes key, value pairs")
    out = {}
    for k in range(0, len(kv), 2):
        if type(kv[k]) not in (int, float, str, bool):
            raise FishValueError(f"a map key must be a number or a string, not a {type_name(kv[k])}")
        out[kv[k]] = kv[k + 1]
    return out


@intrinsic("map.size", 1)
def _map_size(rt, m):
    if type(m) is not dict:
        raise FishValueError(f"map.size needs a map, not a {type_name(m)}")
    return len(m)


@intrinsic("map.has", 2)
def _map_has(rt, m, k):
    if type(m) is not dict:
        raise FishValueError(f"map.has needs a map, not a {type_name(m)}")
    return k in m


@intrinsic("vector", 3)
def _vector(rt, x, y, z):
    return Vec(_number(x), _number(y), _number(z))


for _k, _c in (("x", 0), ("y", 1), ("z", 2)):
    def _comp(rt, v, _c=_c, _k=_k):
        if type(v) is not Vec:
            raise FishValueError(f"vector.{_k} needs a vector, not a {type_name(v)}")
        return v.comp(_c)
    intrinsic(f"vector.{_k}", 1)(_comp)


@intrinsic("math.dot", 2)
def _dot(rt, a, b):
    if type(a) is not Vec or type(b) is not Vec:
        raise FishValueError("math.dot needs two vectors")
    return a.x * b.x + a.y * b.y + a.z * b.z


@intrinsic("math.cross", 2)
def _cross(rt, a, b):
    if type(a) is not Vec or type(b) is not Vec:
        raise FishValueError("math.cross needs two vectors")
    return Vec(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x)


@intrinsic("math.mag", 1)
def _mag(rt, a):
    if type(a) is not Vec:
        raise FishValueError("math.mag needs a vector")
    return math.sqrt(a.x * a.x + a.y * a.y + a.z * a.z)


# ---------------------------------------------------------------- model-wide values

@intrinsic("global.gravity")
def _gravity(rt):
    return Vec(*(float(g) for g in rt.session.model.settings.gravity))


for _k, _c in (("x", 0), ("y", 1), ("z", 2)):
    intrinsic(f"global.gravity.{_k}")(lambda rt, _c=_c: float(rt.session.model.settings.gravity[_c]))


@intrinsic("global.step")
def _global_step(rt):
    return int(rt.session.model.step)


@intrinsic("model.step")
def _model_step(rt):
    return int(rt.session.model.step)


@intrinsic("mech.cycle")
def _mech_cycle(rt):
    return int(rt.session.model.step)


@intrinsic("mech.time")
def _mech_time(rt):
    return float(rt.session.model.time)


@intrinsic("mech.time.total")
def _mech_time_total(rt):
    return float(rt.session.model.time)


@intrinsic("dynamic.time.total")
def _dynamic_time_total(rt):
    """The dynamic time [s]: accumulated while `model dynamic active on` (set by `model dynamic time-total`)."""
    return float(rt.session.model.settings.mechanical.get("dyn_time", 0.0))


#: ``ENGINE[0](model)`` -> the model's rigid engine (registered by dec3d.commands.fish_cmds; FISH imports
#: no physics). mech.timestep and mech.solve read it.
ENGINE: list = [None]


def _engine(rt, name):
    if ENGINE[0] is None:                     # pragma: no cover - the commands layer registers it at import
        raise FishValueError(f"`{name}`: no cycling engine is attached")
    return ENGINE[0](rt.session.model)


@intrinsic("mech.timestep")
def _mech_timestep(rt):
    """The time step [s] of the last cycle (0 before the model has cycled)."""
    return float(_engine(rt, "mech.timestep").dt)


_SOLVE = ("ratio", "ratio-average", "ratio-local", "ratio-maximum", "unbalanced-maximum")


@intrinsic("mech.solve", 1)
def _mech_solve(rt, what):
    """An equilibrium measure of the last step, as `model solve` uses it: 'ratio', 'ratio-average',
    'ratio-local', 'ratio-maximum' or 'unbalanced-maximum' (abbreviations as for the command)."""
    if type(what) is not str:
        raise FishValueError(f"`mech.solve` takes the name of a measure (a string), not a {type_name(what)}")
    key = what.lower()
    hits = [k for k in _SOLVE if k == key] or [k for k in _SOLVE if k.startswith(key)]
    if len(hits) != 1:
        raise FishValueError(f"`mech.solve`: '{what}' is {'ambiguous' if hits else 'not'} one of {', '.join(_SOLVE)}")
    return float(_engine(rt, "mech.solve").criteria()[hits[0]])


@intrinsic("global.title")
def _title(rt):
    return rt.session.model.settings.title

from . import block_intrinsics  # noqa: E402,F401  (registers block.*)
from . import contact_intrinsics  # noqa: E402,F401  (registers block.contact.*, block.subcontact.*)
from . import table_intrinsics  # noqa: E402,F401  (registers table.*)
from . import zone_intrinsics  # noqa: E402,F401  (registers block.zone.*)
from . import struct_intrinsics  # noqa: E402,F401  (registers struct.cable.*, struct.node.*)
from . import liner_intrinsics  # noqa: E402,F401  (registers struct.liner.*, struct.shell.resultant)
from . import extra_intrinsics  # noqa: E402,F401  (registers block.extra, block.gp.extra, block.gp.dsf)
from . import file_intrinsics  # noqa: E402,F401  (registers file.open/read/write/close)
from . import dfn_intrinsics  # noqa: E402,F401  (registers fracture.*)
from . import flow_intrinsics  # noqa: E402,F401  (registers flowknot.*, block.contact.flow.*)
