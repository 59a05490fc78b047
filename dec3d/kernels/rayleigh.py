"""The stiffness-proportional term of Rayleigh damping on the sub-contacts (rigid, zoned and FE sides).

Itasca's 3DEC "Dynamic Analysis" pages (Damping): stiffness-proportional damping "applies a force,
which is proportional to the incremental stiffness matrix multiplied by relative velocities [...], to
contacts"; with the Rayleigh damping matrix C = α M + β K the contact part is β K. For a sub-contact
of area A with normal stiffness kn and shear stiffness ks [Pa/m] (its joint model's current ones,
``joints.joint_stiffness``), relative velocity V (Eq. 15 of the
3DEC theory text, B relative to A), Vⁿ = V·n, Vˢ = V − Vⁿ n:

    Fᵈ = −β A (kn Vⁿ n + ks Vˢ)          (the damping force on B; A takes −Fᵈ)

It is added to the force the joint law put into ``sg`` for this step and is not stored in the
sub-contact's own forces (they stay the elastic, Coulomb-limited ones). dec3d's choices: the normal
term acts only on a closed sub-contact (Fⁿ > 0), the shear term only on one that is closed and not
slipping (a slipping joint already dissipates; damping it would push its force past the Coulomb
limit). The velocities are those of the half step the joint law used.
"""
from __future__ import annotations

from numba import njit, prange

from .gpcontact import add_to_sides
from .joints import ST_SLIP, joint_stiffness


@njit(cache=True, parallel=True)
def contact_stiffness_damping(beta, bpos, bvel, bspin, ca, cb, cn, cmodel, cprop, sc_contact, sc_pos, sc_area,
                              sc_fn, sc_state, sc_hist, sg):
    """Add β K V (see the module text) of every sub-contact to sg (ns, 3) [N], in parallel (each
    sub-contact writes only its own row). beta [s]; the other arrays as ``jointlaw.subcontact_update``."""
    for s in prange(sc_contact.shape[0]):
        if not sc_fn[s] > 0.0:
            continue
        c = sc_contact[s]
        a = ca[c]
        b = cb[c]
        n0 = cn[c, 0]
        n1 = cn[c, 1]
        n2 = cn[c, 2]
        ra0 = sc_pos[s, 0] - bpos[a, 0]
        ra1 = sc_pos[s, 1] - bpos[a, 1]
        ra2 = sc_pos[s, 2] - bpos[a, 2]
        rb0 = sc_pos[s, 0] - bpos[b, 0]
        rb1 = sc_pos[s, 1] - bpos[b, 1]
        rb2 = sc_pos[s, 2] - bpos[b, 2]
        v0 = (bvel[b, 0] + bspin[b, 1] * rb2 - bspin[b, 2] * rb1
              - bvel[a, 0] - (bspin[a, 1] * ra2 - bspin[a, 2] * ra1))
        v1 = (bvel[b, 1] + bspin[b, 2] * rb0 - bspin[b, 0] * rb2
              - bvel[a, 1] - (bspin[a, 2] * ra0 - bspin[a, 0] * ra2))
        v2 = (bvel[b, 2] + bspin[b, 0] * rb1 - bspin[b, 1] * rb0
              - bvel[a, 2] - (bspin[a, 0] * ra1 - bspin[a, 1] * ra0))
        vn = v0 * n0 + v1 * n1 + v2 * n2
        kn, ks = joint_stiffness(cmodel[c], cprop, c, sc_hist, s)
        kn *= beta * sc_area[s]
        ks = 0.0 if (sc_state[s] & ST_SLIP) else beta * ks * sc_area[s]
        sg[s, 0] -= kn * vn * n0 + ks * (v0 - vn * n0)
        sg[s, 1] -= kn * vn * n1 + ks * (v1 - vn * n1)
        sg[s, 2] -= kn * vn * n2 + ks * (v2 - vn * n2)


@njit(cache=True)
def mixed_stiffness_damping(beta, bpos, bvel, bspin, bforce, bmoment, gvel, gforce, ca, cb, cn, cmodel, cprop,
                            sc_contact, sc_pos, sc_area, sc_fn, sc_state, sc_hist, nodes_a, w_a, nodes_b, w_b):
    """The damping force of the module text on every sub-contact of a model where zoned (or FE) and
    rigid blocks touch (``gpcontact.mixed_subcontact_forces`` arrays): V from each side's rigid
    motion or its gridpoints' velocities interpolated with the weights (node -1: rigid side), the
    force on B (−Fᵈ on A) to a rigid side's centroid with its moment, or to a zoned side's gridpoints
    in proportion to their weights (added to gforce (nv, 3)). Serial: sub-contacts share blocks and
    gridpoints. The same rules as ``contact_stiffness_damping`` (closed, not slipping for the shear)."""
    for s in range(sc_contact.shape[0]):
        if not sc_fn[s] > 0.0:
            continue
        c = sc_contact[s]
        n0 = cn[c, 0]
        n1 = cn[c, 1]
        n2 = cn[c, 2]
        x0 = sc_pos[s, 0]
        x1 = sc_pos[s, 1]
        x2 = sc_pos[s, 2]
        v0 = 0.0
        v1 = 0.0
        v2 = 0.0
        for side in range(2):
            blk = ca[c] if side == 0 else cb[c]
            nodes = nodes_a if side == 0 else nodes_b
            w = w_a if side == 0 else w_b
            sg = -1.0 if side == 0 else 1.0
            if nodes[s, 0] < 0:
                r0 = x0 - bpos[blk, 0]
                r1 = x1 - bpos[blk, 1]
                r2 = x2 - bpos[blk, 2]
                v0 += sg * (bvel[blk, 0] + bspin[blk, 1] * r2 - bspin[blk, 2] * r1)
                v1 += sg * (bvel[blk, 1] + bspin[blk, 2] * r0 - bspin[blk, 0] * r2)
                v2 += sg * (bvel[blk, 2] + bspin[blk, 0] * r1 - bspin[blk, 1] * r0)
            else:
                for j in range(3):
                    g = nodes[s, j]
                    if g >= 0:
                        v0 += sg * w[s, j] * gvel[g, 0]
                        v1 += sg * w[s, j] * gvel[g, 1]
                        v2 += sg * w[s, j] * gvel[g, 2]
        vn = v0 * n0 + v1 * n1 + v2 * n2
        kn, ks = joint_stiffness(cmodel[c], cprop, c, sc_hist, s)
        kn *= beta * sc_area[s]
        ks = 0.0 if (sc_state[s] & ST_SLIP) else beta * ks * sc_area[s]
        d0 = -(kn * vn * n0 + ks * (v0 - vn * n0))
        d1 = -(kn * vn * n1 + ks * (v1 - vn * n1))
        d2 = -(kn * vn * n2 + ks * (v2 - vn * n2))
        add_to_sides(s, cb[c], ca[c], x0, x1, x2, d0, d1, d2, nodes_a, w_a, nodes_b, w_b, bpos, bforce, bmoment,
                     gforce)
