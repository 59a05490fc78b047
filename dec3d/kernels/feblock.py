"""20-node serendipity bricks (FE blocks): Gauss-point strains and stresses, nodal forces by
integration of the Gauss-point stresses, lumped masses, nodal stiffness, consistent gravity.
Node tables, shape functions, Gauss rules, slave nodes and face loads are in
``kernels/feblock_shape`` (re-exported here), the Jacobian in ``kernels/feblock_jac``.

Source: the FE-block text (shared/seeds/003_*, "Structural Finite Elements") with the
corrections of shared/seeds/ERRATA.md (section 003). The text follows Hughes (1987).

``gstress[e, g]`` (e, 27, 6) holds the stress of Gauss point g (the first 8 used with nq = 2;
numbering in ``feblock_shape``), xx yy zz xy xz yz, tension positive (the store order of
``zones``; the text's vector is 11 22 33 23 31 12), and ``stress[e]`` the volume-weighted
mean sum_g w_g det J_g sigma_g / V.

Sign convention as ``kernels/zones_ho``: ``force[r]`` accumulates the force the element exerts
on node r, -F^S of the text's Eq. (7), -sum_G B_I^T sigma W_G V_G.

Elements must be positively oriented (det J > 0 at every Gauss point). Every kernel that
integrates skips an element whose det J is not positive at one of its points (no NaN reaches
the stores) and returns the first such element row (-1 if none) for the host to report.
"""
import numpy as np
from numba import njit, prange

from .feblock_hg import hg_jacobians, hg_step
from .feblock_jac import gauss_force, grad_n, jac_inv, strain_increment
from .feblock_shape import (FACES, NGMAX, YNODE, YSLAVE, _slave_weights, feb_gauss_positions, feb_slave_forces,
                            feb_slave_interp, gauss_rule, hg_tables, quad8_traction_loads, ref_tables, shape20)
from .gather import node_lists, node_sums, scatter
from .zones_ho import add_body_force, add_stiffness_bound

#: public kernels, and (from ``feblock_shape``) the tables, rules, slave-node and face-load kernels
__all__ = ["feb_step", "feb_element_pass", "feb_element_pass_serial", "feb_node_lists", "feb_node_sums_mag",
           "feb_node_sums_mag_serial", "feb_step_parallel", "feb_forces", "feb_volume", "feb_lumped_mass",
           "feb_stiffness", "feb_body_force", "CHUNK", "FACES", "NGMAX", "YNODE", "YSLAVE", "_slave_weights",
           "feb_gauss_positions", "feb_slave_forces", "feb_slave_interp", "gauss_rule", "hg_tables",
           "quad8_traction_loads", "ref_tables", "shape20"]

#: elements per work unit of the parallel element pass
CHUNK = 256


@njit(cache=True)
def _gather(arr, nodes, e, nd, out):
    """nd[a] = nodes[e, a] and out[a] = arr[nd[a]] (20 rows) for one element."""
    for a in range(20):
        r = nodes[e, a]
        nd[a] = r
        out[a, 0] = arr[r, 0]
        out[a, 1] = arr[r, 1]
        out[a, 2] = arr[r, 2]


@njit(cache=True)
def _elem_grads(x, dref, wts, dng, wd):
    """Cartesian derivatives dng (ng, 20, 3) and w_g det J_g (ng,) at every Gauss point of one
    element with node coordinates x (20, 3). False when det J is not positive at some point."""
    for g in range(wts.shape[0]):
        det = grad_n(x, dref[g], dng[g])
        if not det > 0.0:
            return False
        wd[g] = wts[g] * det
    return True


@njit(cache=True)
def _elem_force(dng, wd, sg, fe):
    """fe[a] = -sum_g wd[g] sigma_g . grad N_a(g) (Eq. 7 with the engine's sign), sg (>= ng, 6)."""
    for a in range(20):
        fe[a, 0] = 0.0
        fe[a, 1] = 0.0
        fe[a, 2] = 0.0
    for g in range(wd.shape[0]):
        s = sg[g]
        w = wd[g]
        dn = dng[g]
        for a in range(20):
            fe[a, 0] -= w * (s[0] * dn[a, 0] + s[3] * dn[a, 1] + s[4] * dn[a, 2])
            fe[a, 1] -= w * (s[3] * dn[a, 0] + s[1] * dn[a, 1] + s[5] * dn[a, 2])
            fe[a, 2] -= w * (s[4] * dn[a, 0] + s[5] * dn[a, 1] + s[2] * dn[a, 2])


@njit(cache=True)
def _elem_step(xe, ve, dref, wts, lam, g2, dt, sg, se, fe, jinv, wd, hg, dface, wpg, jf, eg, tg):
    """Stress update and nodal forces of one element (node coordinates xe, velocities ve
    (20, 3)): Gauss-point stresses sg (>= ng, 6) and mean se (6,) updated, fe (20, 3) filled
    with the element's force on each node. False, changing nothing, when det J is not positive
    at a Gauss point (or, with the control, at a face centre). Works in master coordinates:
    grad v = (sum_a v_a (x) dN_a/dy) J^-1 and f_a = -(w det J sigma J^-T) dN_a/dy, the same sums
    as B^T sigma without forming grad N. With 8 points and hg > 0 the hourglass control of
    ``feblock_hg`` is added (sg rows 8-13; scratch jf (6, 3, 3), eg and tg (8, 6))."""
    ng = wts.shape[0]
    ctl = ng == 8 and hg > 0.0
    vol = 0.0
    for g in range(ng):
        det = jac_inv(xe, dref[g], jinv[g])
        if not det > 0.0:
            return False
        wd[g] = wts[g] * det
        vol += wd[g]
    if ctl and not hg_jacobians(xe, dface, jf):
        return False
    for a in range(20):
        fe[a, 0] = 0.0
        fe[a, 1] = 0.0
        fe[a, 2] = 0.0
    for c in range(6):
        se[c] = 0.0
    for g in range(ng):
        d = dref[g]
        ji = jinv[g]
        exx, eyy, ezz, exy, exz, eyz = strain_increment(ve, d, ji, dt)
        ev = exx + eyy + ezz
        s = sg[g]
        s[0] += lam * ev + g2 * exx
        s[1] += lam * ev + g2 * eyy
        s[2] += lam * ev + g2 * ezz
        s[3] += g2 * exy
        s[4] += g2 * exz
        s[5] += g2 * eyz
        w = wd[g]
        fv = w / vol
        for c in range(6):
            se[c] += fv * s[c]
        if ctl:
            e = eg[g]
            e[0] = exx; e[1] = eyy; e[2] = ezz; e[3] = exy; e[4] = exz; e[5] = eyz
        else:
            gauss_force(s[0] * w, s[1] * w, s[2] * w, s[3] * w, s[4] * w, s[5] * w, ji, d, fe)
    if ctl:
        hg_step(ve, dface, jf, wpg, vol, lam, g2, hg, dt, eg, sg, tg, fe)
        for g in range(8):
            s = sg[g]
            w = wd[g]
            t = tg[g]
            gauss_force(s[0] * w - t[0], s[1] * w - t[1], s[2] * w - t[2], s[3] * w - t[3], s[4] * w - t[4],
                         s[5] * w - t[5], jinv[g], dref[g], fe)
    return True


@njit(cache=True)
def feb_step(pos, vel, nodes, rows, bulk, shear, dt, gstress, stress, force, nq, hg=0.0):
    """One elastic step of the 20-node elements in ``rows`` with the nq x nq x nq rule.

    pos, vel (nv, 3): node positions and velocities; nodes (ne, 20) node rows; rows (k,) int64
    element rows; bulk, shear (ne,) [Pa] by element row; dt [s]; gstress (ne, 27, 6),
    stress (ne, 6) [Pa]; force (nv, 3) [N]; nq 2 or 3.
    At each Gauss point: grad v = sum_I v_I (x) grad N_I (Eq. 4-5 with velocities), strain
    increment sym(grad v) dt (Eq. 3, 6), gstress += lambda tr(de) I + 2 G de (elastic model),
    then stress[e] = volume-weighted mean and force[nodes[e, a]] += -sum_g w det J sigma . grad N_a
    (Eq. 7), element by element in the order of rows; hg > 0 adds the hourglass control of
    ``feblock_hg`` to 2 x 2 x 2 elements (eps_h = hg). Modifies gstress, stress, force. Returns
    the first element row skipped (det J not positive at a Gauss point), -1 if none.
    """
    shp, dref, wts = ref_tables(nq)
    dface, wpg = hg_tables()
    jf = np.empty((6, 3, 3))
    eg = np.empty((8, 6))
    tg = np.empty((8, 6))
    ng = wts.shape[0]
    jinv = np.empty((ng, 3, 3))
    wd = np.empty(ng)
    nd = np.empty(20, np.int64)
    xe = np.empty((20, 3))
    ve = np.empty((20, 3))
    fe = np.empty((20, 3))
    bad = -1
    for kk in range(rows.shape[0]):
        e = rows[kk]
        _gather(pos, nodes, e, nd, xe)
        _gather(vel, nodes, e, nd, ve)
        if not _elem_step(xe, ve, dref, wts, bulk[e] - 2.0 * shear[e] / 3.0, 2.0 * shear[e], dt,
                          gstress[e], stress[e], fe, jinv, wd, hg, dface, wpg, jf, eg, tg):
            if bad < 0:
                bad = e
            continue
        scatter(force, nd, fe)
    return bad


@njit(cache=True)
def _element_chunk(lo, hi, pos, vel, nodes, rows, bulk, shear, dt, gstress, stress, fe, ok, nq, hg):
    """Elements rows[lo:hi] of the element pass (see ``feb_element_pass``)."""
    shp, dref, wts = ref_tables(nq)
    dface, wpg = hg_tables()
    jf = np.empty((6, 3, 3))
    eg = np.empty((8, 6))
    tg = np.empty((8, 6))
    ng = wts.shape[0]
    jinv = np.empty((ng, 3, 3))
    wd = np.empty(ng)
    nd = np.empty(20, np.int64)
    xe = np.empty((20, 3))
    ve = np.empty((20, 3))
    for kk in range(lo, hi):
        e = rows[kk]
        _gather(pos, nodes, e, nd, xe)
        _gather(vel, nodes, e, nd, ve)
        ok[kk] = _elem_step(xe, ve, dref, wts, bulk[e] - 2.0 * shear[e] / 3.0, 2.0 * shear[e], dt,
                            gstress[e], stress[e], fe[kk], jinv, wd, hg, dface, wpg, jf, eg, tg)


@njit(cache=True, parallel=True)
def feb_element_pass(pos, vel, nodes, rows, bulk, shear, dt, gstress, stress, fe, ok, nq, hg=0.0):
    """The element half of ``feb_step_parallel``, in parallel over chunks of rows (each element
    writes only its own rows): stress update, and fe[k] (20, 3) = the force of element rows[k]
    on each of its nodes; ok[k] = False for an element with det J not positive (untouched)."""
    n = rows.shape[0]
    nchunk = (n + CHUNK - 1) // CHUNK
    for c in prange(nchunk):
        _element_chunk(c * CHUNK, min(n, (c + 1) * CHUNK), pos, vel, nodes, rows, bulk, shear, dt, gstress,
                       stress, fe, ok, nq, hg)


@njit(cache=True)
def feb_element_pass_serial(pos, vel, nodes, rows, bulk, shear, dt, gstress, stress, fe, ok, nq, hg=0.0):
    """``feb_element_pass`` on the calling thread (small meshes: no thread start-up), same results."""
    _element_chunk(0, rows.shape[0], pos, vel, nodes, rows, bulk, shear, dt, gstress, stress, fe, ok, nq, hg)


@njit(cache=True)
def feb_node_lists(nv, nodes, rows):
    """Per node, the (element, local node) entries that add to it, in a fixed order (CSR): the
    entries of node r are nent[nstart[r]:nstart[r + 1]], each 20 k + a (node a of element
    rows[k]), ascending: the order of the serial scatter of ``feb_step``
    (``kernels/gather.node_lists``). Made once per mesh. Returns (nstart (nv + 1,), nent
    (20 k,)) int64."""
    return node_lists(nv, np.arange(nv), nodes, rows, 20)


@njit(cache=True)
def _node_range_mag(lo, hi, force, fmag, fe, ok, nstart, nent):
    for r in range(lo, hi):
        f0 = force[r, 0]; f1 = force[r, 1]; f2 = force[r, 2]
        mg = fmag[r]
        for q in range(nstart[r], nstart[r + 1]):
            kk = nent[q] // 20
            if ok[kk]:
                a = nent[q] - 20 * kk
                x = fe[kk, a, 0]; y = fe[kk, a, 1]; z = fe[kk, a, 2]
                f0 += x; f1 += y; f2 += z
                mg += np.sqrt(x * x + y * y + z * z)
        force[r, 0] = f0; force[r, 1] = f1; force[r, 2] = f2
        fmag[r] = mg


@njit(cache=True, parallel=True)
def feb_node_sums_mag(force, fmag, fe, ok, nstart, nent):
    """``kernels/gather.node_sums`` that also adds to fmag[r] the magnitude of every element force on node
    r (sum over its entries of |fe|: the scale of the forces meeting at the node, for
    equilibrium ratios). Parallel over chunks of nodes; the same sums for any thread count."""
    nv = nstart.shape[0] - 1
    nchunk = (nv + 4 * CHUNK - 1) // (4 * CHUNK)
    for c in prange(nchunk):
        _node_range_mag(c * 4 * CHUNK, min(nv, (c + 1) * 4 * CHUNK), force, fmag, fe, ok, nstart, nent)


@njit(cache=True)
def feb_node_sums_mag_serial(force, fmag, fe, ok, nstart, nent):
    """``feb_node_sums_mag`` on the calling thread, same results."""
    _node_range_mag(0, nstart.shape[0] - 1, force, fmag, fe, ok, nstart, nent)


@njit(cache=True)
def feb_step_parallel(pos, vel, nodes, rows, bulk, shear, dt, gstress, stress, force, nq,
                      fe, ok, nstart, nent, hg=0.0):
    """``feb_step`` on several threads, bit for bit the same result whatever the thread count
    (and the same as ``feb_step``): a parallel element pass into the scratch fe (len(rows), 20,
    3) [N] and ok (len(rows),) bool, then fixed-order sums per node over the lists of
    ``feb_node_lists(len(force), nodes, rows)``. Returns the first element row skipped in the
    order of rows (-1 none)."""
    feb_element_pass(pos, vel, nodes, rows, bulk, shear, dt, gstress, stress, fe, ok, nq, hg)
    node_sums(force, fe, ok, nstart, nent)
    for kk in range(rows.shape[0]):
        if not ok[kk]:
            return rows[kk]
    return -1


@njit(cache=True)
def feb_forces(pos, nodes, rows, gstress, force, nq):
    """Nodal forces of the Gauss-point stresses as they are (no update): force[nodes[e, a]] +=
    -sum_g w det J sigma_g . grad N_a. Modifies force; returns the first element row skipped,
    -1 if none."""
    shp, dref, wts = ref_tables(nq)
    ng = wts.shape[0]
    dng = np.empty((ng, 20, 3))
    wd = np.empty(ng)
    nd = np.empty(20, np.int64)
    xe = np.empty((20, 3))
    fe = np.empty((20, 3))
    bad = -1
    for kk in range(rows.shape[0]):
        e = rows[kk]
        _gather(pos, nodes, e, nd, xe)
        if not _elem_grads(xe, dref, wts, dng, wd):
            if bad < 0:
                bad = e
            continue
        _elem_force(dng, wd, gstress[e], fe)
        scatter(force, nd, fe)
    return bad


@njit(cache=True)
def feb_volume(pos, nodes, rows, volume):
    """Element volumes sum_g w det J by the 3 x 3 x 3 rule (exact for parallelepipeds).
    Modifies volume; returns the first element row with det J not positive (volume 0), -1 if none."""
    shp, dref, wts = ref_tables(np.int64(3))
    dng = np.empty((27, 20, 3))
    wd = np.empty(27)
    nd = np.empty(20, np.int64)
    xe = np.empty((20, 3))
    bad = -1
    for kk in range(rows.shape[0]):
        e = rows[kk]
        _gather(pos, nodes, e, nd, xe)
        if not _elem_grads(xe, dref, wts, dng, wd):
            volume[e] = 0.0
            if bad < 0:
                bad = e
            continue
        v = 0.0
        for g in range(27):
            v += wd[g]
        volume[e] = v
    return bad


@njit(cache=True)
def feb_lumped_mass(pos, nodes, rows, density, mass):
    """Lumped node masses of 20-node elements, added to mass[nodes] (density by element row).

    The text lumps through its fictitious tetrahedral discretization and names "more accurate
    schemes" (Hughes 1987); row sums of the consistent mass are negative at the corners (-M/8,
    errata), so HRZ diagonal scaling is used (Hinton, Rock & Zienkiewicz 1976; Hughes 1987,
    section 7.3.2): node a gets M d_a / sum_b d_b with d_a = int rho N_a^2 dV, M = rho V, both by
    the 3 x 3 x 3 rule (exact for parallelepipeds). Every mass is positive; for a rectangular
    brick the fractions are 0.0282 M per corner and 0.0645 M per mid-edge node (errata).
    Modifies mass; returns the first element row skipped, -1 if none."""
    shp, dref, wts = ref_tables(np.int64(3))
    dng = np.empty((27, 20, 3))
    wd = np.empty(27)
    nd = np.empty(20, np.int64)
    xe = np.empty((20, 3))
    dd = np.empty(20)
    bad = -1
    for kk in range(rows.shape[0]):
        e = rows[kk]
        _gather(pos, nodes, e, nd, xe)
        if not _elem_grads(xe, dref, wts, dng, wd):
            if bad < 0:
                bad = e
            continue
        v = 0.0
        tot = 0.0
        for a in range(20):
            dd[a] = 0.0
        for g in range(27):
            v += wd[g]
            for a in range(20):
                dd[a] += wd[g] * shp[g, a] * shp[g, a]
        for a in range(20):
            tot += dd[a]
        m = density[e] * v
        for a in range(20):
            mass[nd[a]] += m * dd[a] / tot
    return bad


@njit(cache=True)
def feb_stiffness(pos, nodes, rows, bulk, shear, kdiag, nq, hg=0.0):
    """Per-node stiffness bound for the explicit time step, added to kdiag[nodes].

    The text takes its time step from the fictitious tetrahedral discretization ("Solution
    Algorithm"); this uses a bound that is safe by construction instead: the element stiffness
    K = sum_g w det J B^T D B with the nq-rule of the forces (never used for forces, only
    here; with nq = 2 and hg > 0 plus the hourglass stiffness of ``feblock_hg``, its six face
    points weighted hg V / 6) and, per node, the largest absolute row sum of its three rows.
    Summed over elements it bounds the global row sums, so by Gershgorin's theorem the largest
    eigenvalue of M^-1 K is at most max_i k_i / m_i for any diagonal mass, and
    dt <= 2 min sqrt(m_i / k_i) is stable. Modifies kdiag; returns the first element row
    skipped, -1 if none."""
    shp, dref, wts = ref_tables(nq)
    ng = wts.shape[0]
    with_hg = ng == 8 and hg > 0.0
    nh = ng + 6 if with_hg else ng
    dface, wpg = hg_tables()
    dng = np.empty((nh, 20, 3))
    wd = np.empty(nh)
    nd = np.empty(20, np.int64)
    xe = np.empty((20, 3))
    K = np.empty((60, 60))
    bad = -1
    for kk in range(rows.shape[0]):
        e = rows[kk]
        _gather(pos, nodes, e, nd, xe)
        ok = _elem_grads(xe, dref, wts, dng[:ng], wd[:ng])
        if ok and with_hg:
            vol = 0.0
            for g in range(8):
                vol += wd[g]
            for p in range(6):
                # grad of dB_p: grad N(p) - sum_g w_pg grad N(g)
                h = dng[8 + p]
                ok = ok and grad_n(xe, dface[p], h) > 0.0
                for g in range(8):
                    w = wpg[p, g]
                    for a in range(20):
                        for j in range(3):
                            h[a, j] -= w * dng[g, a, j]
                wd[8 + p] = hg * vol / 6.0
        if not ok:
            if bad < 0:
                bad = e
            continue
        add_stiffness_bound(dng, wd, bulk[e] - 2.0 * shear[e] / 3.0, shear[e], nd, K, kdiag)
    return bad


@njit(cache=True)
def feb_body_force(pos, nodes, rows, density, gvec, force):
    """Consistent nodal forces of gravity, the text's Eq. (8) F_I = int N_I g dV (rho g per
    unit volume; the errata: gravity is Eq. 8, not Eq. 5), by the 3 x 3 x 3 rule (exact for
    parallelepipeds). Not all positive: a rectangular brick of weight W gives -W/8 per corner
    and W/6 per mid-edge node. density (ne,) [kg/m3], gvec (3,) [m/s2]. Modifies force;
    returns the first element row skipped, -1 if none."""
    shp, dref, wts = ref_tables(np.int64(3))
    dng = np.empty((27, 20, 3))
    wd = np.empty(27)
    nd = np.empty(20, np.int64)
    xe = np.empty((20, 3))
    bad = -1
    for kk in range(rows.shape[0]):
        e = rows[kk]
        _gather(pos, nodes, e, nd, xe)
        if not _elem_grads(xe, dref, wts, dng, wd):
            if bad < 0:
                bad = e
            continue
        add_body_force(wd, shp, density[e], gvec, nd, force)
    return bad
