"""Contacts with a zoned (or FE) side, for the rigid engine (mixed into ``rigid.RigidEngine``):
which contacts have one, the gridpoint weights of their points, and whole steps of a model where
zoned and rigid blocks touch (the ``MixedContacts`` step of ``physics.steps``).
"""
from __future__ import annotations

import math

import numpy as np

from dec3d.kernels.gpcontact import (mixed_move_points, mixed_subcontact_forces, surface_weights,
                                    take_contact_forces, vertex_sides)
from dec3d.physics.jmodels import stiffness as joint_stiffness
from dec3d.kernels.motion import rigid_motion_groups
from dec3d.kernels.rayleigh import mixed_stiffness_damping
from dec3d.kernels.water import any_pressure, mixed_pore_forces
from dec3d.model.model import KIND_DEFORMABLE, KIND_FE

_I = np.int64


def _deformable(kind):
    """Zoned and FE blocks: they move by their gridpoints (nodes), not as rigid bodies."""
    return (kind == KIND_DEFORMABLE) | (kind == KIND_FE)


class MixedContactSteps:
    """The engine's methods for contacts with a zoned side (``self`` is the ``RigidEngine``)."""

    def _zone_contacts_check(self) -> bool:
        """Whether some contact has a zoned side (its sub-contact forces go to gridpoints, in
        ``_mixed_steps``): zoned against rigid, or zoned against zoned (sub-contacts at the
        surface gridpoints of both; within one joined set they carry none, see
        ``contacts.joined_zoned_inert``). FE blocks count as zoned: their surface nodes (the slave
        mid-face nodes too, whose forces reach the masters by Eq. 9) are the gridpoints."""
        b, cs = self.model.blocks, self.contacts
        if not cs.n:
            return False
        kind = b["kind"]
        za = _deformable(kind[cs["a"]])
        zb = _deformable(kind[cs["b"]])
        return bool((za ^ zb).any() or (za & zb & (cs["sub_count"] > 0)).any())

    def _mixed_weights(self, zst, recompute: bool = True) -> tuple:
        """Gridpoint rows and interpolation weights of every sub-contact and contact point on a
        zoned side (``gpcontact.surface_weights``), and the contact stiffness they give the
        gridpoints (the joint term of Eq. 85: max(kn, ks) · area, shared by the weights).

        They are kept in the contact stores (``gp_a gw_a gp_b gw_b``): made at a detection and
        used until the next one, so a run that starts between two detections (a split run, a
        restored model) takes them as the last run left them (``recompute=False``) instead of
        working them out from points that have moved since."""
        m = self.model
        b, f, v = m.blocks, m.faces, m.vertices
        cs, ss = self.contacts, self.subcontacts
        zoned = _deformable(b["kind"])
        stores = ((ss, ss["contact"]), (cs, np.arange(cs.n, dtype=_I)))
        if not recompute:
            # kept weights are usable only if every point on a zoned side has its triangle
            for st, owner in stores:
                for side, key in (("a", "gp_a"), ("b", "gp_b")):
                    if (st[key][zoned[cs[side][owner]], 0] < 0).any():
                        recompute = True
        if recompute:
            geo = (zoned, v["pos"], b["face_start"], b["face_count"], f["vstart"], f["nvert"],
                   m.face_vertices["vertex"])
            for st, owner in stores:
                k = len(owner)
                na, wa, nb, wb = np.empty((k, 3), _I), np.empty((k, 3)), np.empty((k, 3), _I), np.empty((k, 3))
                surface_weights(np.ascontiguousarray(owner), st["pos"], cs["a"], cs["b"], *geo, na, wa, nb, wb)
                if st is ss:
                    vertex_sides(ss["kind"], ss["key0"], cs["a"], cs["b"], owner, zoned, na, wa, nb, wb)
                st["gp_a"][:] = na
                st["gw_a"][:] = wa
                st["gp_b"][:] = nb
                st["gw_b"][:] = wb
        out = [tuple(st[key] for key in ("gp_a", "gw_a", "gp_b", "gw_b")) for st, _ in stores]
        na, wa, nb, wb = out[0]
        # the gridpoints the sub-contacts load (``_mixed_steps``), made once per detection
        touched = np.unique(np.concatenate((na.ravel(), nb.ravel())))
        self._mixed_touched = (out[0], np.ascontiguousarray(touched[touched >= 0]))
        kk = np.maximum(*joint_stiffness(cs, ss)) * ss["area"]
        rows = np.concatenate((na.ravel(), nb.ravel()))
        kw = np.concatenate(((wa * kk[:, None]).ravel(), (wb * kk[:, None]).ravel()))
        on = rows >= 0
        zst.set_contact_stiffness(rows[on], kw[on])
        return out[0], out[1]

    def _mixed_steps(self, k, zst, wsub, wcon, dt, g, full, damping, groups, bodies, large, vmax, out) -> None:
        """``k`` steps of a model where zoned and rigid blocks touch (3DEC theory, "Deformable
        blocks": a sub-contact on a deformable block moves with the gridpoints of the surface it
        lies on, its force goes to them by the interpolation factors): sub-contact forces
        (``gpcontact.mixed_subcontact_forces``), rigid motion, the zone step with the contact
        forces on the gridpoints, then the contact points move (``mixed_move_points``)."""
        m = self.model
        b, v = m.blocks, m.vertices
        cs, ss = self.contacts, self.subcontacts
        gvel = v["velocity"]
        gc = np.zeros((v.n, 3))
        kept = getattr(self, "_mixed_touched", None)
        if kept is not None and all(x is y for x, y in zip(kept[0], wsub)):
            touched = kept[1]
        else:
            touched = np.unique(np.concatenate((wsub[0].ravel(), wsub[2].ravel())))
            touched = np.ascontiguousarray(touched[touched >= 0])
        cown = np.arange(cs.n, dtype=_I)
        gstart, gmember = groups.start, groups.member
        wet = any_pressure(ss["ppf"])         # pore pressure (physics.water): fixed between detections
        for _ in range(k):
            facc = zst.begin()
            mixed_subcontact_forces(dt, b["centroid"], b["velocity"], b["spin"], b["force"], b["moment"], gvel, gc,
                                    cs["a"], cs["b"], cs["normal"], cs["jmodel"], cs["prop"], ss["contact"], ss["pos"],
                                    ss["area"], ss["fn"], ss["fs"], ss["un"], ss["udil"], ss["us"], ss["state"], ss["hist"],
                                    *wsub)
            if wet:
                mixed_pore_forces(b["centroid"], b["force"], b["moment"], gc, cs["a"], cs["b"], cs["normal"],
                                  ss["contact"], ss["pos"], ss["ppf"], *wsub)
            if zst.beta > 0.0:          # Rayleigh damping's stiffness term (physics.dynamic)
                mixed_stiffness_damping(zst.beta, b["centroid"], b["velocity"], b["spin"], b["force"], b["moment"],
                                        gvel, gc, cs["a"], cs["b"], cs["normal"], cs["jmodel"], cs["prop"],
                                        ss["contact"], ss["pos"], ss["area"], ss["fn"], ss["state"], ss["hist"], *wsub)
            take_contact_forces(touched, gc, facc, zst.fmag)
            if len(gmember):
                gbad = rigid_motion_groups(dt, g, full, damping, groups, bodies, vmax, out)
                if gbad >= 0 or not math.isfinite(out[0]):
                    raise self._blowup(int(gmember[gstart[gbad]]) if gbad >= 0 else int(gmember[0]), dt, False)
            zbad = zst.step(dt, g, damping.mode, damping.alpha, large, vmax, begun=True)
            if zbad >= 0:
                raise zst.unstable(zbad, dt)
            mixed_move_points(dt, cs["a"], cs["b"], cown, cs["pos"], b["centroid"], b["velocity"], b["spin"], gvel,
                              *wcon)
            mixed_move_points(dt, cs["a"], cs["b"], ss["contact"], ss["pos"], b["centroid"], b["velocity"],
                              b["spin"], gvel, *wsub)
