"""Slow twin of the ``mason`` joint law, written from the formulas in the kernel's docstring (MASON
README + Lourenço & Rots 1997), in plain Python on user-unit properties by name: it shares no code
and no column constants with ``dec3d/kernels/joints/mason.py``. History entries by their names."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np


@dataclass
class MasonTwin:
    props: dict                      # user units: Pa, Pa/m, degrees, J/m², 1/m
    hist: dict = field(default_factory=lambda: dict(kappa_t=0.0, dt=0.0, kappa_s=0.0, ds=0.0, u_pc=0.0,
                                                     dft=0.0, dc=0.0, open=0.0))

    def get(self, name, default=0.0):
        return float(self.props.get(name, default))

    def cap_strength(self, d):
        """σ̄c(d): σe = 2fc/(n+1) (initial cap) up to de = σe/kn0, a parabola tangent to the elastic
        line up to fc at n·de, exponential after."""
        fc, n, kn0 = self.get("compression"), self.get("peak_ratio", 1.0), self.kn0()
        gc, fcr = self.get("g_c"), min(self.get("comp-residual"), fc)
        sigma_e = 2 * fc / (n + 1)
        d_e = sigma_e / kn0
        d_p = n * d_e
        if d <= d_e:
            return sigma_e
        if d < d_p:
            return fc - (fc - sigma_e) * ((d_p - d) / (d_p - d_e)) ** 2
        return fcr + (fc - fcr) * math.exp(-(fc - fcr) * (d - d_p) / gc)

    def kn0(self):
        return self.get("stiffness-initial", self.get("stiffness-normal"))

    def step(self, area, dun, dus, un, udil, fs, us):
        """One increment. dus, fs, us: 3-vectors. Returns (fn, fs, un, udil, us, flags) with flags a
        set of {'tension', 'slip', 'failed'} for this step."""
        kn, ks, kn0 = self.get("stiffness-normal"), self.get("stiffness-shear"), self.kn0()
        ft, coh = self.get("tension"), self.get("cohesion")
        ftr, cr = min(self.get("tension-residual"), ft), min(self.get("cohesion-residual"), coh)
        tphi = math.tan(math.radians(self.get("friction")))
        tphir = math.tan(math.radians(self.get("friction-residual", self.get("friction"))))
        gI, gII = self.get("g_i"), self.get("g_ii")
        H = self.hist
        un = un + dun
        us = np.asarray(us, float) + dus
        flags = set()
        if area <= 0:
            return 0.0, np.zeros(3), un, udil, us, flags
        tau = np.asarray(fs, float) / area - ks * np.asarray(dus, float)

        def remaining():
            """min(rt, rs) from the kept losses dft = 1 − rt, ds = 1 − rs (each set with its exp)."""
            return min(1 - H["dft"], 1 - H["ds"])

        # tension cut-off with secant damage
        gap = un - udil + H["u_pc"]
        if gap > 0:
            secant = kn * (1 - H["dt"])
            strength = ftr + (ft - ftr) * remaining()
            if secant * gap > strength:
                H["kappa_t"] += gap - strength / secant
                H["dft"] = 1 - math.exp(-(ft - ftr) * H["kappa_t"] / gI)
                t = ftr + (ft - ftr) * remaining()
                H["dt"] = min(max(1 - t / (kn * gap), H["dt"]), 1.0)
                flags |= {"tension", "failed"}
            else:
                t = secant * gap
            sigma = -t
            H["open"] = 1.0
        else:
            sigma = -kn0 * gap
            H["open"] = 0.0

        # Coulomb with softening cohesion and friction, plastic slip, dilatancy
        r = remaining()
        tau_max = max((cr + (coh - cr) * r) + sigma * (tphir + (tphi - tphir) * r), 0.0)
        tmag = float(np.linalg.norm(tau))
        if tmag > tau_max:
            slip = (tmag - tau_max) / ks if ks > 0 else 0.0
            tau = tau * (tau_max / tmag)
            tmag = tau_max
            tpsi = math.tan(math.radians(self.get("dilation")))
            if tpsi > 0 and slip > 0 and gap <= 0:
                s0 = self.get("dilation-zero")
                conf = 1.0 if s0 <= 0 else min(max(1 - sigma / s0, 0.0), 1.0)
                lift = slip * tpsi * conf * math.exp(-self.get("delta", 2.0) * H["kappa_s"])
                udil += lift
                sigma += kn0 * lift
            H["kappa_s"] += slip
            H["ds"] = 1 - math.exp(-(coh - cr) * H["kappa_s"] / gII)
            flags |= {"slip", "failed"}

        # elliptical cap, returned along the normal
        fc = self.get("compression")
        if fc > 0 and sigma > 0 and kn0 > 0:
            d = udil - un
            sbar = self.cap_strength(d)
            cnn, cn, css = self.get("cnn", 1.0), self.get("cn"), self.get("css", 1.0)
            if cnn * sigma ** 2 + css * tmag ** 2 + cn * sigma > sbar ** 2:    # outside the ellipse
                room = sbar ** 2 - css * tmag ** 2
                if room <= 0 and css > 0:
                    limit = sbar / math.sqrt(css)
                    tau = tau * (limit / tmag) if tmag > 0 else tau
                    tmag = limit
                room = max(room, 0.0)
                sigma_cap = max((-cn + math.sqrt(cn ** 2 + 4 * cnn * room)) / (2 * cnn), 0.0)
                if sigma > sigma_cap:
                    H["u_pc"] = d - sigma_cap / kn0
                    sigma = sigma_cap
                    flags.add("failed")
                n = self.get("peak_ratio", 1.0)
                if d > n * (2 * fc / (n + 1)) / kn0:
                    H["dc"] = max(H["dc"], 1 - sbar / fc)
        return sigma * area, tau * area, un, udil, us, flags
