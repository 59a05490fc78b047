"""Zone model ``mohr-coulomb``: Itasca's Mohr-Coulomb model with tension cut-off and
non-associated flow (the return and its sources: ``dec3d/kernels/zone_mohr.py``).

The update is the elastic trial (Hooke), the yield test and Itasca's single-plane return in
scalars (``zone_mohr.mohr_scalar``); then, in scalars too, Itasca's plane with one other (edge or
corner) and nearly repeated principal values (``zone_mohr_pair.mohr_pair``); and the general
return on arrays (``zone_mohr.mohr_plastic``) for what these leave. The return's constants (N_φ,
N_ψ, …) are kept in the chunk scratch ``wf`` while neighbouring zones share their properties:
wf[0:6] the properties they were made from, wf[6:15] the constants, wf[16:22] the trial handed
to the general return.
"""
from numba import njit

from ..zone_mohr import mohr_constants, mohr_plastic, mohr_scalar
from ..zone_mohr_pair import mohr_pair
from ._common import P_COHESION, P_TANDIL, P_TANFRIC, P_TENSION, hooke

NAME = "mohr-coulomb"
CODE = 2          # kept in save files: never renumber
LEGACY_CODE = 2   # 3DEC 4/5 `change cons=2` (dec3d translate)
NCOLS = 7         # bulk, shear, density, cohesion, tan friction, tension, tan dilation
NHIST = 0
HIST_NAMES = ()
PLASTIC = True


@njit(cache=True, inline="always")
def update(p, h, z, K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5, tab, wf, mw):
    s0, s1, s2, s3, s4, s5 = hooke(K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5)
    coh = p[z, P_COHESION]
    tf = p[z, P_TANFRIC]
    ten = p[z, P_TENSION]
    td = p[z, P_TANDIL]
    if K != wf[0] or G != wf[1] or coh != wf[2] or tf != wf[3] or ten != wf[4] or td != wf[5]:
        npf, csn, ft, nps, a1, a2, sp, ap, den = mohr_constants(K, G, coh, tf, ten, td)
        wf[0] = K; wf[1] = G; wf[2] = coh; wf[3] = tf; wf[4] = ten; wf[5] = td
        wf[6] = npf; wf[7] = csn; wf[8] = ft; wf[9] = nps; wf[10] = a1; wf[11] = a2
        wf[12] = sp; wf[13] = ap; wf[14] = den
    code, s0, s1, s2, s3, s4, s5, dp = mohr_scalar(s0, s1, s2, s3, s4, s5, coh, wf[6], wf[7], wf[8], wf[9],
                                                   wf[10], wf[11], wf[12], wf[13], wf[14])
    if code < 0:
        code, s0, s1, s2, s3, s4, s5, dp = rest(s0, s1, s2, s3, s4, s5, K, G, coh, tf, ten, td, wf[6], wf[7], wf[8],
                                                wf[9], wf[10], wf[11], wf[12], wf[13], wf[14], wf, mw)
    return code, s0, s1, s2, s3, s4, s5, dp


@njit(cache=True)
def rest(s0, s1, s2, s3, s4, s5, K, G, coh, tf, ten, td, npf, csn, ft, nps, a1, a2, sp, ap, den, wf, mw):
    """What ``mohr_scalar`` leaves (code -1) of the trial s0..s5, with the return's constants
    (``zone_mohr.mohr_constants``): ``mohr_pair``, else ``mohr_plastic`` on the chunk scratch past
    the constants (one call out of the step for both: the step's common path stays as short).
    Strain-softening's update takes the same way on."""
    code, s0, s1, s2, s3, s4, s5, dp = mohr_pair(s0, s1, s2, s3, s4, s5, coh, npf, csn, ft, nps, a1, a2, sp, ap,
                                                 den)
    if code < 0:
        s = wf[16:22]
        s[0] = s0; s[1] = s1; s[2] = s2; s[3] = s3; s[4] = s4; s[5] = s5
        code, dp = mohr_plastic(s, K, G, coh, tf, ten, td, mw)
        s0 = s[0]; s1 = s[1]; s2 = s[2]; s3 = s[3]; s4 = s[4]; s5 = s[5]
    return code, s0, s1, s2, s3, s4, s5, dp
