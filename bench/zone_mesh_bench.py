"""Time to zone a unit cube into about 1e5 and 1e6 4-node tetrahedra with the convex mesher
(issue 10 target: 1e6 zones in at most 30 s), and the same for the fast path switched off
(one hull over all points) at the smaller size."""
import sys
import time

import numpy as np

from dec3d.geometry.zoning import mesh_convex, min_dihedral_deg

v = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], float)
loops = np.array([[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]).ravel()
ptr = np.arange(0, 25, 4)
runs = [(0.037, True), (0.037, False), (0.0172, True)]   # about 1e5, 1e5 (one hull), 1e6 zones
if "--quick" in sys.argv:
    runs = runs[:2]
for L, fast in runs:
    t0 = time.perf_counter()
    pts, tets, tris, src = mesh_convex(v, ptr, loops, L, fast=fast)
    dt = time.perf_counter() - t0
    print(f"L={L} {'fast' if fast else 'one hull'}: {len(tets)} zones, {len(pts)} gridpoints, {dt:.2f} s, "
          f"min dihedral {min_dihedral_deg(pts, tets):.2f} deg", flush=True)
