"""The Hoek-Brown envelope of zone model ``hoek-brown`` (``hoek_brown.py`` holds the model and its
returns; the criterion, its sources and conventions are in that module's text): σ1 at yield and the
slope of the envelope at σ3 (compression positive), the Mohr-Coulomb tangent there. Kept apart
because the model's module had grown past the 600-line rule; only ``hoek_brown.py`` imports it.
"""
import math

from numba import njit

#: largest tangent N_φc used (the s = 0 apex, where the curve is vertical)
NPHI_MAX = 1e6


@njit(cache=True, inline="always")
def _envelope(x, mb, s, a, sci):
    """(σ1 at yield, its slope N = dσ1/dσ3, the curvature dN/dσ3) at σ3 = x (compression
    positive) on the envelope: the Hoek-Brown curve for x >= 0, its tangent at 0 for x < 0
    (curvature 0). N is capped at NPHI_MAX; where the cap acts on the curve the line is no
    tangent and the curvature is NaN. One power per call: base^a = base × base^(a-1)."""
    if x < 0.0:
        if s > 0.0:
            t = s ** (a - 1.0)
            n0 = 1.0 + a * mb * t
            if n0 > NPHI_MAX:
                return sci * s ** a + NPHI_MAX * x, NPHI_MAX, 0.0
            return sci * s * t + n0 * x, n0, 0.0
        return NPHI_MAX * x, NPHI_MAX, 0.0
    base = mb * x / sci + s
    if base > 0.0:
        t = base ** (a - 1.0)
        n = 1.0 + a * mb * t
        if n > NPHI_MAX:            # (also where base^(a-1) overflows)
            return x + sci * base ** a, NPHI_MAX, math.nan
        # dN/dσ3 = a (a - 1) mb² base^(a-2) / σci = (a - 1) mb (N - 1) / (σci base)
        return x + sci * base * t, n, (a - 1.0) * mb * (n - 1.0) / (sci * base)
    return x, NPHI_MAX, math.nan


@njit(cache=True, inline="always")
def hb_strength(x, mb, s, a, sci):
    """(σ1 at yield, its slope N = dσ1/dσ3) at σ3 = x (compression positive) on the envelope:
    the Hoek-Brown curve for x >= 0, its tangent at 0 for x < 0. N is capped at NPHI_MAX."""
    q, n, _c = _envelope(x, mb, s, a, sci)
    return q, n


@njit(cache=True, inline="always")
def _tangent(x, mb, s, a, sci):
    """The Mohr-Coulomb tangent of the envelope at σ3 = max(x, 0): (c_c, tan φc)."""
    if x < 0.0:
        x = 0.0
    q, n = hb_strength(x, mb, s, a, sci)
    rn = math.sqrt(n)
    csn = q - n * x                 # 2 c √N (>= 0: the curve is concave and q(0) >= 0)
    if csn < 0.0:
        csn = 0.0
    return 0.5 * csn / rn, 0.5 * (n - 1.0) / rn


@njit(cache=True, inline="always")
def edge_root(c1, k1, c3, k3, x, mb, s, a, sci, tol, mar, maxit):
    """The root of g(x) = c1 + k1 x - q(c3 + k3 x) (σ1 and σ3 of an edge return, linear in the
    multiplier x; g convex and decreasing) from x on: (converged, root). Newton steps, shortened
    by Halley's where g's curvature would overshoot, until the quadratic term of the next step is
    below 0.01 tol (and that step does not carry σ3 across zero), then that Newton step; not
    converged when g(x) <= mar at the start, the envelope fails or ``maxit`` steps pass."""
    y3 = c3 + k3 * x
    q, n, c = _envelope(y3, mb, s, a, sci)
    g = c1 + k1 * x - q
    if not g > mar:
        return False, x
    done = False
    dn = 0.0
    for _it in range(maxit):
        if not c > -1e300:
            break
        den = n * k3 - k1
        if not den > 0.0:
            break
        dn = g / den
        y3n = y3 + dn * k3
        if 0.5 * (-c) * (k3 * k3) * (dn * dn) <= 0.01 * tol and not (y3 < 0.0 and y3n > 0.0):
            done = True
            break
        step = dn
        dd = 2.0 * den * den + g * c * (k3 * k3)
        if dd > den * den:
            step = 2.0 * g * den / dd
        x += step
        y3 = c3 + k3 * x
        q, n, c = _envelope(y3, mb, s, a, sci)
        g = c1 + k1 * x - q
    if not done:
        return False, x
    return True, x + dn                  # the last Newton step
