"""Zone model ``anisotropic``: transversely isotropic linear elasticity, the plane of isotropy
given by its dip and dip direction.

Source: Itasca, FLAC3D/3DEC documentation, "Anisotropic (Transversely) Elastic Model" (FLAC3D
Theory and Background, Constitutive Models),
http://docs.itascacg.com/flac3d700/common/models/aniso/doc/modelaniso.html: the axis of symmetry,
normal to the plane of isotropy, is the local 3' axis; 1', 2' lie in the plane, and the model is
the orthotropic law (``_elastic_aniso.py``, whose law, axes and update this uses) with

    E1 = E2 = E (young-plane),  E3 = E' (young-normal),  ν12 = ν (poisson-plane),
    ν13 = ν23 = ν' (poisson-normal: lateral contraction in the plane under tension normal to it),
    G13 = G23 = G' (shear-normal),  G12 = E / (2 (1 + ν)) (worked out, not a property).

The plane of isotropy is the plane of the dip and dip direction (rotation 0: any in-plane
rotation gives the same law), so 3' is its upward normal (sin δ sin α, sin δ cos α, cos δ):
dip 90, dip direction 90 makes x the axis of symmetry. Like the orthotropic model it returns
dsp = −tr(C : dev d)/3 so that the step's averaging sweep keeps the stiffness symmetric under
nodal mixed discretization (``_elastic_aniso.py``'s text).
"""
from numba import njit

from ._common import P_OWN
from ._elastic_aniso import ortho_increment

NAME = "anisotropic"
CODE = 7          # kept in save files: never renumber
P_E = P_OWN           # young-plane [Pa]
P_EN = P_OWN + 1      # young-normal
P_NU = P_OWN + 2      # poisson-plane
P_NUN = P_OWN + 3     # poisson-normal
P_GN = P_OWN + 4      # shear-normal [Pa]
P_DIP = P_OWN + 5     # dip [deg]
P_DD = P_OWN + 6      # dip-direction [deg]
NCOLS = P_OWN + 7
NHIST = 0
HIST_NAMES = ()
PLASTIC = False   # never yields (bits stay 0)
CORRECTS = True   # its dsp needs the step's averaging sweep (symmetric NMD)


@njit(cache=True)
def update(p, h, z, K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5, tab, wf, mw):
    e = p[z, P_E]
    nu = p[z, P_NU]
    nun = p[z, P_NUN]
    gn = p[z, P_GN]
    g12 = e / (2.0 * (1.0 + nu)) if nu > -1.0 else 0.0       # 0: refused by ortho_increment
    s0, s1, s2, s3, s4, s5, q = ortho_increment(e, e, p[z, P_EN], nu, nun, nun, g12, gn, gn, p[z, P_DIP], p[z, P_DD],
                                             0.0, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5)
    return 0, s0, s1, s2, s3, s4, s5, -q
