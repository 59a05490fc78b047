"""No-tension interfaces: the contact length of a Winkler spring field that cannot pull.

The interface's springs are a field along it, s in [-L/2, L/2] from the midpoint P
along t.  With the local relative motion (delta_n, delta_s, d_omega) of b on a at P
(delta_n > 0 opens), a rigid rotation d_omega moves the point at s by d_omega s (-n),
so the normal gap there is

    g(s) = delta_n - d_omega s          (g < 0: the springs are compressed)

A linear interface ("linear", the thesis) lets every spring carry g(s) whatever its
sign: K_L = diag(k_n L, k_s L, k_n L^3/12).  A no-tension interface keeps only the
springs in compression, the contact [s1, s2] where g(s) < 0 (the open part carries
nothing, and opens and closes again with the motion).  Over the contact the springs
are still linear, so with

    a = s2 - s1,   S1 = (s2^2 - s1^2)/2,   S2 = (s2^3 - s1^3)/3

the interface forces on b at P are exactly (N along n, T along t, M about P)

    N = -k_n (a delta_n - S1 d_omega),  T = -k_s a delta_s,  M = k_n (S1 delta_n - S2 d_omega)

i.e. (N, T, M) = -K_C rel with the symmetric local matrix

    K_C = [[k_n a, 0, -k_n S1], [0, k_s a, 0], [-k_n S1, 0, k_n S2]]

(full contact: a = L, S1 = 0, S2 = L^3/12, the linear K_L).  The compressive
resultant lies on the contact, so its eccentricity e = |M|/|N| from P stays below L/2:
the moment an interface can carry is bounded by |N| L/2 (a footing on tensionless
springs: contact a = L while e <= L/6, a = 3 (L/2 - e) beyond, edge stress 2 |N|/a).
The contact is found by iterating: solve with the last contact, new contact from the
solution, until it no longer changes (solve.run).

Stresses on the contact: sigma_n = -N/a (compression +) is the average over the
contact, the shear stress k_s delta_s acts on the contact only, and the strength
c' + sigma'_n tan(phi') too: the open part has no cohesion.
"""
from __future__ import annotations

import numpy as np


def zone(rel: np.ndarray, length: np.ndarray, no_tension: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Contact [s1, s2] (m,) of each interface from its local relative motion rel (m, 3).

    Interfaces with no_tension False keep the whole length; an open one gets s1 = s2.
    """
    h = 0.5 * length
    dn, dw = rel[:, 0], rel[:, 2]
    s1, s2 = -h.copy(), h.copy()
    with np.errstate(divide="ignore", invalid="ignore"):
        s0 = np.where(dw != 0.0, dn / dw, 0.0)          # where g(s) changes sign
    pos, neg, flat = dw > 0, dw < 0, dw == 0
    # d_omega > 0: g < 0 for s > s0;  d_omega < 0: g < 0 for s < s0
    s1 = np.where(pos, np.clip(s0, -h, h), s1)
    s2 = np.where(neg, np.clip(s0, -h, h), s2)
    closed_flat = dn <= 0                                # no rotation: all or nothing
    s2 = np.where(flat & ~closed_flat, s1, s2)
    s1 = np.where(no_tension, s1, -h)
    s2 = np.where(no_tension, s2, h)
    return s1, s2


def moments(s1: np.ndarray, s2: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """a, S1, S2 of the contact [s1, s2] (its length and first and second moments about P)."""
    return s2 - s1, 0.5 * (s2 ** 2 - s1 ** 2), (s2 ** 3 - s1 ** 3) / 3.0


def local_matrix(kn: np.ndarray, ks: np.ndarray, s1: np.ndarray, s2: np.ndarray) -> np.ndarray:
    """K_C (m, 3, 3) of the contact [s1, s2] (see the module doc)."""
    a, S1, S2 = moments(s1, s2)
    K = np.zeros((len(kn), 3, 3))
    K[:, 0, 0] = kn * a
    K[:, 1, 1] = ks * a
    K[:, 0, 2] = K[:, 2, 0] = -kn * S1
    K[:, 2, 2] = kn * S2
    return K


def forces(rel: np.ndarray, kn: np.ndarray, ks: np.ndarray, s1: np.ndarray, s2: np.ndarray) -> np.ndarray:
    """(N, T, M) on b at P, (m, 3) = -K_C rel."""
    return -np.einsum("mij,mj->mi", local_matrix(kn, ks, s1, s2), rel)
