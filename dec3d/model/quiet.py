"""Quiet (viscous) boundaries and table-driven face stresses on zoned blocks.

Quiet boundary (``block face apply quiet``): the viscous boundary of Lysmer and Kuhlemeyer (1969),
which 3DEC uses for nonreflecting boundaries (Itasca 3DEC 7 documentation, "Dynamic Analysis —
Boundary Conditions"): independent dashpots in the normal and the two shear directions of the
boundary, tractions t_n = −ρ C_p v_n and t_s = −ρ C_s v_s, with C_p = ((K + 4G/3)/ρ)^½ and
C_s = (G/ρ)^½ of the zone the face belongs to (FE blocks: of their elements, which must agree).
Each face keeps its two impedances (``faces.fquiet`` = [ρC_p, ρC_s], Pa·s/m; 0 none). The
gridpoint force of a face is the traction times the gridpoint's share of the face area, with the
shares the applied stresses use (``face_loads``: thirds of a triangle, a hexahedral zone's face
as its quadrilateral, a 10-node zone's face as a 6-node triangle); summed per gridpoint this is a
symmetric 3×3 dashpot matrix C, and the force −C v is added every step from the gridpoint's
velocity (``physics.zones.ZoneStepper``).

Quiet gridpoints (``block gridpoint apply quiet|quiet-x|quiet-y|quiet-z``, 3DEC's spelling: its
`block gridpoint apply` lists `quiet[-x|-y|-z]`): each gridpoint keeps the directions it is quiet in
(``vertices.gquiet``, bits 1 x, 2 y, 4 z; 0 none). While cycling, the boundary faces whose three
gridpoints are all quiet (and that are not quiet faces already) load their gridpoints as quiet faces
do, with the impedances of their zones taken at that time; a gridpoint quiet in some directions only
keeps the part P C P of its matrix (P the projection on those axes: `quiet-x` damps v_x by a force
along x). A face is quiet once, whichever command made it so.

Table-driven stress (``block face apply stress-xz … table <id>``): a stress whose value is
multiplied by a table of time (linear interpolation, end values held outside, as FISH's
``table(t, x)``) at the model time of each step. The face keeps the stress (``faces.fdyn``) and the
index of its table (``faces.fdyn_tab``, −1 none) in ``settings.mechanical["face_tables"]``, a list
of ``{"id", "x", "y"}``: the table's points as they were when the command ran, so a save file
holds everything the run needs. A face carries one table-driven stress (more of the same table
add). The input stress of a wave on a quiet base is 2ρC_s v (shear) or 2ρC_p v (normal) for an
incident velocity v (3DEC 7 documentation, "Application of Dynamic Input", Eqs. 1-2). On an FE
element face it loads the nodes as a fixed stress does (``face_shares(consistent_fe=True)``, the
8-node face's ∫ N_a σ n dA); a quiet FE face keeps the thirds of its triangles: the consistent
shares are negative at the corners of a flat face, and a dashpot there would push.
"""
from __future__ import annotations

import numpy as np

from dec3d.errors import Dec3dError

from .face_loads import _TRI6, _fe_faces, _hex_quads, _lookup, _triangle_nodes, _tri6_faces, loadable_faces
from .model import KIND_FE
from .store import Field
from .zones import ZP_BULK, ZP_DENSITY, ZP_SHEAR, zone_stores

_F = np.float64
_I = np.int64


class QuietError(Dec3dError):
    """A quiet boundary cannot be set up (a zone without density or moduli under quiet gridpoints)."""


def _ensure(model) -> None:
    zone_stores(model)
    f = model.faces
    if "fquiet" not in f:
        f.add_field("fquiet", Field((2,), _F, 0.0))
    if "fdyn" not in f:
        f.add_field("fdyn", Field((6,), _F, 0.0))
    if "fdyn_tab" not in f:
        f.add_field("fdyn_tab", Field((), _I, -1))
    if "gquiet" not in model.vertices:
        model.vertices.add_field("gquiet", Field((), np.uint8, 0))


# ------------------------------------------------------------------ area shares

def face_shares(model, rows: np.ndarray, key: np.ndarray,
                consistent_fe: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """How the faces ``rows`` (triangles) load their gridpoints: (face index into ``rows`` (k,),
    vertex row (k,), area-vector share (k, 3)); a uniform stress σ on the faces gives the nodal
    forces σ·share (what ``face_loads.recompute_fface`` does). Faces are taken together as a
    hexahedral zone's quadrilateral or a 10-node zone's 6-node triangle only when their rows of
    ``key`` (k, m) are equal; with ``consistent_fe`` (stresses), the eight triangles of an FE
    element face as that face, shares ∫ N_a n dA (``feblock_shape.face_stress_loads`` with σ = I;
    −A/12 at the corners of a flat parallelogram face, so not for dashpots)."""
    v = model.vertices
    nodes = _triangle_nodes(model, rows)
    p = v["pos"][nodes]
    an = 0.5 * np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])          # outward normal times area
    fi, nd, sh = [], [], []
    thirds = np.ones(len(rows), bool)
    quads, fmem = _fe_faces(model, nodes, key) if consistent_fe else (np.zeros((0, 8), _I), None)
    if len(quads):
        from dec3d.kernels.feblock_shape import face_stress_loads
        thirds[fmem.ravel()] = False
        g = len(quads)
        share = np.zeros((8 * g, 3))
        face_stress_loads(np.ascontiguousarray(v["pos"][quads].reshape(-1, 3)), np.arange(8 * g, dtype=_I).reshape(g, 8),
                          np.tile(np.array([1.0, 1.0, 1.0, 0.0, 0.0, 0.0]), (g, 1)), share)
        for a in range(8):
            fi.append(fmem[:, 0])
            nd.append(quads[:, a])
            sh.append(share[a::8])
    tri6, members = _tri6_faces(model, nodes, key)
    if len(tri6):
        thirds[members.ravel()] = False
        a6 = an[members].sum(axis=1)
        for c in range(3, 6):               # flat 6-node triangle: a third at each mid-edge node
            fi.append(members[:, 0])
            nd.append(tri6[:, c])
            sh.append(a6 / 3.0)
    rest = np.flatnonzero(thirds)
    pairs = _hex_quads(model, rows[rest], nodes[rest], key[rest])
    weight = np.ones(len(rows))
    if len(pairs):
        pairs = rest[pairs]
        weight[pairs.ravel()] = 0.5         # half from the surface split …
        t1, t2 = nodes[pairs[:, 0]], nodes[pairs[:, 1]]
        in2 = (t1[:, :, None] == t2[:, None, :]).any(axis=2)
        o1 = t1[~in2]
        o2 = t2[~(t2[:, :, None] == t1[:, None, :]).any(axis=2)]
        d = t1[in2].reshape(-1, 2)
        up = an[pairs[:, 0]] + an[pairs[:, 1]]
        for k in range(2):                  # … half from the split on the other diagonal
            tri = np.column_stack([o1, o2, d[:, k]])
            q = v["pos"][tri]
            a2 = 0.5 * np.cross(q[:, 1] - q[:, 0], q[:, 2] - q[:, 0])
            a2 *= np.where(np.einsum("ij,ij->i", a2, up) < 0.0, -1.0, 1.0)[:, None]
            for c in range(3):
                fi.append(pairs[:, 0])
                nd.append(tri[:, c])
                sh.append(0.5 * a2 / 3.0)
    t = np.flatnonzero(thirds)
    for c in range(3):
        fi.append(t)
        nd.append(nodes[t, c])
        sh.append(weight[t, None] * an[t] / 3.0)
    if not fi:
        return np.zeros(0, _I), np.zeros(0, _I), np.zeros((0, 3))
    return np.concatenate(fi).astype(_I), np.concatenate(nd).astype(_I), np.concatenate(sh)


def _per_node(nodes: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Sum ``values`` (k, …) over equal ``nodes``: (unique rows, sums)."""
    u, inv = np.unique(nodes, return_inverse=True)
    out = np.zeros((len(u),) + values.shape[1:])
    np.add.at(out, inv.ravel(), values)
    return u, out


# ------------------------------------------------------------------ quiet boundaries

def face_impedances(model, rows: np.ndarray) -> tuple[np.ndarray, list[str]]:
    """(ρC_p, ρC_s) per face of ``rows`` (zoned or FE faces) from the zone (or the FE block's
    elements) it belongs to, and the problems found (zones or blocks without positive density,
    bulk and shear modulus, FE blocks whose elements differ)."""
    zs = zone_stores(model)
    f, b = model.faces, model.blocks
    props = np.zeros((len(rows), 3))            # density, bulk, shear
    found = np.zeros(len(rows), bool)
    problems: list[str] = []
    blk = f["block"][rows]
    fe = b["kind"][blk] == KIND_FE
    zrows = np.flatnonzero(~fe)
    if len(zrows) and zs.n:
        g = zs["gp"][: zs.n]
        four = np.flatnonzero(zs["nnode"][: zs.n] == 4)
        ten = np.flatnonzero(zs["nnode"][: zs.n] == 10)
        tris, owner = [], []
        for c in ((0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)):
            tris.append(g[four][:, list(c)])
            owner.append(four)
        for c0, c1, c2, m01, m12, m20 in _TRI6:
            for t in ((c0, m01, m20), (m01, c1, m12), (m20, m12, c2), (m01, m12, m20)):
                tris.append(g[ten][:, list(t)])
                owner.append(ten)
        table = np.sort(np.concatenate(tris), axis=1)
        owner = np.concatenate(owner)
        at = _lookup(table, np.sort(_triangle_nodes(model, rows[zrows]), axis=1))
        ok = at >= 0
        z = owner[at[ok]]
        p = zs["prop"][z]
        props[zrows[ok]] = p[:, [ZP_DENSITY, ZP_BULK, ZP_SHEAR]]
        found[zrows[ok]] = True
        bad = (p[:, ZP_DENSITY] <= 0) | (p[:, ZP_BULK] <= 0) | (p[:, ZP_SHEAR] <= 0)
        if bad.any():
            ids = sorted(set(int(i) for i in zs["id"][z[bad]]))
            problems.append(f"zones {_few(ids)} have no positive density, bulk and shear modulus "
                            "(`block zone property density … bulk … shear …`)")
    if fe.any() and "feblocks" in model.stores:
        es = model.store("feblocks")
        for bl in np.unique(blk[fe]):
            el = np.flatnonzero(es["block"][: es.n] == bl)
            if not len(el):
                continue
            p = es["prop"][el][:, [ZP_DENSITY, ZP_BULK, ZP_SHEAR]]
            sel = np.flatnonzero(blk == bl)
            if np.any(p != p[0]):
                problems.append(f"the FE elements of block {int(b['id'][bl])} differ in density or moduli: a quiet "
                                "boundary takes one impedance per FE block")
                continue
            props[sel] = p[0]
            found[sel] = True
            if np.any(p[0] <= 0):
                problems.append(f"the FE elements of block {int(b['id'][bl])} have no positive density, bulk "
                                "and shear modulus")
    if not found.all():
        problems.append(f"{int((~found).sum())} boundary faces belong to no zone or FE element")
    rho, kb, gs = props[:, 0], props[:, 1], props[:, 2]
    with np.errstate(invalid="ignore"):
        imp = np.column_stack([np.sqrt(np.maximum(rho * (kb + 4.0 * gs / 3.0), 0.0)),
                               np.sqrt(np.maximum(rho * gs, 0.0))])
    return imp, problems


def _few(ids) -> str:
    return ", ".join(str(i) for i in ids[:10]) + (f" … ({len(ids)})" if len(ids) > 10 else "")


def quiet_candidates(model, mask: np.ndarray) -> np.ndarray:
    """Rows of the faces in ``mask`` that can be quiet: on the outside of a zoned (or FE) continuum."""
    _ensure(model)
    return np.flatnonzero(mask & loadable_faces(model))


def set_quiet(model, rows: np.ndarray, imp: np.ndarray) -> None:
    _ensure(model)
    model.faces["fquiet"][rows] = imp


def remove_quiet(model, mask: np.ndarray) -> int:
    _ensure(model)
    rows = np.flatnonzero(mask & (model.faces["fquiet"][:, 0] > 0))
    model.faces["fquiet"][rows] = 0.0
    return len(rows)


def _dashpots(model, rows: np.ndarray, key: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(vertex rows, C (g, 3, 3)) of the faces ``rows`` with impedances ``key`` (k, 2):
    C = Σ a (ρC_s I + (ρC_p − ρC_s) n nᵀ) over the shares a n of the faces at each gridpoint."""
    fi, node, s = face_shares(model, rows, key)
    a = np.sqrt((s * s).sum(axis=1))
    keep = a > 0
    fi, node, s, a = fi[keep], node[keep], s[keep], a[keep]
    n = s / a[:, None]
    zp, zs = key[fi, 0], key[fi, 1]
    c = (a * zs)[:, None, None] * np.eye(3)[None] + (a * (zp - zs))[:, None, None] * (n[:, :, None] * n[:, None, :])
    return _per_node(node, c)


def quiet_bits(model) -> np.ndarray:
    """The quiet directions of every vertex row (``vertices.gquiet``, a view: bits 1 x, 2 y, 4 z)."""
    _ensure(model)
    return model.vertices["gquiet"][: model.vertices.n]


def quiet_gridpoint_faces(model, flagged: np.ndarray | None = None) -> np.ndarray:
    """Rows of the boundary faces (not quiet faces themselves) whose three gridpoints are quiet
    gridpoints (``flagged``: a mask over vertex rows to use instead of ``gquiet``)."""
    _ensure(model)
    f, v = model.faces, model.vertices
    on = (v["gquiet"][: v.n] != 0) if flagged is None else flagged
    if not f.n or not on.any():
        return np.zeros(0, _I)
    cand = np.flatnonzero(loadable_faces(model) & (f["fquiet"][: f.n, 0] <= 0))
    if not len(cand):
        return cand
    return cand[on[_triangle_nodes(model, cand)].all(axis=1)]


def quiet_dashpots(model) -> tuple[np.ndarray, np.ndarray] | None:
    """The dashpot matrices of the quiet faces and quiet gridpoints: (vertex rows (g,), C (g, 3, 3)
    [N·s/m]) with the gridpoint force −C v; None when nothing is quiet. Raises ``QuietError`` when a
    face of quiet gridpoints has no impedance (its zone lost its properties since)."""
    f = model.faces
    if "fquiet" not in f or not f.n:
        return None
    parts = []
    rows = np.flatnonzero(f["fquiet"][: f.n, 0] > 0)
    if len(rows):
        parts.append(_dashpots(model, rows, f["fquiet"][rows]))
    grow = quiet_gridpoint_faces(model)
    if len(grow):
        imp, problems = face_impedances(model, grow)
        if problems:
            raise QuietError("quiet gridpoints (`block gridpoint apply quiet`): " + "; ".join(problems))
        node, c = _dashpots(model, grow, imp)
        bits = model.vertices["gquiet"][node].astype(_I)
        p = np.stack([(bits >> i) & 1 for i in range(3)], axis=1).astype(_F)
        parts.append((node, c * p[:, :, None] * p[:, None, :]))
    if not parts:
        return None
    if len(parts) == 1:
        return parts[0]
    return _per_node(np.concatenate([q[0] for q in parts]), np.concatenate([q[1] for q in parts]))


# ------------------------------------------------------------------ table-driven stresses

def table_index(model, tid, xs, ys) -> int:
    """Index of the table ``tid`` with points ``xs``, ``ys`` in ``settings.mechanical["face_tables"]``
    (an entry with the same id and points is shared; a table changed since gets a new entry, and
    faces loaded before keep the points they were given)."""
    _ensure(model)
    lst = model.settings.mechanical.setdefault("face_tables", [])
    entry = {"id": tid, "x": [float(x) for x in xs], "y": [float(y) for y in ys]}
    for i, e in enumerate(lst):
        if e["id"] == tid and e["x"] == entry["x"] and e["y"] == entry["y"]:
            return i
    lst.append(entry)
    return len(lst) - 1


def dynamic_conflicts(model, rows: np.ndarray, tab: int) -> np.ndarray:
    """Rows among ``rows`` that carry a table-driven stress of another table."""
    _ensure(model)
    t = model.faces["fdyn_tab"][rows]
    return rows[(t >= 0) & (t != tab)]


def add_dynamic_stress(model, rows: np.ndarray, stress6: np.ndarray, tab: int) -> None:
    _ensure(model)
    f = model.faces
    f["fdyn"][rows] += np.asarray(stress6, _F)
    f["fdyn_tab"][rows] = tab


def remove_dynamic_stress(model, mask: np.ndarray) -> int:
    _ensure(model)
    f = model.faces
    rows = np.flatnonzero(mask & (f["fdyn_tab"] >= 0))
    f["fdyn"][rows] = 0.0
    f["fdyn_tab"][rows] = -1
    return len(rows)


def dynamic_face_loads(model) -> list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
    """The table-driven face loads: per table used, (table x, table y, vertex rows (g,), nodal
    forces at multiplier 1 (g, 3) [N])."""
    f = model.faces
    if "fdyn_tab" not in f or not f.n:
        return []
    tabs = model.settings.mechanical.get("face_tables", [])
    out = []
    for j in np.unique(f["fdyn_tab"][: f.n]):
        if j < 0:
            continue
        rows = np.flatnonzero(f["fdyn_tab"][: f.n] == j)
        s = f["fdyn"][rows]
        fi, node, share = face_shares(model, rows, s, consistent_fe=True)
        sig = np.empty((len(rows), 3, 3))
        sig[:, 0, 0], sig[:, 1, 1], sig[:, 2, 2] = s[:, 0], s[:, 1], s[:, 2]
        sig[:, 0, 1] = sig[:, 1, 0] = s[:, 3]
        sig[:, 0, 2] = sig[:, 2, 0] = s[:, 4]
        sig[:, 1, 2] = sig[:, 2, 1] = s[:, 5]
        u, force = _per_node(node, np.einsum("kij,kj->ki", sig[fi], share))
        t = tabs[int(j)]
        out.append((np.asarray(t["x"], _F), np.asarray(t["y"], _F), u, force))
    return out


def table_value(xs: np.ndarray, ys: np.ndarray, t: float) -> float:
    """Linear interpolation of the table at ``t``, end values held outside (FISH ``table(t, x)``)."""
    return float(np.interp(t, xs, ys))
