"""FISH run-time values and the operators on them.

Integers and floats are Python int/float (integers are kept within 64 bits, as FISH's);
booleans are bool; strings str; vectors `Vec`; lists and arrays Python lists (1-based
in FISH); maps dict. Every operator checks its operand types and raises `FishTypeError`
with the operator and the two types named: nothing is coerced silently.
"""
from __future__ import annotations

import math

from ..errors import ExpressionError

INT_MAX = 2 ** 63 - 1
MAX_STRING = 1_000_000           # characters in one FISH string
MAX_LIST = 10_000_000            # items in one FISH list / array


class FishValueError(ExpressionError):
    """A FISH operation failed (division by zero, bad types, overflow, bad index)."""


class Vec:
    """A 3-D FISH vector (value semantics: operations make new vectors)."""

    __slots__ = ("x", "y", "z")

    def __init__(self, x, y, z):
        self.x, self.y, self.z = x, y, z

    def comp(self, k: int):
        return (self.x, self.y, self.z)[k]

    def replace(self, k: int, v) -> "Vec":
        c = [self.x, self.y, self.z]
        c[k] = v
        return Vec(*c)

    def __iter__(self):
        return iter((self.x, self.y, self.z))

    def __eq__(self, other):
        return isinstance(other, Vec) and (self.x, self.y, self.z) == (other.x, other.y, other.z)

    def __hash__(self):
        return hash((self.x, self.y, self.z))

    def __repr__(self):
        return f"({to_string(self.x)},{to_string(self.y)},{to_string(self.z)})"


COMPONENTS = {"x": 0, "y": 1, "z": 2}

_TYPE_NAMES = {int: "integer", float: "float", bool: "boolean", str: "string", Vec: "vector", list: "list",
               dict: "map", type(None): "null"}


def type_name(v) -> str:
    name = _TYPE_NAMES.get(type(v))
    if name is None:
        kind = getattr(v, "kind", None)          # pointers of the model intrinsics (contact, sub-contact)
        return kind if isinstance(kind, str) else type(v).__name__
    return name


def to_string(v) -> str:
    """FISH string(): integers as written, floats with a decimal point, booleans true/false."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(v) if v != int(v) or abs(v) >= 1e16 else f"{v:.1f}"
    if isinstance(v, list):
        return "(" + ",".join(to_string(x) for x in v) + ")"
    if v is None:
        return "null"
    return str(v)


def truth(v) -> bool:
    t = type(v)
    if t is bool:
        return v
    if t is int or t is float:
        return v != 0
    if v is None:
        return False
    raise FishValueError(f"a condition must be a boolean or a number, not a {type_name(v)}")


def _num(v) -> bool:
    t = type(v)
    return t is int or t is float


def check_float(r):
    if r - r:                                   # inf - inf and nan - nan are nan (truthy); finite gives 0
        raise FishValueError("numeric overflow: the result is not a finite number")
    return r


def check_int(r: int) -> int:
    if -INT_MAX - 1 <= r <= INT_MAX:
        return r
    raise FishValueError("integer overflow: the result does not fit in 64 bits (write a float, e.g. 2.0)")


def _type_error(op: str, a, b):
    hint = " (convert with string(x))" if op == "+" and (type(a) is str or type(b) is str) else ""
    return FishValueError(f"operator {op} cannot combine {type_name(a)} and {type_name(b)}{hint}")


def add(a, b):
    ta, tb = type(a), type(b)
    if (ta is int or ta is float) and (tb is int or tb is float):
        r = a + b
        return check_int(r) if type(r) is int else check_float(r)
    if ta is str and tb is str:
        if len(a) + len(b) > MAX_STRING:
            raise FishValueError(f"string longer than {MAX_STRING} characters")
        return a + b
    if ta is Vec and tb is Vec:
        return Vec(add(a.x, b.x), add(a.y, b.y), add(a.z, b.z))
    raise _type_error("+", a, b)


def sub(a, b):
    ta, tb = type(a), type(b)
    if (ta is int or ta is float) and (tb is int or tb is float):
        r = a - b
        return check_int(r) if type(r) is int else check_float(r)
    if ta is Vec and tb is Vec:
        return Vec(sub(a.x, b.x), sub(a.y, b.y), sub(a.z, b.z))
    raise _type_error("-", a, b)


def mul(a, b):
    ta, tb = type(a), type(b)
    if (ta is int or ta is float) and (tb is int or tb is float):
        r = a * b
        return check_int(r) if type(r) is int else check_float(r)
    if ta is Vec and _num(b):
        return Vec(mul(a.x, b), mul(a.y, b), mul(a.z, b))
    if tb is Vec and _num(a):
        return Vec(mul(a, b.x), mul(a, b.y), mul(a, b.z))
    raise _type_error("*", a, b)


def div(a, b):
    ta, tb = type(a), type(b)
    if (ta is int or ta is float) and (tb is int or tb is float):
        if b == 0:
            raise FishValueError("division by zero")
        if ta is int and tb is int:
            q = abs(a) // abs(b)                # FISH integer division truncates toward zero
            return check_int(q if (a >= 0) == (b >= 0) else -q)
        return check_float(a / b)
    if ta is Vec and _num(b):
        return Vec(div(a.x, b), div(a.y, b), div(a.z, b))
    raise _type_error("/", a, b)


def power(a, b):
    if not (_num(a) and _num(b)):
        raise _type_error("^", a, b)
    if type(a) is int and type(b) is int and b >= 0:
        if abs(a) > 1 and b * math.log2(abs(a)) > 63:
            raise FishValueError("integer overflow: the result does not fit in 64 bits (write a float, e.g. 2.0)")
        return a ** b
    try:
        r = float(a) ** float(b)
    except ZeroDivisionError:
        raise FishValueError("division by zero (0 to a negative power)") from None
    except OverflowError:
        raise FishValueError("numeric overflow: the result is not a finite number") from None
    if type(r) is complex:
        raise FishValueError(f"a negative number to a fractional power ({to_string(a)}^{to_string(b)})")
    return check_float(r)


def neg(a):
    t = type(a)
    if t is int or t is float:
        return -a
    if t is Vec:
        return Vec(neg(a.x), neg(a.y), neg(a.z))
    raise FishValueError(f"cannot negate a {type_name(a)}")


BINARY = {"+": add, "-": sub, "*": mul, "/": div, "^": power}


def equal(a, b) -> bool:
    if _num(a) and _num(b):
        return a == b
    if type(a) is not type(b):
        return False
    return a == b


def compare(op: str, a, b) -> bool:
    if op == "==":
        return equal(a, b)
    if op == "!=":
        return not equal(a, b)
    if not ((_num(a) and _num(b)) or (type(a) is str and type(b) is str)):
        raise FishValueError(f"operator {op} cannot compare {type_name(a)} and {type_name(b)}")
    if op == "<":
        return a < b
    if op == ">":
        return a > b
    if op == "<=":
        return a <= b
    return a >= b


def index(container, args):
    """`a(i)`: 1-based element of a list/array, value of a map key, component of a vector;
    a list of booleans picks the elements where it is true (as `allpts(check)` in the decks)."""
    t = type(container)
    if t is dict:
        if len(args) != 1:
            raise FishValueError(f"a map takes one key, got {len(args)}")
        key = args[0]
        if key not in container:
            raise FishValueError(f"key {to_string(key)!r} is not in the map")
        return container[key]
    if t is list or t is Vec:
        if len(args) == 1 and type(args[0]) is list:
            sel = args[0]
            if t is not list or len(sel) != len(container) or any(type(s) is not bool for s in sel):
                raise FishValueError("a list can be indexed by a list of booleans of the same size")
            return [v for v, s in zip(container, sel) if s]
        v = container
        for i in args:
            if type(i) is not int:
                raise FishValueError(f"an index must be an integer, not a {type_name(i)}")
            items = list(v) if type(v) is Vec else v
            if type(items) is not list:
                raise FishValueError(f"too many indices: a {type_name(v)} is not a list")
            if not 1 <= i <= len(items):
                raise FishValueError(f"index {i} is out of range 1..{len(items)}")
            v = items[i - 1]
        return v
    raise FishValueError(f"a {type_name(container)} cannot be indexed")


def set_index(container, args, value):
    t = type(container)
    if t is dict:
        if len(args) != 1:
            raise FishValueError(f"a map takes one key, got {len(args)}")
        if type(args[0]) not in (int, str, float, bool):
            raise FishValueError(f"a map key must be a number or a string, not a {type_name(args[0])}")
        if args[0] not in container and len(container) >= MAX_LIST:
            raise FishValueError(f"a map larger than {MAX_LIST} entries")
        container[args[0]] = value
        return
    if t is list:
        v = container
        for n, i in enumerate(args):
            if type(i) is not int:
                raise FishValueError(f"an index must be an integer, not a {type_name(i)}")
            if type(v) is not list:
                raise FishValueError(f"too many indices: a {type_name(v)} is not a list")
            if not 1 <= i <= len(v):
                raise FishValueError(f"index {i} is out of range 1..{len(v)}")
            if n == len(args) - 1:
                v[i - 1] = value
            else:
                v = v[i - 1]
        return
    raise FishValueError(f"a {type_name(container)} cannot be indexed")


def component(v, name: str):
    k = COMPONENTS.get(name)
    if k is None:
        raise FishValueError(f"a vector has components x, y, z, not `{name}`")
    if type(v) is not Vec:
        raise FishValueError(f"`->{name}` needs a vector, not a {type_name(v)}")
    return v.comp(k)


def iterate(v):
    """What `loop foreach` walks: a list, a map's values, a vector's components."""
    t = type(v)
    if t is list:
        return list(v)
    if t is dict:
        return list(v.values())
    if t is Vec:
        return [v.x, v.y, v.z]
    raise FishValueError(f"`loop foreach` needs a list, not a {type_name(v)}")
