"""The stiffness-proportional term of Rayleigh damping on the sub-contacts of rigid blocks.

Itasca's 3DEC "Dynamic Analysis" pages (Damping): stiffness-proportional damping "applies a force,
which is proportional to the incremental stiffness matrix multiplied by relative velocities [...], to
contacts"; with the Rayleigh damping matrix C = α M + β K the contact part is β K. For a sub-contact
of area A with normal stiffness kn and shear stiffness ks [Pa/m], relative velocity V (Eq. 15 of the
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

from .joints import P_KN, P_KS, ST_SLIP


@njit(cache=True, parallel=True)
def contact_stiffness_damping(beta, bpos, bvel, bspin, ca, cb, cn, cprop, sc_contact, sc_pos, sc_area,
                              sc_fn, sc_state, sg):
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
        kn = beta * cprop[c, P_KN] * sc_area[s]
        ks = 0.0 if (sc_state[s] & ST_SLIP) else beta * cprop[c, P_KS] * sc_area[s]
        sg[s, 0] -= kn * vn * n0 + ks * (v0 - vn * n0)
        sg[s, 1] -= kn * vn * n1 + ks * (v1 - vn * n1)
        sg[s, 2] -= kn * vn * n2 + ks * (v2 - vn * n2)
