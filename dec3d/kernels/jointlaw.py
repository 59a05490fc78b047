"""Sub-contact force update and the Coulomb-slip joint law (3DEC theory Eqs. 15-43, ERRATA).

Batched over sub-contacts; every array has the sub-contact as its first dimension.
Units: forces N, displacements m, stiffness Pa/m, stresses Pa, areas m², angles as tangents.

Per sub-contact s of contact c (blocks A = ca[c], B = cb[c], normal n = cn[c], A → B):
  V   = ẋ_B + ω_B × (x − B) − ẋ_A − ω_A × (x − A)              (Eq. 15)
  ΔU  = V Δt,  ΔUⁿ = ΔU·n,  ΔUˢ = ΔU − ΔUⁿ n                   (Eqs. 20-22)
  Fˢ := Fˢ − Fˢ × (n_old × n)                                 (Eq. 23)
  uⁿ := uⁿ + ΔUⁿ (total normal displacement, starting at the sub-contact's own gap when it is
        made; that gap already holds the last step's motion, so its first update (ST_NEW) adds
        no increment: counting it twice made impacts engage one step, v Δt, early)
  Fⁿ  = −Kn A (uⁿ − u_dil)  (Eq. 24 integrated: compression positive, zero while open)
  Fˢ := Fˢ − Ks A ΔUˢ                                          (Eqs. 25, 27)
  intact: Tmax = −T A (Eq. 34), Fˢmax = c A + Fⁿ tan φ (Eq. 35 per ERRATA)
  Fⁿ < Tmax → Fⁿ = Fˢ = 0, failed (Eq. 38); |Fˢ| > Fˢmax → scaled to the limit, failed,
  slipping (Eq. 39); after failure c, T are the residual values (default 0) and φ the
  residual friction (Eqs. 36-37); dilation only while slipping, Δu_dil = ±|ΔUˢ| tan ψ,
  + when ΔUˢ is along the accumulated shear displacement, − against it, and none once
  |uˢ| exceeds the dilation-zero limit (0: no limit) (Eqs. 41-43).
Force on B = Fⁿ n + Fˢ at x, on A the negative; moments (x − centroid) × force (ERRATA Eqs. 28-32).

prop columns (P_*): kn, ks, tan φ, c, T, tan ψ, u_zero, tan φ_res (NaN: = tan φ), c_res, T_res.
"""
from __future__ import annotations

import math

from numba import njit

P_KN = 0
P_KS = 1
P_TANF = 2
P_COH = 3
P_TEN = 4
P_TANDIL = 5
P_ZDIL = 6
P_TANF_RES = 7
P_COH_RES = 8
P_TEN_RES = 9
NPROP = 10

ST_FAILED = 1
ST_SLIP = 2
ST_TENSION = 4
#: set on a sub-contact made at a detection: its uⁿ is its own gap at the current positions,
#: which already hold the motion of the step just taken, so its first update adds no
#: displacement increment (cleared by that update)
ST_NEW = 8

MODEL_ELASTIC = 0
MODEL_MOHR = 1


@njit(cache=True)
def coulomb_one(kn, ks, tanf, coh, ten, tandil, zdil, tanf_r, coh_r, ten_r, model,
                area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state):
    """Scalar core for one sub-contact (shear force already rotated by Eq. 23).

    Returns (Fn, Fs0, Fs1, Fs2, un, udil, us0, us1, us2, state).
    """
    if tanf_r != tanf_r:                   # NaN: residual friction = peak friction
        tanf_r = tanf
    un += dun
    us0 += dus0
    us1 += dus1
    us2 += dus2
    fs0 -= ks * area * dus0
    fs1 -= ks * area * dus1
    fs2 -= ks * area * dus2
    fn = -kn * area * (un - udil)
    if model == MODEL_ELASTIC:
        if fn < 0.0:
            fn = 0.0
            fs0 = 0.0
            fs1 = 0.0
            fs2 = 0.0
        return fn, fs0, fs1, fs2, un, udil, us0, us1, us2, state & ~ST_SLIP
    failed = (state & ST_FAILED) != 0
    c = coh_r if failed else coh
    t = ten_r if failed else ten
    tf = tanf_r if failed else tanf
    state = state & ~(ST_SLIP | ST_TENSION)
    if fn < -t * area:                     # Eq. (38): tensile failure
        return 0.0, 0.0, 0.0, 0.0, un, udil, us0, us1, us2, state | ST_FAILED | ST_TENSION
    fsmax = c * area + fn * tf             # Eq. (35)
    if fsmax < 0.0:
        fsmax = 0.0
    fsm = math.sqrt(fs0 * fs0 + fs1 * fs1 + fs2 * fs2)
    if fsm > fsmax:                        # Eq. (39): shear failure
        if not failed:
            state = state | ST_FAILED
            fsmax = coh_r * area + fn * tanf_r
            if fsmax < 0.0:
                fsmax = 0.0
        r = fsmax / fsm if fsm > 0.0 else 0.0
        fs0 *= r
        fs1 *= r
        fs2 *= r
        state = state | ST_SLIP
        dmag = math.sqrt(dus0 * dus0 + dus1 * dus1 + dus2 * dus2)
        usm = math.sqrt(us0 * us0 + us1 * us1 + us2 * us2)
        if tandil != 0.0 and dmag > 0.0 and (zdil <= 0.0 or usm <= zdil):
            sgn = 1.0 if (dus0 * us0 + dus1 * us1 + dus2 * us2) >= 0.0 else -1.0
            ddil = sgn * dmag * tandil     # Eq. (42), direction-dependent
            udil += ddil
            fn += kn * area * ddil         # Eq. (43)
    return fn, fs0, fs1, fs2, un, udil, us0, us1, us2, state


@njit(cache=True)
def subcontact_forces(dt, bpos, bvel, bspin, bforce, bmoment,
                      ca, cb, cn, cmodel, cprop,
                      sc_contact, sc_pos, sc_area, sc_fn, sc_fs, sc_un, sc_udil, sc_us, sc_state):
    """One force update of every sub-contact; adds the forces and moments to the blocks.

    bpos/bvel/bspin (nb, 3): centroid [m], velocity [m/s], spin [rad/s] at t − Δt/2.
    bforce/bmoment (nb, 3): accumulated in place [N], [N·m].
    ca, cb (nc,) block rows; cn (nc, 3) unit normal A → B; cmodel (nc,); cprop (nc, NPROP).
    sc_* (ns, ...): contact row, position on the c-p (3), area, Fn, Fs (3), uⁿ, u_dil, uˢ (3), state.
    Serial loop: the scatter order is the sub-contact order (deterministic).
    """
    for s in range(sc_contact.shape[0]):
        c = sc_contact[s]
        a = ca[c]
        b = cb[c]
        n0 = cn[c, 0]
        n1 = cn[c, 1]
        n2 = cn[c, 2]
        x0 = sc_pos[s, 0]
        x1 = sc_pos[s, 1]
        x2 = sc_pos[s, 2]
        ra0 = x0 - bpos[a, 0]
        ra1 = x1 - bpos[a, 1]
        ra2 = x2 - bpos[a, 2]
        rb0 = x0 - bpos[b, 0]
        rb1 = x1 - bpos[b, 1]
        rb2 = x2 - bpos[b, 2]
        wa = bspin[a]
        wb = bspin[b]
        # Eq. (15)
        v0 = bvel[b, 0] + wb[1] * rb2 - wb[2] * rb1 - bvel[a, 0] - (wa[1] * ra2 - wa[2] * ra1)
        v1 = bvel[b, 1] + wb[2] * rb0 - wb[0] * rb2 - bvel[a, 1] - (wa[2] * ra0 - wa[0] * ra2)
        v2 = bvel[b, 2] + wb[0] * rb1 - wb[1] * rb0 - bvel[a, 2] - (wa[0] * ra1 - wa[1] * ra0)
        du0 = v0 * dt
        du1 = v1 * dt
        du2 = v2 * dt
        dun = du0 * n0 + du1 * n1 + du2 * n2
        st0 = sc_state[s]
        if st0 & ST_NEW:
            du0 = 0.0
            du1 = 0.0
            du2 = 0.0
            dun = 0.0
            st0 &= ~ST_NEW
        p = cprop[c]
        fn, f0, f1, f2, un, ud, u0, u1, u2, st = coulomb_one(
            p[P_KN], p[P_KS], p[P_TANF], p[P_COH], p[P_TEN], p[P_TANDIL], p[P_ZDIL],
            p[P_TANF_RES], p[P_COH_RES], p[P_TEN_RES], cmodel[c], sc_area[s],
            dun, du0 - dun * n0, du1 - dun * n1, du2 - dun * n2, sc_un[s], sc_udil[s],
            sc_fs[s, 0], sc_fs[s, 1], sc_fs[s, 2], sc_us[s, 0], sc_us[s, 1], sc_us[s, 2], st0)
        sc_fn[s] = fn
        sc_fs[s, 0] = f0
        sc_fs[s, 1] = f1
        sc_fs[s, 2] = f2
        sc_un[s] = un
        sc_udil[s] = ud
        sc_us[s, 0] = u0
        sc_us[s, 1] = u1
        sc_us[s, 2] = u2
        sc_state[s] = st
        # force on B (ERRATA Eqs. 28-32)
        g0 = fn * n0 + f0
        g1 = fn * n1 + f1
        g2 = fn * n2 + f2
        bforce[b, 0] += g0
        bforce[b, 1] += g1
        bforce[b, 2] += g2
        bforce[a, 0] -= g0
        bforce[a, 1] -= g1
        bforce[a, 2] -= g2
        bmoment[b, 0] += rb1 * g2 - rb2 * g1
        bmoment[b, 1] += rb2 * g0 - rb0 * g2
        bmoment[b, 2] += rb0 * g1 - rb1 * g0
        bmoment[a, 0] -= ra1 * g2 - ra2 * g1
        bmoment[a, 1] -= ra2 * g0 - ra0 * g2
        bmoment[a, 2] -= ra0 * g1 - ra1 * g0
