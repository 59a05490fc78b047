"""The slope as the TOML input describes it: ground profile, layers, water, surcharges.

Shared by the mesher (block loads, interface properties, pore pressures) and by
the limit-equilibrium code, so both methods see the same slope.

Layers are listed top to bottom.  Layer 0 starts at the ground surface; layer i > 0
starts at its `top` polyline and ends at the next layer's top (or without limit).
A point exactly on a layer top belongs to the layer below that top.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class Layer:
    name: str
    c: float            # peak cohesion, Pa
    phi: float          # peak friction angle, degrees
    c_res: float
    phi_res: float
    gamma: float        # unit weight, N/m^3
    kn: float           # Pa/m
    ks: float           # Pa/m
    delta_res: float    # m
    tensile: float      # Pa
    cutoff: bool        # tension cut-off applies
    top: np.ndarray | None = None   # (k, 2) polyline, None for the first layer


@dataclass
class Slope:
    profile: np.ndarray                 # (k, 2) ground surface, x increasing
    layers: list                        # [Layer]
    ru: float = 0.0
    ru_mode: str = "standard"
    piezometric: np.ndarray | None = None
    gamma_w: float = 9810.0
    surcharges: list = field(default_factory=list)   # [(x1, x2, q Pa)]
    kh: float = 0.0                     # pseudo-static coefficient, towards the slope face

    def ground(self, x):
        return np.interp(x, self.profile[:, 0], self.profile[:, 1])

    def faces_left(self) -> bool:
        """True when the ground rises to the right (the face looks towards -x)."""
        return self.profile[-1, 1] >= self.profile[0, 1]

    def layer_tops(self, x) -> np.ndarray:
        """(L, len(x)) top elevation of every layer, clipped to the ground."""
        x = np.atleast_1d(np.asarray(x, float))
        g = self.ground(x)
        tops = [g]
        for lay in self.layers[1:]:
            tops.append(np.minimum(np.interp(x, lay.top[:, 0], lay.top[:, 1]), g))
        return np.array(tops)

    def layer_at(self, x, y) -> np.ndarray:
        """Index of the layer holding each point (x, y)."""
        tops = self.layer_tops(x)
        y = np.atleast_1d(np.asarray(y, float))
        if len(self.layers) == 1:
            return np.zeros(len(y), np.int64)
        return np.sum(y[None, :] <= tops[1:], axis=0).astype(np.int64)

    def prop(self, name: str, idx: np.ndarray) -> np.ndarray:
        return np.array([getattr(lay, name) for lay in self.layers])[idx]

    def overburden(self, x, y) -> np.ndarray:
        """Vertical total stress from the soil above (x, y), Pa (no surcharge)."""
        x = np.atleast_1d(np.asarray(x, float))
        y = np.atleast_1d(np.asarray(y, float))
        tops = self.layer_tops(x)
        gam = np.array([lay.gamma for lay in self.layers])
        total = np.zeros(len(x))
        for i in range(len(self.layers)):
            upper = tops[i]
            lower = tops[i + 1] if i + 1 < len(self.layers) else np.full(len(x), -np.inf)
            total += gam[i] * np.clip(np.minimum(upper, tops[0]) - np.maximum(lower, y), 0.0, None)
        return total

    def pore_pressure(self, x, y) -> np.ndarray:
        """Pore pressure at full load for the standard definitions, Pa.

        r_u: u = r_u * sigma_v (= r_u gamma h in one layer; Bishop & Morgenstern 1960);
        piezometric line: u = gamma_w * (y_piezo(x) - y) below the line.
        The listing's r_u mode needs no u (it scales sigma_n), so this returns zeros then.
        """
        x = np.atleast_1d(np.asarray(x, float))
        y = np.atleast_1d(np.asarray(y, float))
        if self.piezometric is not None:
            yp = np.interp(x, self.piezometric[:, 0], self.piezometric[:, 1])
            return self.gamma_w * np.clip(yp - y, 0.0, None)
        if self.ru_mode == "standard" and self.ru:
            return self.ru * self.overburden(x, y)
        return np.zeros(len(x))

    def surcharge_on(self, x0, x1) -> tuple[np.ndarray, np.ndarray]:
        """Vertical surcharge resultant (N/m, downward positive) and its x on [x0, x1] pieces."""
        x0, x1 = np.asarray(x0, float), np.asarray(x1, float)
        force = np.zeros(x0.shape)
        moment = np.zeros(x0.shape)
        for a, b, q in self.surcharges:
            lo, hi = np.maximum(np.minimum(x0, x1), a), np.minimum(np.maximum(x0, x1), b)
            w = np.clip(hi - lo, 0.0, None)
            force += q * w
            moment += q * w * 0.5 * (lo + hi)
        with np.errstate(divide="ignore", invalid="ignore"):
            xbar = np.where(force > 0, moment / force, 0.5 * (x0 + x1))
        return force, xbar
