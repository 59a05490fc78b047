"""Geometric measures of zones (``block zone list information``, ranges, histories, VTK) and the
stress measures derived from a zone's stress tensor. Vectorised numpy over the ``zones`` store
(dec3d.model.zones); only the four corners of a zone are used (10-node zones have straight edges).

Dihedral angle of a tetrahedron at an edge: the angle between the two faces that meet there,
π minus the angle between their outward normals. A regular tetrahedron has arccos(1/3) ≈ 70.53°
at every edge; a sliver has one near 0°.
"""
from __future__ import annotations

import numpy as np

#: the six edges of a tetrahedron as corner pairs, and the two faces (by opposite corner) meeting at each
EDGES = np.array([(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)])
_EDGE_FACES = np.array([(2, 3), (0, 3), (1, 3), (1, 2), (0, 2), (0, 1)])


def corners(model, rows=None) -> np.ndarray:
    """(m, 4, 3) corner positions of the zones ``rows`` (all zones by default)."""
    zs = model.store("zones")
    gp = zs["gp"][:, :4] if rows is None else zs["gp"][np.asarray(rows, dtype=np.int64), :4]
    return model.vertices["pos"][gp]


def centroids(model, rows=None) -> np.ndarray:
    """(m, 3) centroids (mean of the four corners)."""
    return corners(model, rows).mean(axis=1)


def volumes(p: np.ndarray) -> np.ndarray:
    """Signed volumes of tetrahedra with corners ``p`` (m, 4, 3): positive when right-handed."""
    return np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0]) / 6.0


def edge_lengths(p: np.ndarray) -> np.ndarray:
    """(m, 6) lengths of the six edges (order ``EDGES``)."""
    return np.linalg.norm(p[:, EDGES[:, 1]] - p[:, EDGES[:, 0]], axis=2)


def face_normals(p: np.ndarray) -> np.ndarray:
    """(m, 4, 3) outward unit normals of the faces, face k being the one opposite corner k."""
    out = np.empty(p.shape, dtype=np.float64)
    for k in range(4):
        a, b, c = (p[:, j] for j in range(4) if j != k)
        n = np.cross(b - a, c - a)
        # outward: pointing away from the opposite corner
        s = np.sign(np.einsum("ij,ij->i", n, a - p[:, k]))
        n *= s[:, None]
        length = np.linalg.norm(n, axis=1)
        out[:, k] = n / np.where(length > 0.0, length, 1.0)[:, None]
    return out


def dihedral_angles(p: np.ndarray) -> np.ndarray:
    """(m, 6) dihedral angles [rad] at the six edges (order ``EDGES``)."""
    n = face_normals(p)
    cosang = -np.einsum("mij,mij->mi", n[:, _EDGE_FACES[:, 0]], n[:, _EDGE_FACES[:, 1]])
    return np.arccos(np.clip(cosang, -1.0, 1.0))


def mesh_information(model, rows) -> dict:
    """Zone count, gridpoint count (shared gridpoints of joined blocks counted once), smallest and
    largest edge, smallest dihedral angle [degrees], smallest and total volume of the zones ``rows``."""
    rows = np.asarray(rows, dtype=np.int64)
    if rows.size == 0:
        return {"zones": 0, "gridpoints": 0}
    zs = model.store("zones")
    gp = zs["gp"][rows]
    used = np.unique(gp[gp >= 0])
    link = model.vertices["link"][used]
    masters = np.unique(np.where(link >= 0, link, used))
    p = corners(model, rows)
    e = edge_lengths(p)
    vol = volumes(p)
    return {"zones": int(rows.size), "gridpoints": int(masters.size),
            "edge_min": float(e.min()), "edge_max": float(e.max()),
            "dihedral_min": float(np.degrees(dihedral_angles(p).min())),
            "volume_min": float(vol.min()), "volume_total": float(vol.sum())}


# ------------------------------------------------------------------ stress measures
def tensor(stress: np.ndarray) -> np.ndarray:
    """(m, 3, 3) symmetric tensors from (m, 6) rows xx yy zz xy xz yz."""
    s = np.asarray(stress, dtype=np.float64)
    t = np.empty((len(s), 3, 3))
    t[:, 0, 0], t[:, 1, 1], t[:, 2, 2] = s[:, 0], s[:, 1], s[:, 2]
    t[:, 0, 1] = t[:, 1, 0] = s[:, 3]
    t[:, 0, 2] = t[:, 2, 0] = s[:, 4]
    t[:, 1, 2] = t[:, 2, 1] = s[:, 5]
    return t


def mean_stress(stress: np.ndarray) -> np.ndarray:
    s = np.asarray(stress, dtype=np.float64)
    return (s[:, 0] + s[:, 1] + s[:, 2]) / 3.0


def principal_stresses(stress: np.ndarray) -> np.ndarray:
    """(m, 3) principal stresses, ascending: with tension positive the first is the most
    compressive (3DEC's σ1 is the minimum, most compressive)."""
    if len(stress) == 0:
        return np.zeros((0, 3))
    return np.linalg.eigvalsh(tensor(stress))


def von_mises(stress: np.ndarray) -> np.ndarray:
    """√(3 J2), J2 the second invariant of the deviator."""
    s = np.asarray(stress, dtype=np.float64)
    d = s[:, :3] - mean_stress(s)[:, None]
    j2 = 0.5 * (d ** 2).sum(axis=1) + (s[:, 3:] ** 2).sum(axis=1)
    return np.sqrt(3.0 * j2)
