"""Closed-form fields that verification problems compare the whole model state with
(`[[derive]]` kinds of ``dec3d verify`` that read the model, not a history file).

``kirsch``: a circular hole of radius a in an infinite, isotropic, linear elastic medium
under far-field stresses p1 (along x) and p2 (along z), hole axis along y, plane strain
(Kirsch; Jaeger & Cook, "Fundamentals of Rock Mechanics", §10.4). Compressive stresses and
the inward displacement are positive in the formulas, as in Itasca's verification
"Cylindrical Hole in an Infinite Elastic Medium" (3DEC verification problems). The error
measures are the ones that verification defines (its FISH file ``ElasticHole.fis``):

- radial and tangential stress: the mean over every zone of |σ − σ_exact| / p1, in %, the
  numerical σ_r, σ_θ from the zone stress at the zone centroid;
- displacement: Σ over every gridpoint of ||u_xz| − u_exact| / (N · u_edge), in %, where
  u_edge is the exact radial displacement at the hole wall on the x axis and N the number of
  gridpoints (shared gridpoints of joined blocks counted once per block, as 3DEC lists them).

``uniaxial`` and ``self_weight``: the patch test and the self-weight column of the deformable
blocks (shared/verification/PROBLEMS.md D1, D2), measures in their functions' docstrings.

``zone_block``: the mean zone stress and the yielding fractions of one block (the triaxial
specimens of D4). ``footing``: the mean pressure under a strip footing (D5). ``salencon``: the
plastic radius and the stresses around a hole in a Mohr-Coulomb medium (D6).
"""
from __future__ import annotations

import numpy as np


def kirsch_exact(x: np.ndarray, z: np.ndarray, p1: float, p2: float, a: float, shear: float, nu: float):
    """(σ_r, σ_θ, u_r) at points (x, z): stresses compression positive [Pa], u_r the radial
    displacement towards the hole [m] caused by making the hole."""
    r = np.hypot(x, z)
    th = np.arctan2(z, x)
    q2 = (a / r) ** 2
    c2 = np.cos(2.0 * th)
    sr = 0.5 * (p1 + p2) * (1.0 - q2) + 0.5 * (p1 - p2) * (1.0 - 4.0 * q2 + 3.0 * q2 * q2) * c2
    st = 0.5 * (p1 + p2) * (1.0 + q2) - 0.5 * (p1 - p2) * (1.0 + 3.0 * q2 * q2) * c2
    ur = 0.25 * ((p1 + p2) + (p1 - p2) * (4.0 * (1.0 - nu) - q2) * c2) * (a / r) * a / shear
    return sr, st, ur


def kirsch_errors(model, p1: float, p2: float, a: float, bulk: float, shear: float) -> dict[str, float]:
    """The three error measures (%) of the module docstring over the model's zones and gridpoints."""
    zs = model.store("zones")
    vs = model.vertices
    if zs.n == 0:
        raise ValueError("kirsch: the model has no zones")
    nu = (3.0 * bulk - 2.0 * shear) / (6.0 * bulk + 2.0 * shear)
    pos = vs["pos"]
    cen = pos[zs["gp"][:, :4]].mean(axis=1)
    x, z = cen[:, 0], cen[:, 2]
    sr_e, st_e, _ = kirsch_exact(x, z, p1, p2, a, shear, nu)
    s = zs["stress"]
    th = np.arctan2(z, x)
    mean = 0.5 * (s[:, 0] + s[:, 2])
    half = 0.5 * (s[:, 0] - s[:, 2])
    sxz = s[:, 4]
    sr = -(mean + half * np.cos(2.0 * th) + sxz * np.sin(2.0 * th))
    st = -(mean - half * np.cos(2.0 * th) - sxz * np.sin(2.0 * th))
    err_sr = 100.0 * float(np.mean(np.abs(sr - sr_e))) / p1
    err_st = 100.0 * float(np.mean(np.abs(st - st_e))) / p1
    gp = np.flatnonzero(vs["zoned"])
    gx, gz = pos[gp, 0], pos[gp, 2]
    _, _, u_e = kirsch_exact(gx, gz, p1, p2, a, shear, nu)
    u = np.hypot(vs["disp"][gp, 0], vs["disp"][gp, 2])
    u_edge = 0.25 * ((p1 + p2) + (p1 - p2) * (4.0 * (1.0 - nu) - 1.0)) / shear
    err_d = 100.0 * float(np.sum(np.abs(u - u_e))) / (u_edge * len(gp))
    return {"sigr": err_sr, "sigt": err_st, "disp": err_d}


def _slope(x: np.ndarray, y: np.ndarray) -> float:
    """Least-squares slope dy/dx."""
    xm = x - x.mean()
    return float((xm * (y - y.mean())).sum() / (xm * xm).sum())


def uniaxial_measures(model, sigma: float) -> dict[str, float]:
    """A prism of zones under a uniform axial stress ``sigma`` along z (tension positive) on
    rollers (verification D1): the strains as least-squares slopes of the gridpoint
    displacements, ``ezz`` = du_z/dz and ``exx`` = du_x/dx (closed form σ/E and −ν σ/E), and
    ``spread``: the largest deviation of any zone's stress tensor from (0, 0, σ, 0, 0, 0),
    relative to |σ| (closed form 0)."""
    zs, vs = model.store("zones"), model.vertices
    if zs.n == 0:
        raise ValueError("uniaxial: the model has no zones")
    gp = np.flatnonzero(vs["zoned"])
    p, u = vs["pos"][gp], vs["disp"][gp]
    want = np.array([0.0, 0.0, sigma, 0.0, 0.0, 0.0])
    spread = float(np.abs(zs["stress"] - want).max()) / abs(sigma)
    return {"ezz": _slope(p[:, 2], u[:, 2]), "exx": _slope(p[:, 0], u[:, 0]), "spread": spread}


def self_weight_measures(model, density: float, g: float, height: float) -> dict[str, float]:
    """A column of zones standing on z = 0 under its own weight (verification D2): ``settle``
    the mean downward displacement of the gridpoints at the top (z = height) [m]; ``stress``
    the mean over the zones of |σ_zz − σ_exact| / (ρ g H) in %, σ_exact = −ρ g (H − z) at the
    zone centroid; ``stress_max`` the largest of those deviations, in %."""
    zs, vs = model.store("zones"), model.vertices
    if zs.n == 0:
        raise ValueError("self-weight: the model has no zones")
    gp = np.flatnonzero(vs["zoned"])
    top = gp[np.abs(vs["pos"][gp, 2] - height) <= 1e-6 * height]
    if not len(top):
        raise ValueError(f"self-weight: no gridpoint at the top z = {height:g}")
    zc = vs["pos"][zs["gp"][:, :4]].mean(axis=1)[:, 2]
    dev = np.abs(zs["stress"][:, 2] + density * g * (height - zc)) / (density * g * height)
    return {"settle": -float(vs["disp"][top, 2].mean()), "stress": 100.0 * float(dev.mean()),
            "stress_max": 100.0 * float(dev.max())}


def zone_block_measures(model, block: float) -> dict[str, float]:
    """Volume-weighted mean stress components of the zones of one block (by id), and the
    fractions of its zones yielding in shear and in tension at the last step (plastic state
    bits of ``zones.state``): the stress a laboratory specimen of one block shows."""
    from dec3d.model.zones import STRESS_COMPONENTS, ZSTATE_SHEAR_NOW, ZSTATE_TENSION_NOW
    zs = model.store("zones")
    rows = np.flatnonzero(model.blocks["id"][zs["block"]] == int(block))
    if not len(rows):
        raise ValueError(f"zone-block: block {int(block)} has no zones")
    w = zs["volume"][rows]
    mean = (zs["stress"][rows] * w[:, None]).sum(axis=0) / w.sum()
    out = {f"s{c}": float(mean[k]) for k, c in enumerate(STRESS_COMPONENTS)}
    st = zs["state"][rows]
    out["shear_now"] = float(np.mean((st & ZSTATE_SHEAR_NOW) != 0))
    out["tension_now"] = float(np.mean((st & ZSTATE_TENSION_NOW) != 0))
    return out


def footing_measures(model, half_width: float, surface: float, length: float, cohesion: float) -> dict[str, float]:
    """Mean pressure under a strip footing pushed in by gridpoint velocities: the gridpoints on
    the surface z = ``surface`` with 0 <= x <= ``half_width`` (a half model, symmetric about
    x = 0, ``length`` thick in y). The force the zones exert on each of those gridpoints is worked
    out from the zone stresses (a tetrahedron's stress σ pushes its node n with σ·(S n)/3, S n
    the outward area vector of the face opposite n; 3DEC theory text, nodal forces of a
    constant-strain tetrahedron); q = Σ f_z / (half_width · length), and q / c."""
    zs, vs = model.store("zones"), model.vertices
    p = vs["pos"]
    tol = 1e-6 * max(half_width, length)
    link = vs["link"]
    node = np.where(link >= 0, link, np.arange(vs.n))
    on = np.zeros(vs.n, bool)
    on[node[(np.abs(p[:, 2] - surface) <= tol) & (p[:, 0] <= half_width + tol) & (p[:, 0] >= -tol)]] = True
    fz = 0.0
    rows = np.flatnonzero(zs["cmodel"] > 0)
    g = zs["gp"][rows, :4]
    st = zs["stress"][rows]
    for n in range(4):
        sel = on[node[g[:, n]]]
        if not sel.any():
            continue
        a, b, c = (p[g[sel, (n + k) % 4]] for k in (1, 2, 3))
        d = p[g[sel, n]]
        area = 0.5 * np.cross(b - a, c - a)                   # normal of the face opposite n
        away = np.einsum("ij,ij->i", area, a - d) < 0          # make it point away from node n
        area[away] *= -1.0
        s = st[sel]
        fz += float(np.sum((s[:, 4] * area[:, 0] + s[:, 5] * area[:, 1] + s[:, 2] * area[:, 2]) / 3.0))
    q = fz / (half_width * length)
    return {"q": q, "q_c": q / cohesion}


# ---------------------------------------------------------------- D6: the Mohr-Coulomb hole
def salencon_exact(r: np.ndarray, p0: float, p_i: float, a: float, cohesion: float, friction: float):
    """Salençon (1969): a circular hole of radius a, internal pressure p_i, in an infinite,
    elastic-perfectly plastic Mohr-Coulomb medium (cohesion c, friction angle φ in degrees) under
    the isotropic far-field stress p0, plane strain; as written in Itasca's verification problem
    "Cylindrical Hole in an Infinite Mohr-Coulomb Medium" (3DEC/FLAC3D verification problems).
    Compression positive. Returns (R0, σ_r(r), σ_θ(r)):

        K_p = (1 + sin φ)/(1 − sin φ),  q = 2 c tan(45° + φ/2) = 2 c √K_p
        R0  = a [ 2/(K_p + 1) · (p0 + q/(K_p − 1)) / (p_i + q/(K_p − 1)) ]^(1/(K_p − 1))
        r ≤ R0:  σ_r = −q/(K_p − 1) + (p_i + q/(K_p − 1)) (r/a)^(K_p − 1)
                 σ_θ = −q/(K_p − 1) + K_p (p_i + q/(K_p − 1)) (r/a)^(K_p − 1)
        r > R0:  σ_r = p0 − (p0 − σ_re)(R0/r)²,  σ_θ = p0 + (p0 − σ_re)(R0/r)²,
                 σ_re = (2 p0 − q)/(K_p + 1)  (the radial stress at the elastic-plastic boundary)

    The stresses do not depend on the dilation angle or the elastic constants."""
    sphi = np.sin(np.radians(friction))
    kp = (1.0 + sphi) / (1.0 - sphi)
    q = 2.0 * cohesion * np.sqrt(kp)
    h = q / (kp - 1.0)
    r0 = a * (2.0 / (kp + 1.0) * (p0 + h) / (p_i + h)) ** (1.0 / (kp - 1.0))
    sre = (2.0 * p0 - q) / (kp + 1.0)
    r = np.asarray(r, dtype=float)
    inside = r <= r0
    grow = (p_i + h) * (r / a) ** (kp - 1.0)
    decay = (p0 - sre) * (r0 / r) ** 2
    sr = np.where(inside, -h + grow, p0 - decay)
    st = np.where(inside, -h + kp * grow, p0 + decay)
    return float(r0), sr, st


def _zone_groups(zs, pos):
    """Zones as 3DEC shows them: a 4-node tetrahedron is one zone, a hexahedral zone the ten
    tetrahedra of its two overlays. Returns (group of each row, its weight in the area: the row
    volume, halved for the overlaid tetrahedra of a hexahedron, each set filling it once), and per
    group the volume-weighted stress and centroid."""
    hexid = zs["hex"]
    key = np.where(hexid >= 0, hexid, -1 - np.arange(zs.n))
    _, grp = np.unique(key, return_inverse=True)
    w = zs["volume"] * np.where(hexid >= 0, 0.5, 1.0)
    cen = pos[zs["gp"][:, :4]].mean(axis=1)
    ng = int(grp.max()) + 1
    wsum = np.bincount(grp, w, ng)
    stress = np.stack([np.bincount(grp, w * zs["stress"][:, k], ng) for k in range(6)], axis=1) / wsum[:, None]
    centre = np.stack([np.bincount(grp, w * cen[:, k], ng) for k in range(3)], axis=1) / wsum[:, None]
    return grp, w, stress, centre


def _polar(stress: np.ndarray, centre: np.ndarray):
    """(r, σ_r, σ_θ) of zones about the y axis, compression positive, from xx, zz and xz
    (tension positive) at the zone centroid."""
    th = np.arctan2(centre[:, 2], centre[:, 0])
    mean = 0.5 * (stress[:, 0] + stress[:, 2])
    half = 0.5 * (stress[:, 0] - stress[:, 2])
    sxz = stress[:, 4]
    sr = -(mean + half * np.cos(2.0 * th) + sxz * np.sin(2.0 * th))
    st = -(mean - half * np.cos(2.0 * th) - sxz * np.sin(2.0 * th))
    return np.hypot(centre[:, 0], centre[:, 2]), sr, st


def _zones_on_ray(zs, pos, theta: float, y: float, r_from: float, r_to: float, step: float) -> np.ndarray:
    """Rows of the zones a radial line at angle ``theta`` (degrees from +x towards +z) in the plane
    y = ``y`` passes through, sampled every ``step`` from ``r_from`` to ``r_to`` (one overlay of a
    hexahedral set is enough to find its zone)."""
    rows = np.flatnonzero((zs["cmodel"] > 0) & (zs["overlay"] <= 0))
    corner = pos[zs["gp"][rows, :4]]
    edges = np.transpose(corner[:, 1:] - corner[:, :1], (0, 2, 1))           # columns p1-p0, p2-p0, p3-p0
    ok = np.abs(np.linalg.det(edges)) > 1e-12 * np.abs(edges).max() ** 3     # flat tetrahedra hold no point
    rows, corner, edges = rows[ok], corner[ok], edges[ok]
    inv = np.linalg.inv(edges)
    c, s = np.cos(np.radians(theta)), np.sin(np.radians(theta))
    found = []
    for r in np.arange(r_from, r_to, step):
        lam = np.einsum("mij,mj->mi", inv, np.array([r * c, y, r * s]) - corner[:, 0])
        inside = (lam >= -1e-9).all(axis=1) & (lam.sum(axis=1) <= 1.0 + 1e-9)
        found.extend(rows[inside][:1])
    return np.unique(np.array(found, dtype=np.int64))


def salencon_measures(model, p0: float, p_i: float, a: float, cohesion: float, friction: float,
                      theta: float) -> dict[str, float]:
    """The hole of ``salencon_exact`` about the y axis through the origin (a sector model, e.g. a
    quarter, plane strain in y). Measures:

    - ``radius``: the plastic radius [m], the radius of the circle whose sector (the model's angular
      span) has the area of the hole plus the zones that have yielded (any plastic state bit, shear
      or tension, now or past): R = √(2 (A_hole + A_yield) / span), A_yield the yielded zones' volume
      over the model's thickness, A_hole the fan of the hole wall's gridpoints (the wall polygon as
      zoned). ``radius_exact``: R0 of the closed form. ``radius_far``: the largest centroid radius
      of a yielded zone.
    - ``sigr_line``, ``sigt_line``: along the radial line at ``theta`` degrees in the mid-plane, the
      mean over the zones it passes through of |σ − σ_exact| / p0 in %, σ at the zone centroid
      (σ_r, σ_θ rotated by the centroid's angle); ``line_zones`` how many.
    - ``sigr``, ``sigt``: the same mean over every zone of the model."""
    if "zones" not in model.stores or model.store("zones").n == 0:
        raise ValueError("salencon: the model has no zones")
    zs, vs = model.store("zones"), model.vertices
    pos = vs["pos"]
    r0, _, _ = salencon_exact(np.array([a]), p0, p_i, a, cohesion, friction)
    grp, w, stress, centre = _zone_groups(zs, pos)
    rz, sr, st = _polar(stress, centre)
    _, sr_e, st_e = salencon_exact(rz, p0, p_i, a, cohesion, friction)
    gp = np.flatnonzero(vs["zoned"])
    y = pos[gp, 1]
    length = float(y.max() - y.min())
    ang = np.arctan2(pos[gp, 2], pos[gp, 0])
    span = float(ang.max() - ang.min())
    rg = np.hypot(pos[gp, 0], pos[gp, 2])
    wall = gp[(np.abs(rg - a) <= 1e-3 * a) & (np.abs(y - y.min()) <= 1e-6 * max(length, a))]
    if len(wall) < 2 or length <= 0.0:
        raise ValueError("salencon: no hole wall of radius a found on the model's first y plane")
    wth = np.sort(np.unique(np.round(np.arctan2(pos[wall, 2], pos[wall, 0]), 12)))
    a_hole = 0.5 * a * a * float(np.sin(np.diff(wth)).sum())
    yielded = (zs["state"] != 0) & (zs["cmodel"] > 0)
    a_yield = float(w[yielded].sum()) / length
    yg = np.zeros(int(grp.max()) + 1, bool)
    yg[grp[yielded]] = True
    line = np.unique(grp[_zones_on_ray(zs, pos, theta, 0.5 * (y.min() + y.max()), a, float(rg.max()), 0.01 * a)])
    if not len(line):
        raise ValueError(f"salencon: the radial line at {theta:g} degrees meets no zone")
    err_r = 100.0 * np.abs(sr - sr_e) / p0
    err_t = 100.0 * np.abs(st - st_e) / p0
    return {"radius": float(np.sqrt(2.0 * (a_hole + a_yield) / span)), "radius_exact": r0,
            "radius_far": float(rz[yg].max()) if yg.any() else a,
            "sigr_line": float(err_r[line].mean()), "sigt_line": float(err_t[line].mean()),
            "line_zones": float(len(line)), "sigr": float(err_r.mean()), "sigt": float(err_t.mean())}


#: derive kinds that read the model: name -> (function, its parameter names)
FIELDS = {"kirsch": (kirsch_errors, ("p1", "p2", "a", "bulk", "shear")),
          "uniaxial": (uniaxial_measures, ("sigma",)),
          "self_weight": (self_weight_measures, ("density", "g", "height")),
          "zone_block": (zone_block_measures, ("block",)),
          "footing": (footing_measures, ("half_width", "surface", "length", "cohesion")),
          "salencon": (salencon_measures, ("p0", "p_i", "a", "cohesion", "friction", "theta"))}
