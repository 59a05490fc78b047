"""``it.fish``: FISH global variables of the bound model (Itasca's ``itasca.fish.get`` / ``set``).

Values cross as Python values: int, float, bool, str; a FISH vector as a numpy array (3,) (set one from
any three numbers with ``set(name, numpy_array)``); lists as Python lists.
"""
from __future__ import annotations

import math

import numpy as np

from ._bind import Model
from ._objects import api_of


def _out(v):
    from ..fish.values import Vec

    if type(v) is Vec:
        return np.array([v.x, v.y, v.z], dtype=float)
    if isinstance(v, list):
        return [_out(x) for x in v]
    return v


def get(name: str, model: Model | None = None):
    """The value of FISH global ``name`` (KeyError when there is none; a FISH function is called with no
    arguments, as `fish list` shows its value)."""
    if not isinstance(name, str):
        raise TypeError(f"fish.get takes a FISH name (a string), not a {type(name).__name__}")
    api = api_of(model)
    s = api.session
    key = name.lower()
    if key in s.variables:
        return _out(s.variables[key])
    if name in s.variables:
        return _out(s.variables[name])
    fn = s.fish_rt.functions.get(key)
    if fn is not None:
        return _out(fn.invoke([], None))
    raise KeyError(f"there is no FISH variable '{name}'")


def set(name: str, value, model: Model | None = None) -> None:  # noqa: A001 - Itasca's name
    """Set FISH global ``name`` (made when new): int, float, bool, str, or three numbers (a vector)."""
    from ..fish.values import Vec

    if not isinstance(name, str) or not name.replace("_", "a").isalnum() or name[0].isdigit():
        raise ValueError(f"fish.set: '{name}' is not a FISH name")
    if isinstance(value, (bool, np.bool_)):
        v = bool(value)
    elif isinstance(value, (int, np.integer)):
        v = int(value)
    elif isinstance(value, (float, np.floating)):
        v = float(value)
        if not math.isfinite(v):
            raise ValueError(f"fish.set: {name} = {value} is not a finite number")
    elif isinstance(value, str):
        v = value
    else:
        a = np.asarray(value, dtype=float) if not isinstance(value, dict) else None
        if a is None or a.shape != (3,) or not np.all(np.isfinite(a)):
            raise TypeError(f"fish.set: {name} takes an int, float, bool, str or three finite numbers, not {value!r}")
        v = Vec(float(a[0]), float(a[1]), float(a[2]))
    api = api_of(model)
    key = name.lower()
    if key in api.session.fish_rt.functions:
        raise ValueError(f"fish.set: '{name}' is a FISH function, not a variable")
    api.session.variables[key] = v
    api.session.bind_context.assigned.add(key)


def call_function(name: str, *args, model: Model | None = None):
    """Call FISH function ``name`` with ``args`` (numbers, strings, booleans, three-number vectors) and
    return its value (FLAC3D's ``itasca.fish.call_function``). KeyError when there is no such function; an
    error inside it raises ``ItascaError`` with FISH's report."""
    from ..errors import Dec3dError
    from ..fish.values import Vec
    from ._bind import ItascaError

    api = api_of(model)
    fn = api.session.fish_rt.functions.get(str(name).lower())
    if fn is None:
        raise KeyError(f"there is no FISH function '{name}'")
    conv = []
    for a in args:
        if isinstance(a, (bool, int, float, str, np.bool_, np.integer, np.floating)):
            conv.append(a.item() if isinstance(a, np.generic) else a)
        else:
            v = np.asarray(a, dtype=float)
            if v.shape != (3,):
                raise TypeError(f"fish.call_function: an argument is a number, a string or three numbers, not {a!r}")
            conv.append(Vec(float(v[0]), float(v[1]), float(v[2])))
    try:
        return _out(fn.invoke(conv, None))
    except Dec3dError as exc:
        raise ItascaError(f"FISH function '{name}' failed:\n{exc.format()}", exc.format()) from None
