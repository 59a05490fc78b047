"""10-node tetrahedral zones with any zone model: the constitutive update at each Gauss point.

The 3DEC theory text (000_*, "Higher-Order Tetrahedral Elements") applies the constitutive model
at each of the four Gauss points of a 10-node tetrahedron every step. ``zones_ho.tet10_step`` does
that for Hooke's law; this kernel does it for every zone model of ``kernels/zmodels`` through the
same update the 4-node step calls (``zone_update_for``), so a model written once serves both
(issue 26 item 2). Geometry, quadrature and the nodal forces are ``zones_ho``'s.

Per Gauss point g of zone z: the strain increment from the velocity gradient (tensor shear
components), the model's update of ``gstress[z, g]`` with the zone's properties and moduli and the
Gauss point's own history ``ghist[z, g]`` (a strain-softening Gauss point softens by its own plastic
strain, not its neighbours'); then the zone's stress is the mean of its four Gauss points, its
plastic state the union of theirs (``merge_state``), its history row the mean of theirs (what VTK
and FISH show). No mixed discretization is applied to 10-node zones (as in ``tet10_step``), so a
model's mean-stress correction ``dsp`` is not used: its returned stress is final.
"""
import numpy as np
from numba import literally, njit

from .gather import scatter
from .zmodels import NWORK, merge_state, zone_update_for
from .zone_mohr import mohr_work
from .zones_ho import _zone_force, _zone_grads, ref_derivs, vel_grad


@njit(cache=True)
def tet10_model_step(pos, vel, gp, rows, mat, ghist, dt, models, gstress, force):
    """One step of the 10-node zones in ``rows`` with their models.

    pos, vel (nv, 3); gp (nz, 10) node rows; rows (k,) zone rows; ``mat`` a ``bundles.ZoneMaterial``
    (cmodel, prop, hist, bulk, shear, stress, state, tab: hist, stress and state updated); ghist
    (nz, 4, NZHIST) the Gauss points' histories; dt [s]; ``models`` the literal mask of the model
    codes (``zmodels.model_mask``); gstress (nz, 4, 6) [Pa]; force (nv, 3) [N], added to.
    Returns the first zone row skipped as inverted or flat (-1 if none)."""
    literally(models)
    cmodel = mat.cmodel; prop = mat.prop; hist = mat.hist; bulk = mat.bulk; shear = mat.shear
    stress = mat.stress; state = mat.state; tab = mat.tab
    dref = ref_derivs()
    dn4 = np.empty((4, 10, 3))
    wd4 = np.empty(4)
    nodes = np.empty(10, np.int64)
    fz = np.empty((10, 3))
    wf = np.full(NWORK, np.nan)
    mw = mohr_work()
    nh = hist.shape[1]
    bad = -1
    for kk in range(rows.shape[0]):
        z = rows[kk]
        for a in range(10):
            nodes[a] = gp[z, a]
        if not _zone_grads(pos, nodes, dref, dn4, wd4):
            if bad < 0:
                bad = z
            continue
        K = bulk[z]
        G = shear[z]
        code = cmodel[z]
        pz = prop[z:z + 1]
        now = 0
        for c in range(6):
            stress[z, c] = 0.0
        for j in range(nh):
            hist[z, j] = 0.0
        for g in range(4):
            l00, l01, l02, l10, l11, l12, l20, l21, l22 = vel_grad(dn4[g], vel, nodes)
            s = gstress[z, g]
            bits, t0, t1, t2, t3, t4, t5, dsp = zone_update_for(
                models, code, pz, ghist[z, g:g + 1], 0, K, G,
                l00 * dt, l11 * dt, l22 * dt, 0.5 * (l01 + l10) * dt, 0.5 * (l02 + l20) * dt,
                0.5 * (l12 + l21) * dt, s[0], s[1], s[2], s[3], s[4], s[5], tab, wf, mw)
            s[0] = t0; s[1] = t1; s[2] = t2; s[3] = t3; s[4] = t4; s[5] = t5
            now |= bits
            for c in range(6):
                stress[z, c] += 0.25 * s[c]
            for j in range(nh):
                hist[z, j] += 0.25 * ghist[z, g, j]
        state[z] = merge_state(state[z], now)
        _zone_force(dn4, wd4, gstress[z], fz)
        scatter(force, nodes, fz)
    return bad


_STEPS: dict = {}


def tet10_model_step_for(models: int):
    """``tet10_model_step`` with the mask fixed (a literal: each deck compiles the updates it uses,
    once, cached): ``step(pos, vel, gp, rows, mat, ghist, dt, gstress, force)``."""
    step = _STEPS.get(models)
    if step is None:
        mask = int(models)

        @njit(cache=True)      # (numba keys a closure's cache entry on the mask it closes over)
        def step(pos, vel, gp, rows, mat, ghist, dt, gstress, force):
            return tet10_model_step(pos, vel, gp, rows, mat, ghist, dt, mask, gstress, force)
        _STEPS[models] = step
    return step
