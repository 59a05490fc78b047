"""Driving ``dec3d.kernels.zone_step.zone_step`` from the arrays the tests build (a zone table, the
rows stepped, sets, weights, averaging nodes, model codes, properties), as the engine's
``ZoneStepper`` does: ``ElasticPlan`` for the chunks and plans, ``physics.zone_setup.zone_bundles``."""
import numpy as np

from dec3d.kernels.bundles import ZoneMaterial
from dec3d.kernels.zmodels import CORRECTING_CODES, NZHIST, model_mask, no_tables
from dec3d.kernels.zone_elastic import ElasticPlan
from dec3d.kernels.zone_step import zone_step_for
from dec3d.model import zones as mz
from dec3d.physics.zone_setup import zone_bundles


class Stepper:
    """zone_step over fixed geometry: ``step(pos, vel, stress, state, force, fmag, dt, large, nmd)``."""

    def __init__(self, gp, rows, zset, weight, node, nv, cm, prop, parts=1, hist=None, tab=None):
        nset = int(zset.max()) + 1 if len(zset) else 0
        self.plan = ElasticPlan(gp, rows, node, zset, weight, nv, parts)
        self.plastic = bool(np.isin(cm[rows], sorted(CORRECTING_CODES)).any())
        self.models = model_mask(np.unique(cm[rows]))         # (bit 0, the correction sweep: ``plastic``)
        self.mesh, self.zplan, self.scr = zone_bundles(self.plan, nset, self.plastic)
        self.cm = np.ascontiguousarray(cm)
        self.prop = np.ascontiguousarray(prop)
        self.hist = np.zeros((len(cm), NZHIST)) if hist is None else hist
        self.bulk = np.ascontiguousarray(prop[:, mz.ZP_BULK])
        self.shear = np.ascontiguousarray(prop[:, mz.ZP_SHEAR])
        self.tab = no_tables() if tab is None else tab

    def step(self, pos, vel, stress, state, force, fmag, dt, large, nmd):
        mat = ZoneMaterial(self.cm, self.prop, self.hist, self.bulk, self.shear, stress, state, self.tab)
        zone_step_for(self.models | int(self.plastic))(pos, vel, self.mesh, mat, self.zplan, self.scr, dt, large,
                                                       nmd, force, fmag)


def elastic_forces(pos, vel, gp, rows, zset, weight, nset, bulk, shear, dt, large, stress, force, fmag):
    """The engine's zone step on elastic zones without nodal mixed discretization, in the argument
    order of the old ``zonestep.zone_forces`` the twins of tests/deformable/test_zone_step_kernels.py
    were written against (``nset`` is implied by ``zset``)."""
    nz, nv = len(gp), len(pos)
    prop = np.zeros((nz, mz.NZPROP))
    prop[:, mz.ZP_BULK] = bulk
    prop[:, mz.ZP_SHEAR] = shear
    cm = np.full(nz, mz.ZMODEL_ELASTIC, np.int8)
    st = Stepper(np.ascontiguousarray(gp), np.asarray(rows, np.int64), np.asarray(zset, np.int64),
                 np.asarray(weight, float), np.arange(nv, dtype=np.int64), nv, cm, prop)
    st.step(pos, vel, stress, np.zeros(nz, np.int32), force, fmag, dt, large, False)


def elastic_tets(pos, vel, gp, bulk, shear, dt, stress, force):
    """Every zone of ``gp`` through the engine's zone step, elastic, no averaging, small strain."""
    nz = len(gp)
    elastic_forces(pos, vel, gp, np.arange(nz, dtype=np.int64), np.full(nz, -1, np.int64), np.ones(nz), 0, bulk,
                   shear, dt, False, stress, force, np.zeros(len(pos)))
