"""`block zone generate edgelength|edge-length <L> | hexahedra divisions <n1> <n2> <n3> |
high-order-tetra`: zoning of the blocks in range (``dec3d.model.zone_mesh``)."""
from __future__ import annotations

import numpy as np

from ..errors import BindError, ResourceError
from ..model.zones import zone_stores
from .registry import command
from .values import FLAG, Num, Nums, P

# Memory budget: about 1 kB per zone (issue 10); refuse beyond this many zones per command.
ZONE_BUDGET = 20_000_000
# A lattice at spacing L gives about 6 tetrahedra per L^3 (five or six per cube cell).
_TETS_PER_CELL = 6.0


@command("block zone generate",
         keywords=[P("edgelength", Num(lo=0, lo_open=True), "target edge length", units="m"),
                   P("edge-length", Num(lo=0, lo_open=True), "same as edgelength", units="m"),
                   P("hexahedra", FLAG, "hexahedral zones of two overlaid 5-tetrahedron sets (six-faced blocks)"),
                   P("divisions", Nums(3, 3, item=Num(integer=True, lo=1)), "n1 n2 n3 hexahedra along the block's x-, y- and "
                     "z-most edges (with hexahedra)"),
                   P("high-order-tetra", FLAG, "10-node tetrahedra (after model configure highorder)")],
         range="block",
         doc="Zone the blocks in range: 4-node tetrahedra of about the given edge length, hexahedral "
             "mixed-discretization zones, or 10-node tetrahedra.",
         details="`edgelength L`: blocks already zoned are left as they are, so a deck zones fine regions "
                 "first and coarser ones after. `hexahedra divisions n1 n2 n3`: each six-faced block is "
                 "mapped trilinearly from its eight corners into n1 x n2 x n3 hexahedra, each stored as two "
                 "overlaid sets of five tetrahedra (mixed discretization); a block in range that is not "
                 "six-faced is refused by name. `high-order-tetra` (needs `model configure highorder`): the "
                 "4-node zones of the blocks in range become 10-node tetrahedra with a gridpoint at every "
                 "edge midpoint, each surface triangle split in four; with `edgelength L` the unzoned "
                 "blocks are zoned first. Joined blocks (`block join`) are zoned conformingly: a block zoned "
                 "after a joined neighbour takes over the neighbour's gridpoints on their common faces, "
                 "and the copies are linked to one master gridpoint; a warning names the blocks when "
                 "shared faces do not end up with the same triangles (tetrahedra against hexahedra, "
                 "different divisions). A zoning that would make more than "
                 "20 million zones is refused before anything is allocated.",
         examples=["block zone generate edgelength 0.5", "block zone generate edge-length 0.2 range pos-x 0 1",
                   "block zone generate hexahedra divisions 2 5 12", "block zone generate high-order-tetra"])
def block_zone_generate(session, call):
    from ..errors import Dec3dError
    from ..model.zone_mesh import conformity, convert_high_order, zone_hexahedra, zone_tetra, zoned_blocks
    a = call.args
    L = a["edgelength"] if a["edgelength"] is not None else a["edge_length"]
    hexa, divs, ho = a["hexahedra"], a["divisions"], a["high_order_tetra"]
    model = session.model
    if ho and "highorder" not in model.settings.configure:
        raise BindError("`block zone generate high-order-tetra` needs `model configure highorder` first",
                        call.location)
    if hexa and (L is not None or ho):
        raise BindError("`hexahedra` cannot be combined with edgelength or high-order-tetra", call.location)
    if hexa and divs is None:
        raise BindError("`block zone generate hexahedra` needs divisions <n1> <n2> <n3>", call.location)
    if divs is not None and not hexa:
        raise BindError("`divisions` goes with `hexahedra`", call.location)
    if divs is not None and min(int(x) for x in divs) < 1:
        raise BindError("hexahedra divisions must be whole numbers of at least 1", call.location)
    if L is None and not hexa and not ho:
        raise BindError("`block zone generate` needs edgelength <f>, hexahedra divisions <n1> <n2> <n3>, "
                        "or high-order-tetra", call.location)
    zone_stores(model)
    inrange = np.flatnonzero(session.range_mask(call, "block"))
    zoned = zoned_blocks(model)
    rows = [int(r) for r in inrange if not zoned[int(r)]]
    if hexa:
        est = 10.0 * float(np.prod([int(x) for x in divs])) * len(rows)
        what = f"hexahedra divisions {' '.join(str(int(x)) for x in divs)}"
    else:
        est = _TETS_PER_CELL * (float(model.blocks["volume"][rows].sum()) / L / L / L) if (rows and L) else 0.0
        what = f"edgelength {L:g}" if L else "high-order-tetra"
    if est > ZONE_BUDGET:
        raise ResourceError(f"`block zone generate {what}` would make about {est:.3g} zones, over "
                            f"the budget of {ZONE_BUDGET:.3g} zones; use a larger edge length"
                            + (" or fewer divisions" if hexa else ""), call.location)
    try:
        if hexa:
            zone_hexahedra(model, rows, [int(x) for x in divs])
        elif L is not None:
            zone_tetra(model, rows, L)
        if ho:
            convert_high_order(model, [int(r) for r in inrange])
    except Dec3dError as exc:
        raise exc.with_location(call.location)
    rep = conformity(model)
    if rep["unmatched"]:
        pairs = ", ".join(f"{a} / {b} ({n})" for a, b, n in rep["unmatched"][:4])
        more = f" and {len(rep['unmatched']) - 4} more" if len(rep["unmatched"]) > 4 else ""
        session.write(f"warning: {call.location}: joined blocks do not share all surface triangles on their "
                      f"common faces (block / neighbour (triangles): {pairs}{more}); they will not act as one "
                      "continuum there (zone them in one style, tetrahedra or hexahedra, with matching faces)")
