"""Spring laws of the interfaces (thesis Sec. 3.2.1 A and 4.1.4, Figs. 3.2 and 4.2).

Normal spring: linear in compression, never yields there.  In tension beyond the
tensile strength the interface cracks: normal and shear stiffness drop to zero
for good (a tension crack, thesis Sec. 4.1.4).  The cut-off is applied to
cohesive soils only; a cohesionless interface keeps its normal spring (thesis
Sec. 3.2.1 A) and gets no shear strength in tension from Mohr-Coulomb anyway.

Shear spring, secant formulation (Eq. 4.2-4.3):
    tau_p = c_p + sigma'_n tan(phi_p),  tau_r = c_r + sigma'_n tan(phi_r)   (>= 0)
    delta_peak = tau_p / k_s0   (computed per interface, ERRATA; not user input)
    strength(delta) = tau_p                                      delta <= delta_peak
                    = tau_p + (tau_r - tau_p)(delta - delta_peak)/(delta_res - delta_peak)
                                                                 delta_peak < delta < delta_res
                    = tau_r                                      delta >= delta_res
    k_s,new = k_s0 before peak, strength(delta)/delta after; and k_s never increases
    (a larger secant value means unloading: the old stiffness is kept).
"""
from __future__ import annotations

import numpy as np


def effective_normal(sigma_n: np.ndarray, u_pore: np.ndarray, ru: float, ru_mode: str, load: float) -> np.ndarray:
    """sigma'_n (compression positive) at load factor `load`.

    "standard": sigma' = sigma - load * u, u = r_u gamma h (or piezometric) stored per interface;
    "listing" : sigma' = (1 - load * r_u) sigma, as the thesis program did.  Pore pressure
    grows with the load factor because it is proportional to the (growing) unit weight.
    """
    if ru_mode == "listing":
        return (1.0 - load * ru) * sigma_n
    return sigma_n - load * u_pore


def strengths(sig_eff, c_p, tan_p, c_r, tan_r) -> tuple[np.ndarray, np.ndarray]:
    """Peak and residual Mohr-Coulomb strengths (Eq. 3.1, 3.2), never negative."""
    tau_p = np.maximum(c_p + sig_eff * tan_p, 0.0)
    tau_r = np.maximum(c_r + sig_eff * tan_r, 0.0)
    return tau_p, tau_r


def strength_at(delta, tau_p, tau_r, ks0, del_res) -> tuple[np.ndarray, np.ndarray]:
    """Shear strength available at slip |delta| (m,) and delta_peak (m,)."""
    d = np.abs(delta)
    with np.errstate(divide="ignore", invalid="ignore"):
        d_peak = np.where(ks0 > 0, tau_p / ks0, 0.0)
        span = del_res - d_peak
        frac = np.where(span > 0, (d - d_peak) / span, 1.0)
    frac = np.clip(frac, 0.0, 1.0)
    tau = np.where(d <= d_peak, tau_p, tau_p + (tau_r - tau_p) * frac)
    return tau, d_peak


def secant_ks(delta, tau_p, tau_r, ks0, del_res) -> tuple[np.ndarray, np.ndarray]:
    """Secant shear stiffness from the law (before the no-increase rule) and the strength."""
    d = np.abs(delta)
    tau, d_peak = strength_at(d, tau_p, tau_r, ks0, del_res)
    with np.errstate(divide="ignore", invalid="ignore"):
        ks = np.where(d <= d_peak, ks0, tau / d)
    return ks, tau


def update(kn, ks, cracked, ks0, delta_s, sigma_n, sig_eff, c_p, tan_p, c_r, tan_r, del_res, tensile, cutoff):
    """One secant update of the springs.

    Inputs (m,): current kn, ks, cracked flags, initial ks0, midpoint slip delta_s,
    total normal stress sigma_n and effective sigma'_n (compression positive), strength
    parameters.  Returns new (kn, ks, cracked, new_crack, plastic) without modifying the
    inputs; `plastic` marks springs now carrying their full strength (past the peak and
    loading), whose tangent shear stiffness is zero.
    """
    new_crack = (~cracked) & cutoff & (-sigma_n > tensile)
    cracked = cracked | new_crack
    tau_p, tau_r = strengths(sig_eff, c_p, tan_p, c_r, tan_r)
    ks_law, _ = secant_ks(delta_s, tau_p, tau_r, ks0, del_res)
    ks_new = np.minimum(ks, ks_law)                   # secant stiffness never increases
    d_peak = np.where(ks0 > 0, tau_p / np.where(ks0 > 0, ks0, 1.0), 0.0)
    plastic = (np.abs(delta_s) > d_peak) & (ks_law <= ks) & ~cracked
    kn_new = np.where(cracked, 0.0, kn)
    ks_new = np.where(cracked, 0.0, ks_new)
    return kn_new, ks_new, cracked, new_crack, plastic
