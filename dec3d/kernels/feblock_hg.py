"""Hourglass control of 20-node bricks under 2 x 2 x 2 (reduced) integration.

Why: the FE-block text (shared/seeds/003_*, "Stresses and Nodal Forces") takes 2 x 2 x 2 as the
default and warns that it "may allow spurious mechanisms" in unconstrained systems. A 20-node
brick with 8 Gauss points has 60 - 6 (rigid) - 48 (8 points x 6 strains) = 6 zero-energy modes
that are not rigid motions. In a mesh one element thick in two directions (the text's own
fem_beam.dat: 1 x 1 x 10 m, ten elements in a row) one per element survives assembly: each
cross-section deforms as the 8-node quadrilateral's 2 x 2 hourglass (corners in along y and out
along z, mid-edge nodes the other way). The text's three equal point loads on the top tip edge
have a component on that mode, so no equilibrium exists and an explicit run drifts without
bound (measured: 9324 m after 2e5 steps).

Control (stiffness-based, in the spirit of Flanagan & Belytschko, Int. J. Numer. Meth. Eng. 17
(1981) 679-706, and Belytschko, Ong, Liu & Kennedy, Comp. Meth. Appl. Mech. Eng. 43 (1984)
251-276: resist only the part of the deformation the reduced points do not see): at the six face
centres p (the text's slave points 21-26) the strain rate that differs from the trilinear
interpolation of the eight Gauss-point strain rates,

    dh_p = eps(p) - sum_g w_pg eps(g),   w_pg = prod_i (1 + 3 y_gi p_i) / 2

(eps = sym grad v with each point's own Jacobian, Eq. 3-5; w_pg the trilinear weights of Gauss
point g at p), drives an elastic "hourglass stress" s_p += eps_h (lam tr(dh) I + 2 G dh), stored
in gstress rows 8-13 (unused by the 2 x 2 x 2 rule), which acts on the nodes as the forces of
the stiffness eps_h (V/6) sum_p dB_p^T D dB_p, dB_p = B(p) - sum_g w_pg B(g): positive
semi-definite, zero for rigid motions and for every field whose strain is trilinear in y
(uniform, linear, bilinear: all the eight points integrate exactly) on any element shape, so the
patch test is untouched and the converged answer of a load the mode does not see barely moves (on
the cantilever with a uniform end traction the tip deflection goes from 0.39961 m without control
to 0.39953 m with eps_h = 0.1). The six face points catch all six spurious modes of a single
element (the centre alone catches two). ``HOURGLASS`` = 0.1 is eps_h. The hourglass stress is
not an element stress: it is left out of ``stress`` and of the output.
"""
from numba import njit

from .feblock_jac import gauss_force, jac_inv, strain_increment

#: eps_h: the hourglass stiffness as a fraction of the elastic moduli (0 switches control off)
HOURGLASS = 0.1

#: first gstress row holding the hourglass stresses of a 2 x 2 x 2 element
HG_ROW = 8


@njit(cache=True)
def hg_jacobians(xe, dface, jf):
    """Inverse Jacobians jf (6, 3, 3) (jf[p, k, j] = dy_k/dx_j) at the six face centres from the
    master derivatives dface (6, 20, 3) and the node coordinates xe (20, 3) (``feblock_jac.jac_inv``
    at each). False (jf partly written) when det J is not positive at one of them."""
    for p in range(6):
        if not jac_inv(xe, dface[p], jf[p]) > 0.0:
            return False
    return True


@njit(cache=True)
def hg_step(ve, dface, jf, wpg, vol, lam, g2, hg, dt, eg, sg, tg, fe):
    """Hourglass stresses sg[8 + p] (p = 0..5) of one 2 x 2 x 2 element updated, their forces at
    the face points subtracted from fe (20, 3), and tg (8, 6) = sum_p (V/6) w_pg s_p: the part the
    caller takes off each Gauss point's (w det J sigma) before its forces (the - sum_g w_pg B(g)
    half of dB_p). ve (20, 3) node velocities, dface (6, 20, 3) master derivatives at the face
    centres, jf (6, 3, 3) their inverse Jacobians (``hg_jacobians``), wpg (6, 8) the trilinear
    weights, vol the element volume, lam and g2 = 2 G the Lame moduli, hg = eps_h, eg (8, 6) the
    Gauss-point strain increments xx yy zz xy xz yz of this step (tensor shear)."""
    wv = vol / 6.0
    for g in range(8):
        for c in range(6):
            tg[g, c] = 0.0
    for p in range(6):
        d = dface[p]
        ji = jf[p]
        exx, eyy, ezz, exy, exz, eyz = strain_increment(ve, d, ji, dt)
        for g in range(8):
            w = wpg[p, g]
            exx -= w * eg[g, 0]; eyy -= w * eg[g, 1]; ezz -= w * eg[g, 2]
            exy -= w * eg[g, 3]; exz -= w * eg[g, 4]; eyz -= w * eg[g, 5]
        ev = exx + eyy + ezz
        s = sg[8 + p]
        s[0] += hg * (lam * ev + g2 * exx)
        s[1] += hg * (lam * ev + g2 * eyy)
        s[2] += hg * (lam * ev + g2 * ezz)
        s[3] += hg * g2 * exy
        s[4] += hg * g2 * exz
        s[5] += hg * g2 * eyz
        for g in range(8):
            w = wv * wpg[p, g]
            for c in range(6):
                tg[g, c] += w * s[c]
        gauss_force(s[0] * wv, s[1] * wv, s[2] * wv, s[3] * wv, s[4] * wv, s[5] * wv, ji, d, fe)
