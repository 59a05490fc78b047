"""FISH intrinsics of cable structural elements (``dec3d.model.cables``).

Names follow Itasca's structural-element FISH (``struct.cable.force.axial``, ``struct.cable.grout.slip``,
``struct.node.disp``, ``struct.node.pos``, ``struct.node.force.unbal``). Itasca hands these pointers;
dec3d hands ids, as it does for blocks: a cable element by its element id, a node by its node id
(both from 1, as ``structure cable list`` shows them).
"""
from __future__ import annotations

from .intrinsics import intrinsic
from .values import FishValueError, Vec, type_name


def _row(rt, i, name, store_name, what):
    if type(i) is not int:
        raise FishValueError(f"`{name}` takes a {what} id (an integer), not a {type_name(i)}")
    st = rt.session.model.stores.get(store_name)
    if st is not None and st.n:
        import numpy as np

        rows = np.flatnonzero(st["id"] == i)
        if rows.size:
            return st, int(rows[0])
    raise FishValueError(f"`{name}`: there is no {what} with id {i}")


def _seg(rt, i, name):
    return _row(rt, i, name, "cable_segments", "cable element")


def _node(rt, i, name):
    """A structural node: a cable, beam or liner node (one id space)."""
    for sname in ("beam_nodes", "liner_nodes"):
        st = rt.session.model.stores.get(sname)
        if type(i) is int and st is not None and st.n:
            import numpy as np

            rows = np.flatnonzero(st["id"] == i)
            if rows.size:
                return st, int(rows[0])
    return _row(rt, i, name, "cable_nodes", "structural node")


@intrinsic("struct.cable.force.axial", 1)
def _axial(rt, i):
    """Axial force of the cable element [N], tension positive."""
    st, r = _seg(rt, i, "struct.cable.force.axial")
    return float(st["fa"][r])


@intrinsic("struct.cable.grout.slip", 2)
def _slip(rt, i, end):
    """Whether the element's grout slips now and end 1 or 2 carries grout (dec3d keeps one slip flag per
    element: an element whose grout slips at one end reads as slipping at both ends that are grouted)."""
    st, r = _seg(rt, i, "struct.cable.grout.slip")
    if end not in (1, 2):
        raise FishValueError("`struct.cable.grout.slip` takes the end as 1 or 2")
    return bool(int(st["state"][r]) & 4) and abs(float(st["gf"][r, end - 1])) > 0.0


@intrinsic("struct.cable.yield", 1)
def _yield(rt, i):
    """Whether the element yields (tension or compression) now."""
    st, r = _seg(rt, i, "struct.cable.yield")
    return bool(int(st["state"][r]) & 3)


@intrinsic("struct.cable.state", 1)
def _cstate(rt, i):
    """State bits of the cable element: 1 yields in tension now, 2 in compression now, 4 grout slips now,
    8 yielded in the past, 16 grout slipped in the past, 32 ruptured (at its `tensile-failure-strain`).
    (dec3d's, as `struct.hybrid.dowel.state`: a bit set, not Itasca's.)"""
    st, r = _seg(rt, i, "struct.cable.state")
    return int(st["state"][r])


def _vec(arr, r):
    return Vec(float(arr[r, 0]), float(arr[r, 1]), float(arr[r, 2]))


@intrinsic("struct.node.pos", 1)
def _npos(rt, i):
    st, r = _node(rt, i, "struct.node.pos")
    return _vec(st["pos"], r)


@intrinsic("struct.node.disp", 1)
def _ndisp(rt, i):
    st, r = _node(rt, i, "struct.node.disp")
    return _vec(st["disp"], r)


@intrinsic("struct.node.vel", 1)
def _nvel(rt, i):
    st, r = _node(rt, i, "struct.node.vel")
    return _vec(st["vel"], r)


@intrinsic("struct.node.force.unbal", 1)
def _nunbal(rt, i):
    """Unbalanced force of the node at the last step [N] (at a fixed node: the reaction, sign reversed)."""
    st, r = _node(rt, i, "struct.node.force.unbal")
    return _vec(st["force"], r)


# ------------------------------------------------------------------ hybrid bolts' dowels
def _dowel(rt, i, name):
    return _row(rt, i, name, "cable_dowels", "dowel")


@intrinsic("struct.hybrid.dowel.force", 1)
def _dforce(rt, i):
    """Shear force of the dowel [N] (its magnitude; the force on the second block is along the slip's
    opposite)."""
    import math

    st, r = _dowel(rt, i, "struct.hybrid.dowel.force")
    return math.sqrt(float((st["fs"][r] ** 2).sum()))


@intrinsic("struct.hybrid.dowel.disp", 1)
def _ddisp(rt, i):
    """Accumulated shear displacement across the bolt at the dowel [m] (magnitude)."""
    import math

    st, r = _dowel(rt, i, "struct.hybrid.dowel.disp")
    return math.sqrt(float((st["us"][r] ** 2).sum()))


@intrinsic("struct.hybrid.dowel.state", 1)
def _dstate(rt, i):
    """State bits of the dowel: 1 yielding now, 2 yielded in the past, 4 ruptured."""
    st, r = _dowel(rt, i, "struct.hybrid.dowel.state")
    return int(st["state"][r])


# ------------------------------------------------------------------ beams
def _beam(rt, i, end, name):
    st, r = _row(rt, i, name, "beam_elements", "beam element")
    if end not in (1, 2):
        raise FishValueError(f"`{name}` takes the end as 1 or 2")
    return st, r, 6 * (end - 1)


@intrinsic("struct.beam.force", 2)
def _bforce(rt, i, end):
    """Force the node at end 1 or 2 puts on the beam element, in the element's axes (x: axial) [N]."""
    st, r, o = _beam(rt, i, end, "struct.beam.force")
    return Vec(*(float(x) for x in st["fl"][r, o:o + 3]))


@intrinsic("struct.beam.moment", 2)
def _bmoment(rt, i, end):
    """Moment the node at end 1 or 2 puts on the beam element, in the element's axes (x: torsion) [N·m]."""
    st, r, o = _beam(rt, i, end, "struct.beam.moment")
    return Vec(*(float(x) for x in st["fl"][r, o + 3:o + 6]))


@intrinsic("struct.beam.force.axial", 1)
def _baxial(rt, i):
    """Axial force of the beam element [N], tension positive."""
    st, r, _ = _beam(rt, i, 1, "struct.beam.force.axial")
    return float(st["fl"][r, 6])


@intrinsic("struct.node.rot", 1)
def _nrot(rt, i):
    """Rotation of a beam node [rad] (small rotations, a vector)."""
    st, r = _node(rt, i, "struct.node.rot")
    if "rot" not in st.fields:
        raise FishValueError(f"`struct.node.rot`: node {i} is a cable node (no rotation)")
    return _vec(st["rot"], r)
