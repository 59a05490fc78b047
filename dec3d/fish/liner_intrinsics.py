"""FISH intrinsics of liner structural elements (``dec3d.model.liners``).

Itasca's names (the "Liner FISH functions" and "Shell-type" pages of the structural-element manual):
``struct.liner.normal.disp(p, inode <, iside>)``, ``struct.liner.normal.dir(p, inode)``,
``struct.liner.shear.dir(p, inode)``, ``struct.shell.resultant(p, iloc <, ires>)`` and
``struct.node.resultant(sn <, ires>)`` (the last two after ``structure liner recover resultants``).
Itasca hands pointers; dec3d hands ids, as it does for blocks: a liner element by its element id (as
``structure liner list`` shows it), a node by its node id. Liners are one-sided here: ``iside`` may be
1 only.
"""
from __future__ import annotations

import math

import numpy as np

from .intrinsics import intrinsic
from .values import FishValueError, Vec, type_name


def _element(rt, i, name):
    if type(i) is not int:
        raise FishValueError(f"`{name}` takes a liner element id (an integer), not a {type_name(i)}")
    st = rt.session.model.stores.get("liner_elements")
    if st is not None and st.n:
        rows = np.flatnonzero(st["id"] == i)
        if rows.size:
            return st, int(rows[0])
    raise FishValueError(f"`{name}`: there is no liner element with id {i}")


def _node_row(rt, i, inode, name):
    st, r = _element(rt, i, name)
    if type(inode) is not int or inode not in (1, 2, 3):
        raise FishValueError(f"`{name}` takes the node of the element as 1, 2 or 3 (got {inode!r})")
    return rt.session.model.stores["liner_nodes"], int(st["nodes"][r, inode - 1])


def _vec(a) -> Vec:
    return Vec(float(a[0]), float(a[1]), float(a[2]))


@intrinsic("struct.liner.normal.disp", 2, 3)
def _ndisp(rt, i, inode, iside=1):
    """Displacement of the normal coupling spring at node ``inode`` (1-3) of liner element ``i`` [m]:
    separation positive, overlap negative; 0 at a node coupled to no block."""
    nodes, n = _node_row(rt, i, inode, "struct.liner.normal.disp")
    if iside != 1:
        raise FishValueError("`struct.liner.normal.disp`: dec3d's liners are one-sided: the side is 1")
    return float(nodes["un"][n]) if nodes["host"][n] >= 0 else 0.0


@intrinsic("struct.liner.normal.dir", 2)
def _ndir(rt, i, inode):
    """Unit normal (global axes) of the normal coupling spring at node ``inode`` (1-3): the liner's
    outward normal there (area-weighted mean of its elements' z axes), along which the spring pushes the
    liner when compressed and against which it pulls it in tension."""
    nodes, n = _node_row(rt, i, inode, "struct.liner.normal.dir")
    return _vec(nodes["nrm"][n])


@intrinsic("struct.liner.shear.dir", 2)
def _sdir(rt, i, inode):
    """Unit vector (global axes) of the shear coupling force on the liner at node ``inode`` (1-3); the
    zero vector when that force is zero."""
    nodes, n = _node_row(rt, i, inode, "struct.liner.shear.dir")
    f = nodes["fs"][n]
    m = math.sqrt(float(f @ f))
    return _vec(f / m) if m > 0.0 else Vec(0.0, 0.0, 0.0)


def _pick(vals, ires, n, name):
    if ires is None:
        return [float(x) for x in vals]
    if type(ires) is not int or not 1 <= ires <= n:
        raise FishValueError(f"`{name}` takes the resultant index as 1 to {n} (got {ires!r})")
    return float(vals[ires - 1])


@intrinsic("struct.shell.resultant", 2, 3)
def _eres(rt, i, iloc, ires=None):
    """Stress resultants of liner element ``i`` at ``iloc`` (0 the centroid, 1-3 its nodes), in the
    surface system, as the last `structure liner recover resultants` left them: a list M_x, M_y, M_xy
    [N·m/m], N_x, N_y, N_xy [N/m], Q_x, Q_y [N/m] (Itasca: a 1 × 8 matrix), or the one numbered ``ires``
    (1-8)."""
    name = "struct.shell.resultant"
    st, r = _element(rt, i, name)
    if type(iloc) is not int or not 0 <= iloc <= 3:
        raise FishValueError(f"`{name}` takes the location as 0 (centroid) or 1, 2, 3 (nodes) (got {iloc!r})")
    if not st["eresok"][r]:
        raise FishValueError(f"`{name}`: liner element {i} has no recovered resultants: "
                             "`structure liner recover resultants` first")
    return _pick(st["eres"][r, iloc], ires, 8, name)


@intrinsic("struct.shell.resultant.valid", 1)
def _eresok(rt, i):
    """Whether liner element ``i`` has recovered resultants (`structure liner recover resultants`)."""
    st, r = _element(rt, i, "struct.shell.resultant.valid")
    return bool(st["eresok"][r])


@intrinsic("struct.node.resultant", 1, 2)
def _nres(rt, i, ires=None):
    """Stress resultants averaged at liner node ``i`` over the elements of the last recovery, in its
    surface system: a list M_x, M_y, M_xy, N_x, N_y, N_xy (Itasca: a 1 × 6 matrix), or the one numbered
    ``ires`` (1-6)."""
    name = "struct.node.resultant"
    if type(i) is not int:
        raise FishValueError(f"`{name}` takes a node id (an integer), not a {type_name(i)}")
    st = rt.session.model.stores.get("liner_nodes")
    rows = np.flatnonzero(st["id"] == i) if st is not None and st.n else np.zeros(0, np.int64)
    if not rows.size:
        raise FishValueError(f"`{name}`: there is no liner node with id {i}")
    r = int(rows[0])
    if not st["nresok"][r]:
        raise FishValueError(f"`{name}`: node {i} has no recovered resultants: `structure liner recover "
                             "resultants` first")
    return _pick(st["nres"][r], ires, 6, name)
