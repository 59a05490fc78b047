"""The step of the 4-node zones with any constitutive model (elastic, Mohr-Coulomb): strain
pass, mixed discretization of hexahedral sets (3DEC theory text, Eqs. 60-67), nodal mixed
discretization of the other tetrahedra, constitutive update (``kernels/zone_mohr.py``), stress
averaging and nodal forces; serial, threaded, and in fused sweeps over scratch the caller keeps.

Nodal mixed discretization (3DEC theory text, "Nodal Mixed Discretization for a Tetrahedral
Grid", Eqs. 68-76): the volumetric strain increment of each tetrahedron is replaced by the mean
over its four gridpoints of the volume-weighted average of the tetrahedra around each gridpoint
(Eqs. 69-71); the plastic mean-stress correction K de^p returned by the constitutive model
(``dsp`` here: mean trial stress minus mean returned stress) is averaged the same way and the
stress corrected by (dsp - mean dsp) on its diagonal (Eqs. 74-76). Deviatoric parts and the
constitutive model are untouched.
"""
import math

import numpy as np
from numba import njit, prange

from .gather import node_lists
from .zone_mohr import (SHEAR_PAST, TENSION_PAST, ZMODEL_ELASTIC, ZMODEL_MOHR, ZP_BULK, ZP_COHESION, ZP_SHEAR,
                        ZP_TANDIL, ZP_TANFRIC, ZP_TENSION, merge_state, mohr_plastic, mohr_trial,
                        mohr_work)
from .zones import _face_vector, hooke_increment, tet_add_forces, tet_kinematics


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
# even on one thread, but not at 1e4; the serial fused kernel is slower than both: the
# Mohr-Coulomb branch of ``_zone_update`` inside sweep B's loop costs about a third of the
# kernel even when no zone takes it (1e6 elastic zones, one thread: 339 ms with the branch,
# 221 ms with it removed, the same as ``zone_forces_plastic``, whose constitutive pass is a loop
# of its own; array views passed to the helpers cost a further ~5 %). So the stepper uses
# ``zone_forces_plastic`` below PARALLEL_MIN_ZONES zones and the threaded ``*_ws`` kernel above
# when some zone is Mohr-Coulomb; with none, ``zone_elastic.elastic_zone_step`` (the same bits,
# scalar locals, no Mohr branch); the serial ``*_ws`` kernel is kept as the tested serial form.

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
