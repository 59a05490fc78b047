"""Flow in the joints, wired to the model (issue 29 item 2; 3DEC theory, "Joint Fluid Flow").

State (saved and restored with the model, no pickle):

- ``model.settings.mechanical["fluid"]``: {"active", "density" ρ_w, "viscosity" μ, "bulk" K_w, "size" (the
  flow-zone size, 0: the sub-contact points), "aperture" [a0, amin, amax] (the default of the flow planes),
  "sig" (the contacts the network was built from)}.
- contact field ``aperture`` (3,): a flow plane's own [a0, amin, amax] (`flowplane property`), −1: the default;
  carried by the pair through detections.
- stores ``flowknots`` (pos, pp, fixed, p_fixed, q_in, vol, supply), ``flowzones`` (the triangles of
  ``physics.flowgeom``: zk, zcontact, zarea, zcot, zsub, zw, zpipe, zap), ``flowpipes`` (pa, pb, c, dg, q) and
  ``flowsubs`` (per sub-contact: its knot; the first sub-contact at its place and how many share it).

The network is built again from the contacts when their set or their sub-contacts change (after a detection,
``after_detection``); knot pressures and boundary conditions go to the new knot at the same place (within the
contact tolerance); a new knot starts from the water table / `block insitu pore-pressure` there. While the fluid
is active (`model configure fluid`, `model fluid active on`) the sub-contact pore pressures are the knots'
(+ `block contact apply pore-pressure`), not the water table's.

Each batch of the cycle (``FluidStep``): apertures from the sub-contacts' normal displacements, conductances and
volumes (``kernels.jointflow.zone_update``), explicit flow steps over the batch's time with Δt ≤ the stable step
(``network_steps``), then the knot pressures to the sub-contacts (``sub_pressures``: each zone's pressure
force handed to the sub-contacts around it, so the pressure inside a contact reaches the blocks): the joint
laws see the effective stress at the next step.
"""
from __future__ import annotations

import hashlib
import math

import numpy as np

from dec3d.errors import CommandError
from dec3d.kernels.jointflow import network_steps, stable_dt, sub_pressures, zone_update
from dec3d.kernels.water import pressure_areas
from dec3d.model.store import Field, Store

from .flowgeom import build_geometry

_F, _I = np.float64, np.int64
DEFAULTS = {"active": True, "density": 1000.0, "viscosity": 1e-3, "bulk": 2e9, "size": 0.0,
            "aperture": [0.0, 0.0, 1.0], "sig": ""}

KNOT_FIELDS = {"pos": Field((3,), _F, 0.0), "pp": Field((), _F, 0.0), "fixed": Field((), np.uint8, 0),
               "p_fixed": Field((), _F, 0.0), "q_in": Field((), _F, 0.0), "vol": Field((), _F, 0.0),
               "supply": Field((), _F, 0.0)}
ZONE_FIELDS = {"zk": Field((3,), _I, -1), "zcontact": Field((), _I, -1), "zarea": Field((), _F, 0.0),
               "zcot": Field((3,), _F, 0.0), "zsub": Field((3,), _I, 0), "zw": Field((3,), _F, 0.0),
               "zpipe": Field((3,), _I, -1), "zap": Field((), _F, 0.0)}
PIPE_FIELDS = {"pa": Field((), _I, 0), "pb": Field((), _I, 0), "c": Field((), _F, 0.0), "dg": Field((), _F, 0.0),
               "q": Field((), _F, 0.0)}
SUB_FIELDS = {"knot": Field((), _I, -1), "rep": Field((), _I, -1), "count": Field((), _F, 1.0)}
STORES = {"flowknots": KNOT_FIELDS, "flowzones": ZONE_FIELDS, "flowpipes": PIPE_FIELDS, "flowsubs": SUB_FIELDS}


def configured(model) -> bool:
    return "fluid" in model.settings.configure


def settings(model) -> dict:
    """The fluid settings (made with the defaults on first use)."""
    mech = model.settings.mechanical
    f = mech.get("fluid")
    if not isinstance(f, dict):
        f = mech["fluid"] = {}
    for k, v in DEFAULTS.items():
        if k not in f:
            f[k] = list(v) if isinstance(v, list) else v
    return f


def active(model) -> bool:
    f = model.settings.mechanical.get("fluid")
    return configured(model) and isinstance(f, dict) and bool(f.get("active", True))


def stores(model) -> dict:
    """The four flow stores (made on first use) and the contacts' ``aperture`` field."""
    for name, fields in STORES.items():
        if name not in model.stores:
            model.add_store(Store(name, fields, capacity=64))
    cs = model.store("contacts")
    if "aperture" not in cs:
        cs.add_field("aperture", Field((3,), _F, -1.0))
    return {name: model.store(name) for name in STORES}


def _signature(eng, f) -> str:
    cs, ss = eng.contacts, eng.subcontacts
    h = hashlib.sha1()
    for a in (cs["ida"], cs["idb"], cs["sub_count"], ss["kind"], ss["key0"], ss["key1"]):
        h.update(np.ascontiguousarray(a).tobytes())
    # (and what the pipes' gravity term and the merging depend on)
    h.update(repr((float(f["size"]), float(eng.model.tolerance), float(f["density"]),
                   [float(g) for g in eng.model.settings.gravity])).encode())
    return h.hexdigest()


def _source_pressure(model, pos) -> np.ndarray:
    """The water table's and `block insitu pore-pressure`'s pressure at points pos (a new knot's start)."""
    from .water import table_pressure

    w = model.settings.mechanical.get("water")
    if not isinstance(w, dict) or not len(pos):
        return np.zeros(len(pos))
    p = table_pressure(pos, float(w.get("density", 0.0)), w.get("plane"), model.settings.gravity)
    ins = w.get("insitu")
    if ins:
        p = p + ins[0] + pos @ np.asarray(ins[1:], dtype=_F)
    return p


def rebuild(eng, force: bool = False) -> bool:
    """Build the network from the contacts when they changed since it was built (or ``force``). Returns
    whether it was built."""
    m = eng.model
    f = settings(m)
    st = stores(m)
    sig = _signature(eng, f)
    if not force and sig == f.get("sig") and st["flowsubs"].n == eng.subcontacts.n:
        return False
    cs, ss = eng.contacts, eng.subcontacts
    try:
        geo = build_geometry(cs["sub_start"], cs["sub_count"], cs["normal"], ss["pos"], float(f["size"]),
                             float(m.tolerance))
    except ValueError as exc:
        raise CommandError(str(exc)) from None
    kn = st["flowknots"]
    old_pos = kn["pos"].copy()
    old = {k: kn[k].copy() for k in ("pp", "fixed", "p_fixed", "q_in")}
    nk = len(geo["pos"])
    pp = _source_pressure(m, geo["pos"])
    carry = {"pp": pp, "fixed": np.zeros(nk, np.uint8), "p_fixed": np.zeros(nk), "q_in": np.zeros(nk)}
    if len(old_pos) and nk:
        from scipy.spatial import cKDTree

        d, j = cKDTree(old_pos).query(geo["pos"])
        hit = d <= max(eng.tolerance(), float(m.tolerance))
        for k in carry:
            carry[k][hit] = old[k][j[hit]]
    kn.clear()
    kn.append(nk)
    kn["pos"][...] = geo["pos"]
    for k, v in carry.items():
        kn[k][...] = v
    zs = st["flowzones"]
    zs.clear()
    zs.append(len(geo["zk"]))
    for k in ("zk", "zcontact", "zarea", "zcot", "zsub", "zw", "zpipe"):
        zs[k][...] = geo[k]
    ps = st["flowpipes"]
    ps.clear()
    ps.append(len(geo["pa"]))
    ps["pa"][...] = geo["pa"]
    ps["pb"][...] = geo["pb"]
    g = np.asarray(m.settings.gravity, dtype=_F)
    ps["dg"][...] = -float(f["density"]) * ((geo["pos"][geo["pa"]] - geo["pos"][geo["pb"]]) @ g)
    sb = st["flowsubs"]
    sb.clear()
    sb.append(ss.n)
    sb["knot"][...] = geo["sknot"]
    sb["rep"][...] = geo["srep"]
    sb["count"][...] = np.bincount(geo["srep"], minlength=ss.n).astype(_F)
    f["sig"] = sig
    update(eng)
    return True


def apertures(model) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each contact's (a0, amin, amax): its own `flowplane property` values, else the default."""
    f = settings(model)
    cs = model.store("contacts")
    own = cs["aperture"]
    out = [np.where(own[:, i] >= 0.0, own[:, i], float(f["aperture"][i])) for i in range(3)]
    return out[0], out[1], out[2]


def update(eng) -> None:
    """Apertures from the normal displacements, pipe conductances and knot volumes (``zone_update``)."""
    m = eng.model
    f = settings(m)
    st = stores(m)
    zs, ps, kn = st["flowzones"], st["flowpipes"], st["flowknots"]
    a0, amin, amax = apertures(m)
    zone_update(zs["zsub"], zs["zw"], zs["zcontact"], eng.subcontacts["un"], a0, amin, amax, zs["zk"], zs["zarea"],
                zs["zcot"], zs["zpipe"], float(f["viscosity"]), zs["zap"], ps["c"], kn["vol"])


def to_subcontacts(eng) -> None:
    """The knots' pressures to the sub-contacts' ``pp`` (+ the contact's applied pressure) and their force on
    the faces ``ppf`` from the flow zones (``kernels.jointflow.sub_pressures``)."""
    m = eng.model
    st = stores(m)
    ss, cs = eng.subcontacts, eng.contacts
    p = st["flowknots"]["pp"]
    if not np.all(np.isfinite(p)):
        raise CommandError("a flow knot's pressure is not finite: refused before it reaches a contact force")
    if st["flowsubs"].n != ss.n:
        return
    parea = np.empty(ss.n)
    if ss.n:
        pressure_areas(cs["sub_start"], cs["sub_count"], cs["normal"], ss["pos"], ss["area"], parea)
    sb, zs = st["flowsubs"], st["flowzones"]
    sub_pressures(sb["knot"], sb["rep"], sb["count"], ss["contact"], p, cs["pp_apply"], parea, zs["zk"], zs["zsub"],
                  zs["zw"], zs["zarea"], ss["pp"], ss["ppf"])


def _check(eng) -> None:
    """The network's indices point at live rows (a restored file could hold anything): else built anew."""
    st = stores(eng.model)
    kn, zs, ps, sb = st["flowknots"], st["flowzones"], st["flowpipes"], st["flowsubs"]
    nk, ns, npipe = kn.n, eng.subcontacts.n, ps.n

    def inside(a, n, low=0):
        return a.size == 0 or (int(a.min()) >= low and int(a.max()) < n)

    ok = (sb.n == ns and inside(zs["zk"], nk) and inside(zs["zsub"], ns) and inside(zs["zpipe"], npipe, -1)
          and inside(zs["zcontact"], eng.contacts.n) and inside(ps["pa"], nk) and inside(ps["pb"], nk)
          and inside(sb["knot"], nk, -1) and inside(sb["rep"], ns) and bool(np.all(sb["count"][sb["rep"]] >= 1)))
    if not ok:
        settings(eng.model)["sig"] = ""


def after_detection(eng) -> None:
    """Called where the water pressures are worked out (``water.refresh``) while the fluid is active: the
    network follows the contacts and the sub-contacts take the knots' pressures."""
    _check(eng)
    rebuild(eng)
    to_subcontacts(eng)


def _supply(kn, ps) -> None:
    """Each fixed knot's supply [m³/s]: what its boundary puts into the network (net pipe outflow there);
    at the others the applied discharge."""
    net = np.zeros(kn.n)
    np.add.at(net, ps["pa"], ps["q"])
    np.add.at(net, ps["pb"], -ps["q"])
    kn["supply"][...] = np.where(kn["fixed"] != 0, net, kn["q_in"])


def stable_step(eng) -> float:
    """The stable explicit flow step of the network as it is now [s] (inf without pipes)."""
    st = stores(eng.model)
    kn, ps = st["flowknots"], st["flowpipes"]
    update(eng)
    return float(stable_dt(ps["pa"], ps["pb"], ps["c"], kn["vol"], float(settings(eng.model)["bulk"]),
                           kn["fixed"] != 0))


def advance(eng, span: float) -> int:
    """Transient flow over ``span`` seconds: explicit steps of at most the stable Δt (never larger: a step
    too large is reduced). Returns the flow steps taken."""
    m = eng.model
    f = settings(m)
    st = stores(m)
    kn, ps = st["flowknots"], st["flowpipes"]
    if not kn.n or not span > 0.0:
        return 0
    update(eng)
    fixed = kn["fixed"] != 0
    p = kn["pp"]
    p[fixed] = kn["p_fixed"][fixed]
    kw = float(f["bulk"])
    h = stable_dt(ps["pa"], ps["pb"], ps["c"], kn["vol"], kw, fixed)
    n = max(1, int(math.ceil(span / h - 1e-9))) if math.isfinite(h) else 1
    network_steps(n, span / n, ps["pa"], ps["pb"], ps["c"], ps["dg"], kn["vol"], kw, fixed, kn["q_in"], p, ps["q"])
    _supply(kn, ps)
    return n


def solve_steady(eng) -> tuple[int, int]:
    """The steady state of every part of the network that holds a pressure boundary (a sparse direct solve,
    ``jointflow.steady``); the other parts keep their pressures. Returns (knots solved, parts left out)."""
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import connected_components

    from .jointflow import steady

    m = eng.model
    st = stores(m)
    kn, ps = st["flowknots"], st["flowpipes"]
    update(eng)
    nk = kn.n
    fixed = kn["fixed"] != 0
    if not fixed.any():
        raise CommandError("no flow knot has a pressure boundary (`flowknot apply pore-pressure`): "
                           "the steady state is not defined")
    live = ps["c"] > 0.0
    g = csr_matrix((np.ones(int(live.sum())), (ps["pa"][live], ps["pb"][live])), shape=(nk, nk))
    ncomp, lab = connected_components(g, directed=False)
    held = np.zeros(ncomp, bool)
    held[lab[fixed]] = True
    take = held[lab]
    idx = np.flatnonzero(take)
    remap = np.full(nk, -1, _I)
    remap[idx] = np.arange(len(idx))
    sel = take[ps["pa"]] & take[ps["pb"]]
    p, q = steady(len(idx), remap[ps["pa"][sel]], remap[ps["pb"][sel]], ps["c"][sel], fixed[idx],
                  kn["p_fixed"][idx], kn["q_in"][idx], ps["dg"][sel])
    kn["pp"][idx] = p
    ps["q"][...] = 0.0
    ps["q"][sel] = q
    _supply(kn, ps)
    to_subcontacts(eng)
    return len(idx), int(ncomp - held.sum())


#: `flowknot history <quantity>`: what is recorded at the knot nearest a point
FLOWKNOT_QUANTITIES = {"pore-pressure": "pp", "discharge": "supply"}


def flowknot_history(model, quantity: str, position) -> tuple[str, object, dict]:
    """(label, value(eng), spec) of a history of the knot nearest ``position`` at each sample (the network is
    built again when the contacts change): its pressure [Pa] or the discharge its boundary supplies [m³/s];
    NaN while there is no knot."""
    fld = FLOWKNOT_QUANTITIES[quantity]
    pos = np.asarray(position, dtype=_F)

    def value(eng) -> float:
        kn = model.stores.get("flowknots")
        if kn is None or not kn.n:
            return float("nan")
        return float(kn[fld][int(np.argmin(np.linalg.norm(kn["pos"] - pos, axis=1)))])

    label = f"flow knot near ({pos[0]:g} {pos[1]:g} {pos[2]:g}) {quantity}"
    return label, value, {"kind": "flowknot", "quantity": quantity, "position": [float(x) for x in pos]}
