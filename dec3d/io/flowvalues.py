"""Flow values of the contacts for output (contact VTK, FISH `block.contact.flow.*`): from the flow network's
stores (``physics.flownet``) and the fluid settings, read only."""
from __future__ import annotations

import numpy as np

_F = np.float64


def settings_of(model) -> dict:
    f = model.settings.mechanical.get("fluid")
    return f if isinstance(f, dict) else {}


def zone_flux(model) -> np.ndarray:
    """Each flow zone's specific discharge vector [m²/s] (flow per unit width): q = −a³/(12 μ) ∇ψ over the
    triangle, ψ = p − ρ_w g·x linear between its knots."""
    f = settings_of(model)
    zs, kn = model.store("flowzones"), model.store("flowknots")
    g = np.asarray(model.settings.gravity, dtype=_F)
    x = kn["pos"][zs["zk"]]                                   # (nz, 3, 3)
    psi = kn["pp"][zs["zk"]] - float(f.get("density", 1000.0)) * (x @ g)  # (nz, 3)
    nrm = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
    two_a = np.linalg.norm(nrm, axis=1)
    nrm = nrm / np.where(two_a > 0, two_a, 1.0)[:, None]
    grad = np.zeros((zs.n, 3))
    for j in range(3):
        e = x[:, (j + 2) % 3] - x[:, (j + 1) % 3]
        grad += psi[:, j:j + 1] * np.cross(nrm, e)
    grad /= np.where(two_a > 0, two_a, 1.0)[:, None]
    return -(zs["zap"] ** 3 / (12.0 * float(f.get("viscosity", 1e-3))))[:, None] * grad


def contact_values(model) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per contact, area-weighted over its flow zones: the knots' pressure [Pa], the hydraulic aperture [m]
    and the magnitude of the specific discharge [m²/s] (``zone_flux``); zeros while there is no network."""
    cs = model.store("contacts")
    nc = cs.n
    out = np.zeros(nc), np.zeros(nc), np.zeros(nc)
    if "flowzones" not in model.stores or not model.store("flowzones").n:
        return out
    zs, kn = model.store("flowzones"), model.store("flowknots")
    zc, area = zs["zcontact"], zs["zarea"]
    ok = zc < nc
    zc, area = zc[ok], area[ok]
    asum = np.bincount(zc, area, nc)
    den = np.where(asum > 0, asum, 1.0)
    pz = kn["pp"][zs["zk"][ok]].mean(axis=1)
    qz = np.linalg.norm(zone_flux(model)[ok], axis=1)
    return (np.bincount(zc, pz * area, nc) / den, np.bincount(zc, zs["zap"][ok] * area, nc) / den,
            np.bincount(zc, qz * area, nc) / den)
