"""Dowels of hybrid bolts in the cycle (3DEC's hybrid bolt: a grouted cable, ``physics.cables``, plus
a shear spring where the bolt crosses each joint; stores ``dec3d.model.dowels``, kernel
``dec3d.kernels.dowel``).

Model. Where a bolt crosses the contact between blocks A and B, the steel resists the relative shear
displacement of the two faces: a spring across the bolt's axis t (as created: the cable's nodes are
coupled to the rock along the axis only, so its elements' present directions are no guide; small
rotations) acting on the shear part of the
relative displacement of B against A at the crossing point,
    Δu_s = (Δu − (Δu·t) t),  Δu = (v_B(x) − v_A(x)) Δt,   F ← F − k_d Δu_s   (force on B; A gets −F),
elastic, perfectly plastic with |F| ≤ F_y (``dowel-yield``), and broken for good once the accumulated
shear displacement |Σ Δu_s| reaches ``dowel-rupture`` (a length: the shear displacement at which the
bolt shears through; 0 means never). The axial part across the joint is the cable's (its elements
and grout), so a hybrid bolt resists opening through the cable and sliding through the dowel.
Rigid sides move the point with v + ω × r and take F and its moment about the centroid in their
``fapp``/``mapp`` (as a change from the last step, as the cable's grout does); zoned sides follow
the 4-node zone holding a point just inside them (barycentric weights) and take wᵢ F at its
gridpoints. k_d enters the blocks' and gridpoints' stiffness sums (``block_stiffness``,
``gridpoint_stiffness``) for density scaling and the unscaled Δt.

The joints' strength reduction (``model factor-of-safety``) leaves the dowels alone: bolts keep their
strength while joints are reduced, as 3DEC does.
"""
from __future__ import annotations

import numpy as np

from dec3d.kernels.dowel import D_K, dowel_step
from dec3d.model.dowels import DOWELS, has_dowels
from dec3d.model.hosts import spread_stiffness


def advance_dowels(m, dt: float) -> None:
    """One dowel step (after the cable step of the same step)."""
    if not has_dowels(m):
        return
    st = m.stores[DOWELS]
    b, v = m.blocks, m.vertices
    old_f = st["fs"].copy()
    old_m = st["moment"].copy()
    hz = st["hz"]
    hvel = np.zeros((st.n, 2, 3))
    zs = np.argwhere(hz != 0)
    if zs.size:
        i, s = zs[:, 0], zs[:, 1]
        hvel[i, s] = np.einsum("kj,kjc->kc", st["hw"][i, s], v["velocity"][st["hgp"][i, s]])
    dowel_step(float(dt), st["axis"], st["blk"], hz, hvel, st["pos"], st["prop"], st["fs"], st["us"],
               st["state"], st["moment"], b["velocity"], b["spin"], b["centroid"])
    df = st["fs"] - old_f
    dm = st["moment"] - old_m
    for side, sg in ((0, -1.0), (1, 1.0)):
        rig = hz[:, side] == 0
        if rig.any():
            np.add.at(b["fapp"], st["blk"][rig, side], sg * df[rig])
            np.add.at(b["mapp"], st["blk"][rig, side], dm[rig, side])
        zn = ~rig
        if zn.any():
            w = st["hw"][zn, side]
            np.add.at(v["fapp"], st["hgp"][zn, side].ravel(),
                      (w[:, :, None] * (sg * df[zn])[:, None, :]).reshape(-1, 3))


def block_stiffness(m) -> tuple[np.ndarray, np.ndarray]:
    """Per block row: Σ k_d of the dowels on its rigid sides [N/m], and Σ k_d |r|² (r: dowel point −
    centroid) [N·m]."""
    b = m.blocks
    kt, kr = np.zeros(b.n), np.zeros(b.n)
    if not has_dowels(m):
        return kt, kr
    st = m.stores[DOWELS]
    k = st["prop"][:, D_K]
    for side in range(2):
        on = st["hz"][:, side] == 0
        h = st["blk"][on, side]
        np.add.at(kt, h, k[on])
        np.add.at(kr, h, k[on] * np.sum((st["pos"][on] - b["centroid"][h]) ** 2, axis=1))
    return kt, kr


def gridpoint_stiffness(m, n: int) -> np.ndarray:
    """Per vertex row: the Gershgorin sums of the dowels on deformable sides (``model.hosts``)."""
    out = np.zeros(n)
    if not has_dowels(m):
        return out
    st = m.stores[DOWELS]
    k = st["prop"][:, D_K]
    for side in range(2):
        on = st["hz"][:, side] != 0
        if on.any():
            spread_stiffness(out, st["hgp"][on, side], st["hw"][on, side], k[on])
    return out


#: ``structure hybrid history`` quantities: the dowel's shear force and shear displacement (magnitudes)
DOWEL_QUANTITIES = ("shear-force", "shear-displacement")


def _dowel_row(m, ident: int) -> int:
    from dec3d.errors import CommandError

    st = m.stores.get(DOWELS)
    rows = np.flatnonzero(st["id"] == ident) if st is not None and st.n else np.zeros(0, np.int64)
    if rows.size == 0:
        raise CommandError(f"there is no dowel with id {ident}")
    return int(rows[0])


def add_dowel_history(hs, quantity: str, ident: int, name: str | None = None):
    """Add to HistorySet ``hs`` the shear force [N] or shear displacement [m] of dowel ``ident``."""
    m = hs.model
    if quantity not in DOWEL_QUANTITIES:
        raise ValueError(f"unknown dowel history quantity {quantity!r}")
    _dowel_row(m, ident)
    field = "fs" if quantity == "shear-force" else "us"

    def value(eng) -> float:
        st = m.stores[DOWELS]
        rows = np.flatnonzero(st["id"] == ident)
        # (a dowel dropped with a deleted block carries nothing)
        return float(np.linalg.norm(st[field][rows[0]])) if rows.size else 0.0
    return hs.add(f"dowel {ident} {quantity}", value, name, {"kind": "dowel", "quantity": quantity, "id": int(ident)})
