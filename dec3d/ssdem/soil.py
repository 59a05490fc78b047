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

    def circle_spans(self, xc, yc, R):
        """Where the lower arcs of circles run below the ground, found exactly.

        The arc y = yc - sqrt(R^2 - (x - xc)^2) is intersected with every segment of
        the profile (a quadratic per segment), inside the profile's x range.  Between
        consecutive crossings the arc is either below the ground (a slip mass) or
        above it; a circle that just touches the ground splits there.  Returns
        (x_in, x_out, n_masses): the widest stretch below the ground of each circle
        (nan when none) and how many separate stretches there are.  A stretch must begin
        and end where the arc meets the ground inside the profile's x range.  The Bishop search
        and the slip-surface mesher both use the widest stretch, so every circle the
        search proposes is one the mesher accepts.
        """
        xc, yc, R = (np.atleast_1d(np.asarray(v, float)) for v in (xc, yc, R))
        with np.errstate(all="ignore"):
            return self._circle_spans(xc, yc, R)

    def _circle_spans(self, xc, yc, R):
        p = self.profile
        x0, y0, x1, y1 = p[:-1, 0], p[:-1, 1], p[1:, 0], p[1:, 1]
        lo = np.maximum(xc - R, p[0, 0])
        hi = np.minimum(xc + R, p[-1, 0])
        # segment k: (x, y) = (x0 + t dx, y0 + t dy); |(x, y) - (xc, yc)|^2 = R^2
        dx, dy = (x1 - x0)[None, :], (y1 - y0)[None, :]
        ex, ey = x0[None, :] - xc[:, None], y0[None, :] - yc[:, None]
        a = dx * dx + dy * dy
        b = 2 * (ex * dx + ey * dy)
        c = ex * ex + ey * ey - (R * R)[:, None]
        disc = b * b - 4 * a * c
        sq = np.sqrt(np.where(disc >= 0, disc, np.nan))
        cuts = []
        for t in ((-b - sq) / (2 * a), (-b + sq) / (2 * a)):
            y = y0[None, :] + t * dy
            ok = (t >= 0) & (t <= 1) & (y <= yc[:, None])      # on the segment and on the lower arc
            cuts.append(np.where(ok, x0[None, :] + t * dx, np.nan))
        pts = np.concatenate([lo[:, None], hi[:, None]] + cuts, axis=1)
        pts = np.where((pts >= lo[:, None]) & (pts <= hi[:, None]), pts, np.nan)
        pts = np.sort(pts, axis=1)                                # nan last
        xm = 0.5 * (pts[:, 1:] + pts[:, :-1])
        arc = yc[:, None] - np.sqrt(np.clip((R * R)[:, None] - (xm - xc[:, None]) ** 2, 0, None))
        width = np.diff(pts, axis=1)
        below = (self.ground(np.nan_to_num(xm)) - arc > 0) & (width > 0) & np.isfinite(xm)
        below &= lo[:, None] < hi[:, None]
        # runs of consecutive stretches below the ground; the widest run is the slip mass.
        # A run must meet the ground at both ends: one that reaches the side of the
        # circle (x = xc -/+ R) under the ground is no slip surface (the arc turns up
        # underground), and one cut off by an end of the profile leaves the section.
        r = np.arange(len(xc))
        last_col = np.maximum(np.isfinite(pts).sum(axis=1) - 2, 0)
        run = self._runs(below)
        first_run, last_run = run[:, 0], run[r, last_col]
        below &= ~(((run == first_run[:, None]) & (first_run[:, None] >= 0)) |
                   ((run == last_run[:, None]) & (last_run[:, None] >= 0)))
        run = self._runs(below)
        n_runs = run.max(axis=1, initial=-1) + 1
        k = max(int(n_runs.max(initial=0)), 1)
        tot = np.zeros((len(xc), k))
        rows = np.repeat(np.arange(len(xc)), run.shape[1])
        sel = run.ravel() >= 0
        np.add.at(tot, (rows[sel], run.ravel()[sel]), np.nan_to_num(width).ravel()[sel])
        best = np.argmax(tot, axis=1)
        inrun = run == best[:, None]
        first = np.argmax(inrun, axis=1)
        last = inrun.shape[1] - 1 - np.argmax(inrun[:, ::-1], axis=1)
        has = n_runs > 0
        x_in = np.where(has, pts[r, first], np.nan)
        x_out = np.where(has, pts[r, np.minimum(last + 1, pts.shape[1] - 1)], np.nan)
        return x_in, x_out, n_runs

    @staticmethod
    def _runs(below: np.ndarray) -> np.ndarray:
        """Index of the run of consecutive True entries each entry belongs to (-1: False)."""
        start = below & ~np.concatenate([np.zeros((len(below), 1), bool), below[:, :-1]], axis=1)
        return np.where(below, np.cumsum(start, axis=1) - 1, -1)
