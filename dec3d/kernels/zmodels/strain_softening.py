"""Zone model ``strain-softening``: Itasca's strain-softening/strain-hardening Mohr-Coulomb model.

Source: Itasca, FLAC3D/3DEC documentation, "Strain-Softening/Hardening Mohr-Coulomb (SSoft)
Model", https://docs.itascacg.com/itasca900/common/models/ssoft/doc/modelssoft.html (and its
property page: ``table-cohesion``, ``table-friction``, ``table-dilation``, ``table-tension``; the
hardening parameters are read as ``strain-shear-plastic`` and ``strain-tension-plastic``).

The yield and potential functions, flow rules and stress corrections are those of the
Mohr-Coulomb model (``dec3d/kernels/zone_mohr.py``, used here as is); what differs is that the
cohesion c, friction φ and dilation ψ may be piecewise-linear functions (tables) of the shear
hardening parameter κs, and the tensile strength σt a function of the tensile hardening
parameter κt, both sums over the steps of plastic strain increments:

    Δκs = (½ [(Δε1ps − Δεmps)² + (Δεmps)² + (Δε3ps − Δεmps)²])^½,  Δεmps = (Δε1ps + Δε3ps)/3,

the page's measure of the plastic shear-strain increment of a shear return on one plane, whose
principal plastic strains are Δεps = λs (−1, 0, N_ψ) (principal axes of ``zone_mohr``, s1 the
most compressive): Δκs = f(N_ψ) λs, f(N) = (½ [(1 + m)² + m² + (N − m)²])^½, m = (N − 1)/3
(f = 1 when ψ = 0: Δκs is then the compressive plastic strain); and

    Δκt = Δε3pt, the plastic tensile strain (the sum of the tensile multipliers when two or
    three principal stresses are cut off, as Itasca's code adds them).

Itasca's correction is always on one plane (and the apex); dec3d's return also goes to an edge of
two shear planes, or a corner of shear and the cut-off (``zone_mohr``). There dec3d sums
Itasca's increment over the shear planes, Δκs = f(N_ψ) Σ λs (so a triaxial specimen whose two
lateral stresses are equal, an edge return, hardens by its compressive plastic strain as one
whose lateral stresses differ slightly, a one-plane return, does, instead of by the 13 % smaller
(J2')^½ of its symmetric plastic strain), and Δκt = Σ λt.

Per step (Itasca's order): the properties of the step come from κ at the start of the step
(tables at κs, κt; a property without a table keeps its column value), then the elastic trial
and the Mohr-Coulomb return, then κ grows by this step's increments, so the next step sees the
new properties. The multipliers are worked out from the return in principal space: the plastic
strain increment is Δεp = D⁻¹ (σ_trial − σ_new) (the return keeps the principal axes), with
principal values e_k from those of σ_trial − σ_new; each shear flow is −1 on its more compressive
axis and tension flows are >= 0, so Σ λs = −Σ min(e_k, 0), and the trace is Σ λs (N_ψ − 1) +
Σ λt, so Σ λt = Σ e_k − Σ λs (N_ψ − 1) (for a tension return alone the trace, (mean(σ_trial) −
mean(σ_new)) / K). These hold for the returns to a face, an edge of two shear planes, and the
shear-tension corner, where the split of Δεp into planes is unique; at the apex, and where two
axes are cut off on the shear pyramid, four or more planes meet, the split is not unique, and
dec3d's is the one these formulas give.

Table values: c and σt in Pa (taken >= 0), φ and ψ in degrees (kept in [0°, 89.99°]); σt is
capped at the apex c/tan φ by the return (as Itasca). Strength reduction (``model
factor-of-safety``): strengths from tables are divided by F = column P_SRF when F > 0 (c/F,
tan φ/F, σt/F, and tan ψ kept at most the reduced tan φ); constant strengths come already
reduced in their columns (the host's ``reduce``).

Columns: the shared ones (bulk, shear, density, cohesion, tan friction, tension, tan dilation,
P_SRF) and from P_OWN on the table references (table index + 1; 0: none) of cohesion,
friction, dilation and tension. History: h[z, 0] = κs, h[z, 1] = κt.

The chunk scratch ``wf``: wf[16:22] the trial handed to the general return (as ``mohr.py`` uses
it); wf[22] = CODE when wf[23:29] hold tan φ, tan ψ and the constants made from them (N_φ, √N_φ,
N_ψ, α_P; the rest, which the cohesion and tension enter, is made for every zone, its strengths
following κ); ``mohr.py``'s cache in wf[0:15] is left as it was (the zone-model contract). (CODE
= 3 is no value another model's scratch takes there by chance: ubiquitous-joint keeps its tag 5,
hoek-brown projector entries within ±1, in wf[22].)
"""
import math

from numba import njit

from ..principal import _deviator, _invariants, _values
from ..zone_mohr import mohr_scalar
from .mohr import rest
from ._common import (P_COHESION, P_OWN, P_SRF, P_TANDIL, P_TANFRIC, P_TENSION, SHEAR_NOW, TENSION_NOW, hooke,
                      table_value)

NAME = "strain-softening"
CODE = 3          # kept in save files: never renumber
#: own columns: table references (table index + 1, 0 none)
P_TABLE_COHESION = P_OWN
P_TABLE_FRICTION = P_OWN + 1
P_TABLE_DILATION = P_OWN + 2
P_TABLE_TENSION = P_OWN + 3
NCOLS = P_OWN + 4
NHIST = 2
HIST_NAMES = ("strain-shear-plastic", "strain-tension-plastic")     # κs, κt (Itasca's names)
PLASTIC = True

#: wf[22] when wf[23:29] hold this model's constants of tan φ, tan ψ (``_constants``)
_TAG = float(CODE)
#: largest friction or dilation angle a table may give [degrees]: tan and N_φ stay finite
MAX_ANGLE = 89.99
_RAD = math.pi / 180.0
#: ``_common.table_value`` (inlined where it is called: a call would count references of the
#: tables' arrays on each of the four reads)
_table_value = table_value


@njit(cache=True, inline="always")
def _table(tab, col, kappa):
    """(has a table, its value at kappa) for the table reference ``col`` (index + 1; 0 none; a
    reference past the tables bundle counts as none)."""
    if not col >= 1.0:
        return False, 0.0
    t = int(col)
    if t > tab.count.shape[0]:
        return False, 0.0
    return True, _table_value(tab, t - 1, kappa)


@njit(cache=True, inline="always")
def _tan_deg(v):
    if v < 0.0:
        v = 0.0
    elif v > MAX_ANGLE:
        v = MAX_ANGLE
    return math.tan(v * _RAD)


@njit(cache=True, inline="always")
def strengths(p, h, z, tab):
    """(c, tan φ, σt, tan ψ) of zone z for this step: tables at κs = h[z, 0] (c, φ, ψ) and
    κt = h[z, 1] (σt), divided by F = p[z, P_SRF] when F > 0; the columns where there is no
    table. (``tab`` is read only when the zone names a table: its arrays cost reference counts
    wherever it is read.)"""
    coh = p[z, P_COHESION]
    tf = p[z, P_TANFRIC]
    ten = p[z, P_TENSION]
    td = p[z, P_TANDIL]
    rc = p[z, P_TABLE_COHESION]
    rf = p[z, P_TABLE_FRICTION]
    rd = p[z, P_TABLE_DILATION]
    rt = p[z, P_TABLE_TENSION]
    if rc > 0.0 or rf > 0.0 or rd > 0.0 or rt > 0.0:
        ks = h[z, 0]
        f = p[z, P_SRF]
        red = f > 0.0
        has, v = _table(tab, rc, ks)
        if has:
            coh = max(v, 0.0)
            if red:
                coh /= f
        has, v = _table(tab, rf, ks)
        if has:
            tf = _tan_deg(v)
            if red:
                tf /= f
        has, v = _table(tab, rd, ks)
        if has:
            td = _tan_deg(v)
        has, v = _table(tab, rt, h[z, 1])
        if has:
            ten = max(v, 0.0)
            if red:
                ten /= f
        if red and td > tf:
            td = tf
    return coh, tf, ten, td


@njit(cache=True, inline="always")
def shear_factor(nps):
    """f(N_ψ): Itasca's Δκs of a one-plane shear return per unit multiplier (module text)."""
    m = (nps - 1.0) / 3.0
    return math.sqrt(0.5 * ((1.0 + m) ** 2 + m * m + (nps - m) ** 2))


@njit(cache=True, inline="always")
def hardening_increments(bits, one_plane, a0, a1, a2, a3, a4, a5, K, G, nps):
    """(Δκs, Δκt) of a return with bits ``bits`` (SHEAR_NOW, TENSION_NOW or both) from
    a = σ_trial − σ_new (xx yy zz xy xz yz), the moduli K, G and N_ψ (see the module text);
    ``one_plane``: the return was Itasca's one-plane return (then Δκs = (J2 of a)^½ / 2G, which
    is f(N_ψ) λs for the flow λs (−1, 0, N_ψ): no principal values needed)."""
    if K <= 0.0 or G <= 0.0:
        return 0.0, 0.0
    if bits & SHEAR_NOW == 0:
        return 0.0, max((a0 + a1 + a2) / (3.0 * K), 0.0)
    if one_plane:
        d0, d1, d2 = _deviator(a0, a1, a2)
        j2 = 0.5 * (d0 * d0 + d1 * d1 + d2 * d2) + a3 * a3 + a4 * a4 + a5 * a5
        return math.sqrt(j2) / (2.0 * G), 0.0
    m, d0, d1, d2, j2, r = _invariants(a0, a1, a2, a3, a4, a5)
    lo, mid, hi = _values(d0, d1, d2, a3, a4, a5, j2, r)
    ev = m / (3.0 * K)
    e1 = lo / (2.0 * G) + ev
    e2 = mid / (2.0 * G) + ev
    e3 = hi / (2.0 * G) + ev
    ls = -(min(e1, 0.0) + min(e2, 0.0) + min(e3, 0.0))
    lt = 0.0
    if bits & TENSION_NOW:
        lt = max((e1 + e2 + e3) - ls * (nps - 1.0), 0.0)
    return shear_factor(nps) * ls, lt


@njit(cache=True, inline="always")
def _constants(K, G, coh, tf, ten, td, wf):
    """``zone_mohr.mohr_constants`` (the same expressions, so the same bits), with what depends on
    tan φ and tan ψ alone (N_φ, its root, N_ψ, α_P) kept in wf[22:28] while they stay the same:
    softening zones mostly change c or σt only."""
    if wf[22] != _TAG or wf[23] != tf or wf[24] != td:
        sphi = tf / math.sqrt(1.0 + tf * tf)
        npf = (1.0 + sphi) / (1.0 - sphi)
        spsi = td / math.sqrt(1.0 + td * td)
        wf[22] = _TAG; wf[23] = tf; wf[24] = td
        wf[25] = npf
        wf[26] = math.sqrt(npf)
        wf[27] = (1.0 + spsi) / (1.0 - spsi)
        wf[28] = math.sqrt(1.0 + npf * npf) + npf
    npf = wf[25]
    nps = wf[27]
    csn = 2.0 * coh * wf[26]
    ft = ten
    if tf > 0.0 and coh / tf < ft:
        ft = coh / tf
    a1 = K + 4.0 * G / 3.0
    a2 = K - 2.0 * G / 3.0
    sp = ft * npf - csn
    return npf, csn, ft, nps, a1, a2, sp, wf[28], a1 * (1.0 + npf * nps) - a2 * (npf + nps)


@njit(cache=True)
def _scalar_return(e0, e1, e2, e3, e4, e5, coh, npf, csn, ft, nps, a1, a2, sp, ap, den):
    """``zone_mohr.mohr_scalar`` as one call on scalars: ``update`` is inlined into the zone step
    (no array arguments to count references of), this part is compiled once, not into each step."""
    return mohr_scalar(e0, e1, e2, e3, e4, e5, coh, npf, csn, ft, nps, a1, a2, sp, ap, den)


@njit(cache=True)
def _increments(bits, one_plane, a0, a1, a2, a3, a4, a5, K, G, nps):
    """``hardening_increments`` as one call on scalars (as ``_scalar_return``)."""
    return hardening_increments(bits, one_plane, a0, a1, a2, a3, a4, a5, K, G, nps)


@njit(cache=True, inline="always")
def update(p, h, z, K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5, tab, wf, mw):
    coh, tf, ten, td = strengths(p, h, z, tab)
    e0, e1, e2, e3, e4, e5 = hooke(K, G, d0, d1, d2, d3, d4, d5, s0, s1, s2, s3, s4, s5)
    npf, csn, ft, nps, a1, a2, sp, ap, den = _constants(K, G, coh, tf, ten, td, wf)
    code, t0, t1, t2, t3, t4, t5, dp = _scalar_return(e0, e1, e2, e3, e4, e5, coh, npf, csn, ft, nps, a1, a2, sp,
                                                      ap, den)
    one_plane = code >= 0
    if code < 0:
        # as Mohr-Coulomb's update goes on (``mohr.rest``): without tables this model gives its bits
        code, t0, t1, t2, t3, t4, t5, dp = rest(e0, e1, e2, e3, e4, e5, K, G, coh, tf, ten, td, npf, csn, ft, nps,
                                                a1, a2, sp, ap, den, wf, mw)
    if code != 0:
        dks, dkt = _increments(code, one_plane, e0 - t0, e1 - t1, e2 - t2, e3 - t3, e4 - t4, e5 - t5,
                                        K, G, nps)
        h[z, 0] += dks
        h[z, 1] += dkt
    return code, t0, t1, t2, t3, t4, t5, dp
