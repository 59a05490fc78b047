"""`block zone generate edgelength|edge-length <L> | hexahedra divisions <n1> <n2> <n3> |
high-order-tetra`: zoning of the blocks in range (``dec3d.model.zone_mesh``)."""
from __future__ import annotations

import numpy as np

from ..errors import BindError, CommandError, ResourceError
from ..model.zones import zone_stores
from ..units import suffix
from .registry import command
from .values import FLAG, Choice, Num, Nums, P

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
                 "different divisions). Cable, beam and liner nodes made on a block before it was zoned are "
                 "coupled to its zones from then on (to the zone holding each; a node outside every zone is "
                 "freed). A zoning that would make more than "
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
    from ..model.cables import rehost
    rehost(model)           # cable, beam and liner nodes made on these blocks before: on their zones now
    rep = conformity(model)
    if rep["unmatched"]:
        pairs = ", ".join(f"{a} / {b} ({n})" for a, b, n in rep["unmatched"][:4])
        more = f" and {len(rep['unmatched']) - 4} more" if len(rep["unmatched"]) > 4 else ""
        session.write(f"warning: {call.location}: joined blocks do not share all surface triangles on their "
                      f"common faces (block / neighbour (triangles): {pairs}{more}); they will not act as one "
                      "continuum there (zone them in one style, tetrahedra or hexahedra, with matching faces)")


# ----------------------------------------------------------------------------- zone stresses
_COMPS = ("xx", "yy", "zz", "xy", "xz", "yz")
#: Gauss points of a 10-node zone (4-point rule): barycentric weight A on one corner, B on the others
_GA, _GB = 0.5854101966249685, 0.1381966011250105


def _zone_rows(session, call, what: str) -> np.ndarray:
    """Rows of the zones in range; a warning naming file:line when there are none."""
    m = session.model
    zone_stores(m)
    rows = np.flatnonzero(session.range_mask(call, "zone"))
    if not len(rows):
        session.write(f"warning: {call.location}: `{what}` selected no zone"
                      + (" (there are no zones: `block zone generate` makes them)" if m.store("zones").n == 0
                         else ""))
    return rows


def _gauss_points(model, rows) -> np.ndarray:
    """(m, 4, 3) Gauss points of the zones ``rows`` (used for 10-node zones)."""
    from ..model.zone_quality import corners
    p = corners(model, rows)
    w = np.full((4, 4), _GB)
    np.fill_diagonal(w, _GA)
    return np.einsum("gk,mkd->mgd", w, p)


def stress_updates(model, rows, comp: int, value, how: str = "set") -> list:
    """New values of stress component ``comp`` of the zones ``rows``: set (how='set'), added
    ('add') or multiplied ('multiply'); ``value(points (..., 3)) -> (...)`` gives the value at zone
    centroids and Gauss points. A 10-node zone takes the value at each Gauss point, its stress
    being their mean. Returns [(field, index, values)] for ``write_updates`` (nothing written yet,
    so a command can check every value first)."""
    zs = model.store("zones")
    rows = np.asarray(rows, dtype=np.int64)
    ho = rows[zs["nnode"][rows] == 10]
    lo = rows[zs["nnode"][rows] != 10]

    def combine(old, new):
        return new if how == "set" else old + new if how == "add" else old * new

    with np.errstate(over="ignore", invalid="ignore"):     # checked by write_updates
        return _stress_updates(model, zs, lo, ho, comp, value, combine)


def _stress_updates(model, zs, lo, ho, comp, value, combine) -> list:
    from ..model.zone_quality import centroids
    out = []
    if lo.size:
        out.append(("stress", (lo, comp), combine(zs["stress"][lo, comp], value(centroids(model, lo)))))
    if ho.size:
        g = combine(zs["gstress"][ho, :, comp], value(_gauss_points(model, ho)))
        out.append(("gstress", (ho, slice(None), comp), g))
        out.append(("stress", (ho, comp), g.mean(axis=1)))
    return out


def write_updates(model, updates: list, where) -> None:
    """Write ``stress_updates`` results after checking they are all finite (else nothing is written)."""
    for _, _, vals in updates:
        if not np.isfinite(vals).all():
            raise CommandError("the stress would not be finite (a gradient too large for the model's "
                               "coordinates?); nothing was changed", where)
    zs = model.store("zones")
    for key, idx, vals in updates:
        zs[key][idx] = vals


def _check_initialize(call):
    a = call.args
    comps = [c for c in _COMPS if a[f"stress_{c}"] is not None]
    if a["stress"] is None and not comps:
        raise BindError("`block zone initialize` needs stress <sxx syy szz sxy sxz syz> or stress-xx … <f>",
                        call.location)
    if a["stress"] is not None and comps:
        raise BindError("give either stress <6 values> or stress-xx … components, not both", call.location)
    if a["add"] and a["multiply"]:
        raise BindError("give `add` or `multiply`, not both", call.location)
    if a["gradient"] is not None:
        if a["stress"] is not None or len(comps) != 1:
            raise BindError("`gradient` goes with exactly one stress component (stress-xx … <f> gradient <gx gy gz>)",
                            call.locations.get("gradient", call.location))
        if a["multiply"]:
            raise BindError("`gradient` cannot be combined with `multiply`", call.location)
    elif a["origin"] is not None:
        raise BindError("`origin` is the point where a `gradient` starts: give `gradient` too",
                        call.locations.get("origin", call.location))


@command("block zone initialize",
         keywords=[P("stress", Nums(6, 6), "sxx syy szz sxy sxz syz (tension positive)", units="Pa"),
                   *[P(f"stress-{c}", Num(), f"the {c} component", units="Pa") for c in _COMPS],
                   P("gradient", Nums(3, 3), "gx gy gz: the component varies as f + g·(x − origin)", units="Pa/m"),
                   P("origin", Nums(3, 3), "where the gradient starts (default 0 0 0)", units="m"),
                   P("add", FLAG, "add to the present value instead of replacing it", bare=True),
                   P("multiply", FLAG, "multiply the present value instead of replacing it", bare=True),
                   P("vary", Nums(3, 3), "random variation", supported=False)],
         range="zone", check=_check_initialize,
         doc="Set the stress of the zones in range (located by centroid), all six components or some.",
         details="Stresses are tension positive (3DEC sign convention). With `gradient gx gy gz` one component "
                 "varies linearly: f + gx (x − x0) + gy (y − y0) + gz (z − z0), (x0 y0 z0) the `origin` "
                 "(default 0 0 0), taken at the zone centroid; a 10-node zone takes it at each of its four "
                 "Gauss points and its stress is their mean. `add` adds to and `multiply` multiplies the "
                 "stress there. Gridpoint forces follow from the stresses at the next step.",
         examples=["block zone initialize stress -1e6 -1e6 -2e6 0 0 0",
                   "block zone initialize stress-zz -1e6 gradient 0 0 2.6e4 range group 'rock'",
                   "block zone initialize stress-xx 1e5 add range position-z 0 5"])
def block_zone_initialize(session, call):
    a = call.args
    rows = _zone_rows(session, call, "block zone initialize")
    how = "add" if a["add"] else "multiply" if a["multiply"] else "set"
    if a["stress"] is not None:
        vals = [(i, float(v)) for i, v in enumerate(a["stress"])]
    else:
        vals = [(i, float(a[f"stress_{c}"])) for i, c in enumerate(_COMPS) if a[f"stress_{c}"] is not None]
    grad = np.zeros(3) if a["gradient"] is None else np.asarray(a["gradient"], float)
    origin = np.zeros(3) if a["origin"] is None else np.asarray(a["origin"], float)
    if not len(rows):
        return
    updates = []
    for i, f in vals:
        updates += stress_updates(session.model, rows, i, lambda x, f=f: f + (x - origin) @ grad, how)
    write_updates(session.model, updates, call.location)


# ----------------------------------------------------------------------------- in-situ stress
def insitu_contact_forces(model, cmask, stress_at) -> tuple | None:
    """Sub-contact forces of the contacts ``cmask`` under the stress field ``stress_at(points) -> (k, 6)``.

    On a plane of unit normal n (A → B) the material on B's side pulls A by the traction σ·n
    (Cauchy), so the force on B is F = −A σ·n, A the sub-contact area. Its normal part is the
    normal force (compression positive), its tangential part the shear force on B:
        fn = −A n·σ·n,   fs = −A (σ·n − (n·σ·n) n).
    The joint law works from the total normal displacement (Fn = −kn A (un − u_dil),
    dec3d.kernels.jointlaw), so un is set to u_dil − fn / (kn A) for the force to persist.
    Returns (sub-contact rows, fn, fs, un) or None when there are no contacts."""
    from ..physics.jmodels import stiffness
    from ..model.zone_quality import tensor
    if "contacts" not in model.stores:
        return None
    cs, ss = model.store("contacts"), model.store("subcontacts")
    if cs.n == 0 or ss.n == 0:
        return None
    sub = np.flatnonzero(np.asarray(cmask, bool)[ss["contact"]])
    c = ss["contact"][sub]
    n = cs["normal"][c]
    area = ss["area"][sub]
    t = np.einsum("kij,kj->ki", tensor(stress_at(ss["pos"][sub])), n)      # σ·n
    tn = np.einsum("ki,ki->k", t, n)
    fn = -area * tn
    fs = -area[:, None] * (t - tn[:, None] * n)
    kna = stiffness(cs, ss)[0][sub] * area
    un = np.where(kna > 0.0, ss["udil"][sub] - fn / np.where(kna > 0.0, kna, 1.0), ss["un"][sub])
    return sub, fn, fs, un


@command("block insitu",
         keywords=[P("stress", Nums(6, 6), "sxx syy szz sxy sxz syz at the origin (tension positive)", units="Pa"),
                   *[P(f"gradient-{ax}", Nums(6, 6), f"the change of the six components per metre of {ax}",
                       units="Pa/m") for ax in ("x", "y", "z")],
                   P("nodisplacements", FLAG, "keep displacements", bare=True, supported=False),
                   P("total", FLAG, "total stresses with pore pressure", bare=True, supported=False),
                   P("pore-pressure", Num(), "pore pressure of the joints at the origin (with `gradient`)", units="Pa"),
                   P("gradient", Nums(3, 3), "the pore pressure's change per metre of x, y and z", units="Pa/m"),
                   P("fluid-temperature", Num(), "fluid temperature", supported=False)],
         range="zone",
         doc="Set an in-situ stress: the stress of the zones in range and the forces of the existing "
             "sub-contacts in range, consistently.",
         details="σ(x) = σ0 + x·gx + y·gy + z·gz, each g a six-component `gradient-x|y|z` (default zero), tension "
                 "positive. Zones (located by centroid) take σ at their centroid (10-node zones at each Gauss "
                 "point). Each sub-contact of a contact in range (located by the contact's point; groups of the "
                 "contact or of its blocks) takes the force of the traction on its plane: normal force "
                 "−A n·σ·n (compression positive), shear force −A (σ·n − (n·σ·n) n) on the second block, A its "
                 "area, n the contact normal; its normal displacement is set so the joint law keeps that force. "
                 "The contacts are detected first if the blocks changed since the last detection (as 3DEC "
                 "keeps them current), and those following the material-table defaults take them, so the "
                 "force is kept with the stiffness they will cycle with. Contacts made later "
                 "start from their own gap. Displacements are not changed.\n\n"
                 "`pore-pressure p0 gradient gx gy gz` sets the pore pressure of every joint sub-contact to p0 + "
                 "gx x + gy y + gz z (3DEC's words; in dec3d it reaches the joints only, zones carry no pore "
                 "pressure), added to a water table's and to `block contact apply pore-pressure`; the joint models "
                 "then work on effective stress (see `block water`).",
         examples=["block insitu stress -30e6 -30e6 -15e6 0 0 0",
                   "block insitu stress -1e6 -1e6 -2e6 0 0 0 gradient-z 1e4 1e4 2e4 0 0 0 range group 'rock'",
                   "block insitu pore-pressure 1e6 gradient 0 0 -9810"])
def block_insitu(session, call):
    a = call.args
    if a["pore_pressure"] is not None:
        from ..physics.water import set_insitu
        if call.range is not None:
            raise BindError("`block insitu pore-pressure` sets every joint: a range is not supported yet", call.location)
        set_insitu(session.model, float(a["pore_pressure"]), a["gradient"])
        if session.model.blocks.n > 1:
            from ..physics.rigid import engine
            from ..physics.water import refresh
            eng = engine(session.model)
            eng.ensure_contacts()
            refresh(eng)
        if a["stress"] is None:
            return
    elif a["gradient"] is not None:
        raise BindError("`gradient` goes with `pore-pressure`", call.locations.get("gradient", call.location))
    if a["stress"] is None:
        raise BindError("`block insitu` needs stress <sxx syy szz sxy sxz syz> or pore-pressure <p>", call.location)
    m = session.model
    s0 = np.asarray(a["stress"], float)
    grad = np.array([np.zeros(6) if a[f"gradient_{ax}"] is None else np.asarray(a[f"gradient_{ax}"], float)
                     for ax in ("x", "y", "z")])                     # (3, 6): row d = d σ / d x_d

    def stress_at(x):
        return s0 + x @ grad

    zone_stores(m)
    zrows = np.flatnonzero(session.range_mask(call, "zone"))
    updates = []
    for i in range(6):
        updates += stress_updates(m, zrows, i, lambda x, i=i: stress_at(x)[..., i])
    contact = None
    if m.blocks.n > 1:
        # contacts as 3DEC keeps them (current whenever blocks exist), with the joint properties
        # of the material table now: a contact made before `material-table default property …`
        # still had the old stiffness, so the normal displacement set below would not have kept
        # the force (it fell to zero at the first cycle, when the contact took the new kn)
        from ..physics.rigid import engine
        eng = engine(m)
        eng.ensure_contacts()
        eng.follow_defaults()
    if "contacts" in m.stores and m.store("contacts").n:
        try:
            cmask = session.range_mask(call, "contact")
        except CommandError as exc:              # an element contacts lack (`id`): the zones only
            cmask = None
            session.write(f"warning: {call.location}: `block insitu`: the range does not select contacts "
                          f"({exc.message}); their forces are left as they are")
        if cmask is not None:
            with np.errstate(over="ignore", invalid="ignore"):      # checked below
                contact = insitu_contact_forces(m, cmask, stress_at)
    if contact is not None and not all(np.isfinite(v).all() for v in contact[1:]):
        raise CommandError("a sub-contact force would not be finite; nothing was changed", call.location)
    write_updates(m, updates, call.location)
    nsub = 0
    if contact is not None:
        sub, fn, fs, un = contact
        ss = m.store("subcontacts")
        ss["fn"][sub], ss["fs"][sub], ss["un"][sub] = fn, fs, un
        nsub = len(sub)
    if not len(zrows) and not nsub:
        session.write(f"warning: {call.location}: `block insitu` selected no zone and no sub-contact")


# ----------------------------------------------------------------------------- listing
def _plastic_counts(session, zs, rows) -> None:
    """Zones of the rows in each plastic state (``zones.state`` bits), when some have a plastic model:
    a line of output and the session results ``zones_shear_now`` … ``zones_tension_past`` (and the weak
    plane's ``zones_joint_shear_now`` … when a zone in range has such bits)."""
    from ..kernels.zmodels import PLASTIC_CODES
    from ..model.zones import ZSTATE_BITS

    if not np.isin(zs["cmodel"][rows], sorted(PLASTIC_CODES)).any():
        return
    st = zs["state"][rows]
    counts = {name: int(((st & bit) != 0).sum()) for name, bit in ZSTATE_BITS
              if not name.startswith("joint") or (st >= 16).any()}
    past = 0
    for name, bit in ZSTATE_BITS:
        if name.endswith("past"):
            past |= bit
    elastic = int(((st & past) == 0).sum())
    session.write("plastic state: " + ", ".join(f"{k} {n}" for k, n in counts.items())
                  + f", never yielded {elastic}")
    session.results.update({"zones_" + k.replace("-", "_"): float(n) for k, n in counts.items()})


@command("block zone list", positional=[P("what", Choice(("information",)), "mesh summary instead of a zone table")],
         range="zone",
         doc="List the zones in range (id, block, centroid, volume, stress), or a mesh summary with `information`.",
         details="`information`: number of zones and of gridpoints (a gridpoint shared by joined blocks counted "
                 "once), smallest and largest edge, smallest dihedral angle (70.53° for a regular tetrahedron, "
                 "near 0 for a sliver), smallest and total volume. These go into the session results as "
                 "`zones`, `gridpoints`, `zone_edge_min`, `zone_edge_max`, `zone_dihedral_min` (degrees), "
                 "`zone_volume_min` and `zone_volume`. With zones of a plastic model in range, both forms also count the "
                 "zones by plastic state (shear-now, tension-now, shear-past, tension-past, never yielded), "
                 "kept as results `zones_shear_now` … `zones_tension_past`.",
         examples=["block zone list", "block zone list information", "block zone list range position-z 0 1"])
def block_zone_list(session, call):
    from ..model.zone_quality import centroids, mesh_information
    m = session.model
    zs = zone_stores(m)
    rows = np.flatnonzero(session.range_mask(call, "zone"))
    if call.args["what"] == "information":
        info = mesh_information(m, rows)
        session.write(f"zones {info['zones']} (of {zs.n}), gridpoints {info['gridpoints']}")
        session.results.update({"zones": float(info["zones"]), "gridpoints": float(info["gridpoints"])})
        if info["zones"]:
            L, V = suffix(m, "length"), suffix(m, "volume")
            session.write(f"edge length: smallest {info['edge_min']:.6g}{L}, largest {info['edge_max']:.6g}{L}")
            session.write(f"smallest dihedral angle {info['dihedral_min']:.4g} degrees")
            session.write(f"volume: smallest {info['volume_min']:.6g}{V}, total {info['volume_total']:.6g}{V}")
            session.results.update({"zone_edge_min": info["edge_min"], "zone_edge_max": info["edge_max"],
                                    "zone_dihedral_min": info["dihedral_min"],
                                    "zone_volume_min": info["volume_min"], "zone_volume": info["volume_total"]})
        _plastic_counts(session, zs, rows)
        return
    _plastic_counts(session, zs, rows)
    c = centroids(m, rows)
    bid = m.blocks["id"][zs["block"][rows]]
    head = " ".join(f"{'s' + k:>11}" for k in _COMPS)
    session.write(f"{'id':>7} {'block':>6} {'x':>11} {'y':>11} {'z':>11} {'volume':>11} {head}")
    for k, r in enumerate(rows):
        s = " ".join(f"{v:>11.5g}" for v in zs["stress"][r])
        session.write(f"{zs['id'][r]:>7} {bid[k]:>6} {c[k, 0]:>11.5g} {c[k, 1]:>11.5g} {c[k, 2]:>11.5g} "
                      f"{zs['volume'][r]:>11.5g} {s}")
