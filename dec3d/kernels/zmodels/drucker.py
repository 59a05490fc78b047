"""Zone model ``drucker-prager``: Itasca's Drucker-Prager model, a Drucker-Prager shear criterion
with a tension cut-off, non-associated shear flow and associated tension flow.

Source: Itasca, FLAC3D/3DEC documentation, "Drucker-Prager Model" (FLAC3D Theory and Background,
Constitutive Models), https://docs.itascacg.com/itasca920/common/models/drucker/doc/modeldrucker.html
(also pfc700/common/models/drucker/doc/modeldrucker.html). The page's generalized stresses are the
tangential stress τ = sqrt(J2) = sqrt(s_ij s_ij / 2) (s the deviator) and the mean stress
σ = σ_kk / 3, tension positive; Hooke's law on them is Δτ = G Δγ^e, Δσ = K Δε^e. With the
material constants k_φ, q_φ, q_ψ and the tensile strength σ^t:

    shear yield        f_s = τ + q_φ σ − k_φ          (violated when f_s > 0)
    tension cut-off    f_t = σ − σ^t                   (violated when f_t > 0)
    σ^t capped at the apex k_φ / q_φ (q_φ > 0), as Itasca caps it;
    potentials         g_s = τ + q_ψ σ (non-associated), g_t = σ (associated).

A trial stress violating a criterion returns along the flow of one of them, chosen by the line
through the corner (σ^t, τ^P) that bisects the outward normals of the two criteria there:

    h = τ − τ^P − α^P (σ − σ^t),  τ^P = k_φ − q_φ σ^t,  α^P = sqrt(1 + q_φ²) − q_φ;
    h ≥ 0: shear return,  λ = f_s / (G + K q_φ q_ψ),  τ_N = τ − G λ,  σ_N = σ − K q_ψ λ,
           the deviator scaled by τ_N / τ;
    h < 0: tension return, σ_N = σ^t, the deviator kept.

(In the (σ, τ) plane the normals are (q_φ, 1)/sqrt(1 + q_φ²) and (1, 0); their bisector at the
corner has slope 1 / (q_φ + sqrt(1 + q_φ²)) = α^P. Where f_s > 0 the trial lies above it, where
f_t > 0 below it, so one test picks the criterion, as Itasca's h does for Mohr-Coulomb. Since
f_s / sqrt(1 + q_φ²) and f_t are the distances past the two lines, h / sqrt(1 + q_φ²) is their
difference: the return is to the line the trial is farther past, the test of Itasca's published
model source, ties to shear as there.)

dec3d's completion: where the chosen return lands beyond the other criterion (a shear return
to σ_N > σ^t or τ_N < 0, a tension return with τ > τ^P: trial stresses near the corner), the
stress goes to the corner itself, σ_N = σ^t, τ_N = τ^P (both criteria active, bits 1 | 2).

Property columns: q_φ, k_φ, q_ψ in this model's own columns (``P_QPHI``, ``P_KPHI``,
``P_QPSI``), σ^t in the shared ``P_TENSION``. Strengths are constants (no tables, no strength
reduction: see the host). Returns dsp = σ_trial − σ_N (K times the plastic volumetric strain).
"""
import math

from numba import njit

from ._common import P_OWN, P_TENSION, SHEAR_NOW, TENSION_NOW, hooke

NAME = "drucker-prager"
CODE = 6          # kept in save files: never renumber
P_QPHI = P_OWN        # q_φ, friction-like slope of the shear criterion
P_KPHI = P_OWN + 1    # k_φ, the shear criterion's value of τ at σ = 0 [Pa]
P_QPSI = P_OWN + 2    # q_ψ, dilation-like slope of the shear potential
NCOLS = P_OWN + 3
NHIST = 0
HIST_NAMES = ()
PLASTIC = True


@njit(cache=True)
def update(p, h, z, K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5, tab, wf, mw):
    s0, s1, s2, s3, s4, s5 = hooke(K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5)
    qf = p[z, P_QPHI]
    kf = p[z, P_KPHI]
    qp = p[z, P_QPSI]
    st = p[z, P_TENSION]
    if qf > 0.0 and kf / qf < st:
        st = kf / qf
    sig = (s0 + s1 + s2) / 3.0
    e0 = s0 - sig
    e1 = s1 - sig
    e2 = s2 - sig
    tau = math.sqrt(0.5 * (e0 * e0 + e1 * e1 + e2 * e2) + s3 * s3 + s4 * s4 + s5 * s5)
    fs = tau + qf * sig - kf
    ft = sig - st
    if fs <= 0.0 and ft <= 0.0:
        return 0, s0, s1, s2, s3, s4, s5, 0.0
    taup = kf - qf * st
    if taup < 0.0:                       # (round-off when σ^t is the apex)
        taup = 0.0
    ap = math.sqrt(1.0 + qf * qf) - qf
    if tau - taup - ap * (sig - st) >= 0.0:
        den = G + K * qf * qp
        lam = fs / den if den > 0.0 and fs > 0.0 else 0.0
        tn = tau - G * lam
        sn = sig - K * qp * lam
        code = SHEAR_NOW
        if sn > st or tn < 0.0:
            sn = st
            tn = taup
            code = SHEAR_NOW | TENSION_NOW
    else:
        sn = st
        tn = tau
        code = TENSION_NOW
        if tau > taup:
            tn = taup
            code = SHEAR_NOW | TENSION_NOW
    r = tn / tau if tau > 0.0 else 0.0
    return (code, sn + r * e0, sn + r * e1, sn + r * e2, r * s3, r * s4, r * s5, sig - sn)
