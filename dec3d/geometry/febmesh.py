"""Regular meshes of 20-node bricks inside 8-vertex hexahedral blocks (``feblock generate``).

FE-block text (shared/seeds/003_*, "Generation and Use of FE Blocks"): "The automatic generation
of the FE mesh is only possible inside 8-vertex brick blocks … the command feblock gen transforms
them into FE blocks by creating a regular mesh of 20-node elements. The user only indicates the
desired dimensions of the elements in each of the three block axes."

The block's 8 corners define a trilinear map of the unit cube; its local axes are the ones of
the cube turned (among the 24 proper rotations) to be best aligned with global x, y, z, so
``feblock generate dx dy dz`` reads as element sizes along x, y, z for blocks that are roughly
aligned. Along local axis a there are n_a = max(1, round(L_a / d_a)) elements, L_a the mean
length of the block's four edges along a. Nodes are the points of the (2 n1 + 1)(2 n2 + 1)
(2 n3 + 1) lattice of the map with at most one odd index (corners and mid-edge nodes, shared
between elements), plus, on the block's surface, the mid-face slave nodes of the text's Table 2
(two odd indices). Each boundary element face is split into eight triangles fanned around its
slave node ("eight triangular faces are used to approximate each face of the brick", text,
"Element Implementation in 3DEC"), counter-clockwise seen from outside, so the contact code sees
a closed triangulated surface. The centre slave node (27) of the text's plotting scheme is not made.
"""
from __future__ import annotations

import itertools

import numpy as np

from dec3d.kernels.feblock import FACES, YNODE, YSLAVE

# VTK hexahedron corner order as bits (i, j, k) of the unit cube
_CUBE = np.array([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)])
_CIDX = {tuple(c): n for n, c in enumerate(_CUBE.tolist())}


def _rotations():
    """The 24 proper rotations of the cube as (perm, flip): new axis a is old axis perm[a],
    reversed when flip[a]."""
    out = []
    for perm in itertools.permutations(range(3)):
        sgn = np.linalg.det(np.eye(3)[list(perm)])
        for flip in itertools.product((0, 1), repeat=3):
            if sgn * (-1) ** sum(flip) > 0:
                out.append((perm, flip))
    return out


_ROT = _rotations()


def brick_corners(vertices: np.ndarray, faces: list[np.ndarray]) -> np.ndarray | None:
    """The 8 vertex indices of a hexahedral block in VTK hexahedron order (right-handed, local
    axes turned to be best aligned with global x, y, z), or None when the block is not an
    8-vertex hexahedron (6 four-sided faces, 3 edges at every vertex). ``faces`` are loops
    counter-clockwise seen from outside."""
    if len(vertices) != 8 or len(faces) != 6 or any(len(f) != 4 for f in faces):
        return None
    adj: dict[int, set[int]] = {i: set() for i in range(8)}
    for f in faces:
        for k in range(4):
            a, b = int(f[k]), int(f[(k + 1) % 4])
            adj[a].add(b)
            adj[b].add(a)
    if any(len(s) != 3 for s in adj.values()):
        return None
    bottom = [int(v) for v in faces[0][::-1]]       # seen from inside: counter-clockwise about local +z
    top = []
    for v in bottom:
        up = adj[v] - set(bottom)
        if len(up) != 1:
            return None
        top.append(up.pop())
    if sorted(top) not in [sorted(int(x) for x in f) for f in faces]:
        return None
    order = np.array(bottom + top)
    best, best_score = None, -np.inf
    for perm, flip in _ROT:
        new = np.empty(8, np.int64)
        for n, c in enumerate(_CUBE):
            old = [0, 0, 0]
            for a in range(3):
                old[perm[a]] = 1 - c[a] if flip[a] else c[a]
            new[n] = order[_CIDX[tuple(old)]]
        x = vertices[new]
        score = 0.0
        for a in range(3):
            hi = [n for n, c in enumerate(_CUBE) if c[a] == 1]
            lo = [_CIDX[tuple(np.where(np.arange(3) == a, 0, _CUBE[n]))] for n in hi]
            d = (x[hi] - x[lo]).sum(axis=0)
            score += d[a] / max(np.linalg.norm(d), 1e-300)
        if score > best_score + 1e-12:
            best, best_score = new, score
    return best


def edge_lengths(x8: np.ndarray) -> np.ndarray:
    """Mean length of the four edges along each local axis of a hexahedron (8, 3) in VTK order."""
    out = np.empty(3)
    for a in range(3):
        hi = [n for n, c in enumerate(_CUBE) if c[a] == 1]
        lo = [_CIDX[tuple(np.where(np.arange(3) == a, 0, _CUBE[n]))] for n in hi]
        out[a] = np.linalg.norm(x8[hi] - x8[lo], axis=1).mean()
    return out


def divisions(x8: np.ndarray, sizes) -> tuple[int, int, int]:
    """Elements along each local axis for target sizes (d1, d2, d3)."""
    L = edge_lengths(x8)
    return tuple(max(1, int(np.floor(L[a] / sizes[a] + 0.5))) for a in range(3))


def _trilinear(x8: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Points of the trilinear map of the hexahedron x8 (VTK order) at u (m, 3) in [0, 1]^3."""
    w = np.ones((len(u), 8))
    for n, c in enumerate(_CUBE):
        for a in range(3):
            w[:, n] *= u[:, a] if c[a] else 1.0 - u[:, a]
    return w @ x8


def brick_mesh(x8: np.ndarray, n: tuple[int, int, int]):
    """A regular mesh of n1 x n2 x n3 20-node elements in the hexahedron x8 (8, 3), VTK order.

    Returns ``points`` (m, 3): the master nodes, then the slave nodes on the surface;
    ``elems`` (ne, 20) local node indices in the corrected Table 1 order; ``slaves`` (ne, 7)
    local indices of each element's slave nodes 21-27 (-1 where not made: faces inside the block
    and the centre); ``tris`` (k, 3) the surface triangles, counter-clockwise from outside;
    ``tri_side`` (k,) the block side each triangle lies on, 2 a + s for local axis a, side s
    (0 at u_a = 0, 1 at u_a = 1); ``nmaster`` the number of master nodes."""
    n = np.asarray(n, np.int64)
    top = 2 * n
    key_master: dict[tuple, int] = {}
    keys = []
    for k in range(top[2] + 1):
        for j in range(top[1] + 1):
            for i in range(top[0] + 1):
                if (i & 1) + (j & 1) + (k & 1) <= 1:
                    key_master[(i, j, k)] = len(keys)
                    keys.append((i, j, k))
    nmaster = len(keys)
    ne = int(n.prod())
    elems = np.empty((ne, 20), np.int64)
    slaves = np.full((ne, 7), -1, np.int64)
    ynode = YNODE.astype(np.int64)
    yslave = YSLAVE.astype(np.int64)
    tris = []
    sides = []
    e = 0
    for c in range(n[2]):
        for b in range(n[1]):
            for a in range(n[0]):
                base = np.array([2 * a + 1, 2 * b + 1, 2 * c + 1])
                for q in range(20):
                    elems[e, q] = key_master[tuple(base + ynode[q])]
                for s in range(6):
                    ks = base + yslave[s]
                    ax = int(np.flatnonzero(yslave[s])[0])
                    if ks[ax] not in (0, top[ax]):
                        continue
                    slaves[e, s] = len(keys)
                    keys.append(tuple(ks))
                    f = FACES[s]
                    per = [elems[e, f[0]], elems[e, f[4]], elems[e, f[1]], elems[e, f[5]],
                           elems[e, f[2]], elems[e, f[6]], elems[e, f[3]], elems[e, f[7]]]
                    for t in range(8):
                        tris.append((slaves[e, s], per[t], per[(t + 1) % 8]))
                        sides.append(2 * ax + (1 if ks[ax] else 0))
                e += 1
    u = np.array(keys, float) / top
    points = _trilinear(np.asarray(x8, float), u)
    return points, elems, slaves, np.array(tris, np.int64), np.array(sides, np.int64), nmaster


def side_faces(corner_order: np.ndarray, faces: list[np.ndarray]) -> np.ndarray:
    """For each block side 2 a + s (see ``brick_mesh``), the index of the block face on it."""
    out = np.empty(6, np.int64)
    fsets = [set(int(v) for v in f) for f in faces]
    for a in range(3):
        for s in range(2):
            vs = {int(corner_order[n]) for n, c in enumerate(_CUBE) if c[a] == s}
            out[2 * a + s] = fsets.index(vs)
    return out


# ----------------------------------------------------------------------------- meshes read from files
#: corner pairs of the mid-edge nodes 9-20 (0-based 8-19) of the corrected Table 1
MID_EDGES = ((0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7))


class MeshFileError(ValueError):
    """A bad FE mesh file: ``line`` (1-based, 0 for the whole file) and the message."""

    def __init__(self, line: int, message: str):
        super().__init__(message)
        self.line = line


def parse_fe_mesh(text: str):
    """The FE-block text's ASCII mesh ("Generation and Use of FE Blocks"): a title line; a
    header line ``NN NE``; NN lines ``x y z`` (node n is the n-th, from 1); NE lines of 20 node
    numbers (corrected Table 1 order) or of 8 (corners only: the mid-edge nodes are inserted at
    the midpoints of the edges, shared between elements). Values are separated by blanks or
    commas; blank lines are skipped. Returns (points (NN, 3), elems (NE, 8 or 20) 0-based, the
    file line of each element) or raises MeshFileError naming the line."""
    lines = [(k + 1, ln.replace(",", " ").split()) for k, ln in enumerate(text.splitlines())]
    lines = [(k, t) for k, t in lines if t]
    if len(lines) < 2:
        raise MeshFileError(len(text.splitlines()), "the file ends before the header line `NN NE`")
    k, head = lines[1]
    try:
        if len(head) != 2:
            raise ValueError
        nn, ne = int(head[0]), int(head[1])
    except ValueError:
        raise MeshFileError(k, "the header line must be two integers `NN NE` (numbers of nodes and "
                               "elements)") from None
    if nn < 8 or ne < 1:
        raise MeshFileError(k, f"a mesh needs at least 8 nodes and one element (header says {nn} {ne})")
    body = lines[2:]
    if len(body) < nn + ne:
        last = body[-1][0] if body else k
        raise MeshFileError(last, f"the file ends after {len(body)} of the {nn} node and {ne} element lines "
                                  "the header announces")
    pts = np.empty((nn, 3))
    for i in range(nn):
        k, t = body[i]
        try:
            if len(t) != 3:
                raise ValueError
            pts[i] = [float(x) for x in t]
        except ValueError:
            raise MeshFileError(k, f"node {i + 1}: expected three coordinates `x y z`, got "
                                   f"{' '.join(t)[:80]!r}") from None
        if not np.isfinite(pts[i]).all():
            raise MeshFileError(k, f"node {i + 1}: a coordinate is not finite")
    elems, where = [], []
    width = None
    for j in range(ne):
        k, t = body[nn + j]
        try:
            ids = [int(x) for x in t]
        except ValueError:
            raise MeshFileError(k, f"element {j + 1}: node numbers must be integers") from None
        if len(ids) not in (8, 20):
            raise MeshFileError(k, f"element {j + 1}: {len(ids)} node numbers; an element has 20 (or 8: corners "
                                   "only)")
        if width is not None and len(ids) != width:
            raise MeshFileError(k, f"element {j + 1}: {len(ids)} nodes where the elements before have {width}")
        width = len(ids)
        bad = [n for n in ids if not 1 <= n <= nn]
        if bad:
            raise MeshFileError(k, f"element {j + 1}: node {bad[0]} is not between 1 and {nn}")
        if len(set(ids)) != len(ids):
            raise MeshFileError(k, f"element {j + 1}: a node appears twice")
        elems.append(ids)
        where.append(k)
    if len(body) > nn + ne:
        raise MeshFileError(body[nn + ne][0], "text after the last element line")
    return pts, np.array(elems, np.int64) - 1, np.array(where, np.int64)


def complete_20(points: np.ndarray, elems8: np.ndarray):
    """Insert mid-edge nodes (shared by edge) into 8-node elements: returns (points, elems (ne, 20))."""
    pts = [p for p in np.asarray(points, float)]
    key: dict[tuple[int, int], int] = {}
    out = np.empty((len(elems8), 20), np.int64)
    for e, c in enumerate(np.asarray(elems8, np.int64)):
        out[e, :8] = c
        for q, (i, j) in enumerate(MID_EDGES):
            k = (min(c[i], c[j]), max(c[i], c[j]))
            if k not in key:
                key[k] = len(pts)
                pts.append((pts[c[i]] + pts[c[j]]) / 2)
            out[e, 8 + q] = key[k]
    return np.array(pts), out


def mesh_surface(points: np.ndarray, elems: np.ndarray):
    """The boundary of a 20-node mesh: element faces (by their corner nodes) met once. Returns
    (points with a mid-face slave node appended per boundary face, slaves (ne, 7), tris (k, 3)
    counter-clockwise from outside, eight per boundary face). Raises MeshFileError(0, …) when a
    face is shared by more than two elements."""
    from dec3d.kernels.feblock import shape20

    count: dict[frozenset, int] = {}
    for c in elems:
        for s in range(6):
            k = frozenset(int(c[v]) for v in FACES[s][:4])
            count[k] = count.get(k, 0) + 1
    if max(count.values()) > 2:
        raise MeshFileError(0, "an element face is shared by more than two elements")
    w = np.empty((6, 20))
    dn = np.empty((20, 3))
    for s in range(6):
        shape20(YSLAVE[s, 0], YSLAVE[s, 1], YSLAVE[s, 2], w[s], dn)
    pts = list(np.asarray(points, float))
    slaves = np.full((len(elems), 7), -1, np.int64)
    tris = []
    for e, c in enumerate(elems):
        for s in range(6):
            f = FACES[s]
            if count[frozenset(int(c[v]) for v in f[:4])] != 1:
                continue
            slaves[e, s] = len(pts)
            pts.append(w[s] @ np.asarray(points)[c])
            per = [c[f[0]], c[f[4]], c[f[1]], c[f[5]], c[f[2]], c[f[6]], c[f[3]], c[f[7]]]
            for t in range(8):
                tris.append((slaves[e, s], per[t], per[(t + 1) % 8]))
    return np.array(pts), slaves, np.array(tris, np.int64)
