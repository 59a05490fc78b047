"""``it.gridpointarray``: gridpoint values as numpy arrays, one row per gridpoint (the vertices of rigid
blocks and the nodes of zoned blocks; row i is ``it.block.gridpoint.find(i + 1)``). FLAC3D's
``itasca.gridpointarray`` pattern (3DEC's names are not documented).

``pos()`` is a read-only checked view (``LiveArray``) of the model's positions; ``vel()``, ``disp()`` are
computed as FISH block.gp.vel / block.gp.disp compute them (a rigid block's vertex moves with its block:
v + ω × (x − c), x − x₀) and are copies.

==========  =======  ========  ====================
function    shape    dtype     unit
==========  =======  ========  ====================
pos()       (n, 3)   float64   position [m]
vel()       (n, 3)   float64   velocity [m/s]
disp()      (n, 3)   float64   displacement [m]
block()     (n,)     int64     id of the host block
zoned()     (n,)     bool      node of a zoned block
==========  =======  ========  ====================
"""
from __future__ import annotations

import numpy as np

from ._bind import Model
from ._live import LiveArray, live
from ._objects import api_of


def pos(model: Model | None = None) -> LiveArray:
    return live(api_of(model), "vertices", "pos", "gridpointarray")


def zoned(model: Model | None = None) -> np.ndarray:
    v = api_of(model).session.model.vertices
    return v["zoned"].copy() if "zoned" in v else np.zeros(v.n, dtype=bool)


def block(model: Model | None = None) -> np.ndarray:
    st = api_of(model).session.model
    return st.blocks["id"][st.vertices["block"]].copy()


def vel(model: Model | None = None) -> np.ndarray:
    st = api_of(model).session.model
    v, b = st.vertices, st.blocks
    k = v["block"]
    out = b["velocity"][k] + np.cross(b["spin"][k], v["pos"] - b["centroid"][k])
    z = zoned(model)
    out[z] = v["velocity"][z]
    return out


def disp(model: Model | None = None) -> np.ndarray:
    st = api_of(model).session.model
    v = st.vertices
    out = v["pos"] - v["origin"]
    z = zoned(model)
    out[z] = v["disp"][z]
    return out
