"""`block zone generate edgelength|edge-length <L>`: 4-node tetrahedral zoning of the blocks in
range (first step; hexahedra, high-order-tetra and conformity across joined blocks to come)."""
from __future__ import annotations

import numpy as np

from ..errors import BindError, ResourceError
from ..geometry.assemble import block_poly
from ..geometry.zoning import mesh_convex
from ..model.zones import install_block_mesh, zone_stores
from .registry import command
from .values import FLAG, Num, Nums, P

# Memory budget: about 1 kB per zone (issue 10); refuse beyond this many zones per command.
ZONE_BUDGET = 20_000_000
# A lattice at spacing L gives about 6 tetrahedra per L^3 (five or six per cube cell).
_TETS_PER_CELL = 6.0


@command("block zone generate",
         keywords=[P("edgelength", Num(lo=0, lo_open=True), "target edge length", units="m"),
                   P("edge-length", Num(lo=0, lo_open=True), "same as edgelength", units="m"),
                   P("hexahedra", FLAG, "hexahedral zones of two overlaid 5-tetrahedron sets", supported=False),
                   P("divisions", Nums(3, 3), "n1 n2 n3 hexahedra along the block's edges", supported=False),
                   P("high-order-tetra", FLAG, "10-node tetrahedra (after model configure highorder)",
                     supported=False)],
         range="block",
         doc="Zone the blocks in range into 4-node tetrahedra of about the given edge length.",
         details="Blocks already zoned are left as they are, so a deck zones fine regions first and "
                 "coarser ones after. A zoning that would make more than 20 million zones is refused "
                 "before anything is allocated.",
         examples=["block zone generate edgelength 0.5", "block zone generate edge-length 0.2 range pos-x 0 1"])
def block_zone_generate(session, call):
    a = call.args
    L = a["edgelength"] if a["edgelength"] is not None else a["edge_length"]
    if L is None:
        raise BindError("`block zone generate` needs edgelength <f> (hexahedra and high-order-tetra "
                        "are not implemented yet)", call.location)
    model = session.model
    zs = zone_stores(model)
    zoned = set(zs["block"][: zs.n].tolist())
    rows = [int(r) for r in np.flatnonzero(session.range_mask(call, "block")) if int(r) not in zoned]
    est = _TETS_PER_CELL * float(model.blocks["volume"][rows].sum()) / L ** 3 if rows else 0.0
    if est > ZONE_BUDGET:
        raise ResourceError(f"`block zone generate edgelength {L:g}` would make about {est:.3g} zones, over "
                        f"the budget of {ZONE_BUDGET:.3g} zones; use a larger edge length", call.location)
    ids = model.blocks["id"][rows].copy() if "id" in model.blocks else None
    for k, r in enumerate(rows):
        row = r if ids is None else int(np.flatnonzero(model.blocks["id"][: model.blocks.n] == ids[k])[0])
        poly = block_poly(model, row)
        pts, tets, tris, src = mesh_convex(poly.vertices, poly.face_ptr, poly.face_idx, L)
        install_block_mesh(model, row, pts, tets, tris, src)
