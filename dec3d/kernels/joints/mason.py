"""Joint model ``mason``: MASON (Masonry Advanced Softening cONtact), a multi-surface joint model
for masonry: tension cut-off, Coulomb friction with cohesion and dilatancy, an elliptical
compression cap, fracture-energy softening, damage with secant unloading in tension.

Source of the equations. MASON's public repository, yopi1838/mason_constitutive_model (MIT),
README.md ("MASON — Masonry Advanced Softening cONtact Model for 3DEC", its Features and Input
properties sections), describes the model: three surfaces active together, F1 tension cut-off,
F2 Coulomb with cohesion and dilatancy, F3 the elliptical compression cap "adopted from Lourenço &
Rots"; exponential softening of tensile and shear strength governed by ``G_I`` and ``G_II``;
parabolic hardening in compression to the peak, reached at ``peak_ratio`` times the elastic-limit
displacement, then softening governed by ``G_c``; dilatancy decaying with slip (``delta``) and
with confinement (``dilation-zero``: the stress at which it vanishes); secant (damaged) unloading
in tension; damage scalars dt, ds, dc with tension-shear coupling. The README names the
surfaces and laws but gives no formula, so the formulas are those of the model it adopts the
surfaces from: P.B. Lourenço, J.G. Rots, "Multisurface interface model for analysis of masonry
structures", J. Eng. Mech. 123(7) 660-668 (1997) (L&R below), and the MASON papers (Oktiovan et
al., Computers & Structures 303 (2024) 107499 and 321 (2026) 108094) for the cyclic rules, written
out here as this module implements them (none of the plugin's code was read or used):

  stresses: σ = Fⁿ/A (compression +), τ = |Fˢ|/A; e = uⁿ − u_dil + u_pc the elastic normal gap
  (opening +; u_pc the permanent closure left by the cap).

  F1 tension (e > 0), damage with secant unloading: σ = −kn (1 − dt) e while
      kn (1 − dt) e ≤ σt;  σt = ft_r + (ft − ft_r) r,  rt = exp(−(ft − ft_r) κt / G_I)   (L&R's law)
  beyond it the opening advances on the softening front: Δκt = e − σt/(kn(1 − dt)), σ = −σt(κt),
  dt = 1 − σt/(kn e) (the README's secant unloading; the softening is taken along the opening past
  the peak, dec3d's choice, so that G_I is the area of the post-peak stress–opening curve above ft_r).
  F2 Coulomb: τ ≤ c + σ tan φ (≥ 0), c = c_r + (c − c_r) r, tan φ = tan φ_r + (tan φ − tan φ_r) r
      (friction softening coupled to cohesion softening, as L&R), rs = exp(−(c − c_r) κs / G_II)
  (L&R's law); plastic slip Δκs = (τ_trial − τ_max)/ks with τ returned to τ_max (ks unchanged),
  so G_II is the area of the (τ − τ_res)–plastic-slip curve. Tension-shear coupling (d_ts): one
  remaining-strength fraction r = min(rt, rs) softens tension, cohesion and friction together
  (dec3d's choice: the README names the coupling, not its form).
  Dilatancy (L&R's law): Δu_dil = Δκs tan ψ, tan ψ = tan ψ₀ (1 − σ/σ_ψ0) exp(−δ κs), 0 for
  σ ≥ σ_ψ0 (σ_ψ0 = 0: no confinement limit); always an uplift, whichever way the joint slips, and
  only while the joint is closed (an open crack slides freely).
  F3 cap (L&R's ellipse): Cnn σ² + Css τ² + Cn σ ≤ σ̄c², returned along the normal only (a
  non-associated simplification: Δu_pc = (σ_trial − σ_cap)/kn0), the shear clipped to
  τ ≤ σ̄c/√Css where the ellipse leaves no compression. σ̄c is a function of the total closure
  d = −(uⁿ − u_dil) (dec3d's reading of the README's "parabolic hardening to the peak at n times the
  elastic-limit displacement"): σ_e = 2 fc/(n + 1) (the initial cap) up to d_e = σ_e/kn0; then the parabola
  tangent to the elastic line, fc − (fc − σ_e)((d_p − d)/(d_p − d_e))², reaching fc with zero slope at
  d_p = n d_e (n = peak_ratio: displacement at peak / elastic-limit displacement); beyond,
  fc_r + (fc − fc_r) exp(−(fc − fc_r)(d − d_p)/G_c): G_c is the post-peak area above fc_r.
  Unloading and reloading in compression at kn0 (plastic), the crack closing at full stiffness.

Keywords are the README's, lower-case as dec3d reads every keyword (``G_I`` in a deck is ``g_i``).
``compression`` 0 (the default) disables the cap (the README: omitted, the cap is "effectively
disabled"); ``g_c`` is required, as the README says, and so are ``g_i`` and ``g_ii`` (the README's
alternative, the damage tables ``table-dt``/``table-ds``, is not provided). Simplifications against
the plugin as its papers describe it: the shear stiffness does not degrade, the cap returns along
the normal only, compression unloads and reloads linearly at kn0.
"""
from __future__ import annotations

import math

from numba import njit

from ._common import P_KN, P_KS, ST_FAILED, ST_SLIP, ST_TENSION

NAME = "mason"
CODE = 7          # kept in save files: never renumber
P_KN0 = 2         # stiffness-initial kn0 [Pa/m] (NaN: kn): compression, reloading after a crack closes
P_FT = 3          # tension ft [Pa]
P_COH = 4         # cohesion c [Pa]
P_TANF = 5        # tan φ
P_TANDIL = 6      # tan ψ₀
P_SDIL = 7        # dilation-zero σ_ψ0 [Pa] (0: no confinement limit)
P_DELTA = 8       # delta δ [1/m]: dilatancy decay with plastic slip
P_GI = 9          # G_I [N/m = J/m²]
P_GII = 10        # G_II [J/m²]
P_FC = 11         # compression fc [Pa] (0: no cap)
P_GC = 12         # G_c [J/m²]
P_NPEAK = 13      # peak_ratio n ≥ 1
P_CN = 14         # Cn [Pa]
P_CNN = 15        # Cnn
P_CSS = 16        # Css
P_TANF_RES = 17   # friction-residual, tan φ_r (NaN: tan φ)
P_COH_RES = 18    # cohesion-residual c_r [Pa]
P_FT_RES = 19     # tension-residual ft_r [Pa]
P_FC_RES = 20     # comp-residual fc_r [Pa]
NCOLS = 21

H_KT = 0          # κt: crack opening on the tensile softening front [m]
H_DT = 1          # dt: tensile damage, 1 − secant/kn
H_KS = 2          # κs: accumulated plastic slip [m]
H_DS = 3          # ds: shear softening, 1 − rs
H_UPC = 4         # u_pc: permanent (plastic) closure from the cap [m]
H_DFT = 5         # 1 − rt: tensile strength lost (kept so a step needs no exp() unless it yields)
H_DC = 6          # dc: compressive damage, 1 − σ̄c(d)/fc at the furthest closure past the peak
H_OPEN = 7        # 1 while the joint is open (e > 0): which normal stiffness is current
NHIST = 8
HIST_NAMES = ("kappa_t", "dt", "kappa_s", "ds", "u_pc", "dft", "dc", "open")


@njit(cache=True, inline="always")
def cap_envelope(d, kn0, fc, npk, gc, fcr):
    """σ̄c(d): the cap's strength at total closure d (module docstring; fc > 0, kn0 > 0)."""
    se = 2.0 * fc / (npk + 1.0)
    de = se / kn0
    dp = npk * de
    if d <= de:                            # the initial cap: elastic inside it
        return se
    if d < dp:
        x = (dp - d) / (dp - de)
        return fc - (fc - se) * x * x
    return fcr + (fc - fcr) * math.exp(-(fc - fcr) * (d - dp) / gc)


@njit(cache=True, inline="always")
def stiffness(p, c, h, s):
    """Open: the secant kn (1 − dt) (damaged unloading); closed: kn0. ks is not degraded."""
    kn0 = p[c, P_KN0]
    if kn0 != kn0:
        kn0 = p[c, P_KN]
    if h[s, H_OPEN] > 0.0:
        return p[c, P_KN] * (1.0 - h[s, H_DT]), p[c, P_KS]
    return kn0, p[c, P_KS]


@njit(cache=True, inline="always")
def law(p, c, h, s, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state):
    """Tension (damage), Coulomb (plastic slip with dilatancy), cap (normal return), in that order."""
    kn = p[c, P_KN]
    ks = p[c, P_KS]
    kn0 = p[c, P_KN0]
    if kn0 != kn0:
        kn0 = kn
    un += dun
    us0 += dus0
    us1 += dus1
    us2 += dus2
    if area <= 0.0:                        # no area, no force; the history waits
        return 0.0, 0.0, 0.0, 0.0, un, udil, us0, us1, us2, state
    tau0 = fs0 / area - ks * dus0          # shear stress trial (Eq. 27 of the theory text, per area)
    tau1 = fs1 / area - ks * dus1
    tau2 = fs2 / area - ks * dus2
    state = state & ~(ST_SLIP | ST_TENSION)

    ft = p[c, P_FT]
    ftr = min(p[c, P_FT_RES], ft)
    coh = p[c, P_COH]
    cr = min(p[c, P_COH_RES], coh)
    tanf = p[c, P_TANF]
    tanfr = p[c, P_TANF_RES]
    if tanfr != tanfr:
        tanfr = tanf
    kt = h[s, H_KT]
    kss = h[s, H_KS]
    rt = 1.0 - h[s, H_DFT]                 # exp(−(ft − ft_r) κt / G_I), kept
    rs = 1.0 - h[s, H_DS]                  # exp(−(c − c_r) κs / G_II), kept
    r = min(rt, rs)

    # F1: tension, secant damage
    e = un - udil + h[s, H_UPC]
    if e > 0.0:
        dt = h[s, H_DT]
        ksec = kn * (1.0 - dt)
        sig_t = ftr + (ft - ftr) * r
        t = ksec * e
        if t > sig_t:                      # on the softening front: the crack opens further
            kt += e - sig_t / ksec
            rt = math.exp(-(ft - ftr) * kt / p[c, P_GI])
            h[s, H_DFT] = 1.0 - rt
            r = min(rt, rs)
            t = ftr + (ft - ftr) * r
            dt = 1.0 - t / (kn * e) if kn > 0.0 else 1.0
            dt = min(max(dt, h[s, H_DT]), 1.0)
            h[s, H_KT] = kt
            h[s, H_DT] = dt
            state = state | ST_TENSION | ST_FAILED
        sig = -t
        h[s, H_OPEN] = 1.0
    else:
        sig = -kn0 * e
        h[s, H_OPEN] = 0.0

    # F2: Coulomb, plastic slip, dilatancy
    c_now = cr + (coh - cr) * r
    tanf_now = tanfr + (tanf - tanfr) * r
    tmax = c_now + sig * tanf_now
    if tmax < 0.0:
        tmax = 0.0
    tm = math.sqrt(tau0 * tau0 + tau1 * tau1 + tau2 * tau2)
    if tm > tmax:
        dks = (tm - tmax) / ks if ks > 0.0 else 0.0
        q = tmax / tm
        tau0 *= q
        tau1 *= q
        tau2 *= q
        tm = tmax
        tandil = p[c, P_TANDIL]
        if tandil > 0.0 and dks > 0.0 and e <= 0.0:     # an open joint slides without dilating
            sd = p[c, P_SDIL]
            conf = 1.0
            if sd > 0.0:
                conf = 1.0 - sig / sd
                conf = min(max(conf, 0.0), 1.0)
            ddil = dks * tandil * conf * math.exp(-p[c, P_DELTA] * kss)
            udil += ddil
            sig += kn0 * ddil              # the blocked uplift raises the normal stress (as mohr, theory Eq. 43)
        kss += dks
        h[s, H_KS] = kss
        rs = math.exp(-(coh - cr) * kss / p[c, P_GII])
        h[s, H_DS] = 1.0 - rs
        state = state | ST_SLIP | ST_FAILED

    # F3: compression cap, returned along the normal
    fc = p[c, P_FC]
    if fc > 0.0 and sig > 0.0 and kn0 > 0.0:
        npk = p[c, P_NPEAK]
        gc = p[c, P_GC]
        fcr = min(p[c, P_FC_RES], fc)
        d = -(un - udil)
        sbar = cap_envelope(d, kn0, fc, npk, gc, fcr)
        cnn = p[c, P_CNN]
        cn = p[c, P_CN]
        css = p[c, P_CSS]
        if cnn * sig * sig + css * tm * tm + cn * sig > sbar * sbar:   # outside the ellipse
            qq = sbar * sbar - css * tm * tm
            if qq <= 0.0 and css > 0.0:    # the ellipse leaves no compression at this shear
                tl = sbar / math.sqrt(css)
                if tm > 0.0:
                    f = tl / tm
                    tau0 *= f
                    tau1 *= f
                    tau2 *= f
                tm = tl
            if qq < 0.0:
                qq = 0.0
            scap = (-cn + math.sqrt(cn * cn + 4.0 * cnn * qq)) / (2.0 * cnn)
            if scap < 0.0:
                scap = 0.0
            if sig > scap:
                h[s, H_UPC] = d - scap / kn0
                sig = scap
                state = state | ST_FAILED
            # yielding happens only at the furthest closure: past the peak it sets the damage
            if d > npk * 2.0 * fc / (npk + 1.0) / kn0:
                h[s, H_DC] = max(h[s, H_DC], 1.0 - sbar / fc)
    return sig * area, tau0 * area, tau1 * area, tau2 * area, un, udil, us0, us1, us2, state
