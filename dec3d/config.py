"""Settings every layer may read, kernels included.

Kept free of imports from the rest of the package so that `dec3d.kernels`
can use it without breaking the one-direction import rule.
"""
import numpy as np

#: floating point type of every state array
FLOAT = np.float64
#: integer type of indices into the stores
INT = np.int64
#: numba caching of compiled kernels (on disk next to the module)
NUMBA_CACHE = True
#: version written into save files; a file with a newer version is refused
SAVE_FORMAT_VERSION = 1
