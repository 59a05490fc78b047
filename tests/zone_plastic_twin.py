"""The serial twin of ``dec3d/kernels/zone_step.zone_step`` for elastic and Mohr-Coulomb zones, in
passes: strain pass, mixed discretization of hexahedral sets (3DEC theory text, Eqs. 60-67), nodal
mixed discretization of the other tetrahedra, constitutive update (``mohr_trial``/``mohr_plastic``
of ``kernels/zone_mohr.py``, the array path, not the engine's scalar one), stress averaging and
nodal forces, one array per pass. Once the engine's plastic step (``dec3d/kernels/zone_plastic.py``,
moved here when the plug-in zone step replaced the five copies of the step); the tests hold
``zone_step`` to its bits.

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
from numba import njit

from dec3d.kernels.zone_mohr import mohr_plastic, mohr_trial, mohr_work
from dec3d.kernels.zones import hooke_increment, tet_add_forces, tet_kinematics

# the twin's own reading of the store (written from dec3d/model/zones.py's table, not imported):
# model codes 1 elastic, 2 Mohr-Coulomb; columns 0 bulk, 1 shear, 3 cohesion, 4 tan friction,
# 5 tension, 6 tan dilation; state bits 1 shear now, 2 tension now, 4 and 8 the same in the past
ZMODEL_ELASTIC = 1
ZMODEL_MOHR = 2
ZP_BULK, ZP_SHEAR, ZP_COHESION, ZP_TANFRIC, ZP_TENSION, ZP_TANDIL = 0, 1, 3, 4, 5, 6
SHEAR_PAST = 4
TENSION_PAST = 8


@njit(cache=True)
def merge_state(old, now):
    return (old & (SHEAR_PAST | TENSION_PAST)) | now | (now << 2)


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
