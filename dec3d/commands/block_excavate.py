"""`block excavate` and `block fill`: take deformable blocks out of the calculation and put them back.

3DEC's rule (Itasca, 3DEC 7 command reference, "block excavate" and "block fill"): excavated blocks
transmit no force to the rest of the model and are kept in memory so that `block fill` can put them
back; the command is for deformable blocks (zoned or FE), rigid blocks are deleted instead.
`face-group` puts the faces of the blocks left next to the excavation in a group (so a pressure or
a liner can be applied to the excavation's boundary); `block fill` can group the filled blocks and
their new contacts.

In dec3d an excavated block is hidden from the calculation (as a hidden block is: no contacts, no
zone or gridpoint step) and flagged ``excavated`` so that `block hide off` does not bring it back.
It stays where it was while excavated: 3DEC moves its gridpoints with the surrounding grid ("only
displacements are calculated"), dec3d does not, so a block filled after large movements of its
neighbours starts overlapping them — fill soon after excavating, or let `block contact reset
overlap` take the overlap out.
"""
from __future__ import annotations

import numpy as np

from ..errors import CommandError
from ..model.model import KIND_RIGID
from ..physics.rigid import engine
from .registry import command
from .values import P, Text


def _adjacent_faces(model, dug: np.ndarray, tol: float) -> np.ndarray:
    """Face rows of blocks not in ``dug`` (and not hidden) lying on a face of a block in ``dug``: the
    face's area centroid within ``tol`` of that face's plane and inside the (convex) dug block."""
    b, f = model.blocks, model.faces
    live = ~b["hidden"] & ~dug
    fb = f["block"]
    keep = np.zeros(f.n, bool)
    cand = np.flatnonzero((fb >= 0) & live[np.maximum(fb, 0)])
    if not len(cand):
        return cand
    cen = f["centroid"][cand]
    for r in np.flatnonzero(dug):
        mine = np.flatnonzero(fb == r)
        n, c = f["normal"][mine], f["centroid"][mine]
        # signed distances of every candidate centroid to every face plane of block r (outward normals)
        dist = np.einsum("ijk,jk->ij", cen[:, None, :] - c[None, :, :], n)
        inside = (dist <= tol).all(axis=1)
        on_face = (np.abs(dist) <= tol).any(axis=1)
        keep[cand[inside & on_face]] = True
    return np.flatnonzero(keep)


@command("block excavate",
         keywords=[P("face-group", Text(), "put the faces next to the excavation in this group"),
                   P("slot", Text(), "slot of the face group (default 'Default')")],
         range="block",
         doc="Excavate the deformable blocks in range: they carry no force and take no part in the "
             "calculation until `block fill` puts them back.",
         details="Rigid blocks cannot be excavated (use `block delete`). With `face-group` the faces of the "
                 "blocks left that touch the excavated blocks join that group (for `block face apply` on the "
                 "excavation's boundary). An excavated block keeps its zones, stresses and properties and stays "
                 "where it was; `block hide off` does not show it again. Cable and beam nodes in the excavated "
                 "blocks become free (no grout or link force) and hybrid bolts' dowels with a side there go, "
                 "reported once in a notice; `block fill` does not attach them again.",
         examples=["block excavate range group 'tunnel'", "block excavate face-group 'wall' range group 'stage1'",
                   "block excavate face-group 'wall' slot 'bc' range cylinder end-1 0 -1 0 end-2 0 11 0 radius 3"])
def block_excavate(session, call):
    m = session.model
    b = m.blocks
    sel = session.range_mask(call, "block") & ~b["excavated"][: b.n]
    rows = np.flatnonzero(sel)
    rigid = rows[b["kind"][rows] == KIND_RIGID]
    if len(rigid):
        ids = ", ".join(str(int(i)) for i in b["id"][rigid[:8]]) + (" …" if len(rigid) > 8 else "")
        raise CommandError(f"`block excavate` works on deformable (zoned or FE) blocks; {len(rigid)} rigid block(s) "
                           f"in range (id {ids}): `block delete` removes rigid blocks", call.location)
    if not len(rows):
        session.write(f"warning: {call.location}: `block excavate` selected no block")
        return
    a = call.args
    if a["face_group"] is not None:
        tol = max(float(engine(m).tolerance()), 1e-9)
        faces = _adjacent_faces(m, sel, tol)
        if len(faces):
            m.groups.assign(m.faces, faces, a["face_group"], a["slot"])
        else:
            session.write(f"warning: {call.location}: no face of another block touches the excavated blocks")
    b["excavated"][rows] = True
    b["hidden"][rows] = True
    from ..model.cables import release_hosts

    nc, nb, nd, nl = release_hosts(m, sel)
    if nc or nb or nd or nl:
        what = ", ".join(f"{n} {w}" for n, w in ((nc, "cable node(s)"), (nb, "beam node(s)"), (nd, "dowel(s)"),
                                                 (nl, "liner node(s)")) if n)
        session.write(f"notice: {what} lay in the excavated blocks: from now on the nodes are free (no grout "
                      "or link force) and the dowels are gone; `block fill` does not attach them again")


@command("block fill",
         keywords=[P("block-group", Text(), "put the filled blocks in this group"),
                   P("boundary-contact-group", Text(), "put the contacts between a filled block and the rest in "
                     "this group"),
                   P("internal-contact-group", Text(), "put the contacts between two filled blocks in this group"),
                   P("slot", Text(), "slot of the groups given (default 'Default')")],
         range="block",
         doc="Fill the excavated blocks in range: they take part in the calculation again.",
         details="The contacts of the filled blocks are found at once (as a cycle would), so the contact groups "
                 "can be given here. 3DEC's caution holds: a filled block is put back as it was excavated, and "
                 "overlaps its neighbours when they have moved much since (`block contact reset overlap`). One "
                 "`slot` applies to every group given.",
         examples=["block fill range group 'tunnel'", "block fill block-group 'concrete' range group 'tunnel'",
                   "block fill boundary-contact-group 'shotcrete' internal-contact-group 'fill'"])
def block_fill(session, call):
    m = session.model
    b = m.blocks
    sel = session.range_mask(call, "block") & b["excavated"][: b.n]
    rows = np.flatnonzero(sel)
    if not len(rows):
        session.write(f"warning: {call.location}: `block fill` selected no excavated block")
        return
    b["excavated"][rows] = False
    b["hidden"][rows] = False
    a = call.args
    if a["block_group"] is not None:
        m.groups.assign(b, rows, a["block_group"], a["slot"])
    if a["boundary_contact_group"] is None and a["internal_contact_group"] is None:
        return
    e = engine(m)
    e.ensure_contacts()
    c = e.contacts
    fa, fb = sel[c["a"]], sel[c["b"]]
    for key, pick in (("boundary_contact_group", fa ^ fb), ("internal_contact_group", fa & fb)):
        if a[key] is not None:
            m.groups.assign(c, np.flatnonzero(pick), a[key], a["slot"])
