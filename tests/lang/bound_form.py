"""A bound value in comparable form (floats by their bits, locations resolved), for the tests that
compare what two binding paths, or two commits, make of the same line."""
import math

from dec3d.errors import LazyLocation
from dec3d.lang.deferred import Deferred


def norm(v):
    if isinstance(v, float):
        return ("f", v.hex() if math.isfinite(v) else repr(v))
    if isinstance(v, (list, tuple)):
        return (type(v).__name__, tuple(norm(x) for x in v))
    if isinstance(v, dict):
        return ("d", tuple((k, norm(x)) for k, x in v.items()))
    if isinstance(v, LazyLocation):
        return ("loc", v.resolve())
    if isinstance(v, Deferred):
        return ("deferred", v.kind, norm(v.node), str(v.token), v.token.line, v.token.column, norm(v.where))
    return v
