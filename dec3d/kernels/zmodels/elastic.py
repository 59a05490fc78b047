"""Zone model ``elastic``: isotropic linear elasticity (3DEC theory text Eq. 59, with the
three-term volumetric strain of ``shared/seeds/ERRATA.md``)."""
from numba import njit

from ._common import hooke

NAME = "elastic"
CODE = 1          # kept in save files: never renumber
LEGACY_CODE = 1   # 3DEC 4/5 `change cons=1` (dec3d translate)
NCOLS = 3         # bulk, shear, density
NHIST = 0
HIST_NAMES = ()
PLASTIC = False


@njit(cache=True, inline="always")
def update(p, h, z, K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5, tab, wf, mw):
    s0, s1, s2, s3, s4, s5 = hooke(K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5)
    return 0, s0, s1, s2, s3, s4, s5, 0.0
