"""An independent numpy twin of the 20-node brick kernels (kernels/feblock*.py), shared by
tests/test_feblock_kernels.py and tests/test_feblock_beams.py.

The twin never calls the kernels. Its node table is built from the 8 corners and the 12 edges
(mid-edge node = midpoint of its edge's corners, edges in the order of the corrected Table 1 of
shared/seeds/ERRATA.md) and checked against the corrected table written out; its shape
functions are the generic serendipity formulas evaluated on that table, their derivatives by the
complex step (exact to round-off), its quadrature numpy's Gauss-Legendre points, its forces
-sum w det J B^T sigma with an explicit 6 x 60 B matrix (the text's Eq. 6-7).
"""
import itertools

import numpy as np

CORNERS = [(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1), (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)]
EDGES = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)]
TABLE = np.array(CORNERS + [tuple((np.array(CORNERS[i]) + CORNERS[j]) / 2) for i, j in EDGES], float)

# the corrected Table 1 (ERRATA.md, section 003), nodes 9-20
ERRATA_MID = [(0, -1, -1), (1, 0, -1), (0, 1, -1), (-1, 0, -1), (0, -1, 1), (1, 0, 1), (0, 1, 1), (-1, 0, 1),
              (-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]


def twin_n(y):
    """The 20 shape functions at y (real or complex)."""
    out = []
    for c in TABLE:
        if np.all(c != 0):
            v = (1 + c[0] * y[0]) * (1 + c[1] * y[1]) * (1 + c[2] * y[2]) * (c @ y - 2) / 8
        else:
            k = int(np.flatnonzero(c == 0)[0])
            o = [j for j in range(3) if j != k]
            v = (1 - y[k] ** 2) * (1 + c[o[0]] * y[o[0]]) * (1 + c[o[1]] * y[o[1]]) / 4
        out.append(v)
    return np.array(out)


def twin_dn(y, h=1e-30):
    d = np.empty((20, 3))
    for k in range(3):
        yc = np.array(y, complex)
        yc[k] += 1j * h
        d[:, k] = twin_n(yc).imag / h
    return d


def twin_rule(nq):
    x, w = np.polynomial.legendre.leggauss(nq)
    pts, wts = [], []
    for k, j, i in itertools.product(range(nq), repeat=3):      # y1 fastest
        pts.append(np.array([x[i], x[j], x[k]]))
        wts.append(w[i] * w[j] * w[k])
    return pts, wts


def d_matrix(K, G):
    D = np.zeros((6, 6))
    D[:3, :3] = K - 2 * G / 3
    D[:3, :3] += 2 * G * np.eye(3)
    D[3:, 3:] = G * np.eye(3)
    return D


def b_matrix(x, y):
    """B (6, 60) for xx yy zz 2xy 2xz 2yz and det J at y; x (20, 3)."""
    dn = twin_dn(y)
    J = x.T @ dn
    gn = np.linalg.solve(J.T, dn.T).T
    B = np.zeros((6, 60))
    for a in range(20):
        gx, gy, gz = gn[a]
        B[:, 3 * a:3 * a + 3] = [[gx, 0, 0], [0, gy, 0], [0, 0, gz], [gy, gx, 0], [gz, 0, gx], [0, gz, gy]]
    return B, np.linalg.det(J)


def twin_step(x, v, K, G, dt, s0, nq):
    """Gauss-point stresses s0 + D B v dt and element forces -sum w detJ B^T sigma."""
    D = d_matrix(K, G)
    f = np.zeros(60)
    sig = []
    vol = 0.0
    mean = np.zeros(6)
    for g, (p, w) in enumerate(zip(*twin_rule(nq))):
        B, dj = b_matrix(x, p)
        s = s0[g] + D @ (B @ v.ravel() * dt)
        sig.append(s)
        f -= w * dj * B.T @ s
        vol += w * dj
        mean += w * dj * s
    return np.array(sig), mean / vol, f.reshape(20, 3)


def twin_stiffness(x, K, G, nq):
    D = d_matrix(K, G)
    Ke = np.zeros((60, 60))
    for p, w in zip(*twin_rule(nq)):
        B, dj = b_matrix(x, p)
        Ke += w * dj * B.T @ D @ B
    return Ke


def twin_consistent_mass(x, rho, nq=4):
    M = np.zeros((20, 20))
    for p, w in zip(*twin_rule(nq)):
        n = twin_n(p)
        _, dj = b_matrix(x, p)
        M += rho * w * dj * np.outer(n, n)
    return M


def brick(a=1.0, b=1.0, c=1.0, origin=(0, 0, 0)):
    return (TABLE + 1) / 2 * [a, b, c] + origin


def distorted(seed=1, amp=0.08):
    """A unit brick with every node moved at random: curved edges, faces not planar."""
    rng = np.random.default_rng(seed)
    return brick() + rng.uniform(-amp, amp, (20, 3))


def one(x):
    return np.ascontiguousarray(x, float), np.arange(20, dtype=np.int64)[None, :], np.array([0], np.int64)


def beam_mesh(nx, ny, nz, L, B, H):
    """Regular mesh of nx ny nz 20-node elements in [0,L]x[0,B]x[0,H]; nodes shared."""
    grid = {}
    pts = []
    elems = []
    for i, j, k in itertools.product(range(nx), range(ny), range(nz)):
        ids = []
        for c in TABLE:
            key = (2 * i + 1 + int(c[0]), 2 * j + 1 + int(c[1]), 2 * k + 1 + int(c[2]))
            if key not in grid:
                grid[key] = len(pts)
                pts.append((key[0] * L / (2 * nx), key[1] * B / (2 * ny), key[2] * H / (2 * nz)))
            ids.append(grid[key])
        elems.append(ids)
    return np.array(pts, float), np.array(elems, np.int64)
