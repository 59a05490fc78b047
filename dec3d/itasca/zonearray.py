"""``it.zonearray`` (also ``it.block.zonearray``): zone values as numpy arrays, one row per zone (row order
of ``it.block.zone.list()``). FLAC3D's ``itasca.zonearray`` pattern (3DEC's names are not documented).
Getters are read-only checked views (``LiveArray``) except ``pos()`` and ``stress()`` (computed copies).

============  ==========  ========  ==================================================
function      shape       dtype     unit
============  ==========  ========  ==================================================
ids()         (n,)        int64     zone id
vol()         (n,)        float64   volume [m³]
pos()         (n, 3)      float64   centroid [m] (mean of the nodes)
stress()      (n, 3, 3)   float64   stress tensor [Pa], tension positive
============  ==========  ========  ==================================================
"""
from __future__ import annotations

import numpy as np

from ._bind import Model
from ._live import LiveArray, live
from ._objects import api_of


def _zones(model):
    api = api_of(model)
    if "zones" not in api.session.model.stores:
        raise ValueError("the model has no zones (`block zone generate` makes them)")
    return api


def ids(model: Model | None = None) -> LiveArray:
    return live(_zones(model), "zones", "id", "zonearray")


def vol(model: Model | None = None) -> LiveArray:
    return live(_zones(model), "zones", "volume", "zonearray")


def pos(model: Model | None = None) -> np.ndarray:
    """Zone centroids [m]: the same value as ``Zone.pos()`` (FISH block.zone.pos)."""
    from ._objects import fish_call

    api = _zones(model)
    return np.array([fish_call(api, "block.zone.pos", int(i)) for i in api.session.model.stores["zones"]["id"]]
                    ).reshape(-1, 3)


def stress(model: Model | None = None) -> np.ndarray:
    """Stress tensors (n, 3, 3) [Pa], tension positive (stored as xx, yy, zz, xy, xz, yz)."""
    s = _zones(model).session.model.stores["zones"]["stress"]
    out = np.empty((len(s), 3, 3))
    for (i, j), c in {(0, 0): 0, (1, 1): 1, (2, 2): 2, (0, 1): 3, (0, 2): 4, (1, 2): 5}.items():
        out[:, i, j] = out[:, j, i] = s[:, c]
    return out
