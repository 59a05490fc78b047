"""Body forces applied to zones (`block zone apply force…`) as gridpoint forces.

The condition is a force per unit volume f [N/m³] per zone, ``zones.fbody`` (``dec3d.model.zones``; a model
without the field has none). ``ZoneStepper`` turns it into gridpoint forces once per run, on the reference
geometry of the masses (``vertices.gpos0``, as gravity's lumped weights; mass is conserved and so is the
load of a body force f = ρ a), and adds them every step before the sum onto link masters:

- a 4-node zone of volume V gives f V / 4 to each corner (a tetrahedron of a hexahedral zone's two overlaid
  sets half that, as its mass), the split of its lumped mass ρ V / 4: a body force f = ρ g loads the
  gridpoints exactly as gravity g does;
- a 10-node zone gives the consistent loads F_a = f ∫ N_a dV (``zones_ho.tet10_body_force``, the kernel of its
  gravity: −f V / 20 at each corner, f V / 5 at each mid-edge node for straight edges).

Zones without a constitutive model (null) take none: they are not in the calculation. The magnitudes |F| of
the loads count in the applied-force sum of the equilibrium ratio, as gravity's do.
"""
from __future__ import annotations

import numpy as np

_F = np.float64


def body_loads(model, ref, rows4, rows10):
    """(gridpoint rows, forces (k, 3) [N], magnitudes (k,)) of the body forces of the zones ``rows4`` (4-node)
    and ``rows10`` (10-node), on the positions ``ref``; None when no zone of them carries one."""
    zs = model.store("zones")
    if "fbody" not in zs or not zs.n:
        return None
    fb = zs["fbody"]
    gp = zs["gp"]
    f = np.zeros((model.vertices.n, 3))
    r4 = rows4[np.any(fb[rows4] != 0.0, axis=1)]
    if len(r4):
        g = gp[r4, :4]
        a, b, c, d = (ref[g[:, i]] for i in range(4))
        vol = np.abs(np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a))) / 6.0
        w = np.where(zs["overlay"][r4] >= 0, 0.5, 1.0)
        share = (0.25 * vol * w)[:, None] * fb[r4]
        for i in range(4):
            np.add.at(f, g[:, i], share)
    r10 = rows10[np.any(fb[rows10] != 0.0, axis=1)]
    if len(r10):
        from dec3d.kernels.zones_ho import tet10_body_force
        r10 = np.ascontiguousarray(r10, dtype=np.int64)
        for i in range(3):
            unit = np.zeros(3)
            unit[i] = 1.0
            # the kernel's ρ g with ρ = f_i of each zone and g the unit vector of axis i
            tet10_body_force(ref, gp, r10, np.ascontiguousarray(fb[:, i], dtype=_F), unit, f)
    rows = np.flatnonzero(np.any(f != 0.0, axis=1))
    if not len(rows):
        return None
    ff = f[rows]
    return rows, ff, np.sqrt((ff * ff).sum(axis=1))
