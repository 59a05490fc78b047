"""The parts of the zone stepper's set-up (``physics.zones.ZoneStepper``) that the engine's
``zone_cache.StepperCache`` keeps between commands, and their helpers: the zones' models and
property checks (``_zone_models``), the plans of the 4-node step (``_zone_plan``,
``zone_bundles``), the zone tables, the elements of blocks."""
from __future__ import annotations

import numpy as np

from dec3d.errors import Dec3dError
from dec3d.kernels.bundles import ZoneMesh, ZonePlan, ZoneScratch
from dec3d.kernels.zmodels import CORRECTING_CODES, make_tables, model_mask, no_tables
from dec3d.kernels.zone_elastic import ElasticPlan
from dec3d.model.model import KIND_DEFORMABLE
from dec3d.model.zones import ZMODEL_NULL, ZP_BULK, ZP_DENSITY, ZP_SHEAR
from dec3d.physics.cmodels import MODEL_BY_CODE

_F = np.float64
_I = np.int64


def zone_bundles(plan: ElasticPlan, nset: int, plastic: bool):
    """(``ZoneMesh``, ``ZonePlan``, ``ZoneScratch``) of ``zone_step`` from a plan (scratch of the
    plastic correction only when ``plastic``)."""
    nr = plan.g4.shape[0]
    nv = plan.nodesum.shape[0]
    mesh = ZoneMesh(plan.g4, plan.n4, plan.rows, plan.zset, plan.weight, int(nset))
    zplan = ZonePlan(plan.pstart, plan.pk, *plan.fplan, *plan.nplan)
    scratch = ZoneScratch(plan.nodesum, plan.nodevol, np.empty(nv if plastic else 0), plan.sa, plan.sb, plan.evs,
                          plan.vols, np.empty(nr if plastic else 0), np.empty((nr, 13)))
    return mesh, zplan, scratch


def zone_tables(model, error=Dec3dError):
    """The ``Tables`` bundle of the tables zone properties name (``settings.mechanical
    ["zone_tables"]``, table t + 1 in a table column is its entry t), read from the FISH tables
    as they are now; a table that is gone stops the run."""
    ids = model.settings.mechanical.get("zone_tables", [])
    if not ids:
        return no_tables()
    get = getattr(model, "fish_table", None)
    points = []
    for tid in ids:
        tab = get(tid) if get is not None else None
        if tab is None:
            raise error(f"zone properties name table {tid!r}, which does not exist (any more): make it with "
                        "`table` before cycling")
        points.append((list(tab.xs), list(tab.ys)))
    return make_tables(points)


def _ids(model, rows) -> str:
    ids = sorted(set(int(i) for i in model.blocks["id"][np.asarray(rows, _I)]))
    head = ", ".join(str(i) for i in ids[:10])
    return head + (f" … ({len(ids)} blocks)" if len(ids) > 10 else "")


def block_elements(model, store, blocks, allowed, error, what: str, only: str):
    """The elements (zones or FE elements) of ``blocks`` in ``store``: (on (nblocks,) bool mask
    of the blocks, rows int64, their constitutive model codes). Raises ``error`` naming the
    blocks when an element has a model code not in ``allowed`` (``only`` says which cycle)."""
    on = np.zeros(model.blocks.n, bool)
    on[blocks] = True
    rows = np.flatnonzero(on[store["block"]]).astype(_I)
    cm = store["cmodel"][rows]
    bad = ~np.isin(cm, allowed)
    if bad.any():
        raise error(f"{what} of blocks {_ids(model, store['block'][rows[bad]])} have a constitutive model that "
                    f"does not cycle {only}")
    return on, rows, cm


def zoned_blocks(model) -> np.ndarray:
    """Rows of the live zoned (deformable) blocks."""
    b = model.blocks
    return np.flatnonzero((b["kind"] == KIND_DEFORMABLE) & ~b["hidden"]).astype(_I)


def _zone_models(model, zs, blocks, error) -> dict:
    """The zones of the zoned ``blocks`` and their models, checked (``RunError`` naming the blocks
    without a zone that has a model, or the zones whose properties a model refuses): ``on`` (mask
    of the blocks), ``warnings`` of the checks, the moduli and density per zone row (``bulk``,
    ``shear``, ``density``: each model's ``moduli``), the rows of the 4- and 10-node zones with a
    model, whether a 4-node zone's model corrects the mean stress (``plastic``) and the models of
    the 4-node zones (``models``, ``model_mask``)."""
    b = model.blocks
    on, zrow, cm = block_elements(model, zs, blocks, [ZMODEL_NULL] + list(MODEL_BY_CODE), error,
                                  "zones", "(unknown model code)")
    act = cm != ZMODEL_NULL
    live = np.zeros(b.n, bool)
    live[zs["block"][zrow[act]]] = True
    none = blocks[~live[blocks]]
    if len(none):
        raise error(f"zoned blocks {_ids(model, none)} have no zone with a constitutive model: use "
                    "`block zone cmodel assign elastic` (and `block zone property`) before cycling")
    el = zrow[act]
    p = zs["prop"]
    warnings, problems = [], []
    bulk = np.array(p[:, ZP_BULK], dtype=_F, order="C")
    shear = np.array(p[:, ZP_SHEAR], dtype=_F, order="C")
    density = np.array(p[:, ZP_DENSITY], dtype=_F, order="C")
    bid = b["id"]
    for code in np.unique(cm[act]):
        zm = MODEL_BY_CODE[int(code)]
        mine = zrow[cm == code]
        bad, warns = zm.problems(p[mine], zs["id"][mine], bid[zs["block"][mine]])
        problems += [f"{zm.name} zones: {x}" for x in bad]
        warnings += [f"{zm.name} zones: {x}" for x in warns]
        if zm.moduli is not None and not bad:
            bulk[mine], shear[mine] = zm.bulk_shear(p[mine])
    if problems:
        raise error("zone properties: " + "; ".join(problems)
                    + " (set them with `block zone property` before cycling)")
    nn = zs["nnode"][el]
    rows4 = np.ascontiguousarray(el[nn == 4])
    plastic = bool(np.isin(zs["cmodel"][rows4], sorted(CORRECTING_CODES)).any())
    return {"on": on, "warnings": warnings, "bulk": bulk, "shear": shear, "density": density, "rows4": rows4,
            "rows10": np.ascontiguousarray(el[nn == 10]), "plastic": plastic,
            "models": model_mask(np.unique(zs["cmodel"][rows4]), plastic)}


def _zone_plan(zs, v, rows4, plastic: bool, nch: int) -> dict:
    """The NMD averaging node of each vertex row (``node``: its link master, or itself), the
    mixed-discretization weights and compact set numbers of the 4-node zones ``rows4``
    (``weight``, ``zset``, ``nset``), and their step's ``ElasticPlan`` (``fast``; None without
    4-node zones) in ``nch`` chunks with its bundles (``zone_bundles``); ``rows4`` and ``plastic``
    as given (the cache compares them)."""
    link0 = v["link"]
    node = np.ascontiguousarray(np.where(link0 >= 0, link0, np.arange(v.n, dtype=_I)))
    hx = zs["hex"][rows4]
    weight = np.where(zs["overlay"][rows4] >= 0, 0.5, 1.0)
    zset = np.full(len(rows4), -1, _I)
    if (hx >= 0).any():
        _, inv = np.unique(hx[hx >= 0], return_inverse=True)
        zset[hx >= 0] = inv.ravel()
    nset = int(zset.max()) + 1 if len(zset) else 0
    out = {"node": node, "weight": weight, "zset": zset, "nset": nset, "fast": None, "bundles": None,
           "rows4": rows4, "plastic": plastic}
    if len(rows4):
        fast = ElasticPlan(zs["gp"], rows4, node, zset, weight, v.n, nch)
        out.update(fast=fast, bundles=zone_bundles(fast, nset, plastic))
    return out
