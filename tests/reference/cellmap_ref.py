"""Twin of dec3d.kernels.cellmap.cell_pairs: no cells, the O(n²) all-pairs box test."""
import numpy as np


def cell_pairs_ref(lo, hi, active):
    """lo, hi (n, 3); active (n,) bool. Every pair i < j of active blocks whose closed
    boxes overlap in x, y and z, as a sorted (k, 2) int64 array."""
    lo = np.asarray(lo, dtype=float)
    hi = np.asarray(hi, dtype=float)
    idx = np.flatnonzero(active)
    out = []
    for a, i in enumerate(idx):
        js = idx[a + 1:]
        ok = np.all((lo[i] <= hi[js]) & (lo[js] <= hi[i]), axis=1)
        out.extend((int(i), int(j)) for j in js[ok])
    return np.array(sorted(out), dtype=np.int64).reshape(-1, 2)
