"""Mohr-Coulomb zones and nodal mixed discretization (NMD) for 4-node tetrahedra.

Mohr-Coulomb (Itasca's formulation: FLAC3D/3DEC documentation, "Mohr-Coulomb Model",
https://docs.itascacg.com/itasca920/common/models/mohr/doc/modelmohr.html; the 3DEC theory
text 000_*, "Deformable Block Motion": "the basic failure model for blocks in 3DEC is the
Mohr-Coulomb failure criterion with a nonassociated flow rule"). Compression negative; the
principal stresses of the elastic trial are ordered s1 <= s2 <= s3 (s1 the most compressive):

    shear yield       f_s = s1 - s3 N_phi + 2 c sqrt(N_phi)     (yield when f_s < 0)
    tension cut-off   f_t = s3 - sigma_t                        (yield when f_t > 0)
    N_phi = (1 + sin phi) / (1 - sin phi), N_psi likewise from the dilation angle psi,
    sigma_t capped at c / tan phi (the apex of the shear cone), as Itasca does;
    potentials g_s = s1 - s3 N_psi (non-associated), g_t = -s3 (associated);
    alpha1 = K + 4G/3, alpha2 = K - 2G/3 (principal-axis Hooke's law);
    corner function h = s3 - sigma_t + alpha_P (s1 - sigma_P), alpha_P = sqrt(1 + N_phi^2) + N_phi,
    sigma_P = sigma_t N_phi - 2 c sqrt(N_phi): shear return when f_s < 0 and h <= 0,
    tension return when f_t > 0 and h > 0.
    Shear return: lambda_s = f_s / ((alpha1 - alpha2 N_psi) - (alpha2 - alpha1 N_psi) N_phi),
    s1 -= lambda_s (alpha1 - alpha2 N_psi), s2 -= lambda_s alpha2 (1 - N_psi),
    s3 -= lambda_s (alpha2 - alpha1 N_psi). Tension return: s3 = sigma_t, s1 and s2 lowered by
    (s3 - sigma_t) alpha2 / alpha1. The principal directions are kept.

Written here as planes in principal-stress space, F_k(s) = n_k . s - r_k (F > 0: violated),
with plastic flow m_k and return s = s_trial - sum_k lambda_k D m_k, F_k(s) = 0 on the
active planes: the one plane Itasca's h picks gives exactly the formulas above. dec3d's
completion (where Itasca's single-plane return leaves another plane violated: a tension return
past the shear line near the corner, s2 crossing s1 on a shear return near the compression
edge, two or three principal stresses over sigma_t), candidate active sets are tried in a fixed
order and the first consistent one is taken (the system above regular, every multiplier >= 0,
all planes satisfied): Itasca's plane with one other (the corner or edge return), each other
plane alone, any two planes without Itasca's, any three. The planes are the shear line for every
ordered pair of principal stresses and the cut-off on each of the three. (Should none be
consistent, which the tests never meet, the stress goes to the isotropic admissible point.)

Plastic state bits (``zones.state``): 1 shear now, 2 tension now, 4 shear in the past,
8 tension in the past; the "now" bits are those of the last step.

Nodal mixed discretization (3DEC theory text, "Nodal Mixed Discretization for a Tetrahedral
Grid", Eqs. 68-76): the volumetric strain increment of each tetrahedron is replaced by the mean
over its four gridpoints of the volume-weighted average of the tetrahedra around each gridpoint
(Eqs. 69-71); the plastic mean-stress correction K de^p returned by the constitutive model
(``dsp`` here: mean trial stress minus mean returned stress) is averaged the same way and the
stress corrected by (dsp - mean dsp) on its diagonal (Eqs. 74-76). Deviatoric parts and the
constitutive model are untouched.

Kernels may not import dec3d.model: the property columns and model codes below mirror
``dec3d.model.zones`` (a test checks they agree).
"""
import math

import numpy as np
from numba import njit, prange

from .gather import node_lists
from .zones import _face_vector, hooke_increment, tet_add_forces, tet_kinematics

# mirrors of dec3d.model.zones
ZP_BULK = 0
ZP_SHEAR = 1
ZP_COHESION = 3
ZP_TANFRIC = 4
ZP_TENSION = 5
ZP_TANDIL = 6
ZMODEL_ELASTIC = 1
ZMODEL_MOHR = 2
SHEAR_NOW = 1
TENSION_NOW = 2
SHEAR_PAST = 4
TENSION_PAST = 8

#: shear planes: (i, j) = (more compressive, less compressive) principal index; planes 6-8: tension
_SH_I = np.array([0, 0, 1, 1, 2, 2], np.int64)
_SH_J = np.array([2, 1, 2, 0, 0, 1], np.int64)


@njit(cache=True)
def sym_eig3(s, lam, vec):
    """Eigen-decomposition of the symmetric tensor s (6,) (xx yy zz xy xz yz) by cyclic Jacobi
    rotations: lam (3,) ascending, vec (3, 3) with eigenvector k in column k. Deterministic
    (fixed sweep order, no library call)."""
    a00 = s[0]; a11 = s[1]; a22 = s[2]; a01 = s[3]; a02 = s[4]; a12 = s[5]
    for i in range(3):
        for j in range(3):
            vec[i, j] = 1.0 if i == j else 0.0
    scale = abs(a00) + abs(a11) + abs(a22) + abs(a01) + abs(a02) + abs(a12)
    if scale > 0.0:
        for _sweep in range(30):
            off = abs(a01) + abs(a02) + abs(a12)
            if off <= 1e-17 * scale:
                break
            for pq in range(3):
                if pq == 0:
                    p = 0; q = 1; apq = a01; app = a00; aqq = a11
                elif pq == 1:
                    p = 0; q = 2; apq = a02; app = a00; aqq = a22
                else:
                    p = 1; q = 2; apq = a12; app = a11; aqq = a22
                if apq == 0.0:
                    continue
                theta = (aqq - app) / (2.0 * apq)
                if abs(theta) > 1e150:
                    t = 0.5 / theta
                else:
                    t = 1.0 / (abs(theta) + math.sqrt(theta * theta + 1.0))
                    if theta < 0.0:
                        t = -t
                c = 1.0 / math.sqrt(t * t + 1.0)
                sn = t * c
                # A' = J^T A J with J_pp = J_qq = c, J_pq = sn, J_qp = -sn: a'_pq = 0
                app2 = app - t * apq
                aqq2 = aqq + t * apq
                r = 3 - p - q            # the third index
                if r == 0:
                    arp = a01 if p == 1 else a02
                    arq = a02 if q == 2 else a01
                elif r == 1:
                    arp = a01
                    arq = a12
                else:
                    arp = a02
                    arq = a12
                arp2 = c * arp - sn * arq
                arq2 = sn * arp + c * arq
                # write back
                if pq == 0:
                    a00 = app2; a11 = aqq2; a01 = 0.0; a02 = arp2; a12 = arq2
                elif pq == 1:
                    a00 = app2; a22 = aqq2; a02 = 0.0; a01 = arp2; a12 = arq2
                else:
                    a11 = app2; a22 = aqq2; a12 = 0.0; a01 = arp2; a02 = arq2
                for k in range(3):
                    vkp = vec[k, p]; vkq = vec[k, q]
                    vec[k, p] = c * vkp - sn * vkq
                    vec[k, q] = sn * vkp + c * vkq
    lam[0] = a00; lam[1] = a11; lam[2] = a22
    # sort ascending (3 elements), columns follow
    for i in range(2):
        for j in range(2 - i):
            if lam[j] > lam[j + 1]:
                tmp = lam[j]; lam[j] = lam[j + 1]; lam[j + 1] = tmp
                for k in range(3):
                    tmp = vec[k, j]; vec[k, j] = vec[k, j + 1]; vec[k, j + 1] = tmp


@njit(cache=True)
def _solve_small(m, b, na, x):
    """Solve m[:na, :na] x = b[:na] by Gaussian elimination with partial pivoting (m and b are
    overwritten). Returns False when the system is singular (pivot below 1e-12 of the largest)."""
    big = 0.0
    for i in range(na):
        for j in range(na):
            if abs(m[i, j]) > big:
                big = abs(m[i, j])
    if big == 0.0:
        return False
    for col in range(na):
        piv = col
        for i in range(col + 1, na):
            if abs(m[i, col]) > abs(m[piv, col]):
                piv = i
        if abs(m[piv, col]) < 1e-12 * big:
            return False
        if piv != col:
            for j in range(na):
                tmp = m[col, j]; m[col, j] = m[piv, j]; m[piv, j] = tmp
            tmp = b[col]; b[col] = b[piv]; b[piv] = tmp
        for i in range(col + 1, na):
            f = m[i, col] / m[col, col]
            for j in range(col, na):
                m[i, j] -= f * m[col, j]
            b[i] -= f * b[col]
    for i in range(na - 1, -1, -1):
        acc = b[i]
        for j in range(i + 1, na):
            acc -= m[i, j] * x[j]
        x[i] = acc / m[i, i]
    return True


@njit(cache=True)
def _try_planes(act, na, nn, dm, rr, lam, tol, mm, bb, x, sn):
    """Return onto the planes act[:na] from the trial principal stresses lam: solve
    sum_b (n_a . D m_b) x_b = F_a(trial), accept when the system is regular, every multiplier
    x >= 0 and the result sn satisfies all nine planes (F <= tol). Fills x and sn."""
    for a in range(na):
        ka = act[a]
        bb[a] = nn[ka, 0] * lam[0] + nn[ka, 1] * lam[1] + nn[ka, 2] * lam[2] - rr[ka]
        for b in range(na):
            kb = act[b]
            mm[a, b] = nn[ka, 0] * dm[kb, 0] + nn[ka, 1] * dm[kb, 1] + nn[ka, 2] * dm[kb, 2]
    if not _solve_small(mm, bb, na, x):
        return False
    xmax = 0.0
    for a in range(na):
        xmax = max(xmax, abs(x[a]))
    for a in range(na):
        if x[a] < -1e-12 * xmax:
            return False
    for t in range(3):
        acc = lam[t]
        for a in range(na):
            acc -= x[a] * dm[act[a], t]
        sn[t] = acc
    for k in range(9):
        if nn[k, 0] * sn[0] + nn[k, 1] * sn[1] + nn[k, 2] * sn[2] - rr[k] > tol:
            return False
    return True

@njit(cache=True)
def mohr_work():
    """Scratch arrays of ``mohr_core`` (allocate once per batch, not per zone)."""
    return (np.empty(3), np.empty((3, 3)), np.empty((9, 3)), np.empty((9, 3)), np.empty(9),
            np.empty(3, np.int64), np.empty((3, 3)), np.empty(3), np.empty(3), np.empty(3))


@njit(cache=True)
def _principal_values(s):
    """Principal values (ascending) of the symmetric tensor s (6,) in closed form (the
    trigonometric solution of the characteristic cubic); used only to skip clearly elastic zones."""
    m = (s[0] + s[1] + s[2]) / 3.0
    d0 = s[0] - m; d1 = s[1] - m; d2 = s[2] - m
    j2 = 0.5 * (d0 * d0 + d1 * d1 + d2 * d2) + s[3] * s[3] + s[4] * s[4] + s[5] * s[5]
    if j2 <= 0.0:
        return m, m, m
    j3 = d0 * (d1 * d2 - s[5] * s[5]) - s[3] * (s[3] * d2 - s[5] * s[4]) + s[4] * (s[3] * s[5] - d1 * s[4])
    r = math.sqrt(j2 / 3.0)
    cs = j3 / (2.0 * r * r * r)
    if cs > 1.0:
        cs = 1.0
    elif cs < -1.0:
        cs = -1.0
    th = math.acos(cs) / 3.0
    hi = m + 2.0 * r * math.cos(th)
    lo = m + 2.0 * r * math.cos(th + 2.0 * math.pi / 3.0)
    return lo, 3.0 * m - lo - hi, hi


@njit(cache=True)
def mohr_return(s, de, bulk, shear, coh, tanfric, ten, tandil):
    """Mohr-Coulomb update of one zone in place: s (6,) holds the stress at the start of the step
    and receives the new stress (elastic trial s + D:de, then Itasca's return; see the module
    text). de (6,): strain increment (xx yy zz xy xz yz, engineering shear halved: tensor
    components). Returns (bits, dsp): bits = 1 shear now | 2 tension now (0: elastic), dsp = mean
    trial stress - mean returned stress (the plastic correction K de^p of Eq. 73 of the 3DEC text,
    tension positive; 0 when elastic)."""
    return mohr_core(s, de, bulk, shear, coh, tanfric, ten, tandil, mohr_work())


@njit(cache=True)
def mohr_core(s, de, bulk, shear, coh, tanfric, ten, tandil, work):
    """``mohr_return`` with the scratch arrays ``work`` of ``mohr_work``."""
    if mohr_trial(s, de, bulk, shear, coh, tanfric, ten):
        return 0, 0.0
    return mohr_plastic(s, bulk, shear, coh, tanfric, ten, tandil, work)


@njit(cache=True)
def _strength(coh, tanfric, ten):
    """(N_phi, 2 c sqrt(N_phi), sigma_t capped at the apex c / tan phi)."""
    sphi = tanfric / math.sqrt(1.0 + tanfric * tanfric)
    npf = (1.0 + sphi) / (1.0 - sphi)
    ft = ten
    if tanfric > 0.0 and coh / tanfric < ft:
        ft = coh / tanfric
    return npf, 2.0 * coh * math.sqrt(npf), ft


@njit(cache=True)
def mohr_trial(s, de, bulk, shear, coh, tanfric, ten):
    """First half of ``mohr_core``: s += D:de (the elastic trial); True when the trial is clearly
    elastic (then s is the new stress), False when ``mohr_plastic`` must finish the update.
    Kept apart so that hot loops pass the scratch arrays (whose reference counting costs more
    than this test) only for the zones near or at yield."""
    hooke_increment(s, de, bulk, shear)
    npf, csn, ft = _strength(coh, tanfric, ten)
    # clearly elastic: first from the bounds m - 2r <= s1, s3 <= m + 2r (r = sqrt(J2 / 3)), then
    # from the closed-form principal values (margin far above their round-off); no eigenvectors
    m = (s[0] + s[1] + s[2]) / 3.0
    d0 = s[0] - m; d1 = s[1] - m; d2 = s[2] - m
    r2 = 2.0 * math.sqrt((0.5 * (d0 * d0 + d1 * d1 + d2 * d2) + s[3] * s[3] + s[4] * s[4] + s[5] * s[5]) / 3.0)
    bscale = 3.0 * (abs(m) + r2) + coh + abs(ft)
    if (m + r2) * npf - (m - r2) - csn < -1e-7 * bscale and m + r2 - ft < -1e-7 * bscale:
        return True
    q1, q2, q3 = _principal_values(s)
    qscale = abs(q1) + abs(q2) + abs(q3) + coh + abs(ft)
    return q3 * npf - q1 - csn < -1e-7 * qscale and q3 - ft < -1e-7 * qscale


@njit(cache=True)
def mohr_plastic(s, bulk, shear, coh, tanfric, ten, tandil, work):
    """Second half of ``mohr_core``: the return of the trial stress s (in place); (bits, dsp)."""
    npf, csn, ft = _strength(coh, tanfric, ten)
    lam, vec, nn, dm, rr, act, mm, bb, x, sn = work
    sym_eig3(s, lam, vec)
    s1 = lam[0]; s3 = lam[2]
    spsi = tandil / math.sqrt(1.0 + tandil * tandil)
    nps = (1.0 + spsi) / (1.0 - spsi)
    scale = abs(s1) + abs(s3) + abs(lam[1]) + coh + abs(ft)
    tol = 1e-10 * scale
    fs13 = s3 * npf - s1 - csn          # = -f_s (Itasca), > 0 violated
    ft3 = s3 - ft
    if fs13 <= tol and ft3 <= tol:
        return 0, 0.0
    a1 = bulk + 4.0 * shear / 3.0
    a2 = bulk - 2.0 * shear / 3.0
    # Itasca's choice of the plane: h decides between shear and tension
    sp = ft * npf - csn
    ap = math.sqrt(1.0 + npf * npf) + npf
    h = s3 - ft + ap * (s1 - sp)
    first = 0 if (fs13 > tol and (h <= 0.0 or ft3 <= tol)) else 8
    # fast path: Itasca's single-plane return in closed form, kept when it violates no plane
    if first == 0:
        ls = fs13 / (a1 * (1.0 + npf * nps) - a2 * (npf + nps))
        n1 = s1 + ls * (a1 - a2 * nps)
        n2 = lam[1] + ls * a2 * (1.0 - nps)
        n3 = s3 + ls * (a2 - a1 * nps)
        fast = SHEAR_NOW
    else:
        lt = ft3 / a1
        n1 = s1 - lt * a2
        n2 = lam[1] - lt * a2
        n3 = ft
        fast = TENSION_NOW
    lo = min(n1, min(n2, n3))
    hi = max(n1, max(n2, n3))
    if hi * npf - lo - csn <= tol and hi - ft <= tol:
        sn[0] = n1; sn[1] = n2; sn[2] = n3
        return _rotate_back(s, lam, vec, sn, fast)
    # the nine planes: n (normal of F), dm (D times the flow direction), r
    nn[:, :] = 0.0
    for k in range(6):
        i = _SH_I[k]; j = _SH_J[k]
        nn[k, i] = -1.0; nn[k, j] = npf
        rr[k] = csn
        # flow m: m_i = -1, m_j = N_psi;  D m = a2 * sum(m) + (a1 - a2) * m
        sm = nps - 1.0
        for t in range(3):
            dm[k, t] = a2 * sm
        dm[k, i] += (a1 - a2) * -1.0
        dm[k, j] += (a1 - a2) * nps
    for i in range(3):
        nn[6 + i, i] = 1.0
        rr[6 + i] = ft
        for t in range(3):
            dm[6 + i, t] = a2
        dm[6 + i, i] = a1
    sn[0] = lam[0]; sn[1] = lam[1]; sn[2] = lam[2]
    # Itasca's plane alone failed (the fast path above): with one other (corner / edge), then
    # without it
    ok = False
    na = 1
    if not ok:
        na = 2
        for k in range(9):
            if k != first:
                act[0] = first; act[1] = k
                ok = _try_planes(act, 2, nn, dm, rr, lam, tol, mm, bb, x, sn)
                if ok:
                    break
    if not ok:
        na = 1
        for k in range(9):
            if k != first:
                act[0] = k
                ok = _try_planes(act, 1, nn, dm, rr, lam, tol, mm, bb, x, sn)
                if ok:
                    break
    if not ok:
        na = 2
        for k in range(9):
            for k2 in range(k + 1, 9):
                if k != first and k2 != first and not ok:
                    act[0] = k; act[1] = k2
                    ok = _try_planes(act, 2, nn, dm, rr, lam, tol, mm, bb, x, sn)
            if ok:
                break
    if not ok:
        na = 3
        for k in range(9):
            for k2 in range(k + 1, 9):
                for k3 in range(k2 + 1, 9):
                    if not ok:
                        act[0] = k; act[1] = k2; act[2] = k3
                        ok = _try_planes(act, 3, nn, dm, rr, lam, tol, mm, bb, x, sn)
    bits = 0
    if ok:
        for a in range(na):
            if x[a] > 0.0:
                bits |= SHEAR_NOW if act[a] < 6 else TENSION_NOW
    else:
        # no consistent return found (not met in the tests): the isotropic admissible point
        piso = min((lam[0] + lam[1] + lam[2]) / 3.0, ft)
        sn[0] = piso; sn[1] = piso; sn[2] = piso
        bits = SHEAR_NOW
        if piso == ft:
            bits |= TENSION_NOW
    return _rotate_back(s, lam, vec, sn, bits)


@njit(cache=True)
def _rotate_back(s, lam, vec, sn, bits):
    """s (6,) += sum_k (sn_k - lam_k) v_k v_k^T (principal directions kept); returns (bits, dsp)."""
    d0 = sn[0] - lam[0]; d1 = sn[1] - lam[1]; d2 = sn[2] - lam[2]
    s[0] += d0 * vec[0, 0] * vec[0, 0] + d1 * vec[0, 1] * vec[0, 1] + d2 * vec[0, 2] * vec[0, 2]
    s[1] += d0 * vec[1, 0] * vec[1, 0] + d1 * vec[1, 1] * vec[1, 1] + d2 * vec[1, 2] * vec[1, 2]
    s[2] += d0 * vec[2, 0] * vec[2, 0] + d1 * vec[2, 1] * vec[2, 1] + d2 * vec[2, 2] * vec[2, 2]
    s[3] += d0 * vec[0, 0] * vec[1, 0] + d1 * vec[0, 1] * vec[1, 1] + d2 * vec[0, 2] * vec[1, 2]
    s[4] += d0 * vec[0, 0] * vec[2, 0] + d1 * vec[0, 1] * vec[2, 1] + d2 * vec[0, 2] * vec[2, 2]
    s[5] += d0 * vec[1, 0] * vec[2, 0] + d1 * vec[1, 1] * vec[2, 1] + d2 * vec[1, 2] * vec[2, 2]
    return bits, -(d0 + d1 + d2) / 3.0


@njit(cache=True)
def mohr_update(stress6, de6, bulk, shear, coh, tanfric, ten, tandil):
    """One zone, not in place: returns (new stress (6,), bits, dsp) as ``mohr_return``."""
    s = stress6.copy()
    bits, dsp = mohr_return(s, de6, bulk, shear, coh, tanfric, ten, tandil)
    return s, bits, dsp


@njit(cache=True)
def merge_state(old, now):
    """New ``zones.state``: the now bits of this step, the past bits of before and of now."""
    return (old & (SHEAR_PAST | TENSION_PAST)) | now | (now << 2)


@njit(cache=True)
def tet_mohr_step(pos, vel, gp, rows, prop, dt, stress, state, force):
    """One step of the Mohr-Coulomb 4-node zones ``rows`` without NMD: strain increment
    (``kernels.zones.tet_kinematics``), ``mohr_return`` with the zone's ``prop`` columns,
    ``state`` updated (``merge_state``), nodal forces added to ``force``."""
    av = np.empty((4, 3))
    de = np.empty(6)
    w = np.empty(3)
    work = mohr_work()
    for k in range(rows.shape[0]):
        z = rows[k]
        tet_kinematics(pos, vel, gp, z, dt, av, de, w)
        bits = 0
        if not mohr_trial(stress[z], de, prop[z, ZP_BULK], prop[z, ZP_SHEAR], prop[z, ZP_COHESION],
                          prop[z, ZP_TANFRIC], prop[z, ZP_TENSION]):
            bits, _dsp = mohr_plastic(stress[z], prop[z, ZP_BULK], prop[z, ZP_SHEAR], prop[z, ZP_COHESION],
                                      prop[z, ZP_TANFRIC], prop[z, ZP_TENSION], prop[z, ZP_TANDIL], work)
        state[z] = merge_state(state[z], bits)
        tet_add_forces(gp, z, av, stress[z], 1.0, force)


# --- the NMD step, in passes ---------------------------------------------------------------

@njit(cache=True)
def tet_strain_pass(pos, vel, gp, rows, dt, de, vol, av, spin):
    """For entry k of ``rows``: de[k] (6,) strain increment, vol[k] volume, av[k] (4, 3) face
    area vectors, spin[k] (3,) spin increment (``tet_kinematics``)."""
    for k in range(rows.shape[0]):
        vol[k] = tet_kinematics(pos, vel, gp, rows[k], dt, av[k], de[k], spin[k])


@njit(cache=True)
def _node_average(gp, rows, sel, node, vol, val, nodesum, nodevol, out):
    """out[k] = mean over the 4 gridpoints of zone rows[k] of the volume-weighted average of
    ``val`` over the selected zones (sel[k]) of ``rows`` around each gridpoint (Eqs. 69-70 /
    74-75); entries not selected are not written. Gridpoint row r averages at ``node[r]`` (its
    master when linked). Fixed summation order."""
    nodesum[:] = 0.0
    nodevol[:] = 0.0
    for k in range(rows.shape[0]):
        if sel[k]:
            z = rows[k]
            for n in range(4):
                m = node[gp[z, n]]
                nodesum[m] += val[k] * vol[k]
                nodevol[m] += vol[k]
    for k in range(rows.shape[0]):
        if sel[k]:
            z = rows[k]
            acc = 0.0
            for n in range(4):
                m = node[gp[z, n]]
                acc += nodesum[m] / nodevol[m]
            out[k] = 0.25 * acc


@njit(cache=True)
def nmd_strain_average(gp, rows, node, vol, de):
    """NMD on strain (Eqs. 68-71), in place on de (nrows, 6): each zone's volumetric increment
    de_xx + de_yy + de_zz is replaced by the mean of its gridpoints' volume-weighted averages;
    deviatoric parts kept. gp: zones.gp; rows (nrows,): the zone rows taking part (their entries
    k index de and vol); node (nvert,): averaging node of each gridpoint row (the row itself, or
    its master for a linked gridpoint); vol (nrows,): zone volumes."""
    nr = rows.shape[0]
    ev = np.empty(nr)
    for k in range(nr):
        ev[k] = de[k, 0] + de[k, 1] + de[k, 2]
    nsz = node.shape[0]
    bar = np.empty(nr)
    _node_average(gp, rows, np.ones(nr, np.bool_), node, vol, ev, np.empty(nsz), np.empty(nsz), bar)
    for k in range(nr):
        shift = (bar[k] - ev[k]) / 3.0
        de[k, 0] += shift; de[k, 1] += shift; de[k, 2] += shift


@njit(cache=True)
def nmd_stress_correction(gp, rows, node, vol, dsp, stress):
    """NMD on stress (Eqs. 74-76): for entry k of rows (zone z = rows[k]) the diagonal of
    stress[z] += dsp[k] - mean over its gridpoints of the volume-weighted nodal averages of dsp,
    i.e. the zone's own plastic mean-stress correction is replaced by the averaged one. dsp
    (nrows,): ``mohr_return``'s second value (0 for elastic zones); other arguments as
    ``nmd_strain_average``."""
    nr = rows.shape[0]
    nsz = node.shape[0]
    bar = np.empty(nr)
    _node_average(gp, rows, np.ones(nr, np.bool_), node, vol, dsp, np.empty(nsz), np.empty(nsz), bar)
    for k in range(nr):
        z = rows[k]
        c = dsp[k] - bar[k]
        stress[z, 0] += c; stress[z, 1] += c; stress[z, 2] += c


@njit(cache=True)
def zone_constitutive(rows, cmodel, prop, de, stress, state, dsp):
    """Constitutive pass: entry k (zone z = rows[k]) gets de[k] applied by its model: elastic
    (Hooke) or Mohr-Coulomb (``mohr_return``, state merged, dsp[k] its plastic mean-stress
    correction); other codes (null) are left alone. dsp[k] = 0 unless Mohr-Coulomb yielded."""
    work = mohr_work()
    for k in range(rows.shape[0]):
        z = rows[k]
        dsp[k] = 0.0
        code = cmodel[z]
        if code == ZMODEL_ELASTIC:
            hooke_increment(stress[z], de[k], prop[z, ZP_BULK], prop[z, ZP_SHEAR])
        elif code == ZMODEL_MOHR:
            if mohr_trial(stress[z], de[k], prop[z, ZP_BULK], prop[z, ZP_SHEAR], prop[z, ZP_COHESION],
                          prop[z, ZP_TANFRIC], prop[z, ZP_TENSION]):
                state[z] = state[z] & (SHEAR_PAST | TENSION_PAST)
            else:
                bits, d = mohr_plastic(stress[z], prop[z, ZP_BULK], prop[z, ZP_SHEAR], prop[z, ZP_COHESION],
                                       prop[z, ZP_TANFRIC], prop[z, ZP_TENSION], prop[z, ZP_TANDIL], work)
                state[z] = merge_state(state[z], bits)
                dsp[k] = d


@njit(cache=True)
def tet_force_pass(gp, rows, av, weight, stress, force):
    """Nodal forces of the zones ``rows`` from their present stress, times weight[k], with the
    face area vectors av (nrows, 4, 3) of ``tet_strain_pass``."""
    for k in range(rows.shape[0]):
        tet_add_forces(gp, rows[k], av[k], stress[rows[k]], weight[k], force)


@njit(cache=True)
def tet_zone_step(pos, vel, gp, rows, node, cmodel, prop, dt, nmd, stress, state, force):
    """A whole small-strain step of the 4-node zones ``rows`` (elastic and Mohr-Coulomb mixed):
    strain pass, NMD on strain (if ``nmd``), constitutive pass, NMD on stress (if ``nmd``),
    nodal forces (weight 1). Returns nothing."""
    nr = rows.shape[0]
    de = np.empty((nr, 6))
    vol = np.empty(nr)
    av = np.empty((nr, 4, 3))
    dsp = np.empty(nr)
    tet_strain_pass(pos, vel, gp, rows, dt, de, vol, av, np.empty((nr, 3)))
    if nmd:
        nmd_strain_average(gp, rows, node, vol, de)
    zone_constitutive(rows, cmodel, prop, de, stress, state, dsp)
    if nmd:
        nmd_stress_correction(gp, rows, node, vol, dsp, stress)
    tet_force_pass(gp, rows, av, np.ones(nr), stress, force)


@njit(cache=True)
def md_stress_average(rows, zset, nset, vol, dsp, stress):
    """Mixed discretization on stress for hexahedral zone sets (3DEC text Eqs. 64-67; the
    ERRATA: s of Eq. 64 is the deviatoric *stress*), in increment form: the plastic mean-stress
    correction dsp[k] of each tetrahedron of a set (both overlays of one hexahedral zone) is
    replaced by its volume average over the set, i.e. stress[z] diagonal += dsp[k] - average.
    Since the strain averaging already gives every tetrahedron of a set the same volumetric
    increment, this is Eq. 67 for a set whose tetrahedra started with one mean stress, and it
    leaves elastic zones (dsp = 0) exactly as the elastic step has them (dec3d's choice: an
    initial stress that varies inside a hexahedron is not smoothed). Entry k of rows belongs to
    set zset[k] (0..nset-1, -1: none, left alone); vol[k] its volume."""
    sv = np.zeros(nset)
    ss = np.zeros(nset)
    for k in range(rows.shape[0]):
        h = zset[k]
        if h >= 0:
            sv[h] += dsp[k] * vol[k]
            ss[h] += vol[k]
    for k in range(rows.shape[0]):
        h = zset[k]
        if h >= 0 and ss[h] > 0.0:
            z = rows[k]
            c = dsp[k] - sv[h] / ss[h]
            stress[z, 0] += c; stress[z, 1] += c; stress[z, 2] += c


@njit(cache=True)
def jaumann_rotate(s, w01, w02, w12):
    """s (6,) += W s - s W for the spin increment W (W01 = w01, W02 = w02, W12 = w12,
    antisymmetric): the stress turned with the material in large strain."""
    s00 = s[0]; s11 = s[1]; s22 = s[2]; s01 = s[3]; s02 = s[4]; s12 = s[5]
    s[0] = s00 + 2.0 * (w01 * s01 + w02 * s02)
    s[1] = s11 + 2.0 * (-w01 * s01 + w12 * s12)
    s[2] = s22 + 2.0 * (-w02 * s02 - w12 * s12)
    s[3] = s01 + w01 * (s11 - s00) + w02 * s12 + w12 * s02
    s[4] = s02 + w02 * (s22 - s00) + w01 * s12 - w12 * s01
    s[5] = s12 + w12 * (s22 - s11) - w01 * s02 - w02 * s01


@njit(cache=True)
def _set_strain_mean(de, vol, zset, nset):
    """Volumetric strain increments ev (nr,) of the entries, free (nr,) True for an entry
    outside every hexahedral set, and bar (nr,): the volume-weighted mean ev of the entry's set
    (Eqs. 60-63), ev itself for a free entry. Shared by the serial and threaded steps."""
    nr = de.shape[0]
    sv = np.zeros(nset)
    ss = np.zeros(nset)
    free = np.empty(nr, np.bool_)
    ev = np.empty(nr)
    for k in range(nr):
        ev[k] = de[k, 0] + de[k, 1] + de[k, 2]
        h = zset[k]
        free[k] = h < 0
        if h >= 0:
            sv[h] += ev[k] * vol[k]
            ss[h] += vol[k]
    bar = ev.copy()
    for k in range(nr):
        h = zset[k]
        if h >= 0 and ss[h] > 0.0:
            bar[k] = sv[h] / ss[h]
    return ev, free, bar


@njit(cache=True)
def zone_forces_plastic(pos, vel, gp, rows, zset, weight, nset, node, cmodel, prop, dt, large, nmd,
                        stress, state, force, fmag):
    """One step of the 4-node zones ``rows`` with elastic and Mohr-Coulomb zones mixed, laid out
    as the deformable step's elastic ``zone_forces`` (zset: mixed-discretization set of each
    entry, -1 none; weight: 1, or 1/2 for an overlay zone; large: turn the stress with the spin
    first) plus: node (nvert,) averaging gridpoint of each row (its link master or itself),
    cmodel/prop the zones' model codes and properties, nmd: nodal mixed discretization for the
    entries outside hexahedral sets, state the plastic bits. Sequence: strain pass; strain
    averaging (hexahedral sets: Eqs. 60-63; other zones: NMD Eqs. 68-71 when ``nmd``); stress
    rotation (large); constitutive pass; stress averaging (sets: Eqs. 64-67; others: NMD Eqs.
    74-76 when ``nmd``); nodal forces times weight into ``force``, their magnitudes into
    ``fmag``."""
    nr = rows.shape[0]
    de = np.empty((nr, 6))
    vol = np.empty(nr)
    av = np.empty((nr, 4, 3))
    spin = np.empty((nr, 3))
    dsp = np.empty(nr)
    tet_strain_pass(pos, vel, gp, rows, dt, de, vol, av, spin)
    # strain: hexahedral sets
    ev, free, bar = _set_strain_mean(de, vol, zset, nset)
    nsz = node.shape[0]
    nodesum = np.empty(nsz)
    nodevol = np.empty(nsz)
    if nmd:
        _node_average(gp, rows, free, node, vol, ev, nodesum, nodevol, bar)
    for k in range(nr):
        shift = (bar[k] - ev[k]) / 3.0
        de[k, 0] += shift; de[k, 1] += shift; de[k, 2] += shift
    if large:
        for k in range(nr):
            jaumann_rotate(stress[rows[k]], spin[k, 0], spin[k, 1], spin[k, 2])
    zone_constitutive(rows, cmodel, prop, de, stress, state, dsp)
    # stress: hexahedral sets average their mean stress; NMD corrects the others
    md_stress_average(rows, zset, nset, vol, dsp, stress)
    if nmd:
        pb = dsp.copy()
        _node_average(gp, rows, free, node, vol, dsp, nodesum, nodevol, pb)
        for k in range(nr):
            if free[k]:
                z = rows[k]
                c = dsp[k] - pb[k]
                stress[z, 0] += c; stress[z, 1] += c; stress[z, 2] += c
    for k in range(nr):
        z = rows[k]
        s = stress[z]
        w = weight[k] / 3.0
        for n in range(4):
            r = gp[z, n]
            fx = (s[0] * av[k, n, 0] + s[3] * av[k, n, 1] + s[4] * av[k, n, 2]) * w
            fy = (s[3] * av[k, n, 0] + s[1] * av[k, n, 1] + s[5] * av[k, n, 2]) * w
            fz = (s[4] * av[k, n, 0] + s[5] * av[k, n, 1] + s[2] * av[k, n, 2]) * w
            force[r, 0] += fx; force[r, 1] += fy; force[r, 2] += fz
            fmag[r] += math.sqrt(fx * fx + fy * fy + fz * fz)


# --- the same step on threads --------------------------------------------------------------

@njit(cache=True)
def node_lists4(ntarget, target, gp, rows):
    """Per target t, the (zone entry, node) pairs that add to it, in a fixed order (CSR): the
    entries of t are nent[nstart[t]:nstart[t + 1]], each 4 k + a (node a of zone rows[k]),
    ascending: the order of the serial scatter. ``target`` maps a gridpoint row to its target:
    the row itself (nodal forces) or the averaging node (NMD) (``kernels/gather.node_lists``).
    Made once per mesh."""
    return node_lists(ntarget, target, gp, rows, 4)


@njit(cache=True, parallel=True)
def _node_average_par(gp, rows, sel, node, vol, val, nstart, nent, nodesum, nodevol, out):
    """``_node_average`` with the sums gathered per node in the fixed order of ``node_lists4``
    (same bits as the serial scatter, any thread count)."""
    for t in prange(nstart.shape[0] - 1):
        a = 0.0
        b = 0.0
        for e in range(nstart[t], nstart[t + 1]):
            k = nent[e] // 4
            if sel[k]:
                a += val[k] * vol[k]
                b += vol[k]
        nodesum[t] = a
        nodevol[t] = b
    for k in prange(rows.shape[0]):
        if sel[k]:
            z = rows[k]
            acc = 0.0
            for n in range(4):
                m = node[gp[z, n]]
                acc += nodesum[m] / nodevol[m]
            out[k] = 0.25 * acc


@njit(cache=True)
def zone_forces_plastic_parallel(pos, vel, gp, rows, zset, weight, nset, node, cmodel, prop, dt, large, nmd,
                                 stress, state, force, fmag, fstart, fent, nstart, nent):
    """``zone_forces_plastic`` on threads, bit for bit the same result for any thread count:
    zone passes in parallel, gridpoint sums gathered in the serial order. fstart/fent:
    ``node_lists4(nvert, arange(nvert), gp, rows)``; nstart/nent: ``node_lists4(nvert, node, gp,
    rows)`` (only read when ``nmd``)."""
    nr = rows.shape[0]
    nsz = node.shape[0]
    zone_forces_plastic_parallel_ws(pos, vel, gp, rows, zset, weight, nset, node, cmodel, prop, dt, large, nmd,
                                    stress, state, force, fmag, fstart, fent, nstart, nent,
                                    np.empty((nr, 6)), np.empty(nr), np.empty(nr), np.empty(nr),
                                    np.empty((nr, 3)), np.empty(nsz), np.empty(nsz), np.empty((nr, 4, 3)),
                                    np.empty((nr, 4)))


# --- the step with its scratch kept by the caller, in fused sweeps ---------------------------
#
# ``zone_forces_plastic`` / ``zone_forces_plastic_parallel`` above make several sweeps over
# per-zone temporaries allocated each step. The ``*_ws`` kernels below give the same numbers
# (the same operations in the same order, so the same bits) in fewer sweeps over scratch the
# stepper allocates once (``zone_scratch``):
#   sweep A: strain increment, volume, spin; the hexahedral-set sums and (serial) the NMD
#            gridpoint sums of ev vol and vol added as each zone is done (same order as before);
#   sweep B: averaged volumetric increment, stress rotation, constitutive model, and, when no
#            zone of ``rows`` is Mohr-Coulomb (no plastic correction can arise, so the stress
#            averaging passes change nothing), the nodal forces, the face area vectors
#            recomputed from the positions (the same formulas, so the same bits) rather than
#            streamed from memory;
#   sweep C (only with Mohr-Coulomb zones): stress averaging and nodal forces.
# The threaded kernel runs sweeps A-C over zones in parallel and makes every gridpoint sum by
# the fixed-order gather of ``node_lists4``: bit for bit the serial result, any thread count.
# Measured (bench/README.md): the threaded kernel beats the allocating serial one at 1e6 zones
# even on one thread, but not at 1e4; the serial fused kernel is slower than both (cause not
# found), so the stepper uses ``zone_forces_plastic`` below PARALLEL_MIN_ZONES zones and the
# threaded ``*_ws`` kernel above; the serial ``*_ws`` kernel is kept as the tested serial form.

def zone_scratch(nr, nvert, parallel):
    """Scratch of the ``*_ws`` kernels for ``nr`` zone entries and ``nvert`` gridpoint rows:
    (de (nr, 6), vol, ev, dsp (nr,), spin (nr, 3), nodesum, nodevol (nvert,), zf (nr, 4, 3),
    zm (nr, 4)); zf/zm are only used by the threaded kernel (empty otherwise)."""
    nf = nr if parallel else 0
    return (np.empty((nr, 6)), np.empty(nr), np.empty(nr), np.empty(nr), np.empty((nr, 3)),
            np.empty(nvert), np.empty(nvert), np.empty((nf, 4, 3)), np.empty((nf, 4)))


@njit(cache=True)
def _any_mohr(rows, cmodel):
    for k in range(rows.shape[0]):
        if cmodel[rows[k]] == ZMODEL_MOHR:
            return True
    return False


@njit(cache=True, inline="always")
def _face_vectors(pos, gp, z, av):
    """av (4, 3): the outward area vectors of the faces opposite nodes 0-3 of zone z, by the
    formulas of ``tet_kinematics`` (same bits)."""
    for n in range(4):
        i1 = gp[z, (n + 1) % 4]; i2 = gp[z, (n + 2) % 4]; i3 = gp[z, (n + 3) % 4]
        ax, ay, az = _face_vector(pos[i1], pos[i2], pos[i3], pos[gp[z, n]])
        av[n, 0] = ax; av[n, 1] = ay; av[n, 2] = az


@njit(cache=True, inline="always")
def _zone_update(k, z, gp, zset, node, cmodel, prop, large, nmd, de, ev, spin, sv, ss,
                 nodesum, nodevol, stress, state, d6, work):
    """Sweep B for entry k (zone z) up to the constitutive model: volumetric increment averaged
    (set mean, NMD gridpoint mean, or its own), stress rotated (large), model applied. Returns
    the plastic mean-stress correction (0 unless Mohr-Coulomb yielded)."""
    e = ev[k]
    bar = e
    h = zset[k]
    if h >= 0:
        if ss[h] > 0.0:
            bar = sv[h] / ss[h]
    elif nmd:
        acc = 0.0
        for n in range(4):
            m = node[gp[z, n]]
            acc += nodesum[m] / nodevol[m]
        bar = 0.25 * acc
    shift = (bar - e) / 3.0
    d6[0] = de[k, 0] + shift; d6[1] = de[k, 1] + shift; d6[2] = de[k, 2] + shift
    d6[3] = de[k, 3]; d6[4] = de[k, 4]; d6[5] = de[k, 5]
    if large:
        jaumann_rotate(stress[z], spin[k, 0], spin[k, 1], spin[k, 2])
    code = cmodel[z]
    d = 0.0
    if code == ZMODEL_ELASTIC:
        hooke_increment(stress[z], d6, prop[z, ZP_BULK], prop[z, ZP_SHEAR])
    elif code == ZMODEL_MOHR:
        if mohr_trial(stress[z], d6, prop[z, ZP_BULK], prop[z, ZP_SHEAR], prop[z, ZP_COHESION],
                      prop[z, ZP_TANFRIC], prop[z, ZP_TENSION]):
            state[z] = state[z] & (SHEAR_PAST | TENSION_PAST)
        else:
            bits, d = mohr_plastic(stress[z], prop[z, ZP_BULK], prop[z, ZP_SHEAR], prop[z, ZP_COHESION],
                                   prop[z, ZP_TANFRIC], prop[z, ZP_TENSION], prop[z, ZP_TANDIL], work)
            state[z] = merge_state(state[z], bits)
    return d


@njit(cache=True)
def _set_sums(ev, vol, zset, nset):
    sv = np.zeros(nset)
    ss = np.zeros(nset)
    for k in range(zset.shape[0]):
        h = zset[k]
        if h >= 0:
            sv[h] += ev[k] * vol[k]
            ss[h] += vol[k]
    return sv, ss


@njit(cache=True)
def zone_forces_plastic_ws(pos, vel, gp, rows, zset, weight, nset, node, cmodel, prop, dt, large, nmd,
                           stress, state, force, fmag, de, vol, ev, dsp, spin, nodesum, nodevol):
    """``zone_forces_plastic`` (same arguments, same bits) in two or three sweeps over the
    caller's scratch (``zone_scratch(len(rows), nvert, False)``)."""
    nr = rows.shape[0]
    av = np.empty((4, 3))
    w3 = np.empty(3)
    d6 = np.empty(6)
    work = mohr_work()
    if nmd:
        for m in range(node.shape[0]):
            nodesum[m] = 0.0
            nodevol[m] = 0.0
    # sweep A
    for k in range(nr):
        z = rows[k]
        v = tet_kinematics(pos, vel, gp, z, dt, av, de[k], w3)
        vol[k] = v
        if large:
            spin[k, 0] = w3[0]; spin[k, 1] = w3[1]; spin[k, 2] = w3[2]
        ev[k] = de[k, 0] + de[k, 1] + de[k, 2]
    if nmd:
        for k in range(nr):
            if zset[k] < 0:
                z = rows[k]
                e = ev[k] * vol[k]
                v = vol[k]
                for n in range(4):
                    m = node[gp[z, n]]
                    nodesum[m] += e
                    nodevol[m] += v
    sv, ss = _set_sums(ev, vol, zset, nset)
    fused = not _any_mohr(rows, cmodel)
    # sweep B
    for k in range(nr):
        z = rows[k]
        dsp[k] = _zone_update(k, z, gp, zset, node, cmodel, prop, large, nmd, de, ev, spin, sv, ss,
                              nodesum, nodevol, stress, state, d6, work)
        if fused:
            _face_vectors(pos, gp, z, av)
            s = stress[z]
            w = weight[k] / 3.0
            for n in range(4):
                r = gp[z, n]
                fx = (s[0] * av[n, 0] + s[3] * av[n, 1] + s[4] * av[n, 2]) * w
                fy = (s[3] * av[n, 0] + s[1] * av[n, 1] + s[5] * av[n, 2]) * w
                fz = (s[4] * av[n, 0] + s[5] * av[n, 1] + s[2] * av[n, 2]) * w
                force[r, 0] += fx; force[r, 1] += fy; force[r, 2] += fz
                fmag[r] += math.sqrt(fx * fx + fy * fy + fz * fz)
    if fused:
        return
    # sweep C: stress averaging, then the forces
    md_stress_average(rows, zset, nset, vol, dsp, stress)
    if nmd:
        for m in range(node.shape[0]):
            nodesum[m] = 0.0
            nodevol[m] = 0.0
        for k in range(nr):
            if zset[k] < 0:
                z = rows[k]
                for n in range(4):
                    m = node[gp[z, n]]
                    nodesum[m] += dsp[k] * vol[k]
                    nodevol[m] += vol[k]
    for k in range(nr):
        z = rows[k]
        if nmd and zset[k] < 0:
            acc = 0.0
            for n in range(4):
                m = node[gp[z, n]]
                acc += nodesum[m] / nodevol[m]
            c = dsp[k] - 0.25 * acc
            stress[z, 0] += c; stress[z, 1] += c; stress[z, 2] += c
        _face_vectors(pos, gp, z, av)
        s = stress[z]
        w = weight[k] / 3.0
        for n in range(4):
            r = gp[z, n]
            fx = (s[0] * av[n, 0] + s[3] * av[n, 1] + s[4] * av[n, 2]) * w
            fy = (s[3] * av[n, 0] + s[1] * av[n, 1] + s[5] * av[n, 2]) * w
            fz = (s[4] * av[n, 0] + s[5] * av[n, 1] + s[2] * av[n, 2]) * w
            force[r, 0] += fx; force[r, 1] += fy; force[r, 2] += fz
            fmag[r] += math.sqrt(fx * fx + fy * fy + fz * fz)


@njit(cache=True, parallel=True)
def _gather_node_sums(zset, val, vol, nstart, nent, nodesum, nodevol):
    """nodesum[t], nodevol[t] = sums of val[k] vol[k] and vol[k] over the entries of target t
    outside hexahedral sets, in the fixed order of ``node_lists4`` (the serial order)."""
    for t in prange(nstart.shape[0] - 1):
        a = 0.0
        b = 0.0
        for e in range(nstart[t], nstart[t + 1]):
            k = nent[e] // 4
            if zset[k] < 0:
                a += val[k] * vol[k]
                b += vol[k]
        nodesum[t] = a
        nodevol[t] = b


@njit(cache=True, parallel=True)
def zone_forces_plastic_parallel_ws(pos, vel, gp, rows, zset, weight, nset, node, cmodel, prop, dt, large, nmd,
                                    stress, state, force, fmag, fstart, fent, nstart, nent,
                                    de, vol, ev, dsp, spin, nodesum, nodevol, zf, zm):
    """``zone_forces_plastic_ws`` on threads (``zone_scratch(len(rows), nvert, True)``; gather
    lists as ``zone_forces_plastic_parallel``): bit for bit the serial result."""
    nr = rows.shape[0]
    nch = 256 if nr >= 256 else 1
    # sweep A
    for ch in prange(nch):
        av = np.empty((4, 3))
        w3 = np.empty(3)
        for k in range(ch * nr // nch, (ch + 1) * nr // nch):
            vol[k] = tet_kinematics(pos, vel, gp, rows[k], dt, av, de[k], w3)
            if large:
                spin[k, 0] = w3[0]; spin[k, 1] = w3[1]; spin[k, 2] = w3[2]
            ev[k] = de[k, 0] + de[k, 1] + de[k, 2]
    sv, ss = _set_sums(ev, vol, zset, nset)
    if nmd:
        _gather_node_sums(zset, ev, vol, nstart, nent, nodesum, nodevol)
    fused = not _any_mohr(rows, cmodel)
    # sweep B
    for ch in prange(nch):
        av = np.empty((4, 3))
        d6 = np.empty(6)
        work = mohr_work()
        for k in range(ch * nr // nch, (ch + 1) * nr // nch):
            z = rows[k]
            dsp[k] = _zone_update(k, z, gp, zset, node, cmodel, prop, large, nmd, de, ev, spin, sv, ss,
                                  nodesum, nodevol, stress, state, d6, work)
            if fused:
                _face_vectors(pos, gp, z, av)
                s = stress[z]
                w = weight[k] / 3.0
                for n in range(4):
                    fx = (s[0] * av[n, 0] + s[3] * av[n, 1] + s[4] * av[n, 2]) * w
                    fy = (s[3] * av[n, 0] + s[1] * av[n, 1] + s[5] * av[n, 2]) * w
                    fz = (s[4] * av[n, 0] + s[5] * av[n, 1] + s[2] * av[n, 2]) * w
                    zf[k, n, 0] = fx; zf[k, n, 1] = fy; zf[k, n, 2] = fz
                    zm[k, n] = math.sqrt(fx * fx + fy * fy + fz * fz)
    if not fused:
        # sweep C
        md_stress_average(rows, zset, nset, vol, dsp, stress)
        if nmd:
            _gather_node_sums(zset, dsp, vol, nstart, nent, nodesum, nodevol)
        for ch in prange(nch):
            av = np.empty((4, 3))
            for k in range(ch * nr // nch, (ch + 1) * nr // nch):
                z = rows[k]
                if nmd and zset[k] < 0:
                    acc = 0.0
                    for n in range(4):
                        m = node[gp[z, n]]
                        acc += nodesum[m] / nodevol[m]
                    c = dsp[k] - 0.25 * acc
                    stress[z, 0] += c; stress[z, 1] += c; stress[z, 2] += c
                _face_vectors(pos, gp, z, av)
                s = stress[z]
                w = weight[k] / 3.0
                for n in range(4):
                    fx = (s[0] * av[n, 0] + s[3] * av[n, 1] + s[4] * av[n, 2]) * w
                    fy = (s[3] * av[n, 0] + s[1] * av[n, 1] + s[5] * av[n, 2]) * w
                    fz = (s[4] * av[n, 0] + s[5] * av[n, 1] + s[2] * av[n, 2]) * w
                    zf[k, n, 0] = fx; zf[k, n, 1] = fy; zf[k, n, 2] = fz
                    zm[k, n] = math.sqrt(fx * fx + fy * fy + fz * fz)
    for r in prange(fstart.shape[0] - 1):
        f0 = force[r, 0]; f1 = force[r, 1]; f2 = force[r, 2]; fm = fmag[r]
        for e in range(fstart[r], fstart[r + 1]):
            k = fent[e] // 4
            n = fent[e] - 4 * k
            f0 += zf[k, n, 0]; f1 += zf[k, n, 1]; f2 += zf[k, n, 2]; fm += zm[k, n]
        force[r, 0] = f0; force[r, 1] = f1; force[r, 2] = f2; fmag[r] = fm
