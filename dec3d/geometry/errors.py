"""The geometry layer's error: bad input shapes, impossible cuts, unknown blocks."""
from __future__ import annotations

from dec3d.errors import Dec3dError


class GeometryError(Dec3dError):
    """A polyhedron or a geometric operation is invalid; the message says why."""
