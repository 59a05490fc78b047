"""FISH contact and sub-contact intrinsics (block.contact.*, block.subcontact.*) on the rigid engine's
``contacts`` / ``subcontacts`` stores (dec3d.physics.contacts).

Contacts are found again at every detection, so FISH holds them as pointers that name them, not as
rows: a contact is its two block ids (A < B, the key the engine sorts contacts by), a sub-contact its
contact and its index among that contact's sub-contacts. A pointer keeps its last row as a hint and
is looked up again when the hint no longer fits; a contact that has gone (its blocks separated) is a
clear error. Before a list is made the contacts are brought up to date (`ensure_contacts`: detected
when the blocks changed since the last detection), through the provider the commands layer registers
(``CONTACTS``; FISH imports no physics).

Values are dec3d's as stored: normal force compression positive [N], shear force on block B [N],
normal displacement (from the initial gap, opening positive) [m], accumulated shear displacement [m].
Names follow Itasca's 3DEC 7 FISH reference.
"""
from __future__ import annotations

import numpy as np

from .intrinsics import intrinsic
from .values import FishValueError, Vec, type_name

#: ``CONTACTS[0](model) -> (contacts, subcontacts)`` stores, detected if the blocks changed (set by
#: dec3d.commands.fish_cmds); None before, when the stores are read as they are
CONTACTS: list = [None]


class ContactPtr:
    """A contact (kind 'contact', key (ida, idb)) or sub-contact (kind 'subcontact', key (ida, idb, k))."""

    __slots__ = ("kind", "key", "hint")

    def __init__(self, kind, key, hint=-1):
        self.kind, self.key, self.hint = kind, key, hint

    def __eq__(self, other):
        return isinstance(other, ContactPtr) and self.kind == other.kind and self.key == other.key

    def __hash__(self):
        return hash((self.kind, self.key))

    def __repr__(self):
        return f"{self.kind}({','.join(str(k) for k in self.key)})"


def _stores(rt, current=False):
    model = rt.session.model
    if current and CONTACTS[0] is not None:
        return CONTACTS[0](model)
    st = model.stores
    return st.get("contacts"), st.get("subcontacts")


def _contact_row(rt, c, name):
    if type(c) is not ContactPtr or c.kind != "contact":
        raise FishValueError(f"`{name}` takes a contact (from block.contact.list), not a "
                             f"{'sub-contact' if type(c) is ContactPtr else type_name(c)}")
    cs, _ss = _stores(rt)
    ida, idb = c.key
    r = c.hint
    if cs is None or not (0 <= r < cs.n and cs["ida"][r] == ida and cs["idb"][r] == idb):
        hit = np.flatnonzero((cs["ida"] == ida) & (cs["idb"] == idb)) if cs is not None and cs.n else ()
        if len(hit) == 0:
            raise FishValueError(f"`{name}`: the contact of blocks {ida} and {idb} is gone")
        r = c.hint = int(hit[0])
    return cs, r


def _sub_row(rt, s, name):
    if type(s) is not ContactPtr or s.kind != "subcontact":
        raise FishValueError(f"`{name}` takes a sub-contact (from block.subcontact.list or "
                             f"block.contact.subcontactlist), not a "
                             f"{'contact' if type(s) is ContactPtr else type_name(s)}")
    ida, idb, k = s.key
    cs, r = _contact_row(rt, ContactPtr("contact", (ida, idb), s.hint), name)
    if not 0 <= k < int(cs["sub_count"][r]):
        raise FishValueError(f"`{name}`: sub-contact {k + 1} of the contact of blocks {ida} and {idb} is gone")
    s.hint = r
    return rt.session.model.stores["subcontacts"], int(cs["sub_start"][r]) + k


def _ptr(cs, r):
    return ContactPtr("contact", (int(cs["ida"][r]), int(cs["idb"][r])), r)


def _subs(cs, r):
    ida, idb = int(cs["ida"][r]), int(cs["idb"][r])
    return [ContactPtr("subcontact", (ida, idb, k), r) for k in range(int(cs["sub_count"][r]))]


def _vec(a):
    return Vec(float(a[0]), float(a[1]), float(a[2]))


# ---------------------------------------------------------------- contacts

@intrinsic("block.contact.list")
def _list(rt):
    cs, _ = _stores(rt, current=True)
    return [] if cs is None else [_ptr(cs, r) for r in range(cs.n)]


@intrinsic("block.contact.num")
def _num(rt):
    cs, _ = _stores(rt, current=True)
    return 0 if cs is None else int(cs.n)


@intrinsic("block.contact.find", 2)
def _find(rt, b1, b2):
    """The contact between blocks b1 and b2 (ids, either order); 0 when they have none."""
    if type(b1) is not int or type(b2) is not int:
        raise FishValueError("`block.contact.find` takes two block ids")
    cs, _ = _stores(rt, current=True)
    a, b = min(b1, b2), max(b1, b2)
    hit = np.flatnonzero((cs["ida"] == a) & (cs["idb"] == b)) if cs is not None and cs.n else ()
    return _ptr(cs, int(hit[0])) if len(hit) else 0


def _scalar(name, get, contact=True):
    """Registers the one-argument intrinsic ``name``: get(store, row) of its contact (or, with
    contact False, sub-contact) pointer's row."""
    row = _contact_row if contact else _sub_row

    def fn(rt, p):
        st, r = row(rt, p, name)
        return get(st, r)
    intrinsic(name, 1)(fn)


_scalar("block.contact.b1", lambda cs, r: int(cs["ida"][r]))
_scalar("block.contact.b2", lambda cs, r: int(cs["idb"][r]))


def _family(prefix, get, contact=True):
    row = _contact_row if contact else _sub_row

    def whole(rt, p):
        st, r = row(rt, p, prefix)
        return _vec(get(st, r))
    intrinsic(prefix, 1)(whole)
    for k, c in (("x", 0), ("y", 1), ("z", 2)):
        def comp(rt, p, c=c, full=f"{prefix}.{k}"):
            st, r = row(rt, p, full)
            return float(get(st, r)[c])
        intrinsic(f"{prefix}.{k}", 1)(comp)


_family("block.contact.pos", lambda cs, r: cs["pos"][r])
_family("block.contact.normal", lambda cs, r: cs["normal"][r])


def _contact_subs(rt, c, name):
    cs, r = _contact_row(rt, c, name)
    ss = rt.session.model.stores["subcontacts"]
    s0, n = int(cs["sub_start"][r]), int(cs["sub_count"][r])
    return ss, slice(s0, s0 + n)


@intrinsic("block.contact.force.norm", 1)
def _c_fn(rt, c):
    """Normal force of the contact: the sum over its sub-contacts [N], compression positive."""
    ss, sl = _contact_subs(rt, c, "block.contact.force.norm")
    return float(ss["fn"][sl].sum())


def _c_fs(rt, c, name):
    ss, sl = _contact_subs(rt, c, name)
    return ss["fs"][sl].sum(axis=0) if sl.stop > sl.start else np.zeros(3)


intrinsic("block.contact.force.shear", 1)(lambda rt, c: _vec(_c_fs(rt, c, "block.contact.force.shear")))
for _k, _i in (("x", 0), ("y", 1), ("z", 2)):
    intrinsic(f"block.contact.force.shear.{_k}", 1)(
        lambda rt, c, _i=_i, _n=f"block.contact.force.shear.{_k}": float(_c_fs(rt, c, _n)[_i]))


@intrinsic("block.contact.subcontactlist", 1)
def _subcontactlist(rt, c):
    cs, r = _contact_row(rt, c, "block.contact.subcontactlist")
    return _subs(cs, r)


@intrinsic("block.contact.group", 1, 2)
def _c_group(rt, c, slot=None):
    """The contact's group in `slot` (default slot when omitted); "" when it has none there."""
    cs, r = _contact_row(rt, c, "block.contact.group")
    if slot is not None and type(slot) is not str:
        raise FishValueError(f"`block.contact.group`: the slot is a string, not a {type_name(slot)}")
    groups = rt.session.model.groups
    col = groups.slot_index(cs, slot)
    return "" if col < 0 else groups.name(int(cs["group"][r, col]))


@intrinsic("block.contact.isgroup", 2, 3)
def _c_isgroup(rt, c, name, slot=None):
    """True when the contact is in group `name` (in `slot`, or in any slot when omitted)."""
    cs, r = _contact_row(rt, c, "block.contact.isgroup")
    if type(name) is not str or (slot is not None and type(slot) is not str):
        raise FishValueError("`block.contact.isgroup` takes a group name (and a slot name) as strings")
    groups = rt.session.model.groups
    code = groups.code(name)
    if code < 0:
        return False
    if slot is None:
        return bool((cs["group"][r] == code).any())
    col = groups.slot_index(cs, slot)
    return col >= 0 and int(cs["group"][r, col]) == code


# ---------------------------------------------------------------- sub-contacts

@intrinsic("block.subcontact.list")
def _sub_list(rt):
    cs, _ = _stores(rt, current=True)
    out = []
    if cs is not None:
        for r in range(cs.n):
            out.extend(_subs(cs, r))
    return out


@intrinsic("block.subcontact.contact", 1)
def _sub_contact(rt, s):
    _sub_row(rt, s, "block.subcontact.contact")
    return ContactPtr("contact", s.key[:2], s.hint)


@intrinsic("block.subcontact.face", 1)
def _sub_face(rt, s):
    """The block face under a vertex-face sub-contact, as block.face.* take it (its face row + 1, valid
    until the blocks change); 0 (null) for edge crossings and point sub-contacts."""
    ss, k = _sub_row(rt, s, "block.subcontact.face")
    if int(ss["kind"][k]) in (0, 1) and int(ss["key1"][k]) >= 0:
        return int(ss["key1"][k]) + 1
    return 0


_scalar("block.subcontact.area", lambda ss, k: float(ss["area"][k]), contact=False)
_scalar("block.subcontact.force.norm", lambda ss, k: float(ss["fn"][k]), contact=False)
_scalar("block.subcontact.disp.norm", lambda ss, k: float(ss["un"][k]), contact=False)
_family("block.subcontact.pos", lambda ss, k: ss["pos"][k], contact=False)
_family("block.subcontact.force.shear", lambda ss, k: ss["fs"][k], contact=False)
_family("block.subcontact.disp.shear", lambda ss, k: ss["us"][k], contact=False)


@intrinsic("block.subcontact.state", 1)
def _sub_state(rt, s):
    """The sub-contact's state bits (0 elastic; slip and tension bits as the joint law sets them)."""
    ss, k = _sub_row(rt, s, "block.subcontact.state")
    return int(ss["state"][k])


_scalar("block.subcontact.force.shear.mag", lambda ss, k: float(np.linalg.norm(ss["fs"][k])), contact=False)
_scalar("block.subcontact.disp.shear.mag", lambda ss, k: float(np.linalg.norm(ss["us"][k])), contact=False)


@intrinsic("block.contact.type", 1)
def _c_type(rt, c):
    """The contact's type code as the engine keeps it (dec3d.kernels.commonplane CT_*)."""
    cs, r = _contact_row(rt, c, "block.contact.type")
    return int(cs["type"][r])


@intrinsic("block.contact.head")
def _c_head(rt):
    """The first contact (0 when there is none); walk on with block.contact.next."""
    cs, _ = _stores(rt, current=True)
    return _ptr(cs, 0) if cs is not None and cs.n else 0


@intrinsic("block.contact.next", 1)
def _c_next(rt, c):
    cs, r = _contact_row(rt, c, "block.contact.next")
    return _ptr(cs, r + 1) if r + 1 < cs.n else 0


@intrinsic("block.subcontact.next", 1)
def _sub_next(rt, s):
    """The next sub-contact of the same contact, 0 after its last."""
    _sub_row(rt, s, "block.subcontact.next")
    cs = rt.session.model.stores["contacts"]
    ida, idb, k = s.key
    return ContactPtr("subcontact", (ida, idb, k + 1), s.hint) if k + 1 < int(cs["sub_count"][s.hint]) else 0


def _per_area(ss, k, name):
    a = float(ss["area"][k])
    if not a > 0.0:
        raise FishValueError(f"`{name}`: the sub-contact has no area (a point contact): use its force")
    return a


@intrinsic("block.subcontact.stress.norm", 1)
def _sub_sn(rt, s):
    """Normal stress [Pa]: normal force / area, compression positive as the force."""
    ss, k = _sub_row(rt, s, "block.subcontact.stress.norm")
    return float(ss["fn"][k]) / _per_area(ss, k, "block.subcontact.stress.norm")


@intrinsic("block.subcontact.stress.shear", 1)
def _sub_ss(rt, s):
    """Shear stress vector [Pa]: shear force on block B / area."""
    ss, k = _sub_row(rt, s, "block.subcontact.stress.shear")
    a = _per_area(ss, k, "block.subcontact.stress.shear")
    return _vec(ss["fs"][k] / a)


@intrinsic("block.subcontact.pp", 1)
def _sub_pp(rt, s):
    """Pore pressure [Pa] of the sub-contact (`block water`, `block contact apply pore-pressure`; 0 dry).
    Its stresses above are effective: the water pushes the faces apart on top of them."""
    ss, k = _sub_row(rt, s, "block.subcontact.pp")
    return float(ss["pp"][k]) if "pp" in ss else 0.0


@intrinsic("block.contact.pp", 1)
def _c_pp(rt, c):
    """Mean pore pressure [Pa] of the contact: its water force over its area (0 dry or without area)."""
    cs, r = _contact_row(rt, c, "block.contact.pp")
    ss = _stores(rt)[1]
    if "ppf" not in ss:
        return 0.0
    lo = int(cs["sub_start"][r])
    hi = lo + int(cs["sub_count"][r])
    a = float(ss["area"][lo:hi].sum())
    return float(ss["ppf"][lo:hi].sum()) / a if a > 0.0 else 0.0


# ---------------------------------------------------------------- joint-model properties

#: ``JMODELS[0](code)`` -> the joint model of that code (``physics.jmodels.JointModel``: ``name``, ``props``,
#: ``value(row, name)``), or None; set by dec3d.commands.fish_cmds (FISH imports no physics)
JMODELS: list = [None]


def _prop(rt, cs, r, name, fname):
    if type(name) is not str:
        raise FishValueError(f"`{fname}` takes a property name (a string), not a {type_name(name)}")
    m = JMODELS[0](int(cs["jmodel"][r])) if JMODELS[0] is not None else None
    if m is None:                                # pragma: no cover - every stored code has a host model
        raise FishValueError(f"`{fname}`: the contact has an unknown joint model")
    key = name.lower()
    if key not in m.props:
        raise FishValueError(f"`{fname}`: joint model `{m.name}` has no property '{name}' "
                             f"(it has {', '.join(sorted(m.props))})")
    return float(m.value(cs["prop"][r], key))


@intrinsic("block.contact.prop", 2)
def _c_prop(rt, c, name):
    """A property of the contact's joint model, by the name `block contact property` uses, in the same
    units (angles in degrees; an unset residual friction reads as the friction)."""
    cs, r = _contact_row(rt, c, "block.contact.prop")
    return _prop(rt, cs, r, name, "block.contact.prop")


@intrinsic("block.subcontact.prop", 2)
def _s_prop(rt, s, name):
    """The property of the sub-contact's contact (3DEC keeps joint properties per sub-contact; dec3d per
    contact, so every sub-contact of a contact reads the same value), or an entry of the sub-contact's
    own joint-model history by the name its model gives it (e.g. a damage or a plastic displacement)."""
    ss, k = _sub_row(rt, s, "block.subcontact.prop")
    cs, r = _contact_row(rt, ContactPtr("contact", s.key[:2], s.hint), "block.subcontact.prop")
    m = JMODELS[0](int(cs["jmodel"][r])) if JMODELS[0] is not None else None
    if type(name) is str and m is not None:
        hist = [h.lower() for h in m.hist_names]
        if name.lower() in hist:
            return float(ss["hist"][k, hist.index(name.lower())])
        if name.lower() not in m.props and hist:
            raise FishValueError(f"`block.subcontact.prop`: joint model `{m.name}` has no property or history "
                                 f"'{name}' (it has {', '.join(sorted(m.props) + list(m.hist_names))})")
    return _prop(rt, cs, r, name, "block.subcontact.prop")


from . import contact_near  # noqa: E402,F401  (registers block.contact.near)
