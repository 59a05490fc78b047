"""Zone model ``orthotropic``: orthotropic linear elasticity in local axes 1', 2', 3' oriented by
the dip and dip direction of the (1', 2') plane and the rotation of 1' in it.

Source: Itasca, FLAC3D/3DEC documentation, "Orthotropic Elastic Model",
https://docs.itascacg.com/pfc700/common/models/ortho/doc/modelortho.html. The law, the axes, the
update and the mean-stress correction that keeps nodal mixed discretization symmetric are in
``_elastic_aniso.py`` (shared with the transversely isotropic model ``anisotropic``). The 12 own
columns hold the nine constants and the three angles (degrees). The update returns bits 0 and
dsp = −tr(C : dev d)/3; CORRECTS is declared for the step's averaging sweep (it never yields).
"""
from numba import njit

from ._common import P_OWN
from ._elastic_aniso import ortho_increment

NAME = "orthotropic"
CODE = 8          # kept in save files: never renumber
P_E1 = P_OWN          # young-1 [Pa]
P_E2 = P_OWN + 1      # young-2
P_E3 = P_OWN + 2      # young-3
P_NU12 = P_OWN + 3    # poisson-12
P_NU13 = P_OWN + 4    # poisson-13
P_NU23 = P_OWN + 5    # poisson-23
P_G12 = P_OWN + 6     # shear-12 [Pa]
P_G13 = P_OWN + 7     # shear-13
P_G23 = P_OWN + 8     # shear-23
P_DIP = P_OWN + 9     # dip [deg]
P_DD = P_OWN + 10     # dip-direction [deg]
P_ROT = P_OWN + 11    # rotation [deg]
NCOLS = P_OWN + 12
NHIST = 0
HIST_NAMES = ()
PLASTIC = False   # never yields (bits stay 0)
CORRECTS = True   # its dsp needs the step's averaging sweep (symmetric NMD)


@njit(cache=True)
def update(p, h, z, K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5, tab, wf, mw):
    s0, s1, s2, s3, s4, s5, q = ortho_increment(p[z, P_E1], p[z, P_E2], p[z, P_E3], p[z, P_NU12], p[z, P_NU13],
                                             p[z, P_NU23], p[z, P_G12], p[z, P_G13], p[z, P_G23], p[z, P_DIP],
                                             p[z, P_DD], p[z, P_ROT], d0, d1, d2, d3, d4, d5,
                                             s0, s1, s2, s3, s4, s5)
    return 0, s0, s1, s2, s3, s4, s5, -q
