"""The model: every store of the simulation plus its settings.

`model new` replaces the session's Model with a fresh one.

Stores (struct-of-arrays, see ``store.py``; shapes after the leading row dimension):

``blocks``       one row per convex block (rigid, deformable or FE)
    id ()            int64  user-visible number, from 1, stable across deletes and cuts
    centroid (3,)    m      volume centroid
    volume ()        m³
    density ()       kg/m³  (0 until ``block property density`` sets it)
    mass ()          kg
    inertia (3, 3)   kg·m²  full tensor about the centroid, global axes
    principal_moment (3,) kg·m², ascending; principal_axes (3, 3) columns are the axes
    inertia_approx () kg·m² scalar inertia for quasi-static runs (``geometry.mass``)
    velocity, spin, force, moment (3,)  m/s, rad/s, N, N·m (the engine fills them)
    fixity ()        uint8  bits 0-2 velocity x, y, z; bits 3-5 rotation x, y, z (``block fix``)
    disp (3,)        m      accumulated centroid displacement (``block initialize`` resets it)
    fapp, mapp (3,)  N, N·m applied force and moment (``block apply force|moment``)
    apply_fix ()     uint8  components held by ``block apply velocity|rvelocity`` (fixity bits);
                     the engine moves a block with ``fixity | apply_fix``
    kind ()          int8   KIND_RIGID / KIND_DEFORMABLE / KIND_FE
    hidden ()        bool
    leader ()        int64  row of the block whose motion this one follows (itself if not joined)
    group (nslots,)  int32  group code per slot, -1 none
    vert_start, vert_count, face_start, face_count () int64: contiguous ranges in
                     ``vertices`` and ``faces``
``vertices``     rigid-block vertices and deformable-block gridpoints alike
    pos, velocity, disp, force (3,) m, m/s, m, N; mass () kg; fixity () uint8; block () int64 row
    origin (3,)      m      where the vertex was when its block was made (a vertex a cut adds: taken
                     back through the block's rigid motion); pos − origin is what the vertex moved
                     (``dec3d.model.kinematics``). The rigid engine moves ``pos`` only.
``faces``        polygons, counter-clockwise seen from outside
    block () int64 row; normal (3,) unit outward; area () m²; centroid (3,) m;
    vstart, nvert () int64 range in ``face_vertices``; group (nslots,) int32
``face_vertices`` the CSR face loops: vertex () int64 row in ``vertices``
"""
from __future__ import annotations

import numpy as np

from .groups import GroupTable, group_field
from .settings import Settings
from .store import Field, Store

KIND_RIGID = 0
KIND_DEFORMABLE = 1
KIND_FE = 2

#: default geometric tolerance [m] (``block tolerance``): cut snapping, merging, selection
DEFAULT_TOLERANCE = 1e-6

_F = np.float64
_I = np.int64


def _block_fields() -> dict[str, Field]:
    return {
        "id": Field((), _I, 0),
        "centroid": Field((3,), _F, 0.0),
        "volume": Field((), _F, 0.0),
        "density": Field((), _F, 0.0),
        "mass": Field((), _F, 0.0),
        "inertia": Field((3, 3), _F, 0.0),
        "principal_moment": Field((3,), _F, 0.0),
        "principal_axes": Field((3, 3), _F, 0.0),
        "inertia_approx": Field((), _F, 0.0),
        # density scaling by body: the inertial mass and scalar inertia of the block's body at the
        # last detection (0: not worked out), so a run split into several commands goes on with them
        "scaled_mass": Field((), _F, 0.0),
        "scaled_inertia": Field((), _F, 0.0),
        "velocity": Field((3,), _F, 0.0),
        "spin": Field((3,), _F, 0.0),
        "force": Field((3,), _F, 0.0),
        "moment": Field((3,), _F, 0.0),
        "fixity": Field((), np.uint8, 0),
        "disp": Field((3,), _F, 0.0),
        "fapp": Field((3,), _F, 0.0),
        "mapp": Field((3,), _F, 0.0),
        "apply_fix": Field((), np.uint8, 0),
        "kind": Field((), np.int8, KIND_RIGID),
        "hidden": Field((), np.bool_, False),
        "excavated": Field((), np.bool_, False),   # `block excavate`: hidden until `block fill`
        "leader": Field((), _I, -1),
        "region": Field((), _I, 0),          # 3DEC 5 region number (`r=<i>` of generators, `range region`)
        "group": group_field(),
        "extra": Field((0,), _F, 0.0),        # FISH block.extra slots (widened on first write)
        "vert_start": Field((), _I, 0),
        "vert_count": Field((), _I, 0),
        "face_start": Field((), _I, 0),
        "face_count": Field((), _I, 0),
    }


def _vertex_fields() -> dict[str, Field]:
    return {
        "pos": Field((3,), _F, 0.0),
        "origin": Field((3,), _F, 0.0),
        "velocity": Field((3,), _F, 0.0),
        "disp": Field((3,), _F, 0.0),
        "force": Field((3,), _F, 0.0),
        "mass": Field((), _F, 0.0),
        "fixity": Field((), np.uint8, 0),
        "block": Field((), _I, -1),
        "group": group_field(),               # gridpoint groups (`block gridpoint group`)
        "extra": Field((0,), _F, 0.0),        # FISH block.gp.extra slots (widened on first write)
    }


def _face_fields() -> dict[str, Field]:
    return {
        "block": Field((), _I, -1),
        "normal": Field((3,), _F, 0.0),
        "area": Field((), _F, 0.0),
        "centroid": Field((3,), _F, 0.0),
        "vstart": Field((), _I, 0),
        "nvert": Field((), _I, 0),
        "group": group_field(),
    }


#: other names by which commands and ranges refer to stores
STORE_ALIASES = {"block": "blocks", "vertex": "vertices", "gridpoint": "vertices",
                 "face": "faces", "contact": "contacts", "subcontact": "subcontacts",
                 "zone": "zones", "flowknot": "flowknots"}


class Model:
    """All state of one simulation. Physics layers add their own stores and fields."""

    def __init__(self) -> None:
        self.settings = Settings()
        #: ``block tolerance`` [m]
        self.tolerance: float = DEFAULT_TOLERANCE
        self.groups = GroupTable()
        self.blocks = Store("blocks", _block_fields())
        self.vertices = Store("vertices", _vertex_fields(), capacity=128)
        self.faces = Store("faces", _face_fields(), capacity=128)
        self.face_vertices = Store("face_vertices", {"vertex": Field((), _I, -1)}, capacity=512)
        #: the next block id handed out (ids are never reused)
        self.next_block_id: int = 1
        self._extra_stores: dict[str, Store] = {}
        #: model time [s] and step count (the engine advances them; saved with the state)
        self.time: float = 0.0
        self.step: int = 0
        #: periodic outputs requested by commands (e.g. "vtk": ``dec3d.io.vtk.periodic_vtk``);
        #: plain data, not saved
        self.outputs: dict[str, dict] = {}

    @property
    def stores(self) -> dict[str, Store]:
        """Every store by its name: the four geometry stores first, then added ones."""
        core = {s.name: s for s in (self.blocks, self.vertices, self.faces, self.face_vertices)}
        core.update(self._extra_stores)
        return core

    def add_store(self, store: Store) -> Store:
        """Register a store made by another layer (contacts, zones ...): saved and restored
        with the rest, reachable by ``model.store(name)``."""
        if store.name in self.stores:
            raise KeyError(f"the model already has a store '{store.name}'")
        self._extra_stores[store.name] = store
        return store

    def store(self, name: str) -> Store:
        """A store by name or alias ('block', 'gridpoint', 'face', ...)."""
        key = STORE_ALIASES.get(name, name)
        stores = self.stores
        if key not in stores:
            raise KeyError(f"the model has no store '{name}'")
        return stores[key]

    def block_rows(self, ids) -> np.ndarray:
        """Rows (int64) of the blocks with the given ids; -1 where no live block has the id."""
        ids = np.atleast_1d(np.asarray(ids, dtype=_I))
        have = self.blocks["id"]
        order = np.argsort(have, kind="stable")
        pos = np.searchsorted(have[order], ids)
        pos = np.clip(pos, 0, max(len(have) - 1, 0))
        rows = order[pos] if len(have) else np.full(ids.shape, -1, _I)
        ok = (have[rows] == ids) if len(have) else np.zeros(ids.shape, bool)
        return np.where(ok, rows, -1).astype(_I)
