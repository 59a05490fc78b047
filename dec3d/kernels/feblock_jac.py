"""The 3 x 3 Jacobian of the 20-node brick's map at one point, its determinant and inverse:
shared by the element kernels (``kernels/feblock``) and the hourglass control
(``kernels/feblock_hg``), which cannot import each other.

Source: the FE-block text (shared/seeds/003_*, "Shape Functions and Derivatives", Eq. 4-5):
J_km = dN_I/dy_m x_Ik, Y = J^-1, N_I,m = dN_I/dy_j Y_jm; the inverse by cofactors.
"""
from numba import njit


@njit(cache=True, inline='always')
def jacobian(x, dxi):
    """det J and the entries i_kj = dy_k/dx_j of J^-1 at one point, from the master derivatives
    dxi (20, 3) and the element's node coordinates x (20, 3) (text: J_km = dN_I/dy_m x_Ik,
    Y = J^-1). Returns (det, i00, i01, i02, i10, i11, i12, i20, i21, i22), the inverse all
    zeros when det J is not positive. Scalars only (every Gauss point of every element)."""
    j00 = 0.0; j01 = 0.0; j02 = 0.0
    j10 = 0.0; j11 = 0.0; j12 = 0.0
    j20 = 0.0; j21 = 0.0; j22 = 0.0
    for a in range(20):
        x0 = x[a, 0]; x1 = x[a, 1]; x2 = x[a, 2]
        d0 = dxi[a, 0]; d1 = dxi[a, 1]; d2 = dxi[a, 2]
        j00 += x0 * d0; j01 += x0 * d1; j02 += x0 * d2
        j10 += x1 * d0; j11 += x1 * d1; j12 += x1 * d2
        j20 += x2 * d0; j21 += x2 * d1; j22 += x2 * d2
    c00 = j11 * j22 - j12 * j21
    c01 = j12 * j20 - j10 * j22
    c02 = j10 * j21 - j11 * j20
    det = j00 * c00 + j01 * c01 + j02 * c02
    if not det > 0.0:
        return det, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    r = 1.0 / det
    return (det, c00 * r, (j02 * j21 - j01 * j22) * r, (j01 * j12 - j02 * j11) * r,
            c01 * r, (j00 * j22 - j02 * j20) * r, (j02 * j10 - j00 * j12) * r,
            c02 * r, (j01 * j20 - j00 * j21) * r, (j00 * j11 - j01 * j10) * r)


@njit(cache=True)
def jac_inv(x, dxi, jinv):
    """Inverse Jacobian jinv (3, 3) (jinv[k, j] = dy_k/dx_j) at one point; returns det J (jinv
    untouched when not positive)."""
    det, i00, i01, i02, i10, i11, i12, i20, i21, i22 = jacobian(x, dxi)
    if not det > 0.0:
        return det
    jinv[0, 0] = i00; jinv[0, 1] = i01; jinv[0, 2] = i02
    jinv[1, 0] = i10; jinv[1, 1] = i11; jinv[1, 2] = i12
    jinv[2, 0] = i20; jinv[2, 1] = i21; jinv[2, 2] = i22
    return det


@njit(cache=True)
def grad_n(x, dxi, dn):
    """Cartesian derivatives dn (20, 3) = dN_a/dx_j at one point from the master derivatives
    dxi (20, 3) and the element's node coordinates x (20, 3) (text, Eq. 5: N_I,m = dN_I/dy_j
    Y_jm). Returns det J; dn is left as it was when det J is not positive."""
    det, i00, i01, i02, i10, i11, i12, i20, i21, i22 = jacobian(x, dxi)
    if not det > 0.0:
        return det
    for a in range(20):
        d0 = dxi[a, 0]; d1 = dxi[a, 1]; d2 = dxi[a, 2]
        dn[a, 0] = d0 * i00 + d1 * i10 + d2 * i20
        dn[a, 1] = d0 * i01 + d1 * i11 + d2 * i21
        dn[a, 2] = d0 * i02 + d1 * i12 + d2 * i22
    return det


@njit(cache=True, inline='always')
def strain_increment(ve, d, ji, dt):
    """(exx, eyy, ezz, exy, exz, eyz): the strain increment (tensor shear) over dt at one point from
    the node velocities ve (20, 3), the master derivatives d (20, 3) there and the inverse Jacobian
    ji (ji[k, j] = dy_k/dx_j): grad v = m J^-1 with the master gradient m[i, k] = sum_a v_ai dN_a/dy_k."""
    m00 = 0.0; m01 = 0.0; m02 = 0.0
    m10 = 0.0; m11 = 0.0; m12 = 0.0
    m20 = 0.0; m21 = 0.0; m22 = 0.0
    for a in range(20):
        v0 = ve[a, 0]; v1 = ve[a, 1]; v2 = ve[a, 2]
        n0 = d[a, 0]; n1 = d[a, 1]; n2 = d[a, 2]
        m00 += v0 * n0; m01 += v0 * n1; m02 += v0 * n2
        m10 += v1 * n0; m11 += v1 * n1; m12 += v1 * n2
        m20 += v2 * n0; m21 += v2 * n1; m22 += v2 * n2
    l00 = m00 * ji[0, 0] + m01 * ji[1, 0] + m02 * ji[2, 0]
    l01 = m00 * ji[0, 1] + m01 * ji[1, 1] + m02 * ji[2, 1]
    l02 = m00 * ji[0, 2] + m01 * ji[1, 2] + m02 * ji[2, 2]
    l10 = m10 * ji[0, 0] + m11 * ji[1, 0] + m12 * ji[2, 0]
    l11 = m10 * ji[0, 1] + m11 * ji[1, 1] + m12 * ji[2, 1]
    l12 = m10 * ji[0, 2] + m11 * ji[1, 2] + m12 * ji[2, 2]
    l20 = m20 * ji[0, 0] + m21 * ji[1, 0] + m22 * ji[2, 0]
    l21 = m20 * ji[0, 1] + m21 * ji[1, 1] + m22 * ji[2, 1]
    l22 = m20 * ji[0, 2] + m21 * ji[1, 2] + m22 * ji[2, 2]
    return (l00 * dt, l11 * dt, l22 * dt, 0.5 * (l01 + l10) * dt, 0.5 * (l02 + l20) * dt,
            0.5 * (l12 + l21) * dt)


@njit(cache=True, inline='always')
def gauss_force(sxx, syy, szz, sxy, sxz, syz, ji, d, fe):
    """fe[a] -= (S J^-T) dN_a/dy for the weighted stress S (w det J sigma) of one point."""
    p00 = sxx * ji[0, 0] + sxy * ji[0, 1] + sxz * ji[0, 2]
    p01 = sxx * ji[1, 0] + sxy * ji[1, 1] + sxz * ji[1, 2]
    p02 = sxx * ji[2, 0] + sxy * ji[2, 1] + sxz * ji[2, 2]
    p10 = sxy * ji[0, 0] + syy * ji[0, 1] + syz * ji[0, 2]
    p11 = sxy * ji[1, 0] + syy * ji[1, 1] + syz * ji[1, 2]
    p12 = sxy * ji[2, 0] + syy * ji[2, 1] + syz * ji[2, 2]
    p20 = sxz * ji[0, 0] + syz * ji[0, 1] + szz * ji[0, 2]
    p21 = sxz * ji[1, 0] + syz * ji[1, 1] + szz * ji[1, 2]
    p22 = sxz * ji[2, 0] + syz * ji[2, 1] + szz * ji[2, 2]
    for a in range(20):
        n0 = d[a, 0]; n1 = d[a, 1]; n2 = d[a, 2]
        fe[a, 0] -= p00 * n0 + p01 * n1 + p02 * n2
        fe[a, 1] -= p10 * n0 + p11 * n1 + p12 * n2
        fe[a, 2] -= p20 * n0 + p21 * n1 + p22 * n2
