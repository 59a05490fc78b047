"""FISH access to the flow in the joints (``dec3d.physics.flownet``): knots by index 1 … flowknot.num
(the network's order; it is built again when the contacts change), and each contact's flow values."""
from __future__ import annotations

import numpy as np

from .intrinsics import _number, intrinsic
from .values import FishValueError, Vec

#: ``contact_values(model)`` (dec3d.io.flowvalues), set by the commands layer (FISH knows no model layout)
FLOW_VALUES = [None]


def _knots(rt, name):
    m = rt.session.model
    if "flowknots" not in m.stores:
        raise FishValueError(f"`{name}`: there is no flow network (`model configure fluid`, contacts)")
    return m.store("flowknots")


def _row(rt, k, name):
    kn = _knots(rt, name)
    i = _number(k, f"`{name}`: the knot index")
    if i != int(i) or not 1 <= int(i) <= kn.n:
        raise FishValueError(f"`{name}`: knot index {i:g} is not in 1 … {kn.n}")
    return kn, int(i) - 1


@intrinsic("flowknot.num")
def _num(rt):
    m = rt.session.model
    return int(m.store("flowknots").n) if "flowknots" in m.stores else 0


@intrinsic("flowknot.pos", 1)
def _pos(rt, k):
    """The knot's position [m]."""
    kn, r = _row(rt, k, "flowknot.pos")
    p = kn["pos"][r]
    return Vec(float(p[0]), float(p[1]), float(p[2]))


for _c, _ax in enumerate("xyz"):
    def _pos_c(rt, k, _c=_c, _ax=_ax):
        kn, r = _row(rt, k, f"flowknot.pos.{_ax}")
        return float(kn["pos"][r, _c])
    intrinsic(f"flowknot.pos.{_ax}", 1)(_pos_c)


@intrinsic("flowknot.pp", 1)
def _pp(rt, k):
    """The knot's pressure [Pa]."""
    kn, r = _row(rt, k, "flowknot.pp")
    return float(kn["pp"][r])


@intrinsic("flowknot.discharge", 1)
def _discharge(rt, k):
    """What the knot's boundary puts into the network [m³/s] (a pressure boundary: the net flow out of it
    through the pipes; otherwise the applied inflow)."""
    kn, r = _row(rt, k, "flowknot.discharge")
    return float(kn["supply"][r])


@intrinsic("flowknot.volume", 1)
def _volume(rt, k):
    """The knot's fluid volume [m³] (aperture × its share of the flow planes)."""
    kn, r = _row(rt, k, "flowknot.volume")
    return float(kn["vol"][r])


@intrinsic("flowknot.near", 1, 3)
def _near(rt, x, y=None, z=None):
    """The index of the knot nearest the point (a vector, or x, y, z); 0 when there is no knot."""
    kn = _knots(rt, "flowknot.near")
    if y is None:
        if type(x) is not Vec:
            raise FishValueError("`flowknot.near`: give a vector or x, y, z")
        p = np.array([x.x, x.y, x.z])
    else:
        p = np.array([_number(x), _number(y), _number(z)])
    if not kn.n:
        return 0
    return int(np.argmin(np.linalg.norm(kn["pos"] - p, axis=1))) + 1


def _contact_value(rt, c, name, which):
    from .contact_intrinsics import _contact_row

    _cs, r = _contact_row(rt, c, name)
    if FLOW_VALUES[0] is None:
        return 0.0
    return float(FLOW_VALUES[0](rt.session.model)[which][r])


@intrinsic("block.contact.flow.pp", 1)
def _c_fpp(rt, c):
    """The contact's flow pressure [Pa]: the knots' pressure averaged over its flow zones."""
    return _contact_value(rt, c, "block.contact.flow.pp", 0)


@intrinsic("block.contact.flow.aperture", 1)
def _c_ap(rt, c):
    """The contact's hydraulic aperture [m], averaged over its flow zones."""
    return _contact_value(rt, c, "block.contact.flow.aperture", 1)


@intrinsic("block.contact.flow.rate", 1)
def _c_rate(rt, c):
    """The contact's flow rate per unit width [m²/s]: |specific discharge| averaged over its flow zones."""
    return _contact_value(rt, c, "block.contact.flow.rate", 2)
