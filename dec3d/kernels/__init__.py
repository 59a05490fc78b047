"""dec3d.kernels: the numba kernels (their cache is guarded by ``dec3d.kcache``)."""
