"""Generating disk fractures from a template (``fracture template create``, ``fracture generate``).

Pure numpy, vectorised; every random number comes from ``numpy.random.Generator(PCG64(seed))`` so
the same seed gives the same fractures on every machine.

Template (JSON, angles in radians, sizes are disk *diameters* as 3DEC's fracture size):

    orientation  {"kind": "uniform"}                      isotropic normals (uniform on the sphere)
                 {"kind": "fisher", "dip", "ddir", "kappa"}  Fisher about the mean normal of dip/ddir
                 {"kind": "bootstrapped", "dip": [...], "ddir": [...], "weight": [...]}
    size         {"kind": "power-law", "exponent": a}       n(l) ∝ l^-a on [lmin, lmax]
                 {"kind": "uniform"}                        uniform on [lmin, lmax]
                 {"kind": "log-normal", "mean", "std"}      of the diameter itself, truncated to the limits
                 {"kind": "gauss", "mean", "std"}           normal, truncated to the limits (and > 0)
    size_limits  [lmin, lmax or None]; dip_limits [lo, hi]; ddir_limits [lo, hi]; set: int
    position     "uniform" (in the generation box)

Sampling rules (from the distributions' formulas):
- Fisher: the angle θ to the mean has cos θ = 1 + ln(u + (1 − u) e^{−2κ}) / κ (inverse CDF of the
  density ∝ e^{κ cos θ} sin θ), the azimuth is uniform; normals are then turned to point up.
- Truncated power law (a ≠ 1): l = [lmin^{1−a} + u (lmax^{1−a} − lmin^{1−a})]^{1/(1−a)};
  a = 1: l = lmin (lmax/lmin)^u.
- Dip and dip-direction limits, the size limits of the log-normal and Gaussian laws: rejection.
"""
from __future__ import annotations

import math

import numpy as np

from .dfn_measure import clipped_areas, scanline_hits

_F = np.float64
#: at most this many fractures per `fracture generate` unless `maximum` says otherwise
DEFAULT_MAXIMUM = 2_000_000


class GenerationError(ValueError):
    """A template or target that cannot be generated (the command adds file:line:column)."""


def default_template() -> dict:
    """3DEC's default template: uniform positions and orientations, power-law sizes (exponent 4) from 1."""
    return {"orientation": {"kind": "uniform"}, "size": {"kind": "power-law", "exponent": 4.0},
            "size_limits": [1.0, None], "dip_limits": [0.0, math.pi / 2], "ddir_limits": [0.0, 2 * math.pi],
            "position": "uniform", "set": 1}


def check_template(t: dict) -> None:
    """Refuse what cannot be sampled (the messages name the keyword)."""
    o, s = t["orientation"], t["size"]
    lo, hi = t["size_limits"]
    if o["kind"] == "fisher" and not o["kappa"] > 0:
        raise GenerationError(f"`orientation fisher`: kappa must be positive, got {o['kappa']:g}")
    if o["kind"] == "bootstrapped" and len(o["dip"]) == 0:
        raise GenerationError("`orientation bootstrapped`: the list holds no orientation")
    if not lo > 0:
        raise GenerationError(f"`size-limits`: the minimum size must be positive, got {lo:g}")
    if hi is not None and not hi > lo:
        raise GenerationError(f"`size-limits`: the maximum {hi:g} is not above the minimum {lo:g} (reversed limits?)")
    if s["kind"] == "power-law" and hi is None and not s["exponent"] > 1:
        raise GenerationError(f"`size power-law {s['exponent']:g}`: an exponent ≤ 1 with no maximum size has no "
                              "finite mean (give `size-limits` a maximum, or an exponent above 1)")
    if s["kind"] == "uniform" and hi is None:
        raise GenerationError("`size uniform` needs a maximum size (`size-limits lmin lmax`)")
    if s["kind"] in ("log-normal", "gauss") and not (s["mean"] > 0 and s["std"] > 0):
        raise GenerationError(f"`size {s['kind']}`: mean and standard deviation must be positive")
    dl, al = t["dip_limits"], t["ddir_limits"]
    if not (0 <= dl[0] < dl[1] <= math.pi / 2 + 1e-12):
        raise GenerationError("`dip-limits` must satisfy 0 ≤ min < max ≤ 90")
    if not (al[0] < al[1]):
        raise GenerationError("`dip-direction-limits`: the minimum must be below the maximum")


# ------------------------------------------------------------------ distributions
def _upward(n):
    flip = (n[:, 2] < 0) | ((n[:, 2] == 0) & (n[:, 1] < 0))
    n[flip] *= -1.0
    return n


def _orient(o: dict, k: int, rng) -> np.ndarray:
    if o["kind"] == "uniform":
        z = rng.uniform(-1.0, 1.0, k)
        phi = rng.uniform(0.0, 2 * math.pi, k)
        s = np.sqrt(np.clip(1 - z * z, 0, None))
        return _upward(np.column_stack([s * np.cos(phi), s * np.sin(phi), z]))
    if o["kind"] == "fisher":
        kap = float(o["kappa"])
        u = rng.uniform(0.0, 1.0, k)
        w = 1.0 + np.log(u + (1.0 - u) * math.exp(-2 * kap)) / kap
        w = np.clip(w, -1.0, 1.0)
        phi = rng.uniform(0.0, 2 * math.pi, k)
        s = np.sqrt(1 - w * w)
        mu = _dipn(o["dip"], o["ddir"])
        a = np.array([0.0, 0.0, 1.0]) if abs(mu[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
        e1 = np.cross(a, mu)
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(mu, e1)
        n = (s * np.cos(phi))[:, None] * e1 + (s * np.sin(phi))[:, None] * e2 + w[:, None] * mu
        return _upward(n)
    p = np.asarray(o["weight"], _F)
    i = rng.choice(len(p), size=k, p=p / p.sum())
    d, a = np.asarray(o["dip"], _F)[i], np.asarray(o["ddir"], _F)[i]
    return _upward(np.column_stack([np.sin(d) * np.sin(a), np.sin(d) * np.cos(a), np.cos(d)]))


def _dipn(dip, ddir):
    return np.array([math.sin(dip) * math.sin(ddir), math.sin(dip) * math.cos(ddir), math.cos(dip)])


def _sizes(s: dict, lo: float, hi, k: int, rng) -> np.ndarray:
    kind = s["kind"]
    if kind == "power-law":
        a = float(s["exponent"])
        u = rng.uniform(0.0, 1.0, k)
        if abs(a - 1.0) < 1e-12:
            return lo * (hi / lo) ** u
        e = 1.0 - a
        top = 0.0 if hi is None else hi ** e
        return (lo ** e + u * (top - lo ** e)) ** (1.0 / e)
    if kind == "uniform":
        return rng.uniform(lo, hi, k)
    if kind == "log-normal":
        m, sd = float(s["mean"]), float(s["std"])
        sig2 = math.log(1 + (sd / m) ** 2)
        draw = lambda j: rng.lognormal(math.log(m) - sig2 / 2, math.sqrt(sig2), j)  # noqa: E731
    else:
        draw = lambda j: rng.normal(float(s["mean"]), float(s["std"]), j)  # noqa: E731
    out = np.empty(0)
    tries = 0
    while out.size < k:
        x = draw(max(2 * (k - out.size), 64))
        keep = x >= lo
        if hi is not None:
            keep &= x <= hi
        x = x[keep]
        out = np.concatenate([out, x])
        tries += 1
        if tries > 200:
            raise GenerationError(f"`size {kind}`: almost no size falls within the size limits")
    return out[:k]


def sample(t: dict, k: int, box, rng) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``k`` fractures of template ``t`` with centres uniform in ``box`` (xmin xmax ymin ymax zmin zmax):
    centres (k, 3), upward unit normals (k, 3), radii (k,)."""
    b = np.asarray(box, _F)
    c = np.column_stack([rng.uniform(b[0], b[1], k), rng.uniform(b[2], b[3], k), rng.uniform(b[4], b[5], k)])
    n = _limited_orient(t, k, rng)
    lo, hi = t["size_limits"]
    d = _sizes(t["size"], float(lo), None if hi is None else float(hi), k, rng)
    return c, n, 0.5 * d


def _limited_orient(t, k, rng):
    dl, al = t["dip_limits"], t["ddir_limits"]
    full = dl[0] <= 0 and dl[1] >= math.pi / 2 - 1e-12 and al[0] <= 0 and al[1] >= 2 * math.pi - 1e-12
    if full:
        return _orient(t["orientation"], k, rng)
    out = np.empty((0, 3))
    tries = 0
    while len(out) < k:
        n = _orient(t["orientation"], max(2 * (k - len(out)), 64), rng)
        dip = np.arccos(np.clip(n[:, 2], -1, 1))
        dd = np.mod(np.arctan2(n[:, 0], n[:, 1]), 2 * math.pi)
        ok = (dip >= dl[0]) & (dip <= dl[1]) & (dd >= al[0]) & (dd <= al[1])
        out = np.concatenate([out, n[ok]])
        tries += 1
        if tries > 200:
            raise GenerationError("almost no orientation falls within the dip and dip-direction limits")
    return out[:k]


def mean_area(t: dict, seed: int) -> float:
    """Mean disk area of the template (from 20000 sizes of a generator of its own: deterministic)."""
    rng = np.random.Generator(np.random.PCG64([int(seed), 7]))
    lo, hi = t["size_limits"]
    d = _sizes(t["size"], float(lo), None if hi is None else float(hi), 20000, rng)
    return float(np.mean(math.pi * d * d / 4))


def generate(t: dict, box, seed: int, count: int | None = None, p32: float | None = None,
             p10: float | None = None, scanline=None, maximum: int = DEFAULT_MAXIMUM):
    """Fractures of template ``t`` in ``box`` until ``count`` fractures, or the fracture area inside the
    box over its volume reaches ``p32``, or the fractures crossing ``scanline`` (two points) per its
    length reach ``p10``. Returns (centres, normals, radii)."""
    check_template(t)
    rng = np.random.Generator(np.random.PCG64(int(seed)))
    b = np.asarray(box, _F)
    vol = float((b[1] - b[0]) * (b[3] - b[2]) * (b[5] - b[4]))
    if not vol > 0:
        raise GenerationError("the generation box has no volume")
    if count is not None:
        if count > maximum:
            raise GenerationError(f"{count} fractures is more than the maximum {maximum}")
        return sample(t, int(count), b, rng)
    if p32 is not None:
        need = p32 * vol / mean_area(t, seed)
        what, target = "P32", p32 * vol
    else:
        p0, p1 = np.asarray(scanline[:3], _F), np.asarray(scanline[3:], _F)
        length = float(np.linalg.norm(p1 - p0))
        if not length > 0:
            raise GenerationError("the scanline has no length")
        # a disk of radius r crosses a line with probability ~ π r² E|cos θ| / volume; E|cos θ| ≤ 1
        need = p10 * length * vol / (mean_area(t, seed) * 0.5)
        what, target = "P10", p10 * length
    if need > maximum:
        raise GenerationError(f"{what} {p32 if p32 is not None else p10:g} would need about {need:.3g} fractures, "
                              f"more than the maximum {maximum} (raise `maximum`, or lower the target)")
    parts, total = [], 0.0
    made = 0
    while True:
        k = int(min(max(1.1 * (need - made) + 64, 64), maximum - made))
        if k <= 0:
            raise GenerationError(f"{what} target not reached with the maximum of {maximum} fractures")
        c, n, r = sample(t, k, b, rng)
        w = clipped_areas(c, n, r, b) if p32 is not None else scanline_hits(c, n, r, p0, p1).astype(_F)
        cum = total + np.cumsum(w)
        hit = np.flatnonzero(cum >= target)
        if hit.size:
            j = int(hit[0]) + 1
            parts.append((c[:j], n[:j], r[:j]))
            break
        parts.append((c, n, r))
        total = float(cum[-1]) if cum.size else total
        made += k
        need = max(need, made * target / max(total, 1e-300)) if total > 0 else need * 2
    return tuple(np.concatenate([p[i] for p in parts]) for i in range(3))
