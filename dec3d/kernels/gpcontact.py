"""Sub-contacts on deformable (zoned) blocks: where a sub-contact sits on a zoned block's
surface, the velocity of that point and the share of the contact force each gridpoint takes
(3DEC theory, "Deformable blocks": a sub-contact on a deformable block moves with the
gridpoints of the surface it lies on, and its force goes to those gridpoints — on the vertex
side to the vertex gridpoint, on the face side shared among the face's gridpoints by the
interpolation factors of the point in the face triangle).

Every sub-contact gets, for each of its two sides, up to three gridpoint rows and weights
(``nodes`` (k, 3) int64, ``w`` (k, 3)): the surface triangle of that block nearest to the
point and the barycentric coordinates of the nearest point of the triangle (clamped to it,
so they are ≥ 0 and sum to 1) — the face side's interpolation factors of the text;
``vertex_sides`` then puts the vertex side of a vertex sub-contact on its own gridpoint
(weight 1). A rigid side gets node -1 and moves with its block (Eq. 11). Between two zoned
blocks both sides are interpolated this way: the force on B goes to B's gridpoints, its
opposite to A's, so the two blocks' forces and (when the point lies in both faces) moments
balance exactly. The weights are made at each detection and kept until the next (the text:
"sub-contact locations and weights are updated every 10 steps"), which relocates a
sub-contact onto the triangle its gridpoint has moved onto.

With the weights fixed between two detection passes, one step is:
  V = v_B(x) − v_A(x), v_side(x) = Σ wᵢ vᵢ (zoned) or ẋ + ω × (x − x̄) (rigid)   (Eq. 15)
  the joint law of the contact's model (``joints.joint_law``) unchanged;
  force on B: + (Fⁿ n + Fˢ), on A: −; to a zoned side's gridpoints in proportion wᵢ, to a
  rigid side's centroid with its moment (ERRATA Eqs. 28-32).
"""
from __future__ import annotations

import math

from numba import literally, njit, prange

from .joints import ST_NEW, cycle_mask, joint_law_for


@njit(cache=True, inline="always")
def add_to_sides(s, blk_b, blk_a, x0, x1, x2, d0, d1, d2, nodes_a, w_a, nodes_b, w_b, bpos, bforce, bmoment,
                 gforce):
    """The force d at the point x of sub-contact ``s`` onto side B and −d onto side A: to a rigid side's
    centroid with its moment (x − centroid) × force, or to a zoned side's gridpoints in proportion to
    their weights (node −1: rigid side). B first, then A. The mixed-contact kernels' one way of handing a
    sub-contact's force to its two sides (joint force here, Rayleigh damping, pore pressure)."""
    for side in range(2):
        blk = blk_b if side == 0 else blk_a
        nodes = nodes_b if side == 0 else nodes_a
        w = w_b if side == 0 else w_a
        sg = 1.0 if side == 0 else -1.0
        g0 = sg * d0
        g1 = sg * d1
        g2 = sg * d2
        if nodes[s, 0] < 0:
            r0 = x0 - bpos[blk, 0]
            r1 = x1 - bpos[blk, 1]
            r2 = x2 - bpos[blk, 2]
            bforce[blk, 0] += g0
            bforce[blk, 1] += g1
            bforce[blk, 2] += g2
            bmoment[blk, 0] += r1 * g2 - r2 * g1
            bmoment[blk, 1] += r2 * g0 - r0 * g2
            bmoment[blk, 2] += r0 * g1 - r1 * g0
        else:
            for j in range(3):
                g = nodes[s, j]
                if g >= 0:
                    gforce[g, 0] += w[s, j] * g0
                    gforce[g, 1] += w[s, j] * g1
                    gforce[g, 2] += w[s, j] * g2


@njit(cache=True)
def _closest_on_triangle(p0, p1, p2, a, b, c):
    """Barycentric (u, v, w) of the point of triangle abc nearest to p, and the squared distance."""
    ab0, ab1, ab2 = b[0] - a[0], b[1] - a[1], b[2] - a[2]
    ac0, ac1, ac2 = c[0] - a[0], c[1] - a[1], c[2] - a[2]
    ap0, ap1, ap2 = p0 - a[0], p1 - a[1], p2 - a[2]
    d00 = ab0 * ab0 + ab1 * ab1 + ab2 * ab2
    d01 = ab0 * ac0 + ab1 * ac1 + ab2 * ac2
    d11 = ac0 * ac0 + ac1 * ac1 + ac2 * ac2
    d20 = ap0 * ab0 + ap1 * ab1 + ap2 * ab2
    d21 = ap0 * ac0 + ap1 * ac1 + ap2 * ac2
    den = d00 * d11 - d01 * d01
    best_u, best_v, best_w, best_d = 1.0, 0.0, 0.0, math.inf
    if den > 0.0:
        v = (d11 * d20 - d01 * d21) / den
        w = (d00 * d21 - d01 * d20) / den
        u = 1.0 - v - w
        if u >= 0.0 and v >= 0.0 and w >= 0.0:
            q0 = a[0] + v * ab0 + w * ac0 - p0
            q1 = a[1] + v * ab1 + w * ac1 - p1
            q2 = a[2] + v * ab2 + w * ac2 - p2
            return u, v, w, q0 * q0 + q1 * q1 + q2 * q2
    # outside (or degenerate): the nearest point of the three edges
    for e in range(3):
        if e == 0:
            s, t = a, b
        elif e == 1:
            s, t = b, c
        else:
            s, t = c, a
        e0, e1, e2 = t[0] - s[0], t[1] - s[1], t[2] - s[2]
        ll = e0 * e0 + e1 * e1 + e2 * e2
        f = 0.0
        if ll > 0.0:
            f = ((p0 - s[0]) * e0 + (p1 - s[1]) * e1 + (p2 - s[2]) * e2) / ll
            f = min(1.0, max(0.0, f))
        q0 = s[0] + f * e0 - p0
        q1 = s[1] + f * e1 - p1
        q2 = s[2] + f * e2 - p2
        d = q0 * q0 + q1 * q1 + q2 * q2
        if d < best_d:
            best_d = d
            if e == 0:
                best_u, best_v, best_w = 1.0 - f, f, 0.0
            elif e == 1:
                best_u, best_v, best_w = 0.0, 1.0 - f, f
            else:
                best_u, best_v, best_w = f, 0.0, 1.0 - f
    return best_u, best_v, best_w, best_d


@njit(cache=True)
def surface_weights(owner, pts, ca, cb, zoned, vpos, bfstart, bfcount, fvstart, fnvert, fverts,
                    nodes_a, w_a, nodes_b, w_b):
    """For points pts (k, 3) of contacts owner (k,): per side, the nearest surface triangle of a
    zoned block (zoned (nb,) bool) and the barycentric weights of the point in it; -1 and 0 for a
    rigid side (or a face that is not a triangle)."""
    for i in range(owner.shape[0]):
        c = owner[i]
        for side in range(2):
            blk = ca[c] if side == 0 else cb[c]
            nodes = nodes_a if side == 0 else nodes_b
            w = w_a if side == 0 else w_b
            for j in range(3):
                nodes[i, j] = -1
                w[i, j] = 0.0
            if not zoned[blk]:
                continue
            best = math.inf
            for f in range(bfstart[blk], bfstart[blk] + bfcount[blk]):
                if fnvert[f] != 3:
                    continue
                k0 = fverts[fvstart[f]]
                k1 = fverts[fvstart[f] + 1]
                k2 = fverts[fvstart[f] + 2]
                u, v, ww, d = _closest_on_triangle(pts[i, 0], pts[i, 1], pts[i, 2], vpos[k0], vpos[k1], vpos[k2])
                if d < best:
                    best = d
                    nodes[i, 0] = k0
                    nodes[i, 1] = k1
                    nodes[i, 2] = k2
                    w[i, 0] = u
                    w[i, 1] = v
                    w[i, 2] = ww


@njit(cache=True)
def vertex_sides(kind, key0, ca, cb, sc_contact, zoned, nodes_a, w_a, nodes_b, w_b):
    """The vertex side of vertex-face sub-contacts on a zoned block is its own gridpoint (3DEC
    theory, "Sub-contact Force Update": on the vertex side the force is added to that gridpoint,
    whose velocity is the vertex velocity): node key0 with weight 1, in place of the nearest
    triangle ``surface_weights`` found (the point on the c-p lies off the vertex by half the gap).
    kind (ns,) 0 A's vertex, 1 B's vertex, others untouched; key0 (ns,) the vertex row."""
    for s in range(kind.shape[0]):
        k = kind[s]
        if k != 0 and k != 1:
            continue
        c = sc_contact[s]
        blk = ca[c] if k == 0 else cb[c]
        if not zoned[blk]:
            continue
        nodes = nodes_a if k == 0 else nodes_b
        w = w_a if k == 0 else w_b
        nodes[s, 0] = key0[s]
        nodes[s, 1] = -1
        nodes[s, 2] = -1
        w[s, 0] = 1.0
        w[s, 1] = 0.0
        w[s, 2] = 0.0


def mixed_subcontact_forces(dt, bpos, bvel, bspin, bforce, bmoment, gvel, gforce,
                            ca, cb, cn, cmodel, cprop,
                            sc_contact, sc_pos, sc_area, sc_fn, sc_fs, sc_un, sc_udil, sc_us, sc_state, sc_hist,
                            nodes_a, w_a, nodes_b, w_b, models=None):
    """``_mixed_subcontact_forces`` (the kernel, documented there) for the joint models of the mask
    ``models`` (``joints.cycle_mask``; worked out from cmodel when None)."""
    if models is None:
        models = cycle_mask(cmodel)
    _mixed_for(int(models))(dt, bpos, bvel, bspin, bforce, bmoment, gvel, gforce, ca, cb, cn, cmodel, cprop,
                            sc_contact, sc_pos, sc_area, sc_fn, sc_fs, sc_un, sc_udil, sc_us, sc_state, sc_hist,
                            nodes_a, w_a, nodes_b, w_b)


_MIXED: dict = {}


def _mixed_for(models: int):
    """The kernel with the mask fixed (a constant: see ``cycle._stepper``), one per mask and process,
    cached on disk."""
    f = _MIXED.get(models)
    if f is None:
        mask = int(models)

        @njit(cache=True)
        def f(dt, bpos, bvel, bspin, bforce, bmoment, gvel, gforce, ca, cb, cn, cmodel, cprop, sc_contact, sc_pos,
              sc_area, sc_fn, sc_fs, sc_un, sc_udil, sc_us, sc_state, sc_hist, nodes_a, w_a, nodes_b, w_b):
            _mixed_subcontact_forces(mask, dt, bpos, bvel, bspin, bforce, bmoment, gvel, gforce, ca, cb, cn, cmodel,
                                     cprop, sc_contact, sc_pos, sc_area, sc_fn, sc_fs, sc_un, sc_udil, sc_us,
                                     sc_state, sc_hist, nodes_a, w_a, nodes_b, w_b)
        _MIXED[models] = f
    return f


@njit(cache=True, parallel=True)
def _mixed_subcontact_forces(models, dt, bpos, bvel, bspin, bforce, bmoment, gvel, gforce,
                             ca, cb, cn, cmodel, cprop,
                             sc_contact, sc_pos, sc_area, sc_fn, sc_fs, sc_un, sc_udil, sc_us, sc_state, sc_hist,
                             nodes_a, w_a, nodes_b, w_b):
    """One force update of every sub-contact when some blocks are zoned: as
    ``jointlaw.subcontact_forces``, with each zoned side's velocity interpolated from its
    gridpoints (gvel (nv, 3)) and its force shared to them (added to gforce (nv, 3)).

    (Both sides are written out in one loop over ``side`` rather than through a helper that
    returns a tuple: numba compiled that form some 40 times slower.) The joint laws run on
    threads (each sub-contact's own numbers); the forces are then added to the gridpoints and
    blocks in sub-contact order, as before: the same bits for any thread count. ``models``: the mask
    of the joint models among the contacts, a compile-time constant (``joints.joint_law_for``)."""
    literally(models)
    for s in prange(sc_contact.shape[0]):
        c = sc_contact[s]
        n0 = cn[c, 0]
        n1 = cn[c, 1]
        n2 = cn[c, 2]
        x0 = sc_pos[s, 0]
        x1 = sc_pos[s, 1]
        x2 = sc_pos[s, 2]
        # V = v_B(x) - v_A(x) (Eq. 15), each side rigid (Eq. 11) or interpolated (zoned)
        du0 = 0.0
        du1 = 0.0
        du2 = 0.0
        for side in range(2):
            blk = ca[c] if side == 0 else cb[c]
            nodes = nodes_a if side == 0 else nodes_b
            w = w_a if side == 0 else w_b
            sg = -1.0 if side == 0 else 1.0
            if nodes[s, 0] < 0:
                r0 = x0 - bpos[blk, 0]
                r1 = x1 - bpos[blk, 1]
                r2 = x2 - bpos[blk, 2]
                du0 += sg * (bvel[blk, 0] + bspin[blk, 1] * r2 - bspin[blk, 2] * r1)
                du1 += sg * (bvel[blk, 1] + bspin[blk, 2] * r0 - bspin[blk, 0] * r2)
                du2 += sg * (bvel[blk, 2] + bspin[blk, 0] * r1 - bspin[blk, 1] * r0)
            else:
                for j in range(3):
                    g = nodes[s, j]
                    if g >= 0:
                        du0 += sg * w[s, j] * gvel[g, 0]
                        du1 += sg * w[s, j] * gvel[g, 1]
                        du2 += sg * w[s, j] * gvel[g, 2]
        du0 *= dt
        du1 *= dt
        du2 *= dt
        dun = du0 * n0 + du1 * n1 + du2 * n2
        st0 = sc_state[s]
        if st0 & ST_NEW:
            du0 = 0.0
            du1 = 0.0
            du2 = 0.0
            dun = 0.0
            st0 &= ~ST_NEW
        fn, f0, f1, f2, un, ud, u0, u1, u2, st = joint_law_for(
            models, cmodel[c], cprop, c, sc_hist, s, sc_area[s], dun, du0 - dun * n0, du1 - dun * n1, du2 - dun * n2, sc_un[s],
            sc_udil[s], sc_fs[s, 0], sc_fs[s, 1], sc_fs[s, 2], sc_us[s, 0], sc_us[s, 1], sc_us[s, 2], st0)
        sc_fn[s] = fn
        sc_fs[s, 0] = f0
        sc_fs[s, 1] = f1
        sc_fs[s, 2] = f2
        sc_un[s] = un
        sc_udil[s] = ud
        sc_us[s, 0] = u0
        sc_us[s, 1] = u1
        sc_us[s, 2] = u2
        sc_state[s] = st
    for s in range(sc_contact.shape[0]):
        c = sc_contact[s]
        n0 = cn[c, 0]
        n1 = cn[c, 1]
        n2 = cn[c, 2]
        x0 = sc_pos[s, 0]
        x1 = sc_pos[s, 1]
        x2 = sc_pos[s, 2]
        fn = sc_fn[s]
        f0 = sc_fs[s, 0]
        f1 = sc_fs[s, 1]
        f2 = sc_fs[s, 2]
        # force on B: + (Fn n + Fs), on A: - (ERRATA Eqs. 28-32); B first, then A
        add_to_sides(s, cb[c], ca[c], x0, x1, x2, fn * n0 + f0, fn * n1 + f1, fn * n2 + f2,
                     nodes_a, w_a, nodes_b, w_b, bpos, bforce, bmoment, gforce)




@njit(cache=True, parallel=True)
def mixed_move_points(dt, ca, cb, owner, pts, bpos, bvel, bspin, gvel, nodes_a, w_a, nodes_b, w_b):
    """Eq. (11) with zoned sides: each point moves by the mean of the two sides' displacement
    at it (a rigid side's rigid motion, a zoned side's interpolated gridpoint velocity) × Δt.
    (Each point its own numbers: on threads.)"""
    for i in prange(owner.shape[0]):
        c = owner[i]
        x0 = pts[i, 0]
        x1 = pts[i, 1]
        x2 = pts[i, 2]
        m0 = 0.0
        m1 = 0.0
        m2 = 0.0
        for side in range(2):
            blk = ca[c] if side == 0 else cb[c]
            nodes = nodes_a if side == 0 else nodes_b
            w = w_a if side == 0 else w_b
            if nodes[i, 0] < 0:
                r0 = x0 - bpos[blk, 0]
                r1 = x1 - bpos[blk, 1]
                r2 = x2 - bpos[blk, 2]
                m0 += bvel[blk, 0] + bspin[blk, 1] * r2 - bspin[blk, 2] * r1
                m1 += bvel[blk, 1] + bspin[blk, 2] * r0 - bspin[blk, 0] * r2
                m2 += bvel[blk, 2] + bspin[blk, 0] * r1 - bspin[blk, 1] * r0
            else:
                for j in range(3):
                    g = nodes[i, j]
                    if g >= 0:
                        m0 += w[i, j] * gvel[g, 0]
                        m1 += w[i, j] * gvel[g, 1]
                        m2 += w[i, j] * gvel[g, 2]
        pts[i, 0] = x0 + 0.5 * dt * m0
        pts[i, 1] = x1 + 0.5 * dt * m1
        pts[i, 2] = x2 + 0.5 * dt * m2


@njit(cache=True)
def take_contact_forces(rows, gc, facc, fmag):
    """The contact forces gathered in gc (nv, 3) on gridpoint rows ``rows`` go to the step's force
    accumulator facc and their magnitudes to fmag (the applied-force magnitude of the equilibrium
    ratio); gc is zeroed there for the next step."""
    for k in range(rows.shape[0]):
        g = rows[k]
        f0 = gc[g, 0]
        f1 = gc[g, 1]
        f2 = gc[g, 2]
        facc[g, 0] += f0
        facc[g, 1] += f1
        facc[g, 2] += f2
        fmag[g] += math.sqrt(f0 * f0 + f1 * f1 + f2 * f2)
        gc[g, 0] = 0.0
        gc[g, 1] = 0.0
        gc[g, 2] = 0.0
