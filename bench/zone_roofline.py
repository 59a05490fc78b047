"""The roofline of the 4-node zone step: a minimal numba kernel doing the per-zone arithmetic of an
elastic step (gather four corners, face area vectors and volume, strain increment, incremental
Hooke, the four nodal forces scattered) in one serial loop with nothing else — no mixed
discretization, no plans, no model dispatch — against the engine's ``zone_step`` on the same
mesh, one thread.

    python bench/zone_roofline.py [--zones 1e5 1e6] [--steps 20] [--repeat 5]

Printed per size: ns per zone-step (process CPU time, one thread: the figures hold on a shared
machine) of the minimal kernel and of ``zone_step`` without nodal mixed discretization, of the
minimal kernel with NMD (``minimal_nmd_step``: the same arithmetic plus the two-sweep volumetric
averaging of Eqs. 68-73) and of ``zone_step`` with NMD (the engine's default), and the ratios
minimal / engine (the fraction of the roofline the engine reaches; issue 26/33 aim: >= 0.5) —
each step against the minimal kernel doing the same arithmetic, and, last column, the NMD step
against the kernel without NMD. The mesh is the unit cube
zoned by dec3d's mesher (``block zone generate edgelength``), its gridpoints in the mesher's
order; velocities random. The minimal kernel is written here from the formulas (3DEC theory
text Eqs. 53-59), sharing no code with dec3d's kernels.
"""
from __future__ import annotations

import argparse
import io
import os
import statistics
import sys
import tempfile
import time

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def _grads(pos, i0, i1, i2, i3):
    """Shape-function gradients g0..g3 (rows of the inverse of [e1 e2 e3]ᵀ) and the determinant."""
    x0 = pos[i0, 0]; y0 = pos[i0, 1]; z0 = pos[i0, 2]
    e1x = pos[i1, 0] - x0; e1y = pos[i1, 1] - y0; e1z = pos[i1, 2] - z0
    e2x = pos[i2, 0] - x0; e2y = pos[i2, 1] - y0; e2z = pos[i2, 2] - z0
    e3x = pos[i3, 0] - x0; e3y = pos[i3, 1] - y0; e3z = pos[i3, 2] - z0
    c1x = e2y * e3z - e2z * e3y; c1y = e2z * e3x - e2x * e3z; c1z = e2x * e3y - e2y * e3x
    c2x = e3y * e1z - e3z * e1y; c2y = e3z * e1x - e3x * e1z; c2z = e3x * e1y - e3y * e1x
    c3x = e1y * e2z - e1z * e2y; c3y = e1z * e2x - e1x * e2z; c3z = e1x * e2y - e1y * e2x
    det = e1x * c1x + e1y * c1y + e1z * c1z
    inv = 1.0 / det
    g1x = c1x * inv; g1y = c1y * inv; g1z = c1z * inv
    g2x = c2x * inv; g2y = c2y * inv; g2z = c2z * inv
    g3x = c3x * inv; g3y = c3y * inv; g3z = c3z * inv
    g0x = -(g1x + g2x + g3x); g0y = -(g1y + g2y + g3y); g0z = -(g1z + g2z + g3z)
    return g0x, g0y, g0z, g1x, g1y, g1z, g2x, g2y, g2z, g3x, g3y, g3z, det


@njit(cache=True, inline="always")
def _strain(vel, i0, i1, i2, i3, g0x, g0y, g0z, g1x, g1y, g1z, g2x, g2y, g2z, g3x, g3y, g3z, dt):
    """Strain increment (xx yy zz xy xz yz) from the velocity gradient L_ij = Σ v_i dN/dx_j."""
    lxx = vel[i0, 0] * g0x + vel[i1, 0] * g1x + vel[i2, 0] * g2x + vel[i3, 0] * g3x
    lyy = vel[i0, 1] * g0y + vel[i1, 1] * g1y + vel[i2, 1] * g2y + vel[i3, 1] * g3y
    lzz = vel[i0, 2] * g0z + vel[i1, 2] * g1z + vel[i2, 2] * g2z + vel[i3, 2] * g3z
    lxy = vel[i0, 0] * g0y + vel[i1, 0] * g1y + vel[i2, 0] * g2y + vel[i3, 0] * g3y
    lyx = vel[i0, 1] * g0x + vel[i1, 1] * g1x + vel[i2, 1] * g2x + vel[i3, 1] * g3x
    lxz = vel[i0, 0] * g0z + vel[i1, 0] * g1z + vel[i2, 0] * g2z + vel[i3, 0] * g3z
    lzx = vel[i0, 2] * g0x + vel[i1, 2] * g1x + vel[i2, 2] * g2x + vel[i3, 2] * g3x
    lyz = vel[i0, 1] * g0z + vel[i1, 1] * g1z + vel[i2, 1] * g2z + vel[i3, 1] * g3z
    lzy = vel[i0, 2] * g0y + vel[i1, 2] * g1y + vel[i2, 2] * g2y + vel[i3, 2] * g3y
    return (lxx * dt, lyy * dt, lzz * dt,
            0.5 * (lxy + lyx) * dt, 0.5 * (lxz + lzx) * dt, 0.5 * (lyz + lzy) * dt)


@njit(cache=True, inline="always")
def _hooke_forces(stress, force, z, K, G, exx, eyy, ezz, exy, exz, eyz, det, i0, i1, i2, i3,
                  g0x, g0y, g0z, g1x, g1y, g1z, g2x, g2y, g2z, g3x, g3y, g3z):
    """Incremental Hooke on zone z's stress, then its nodal forces −V σ ∇N onto the four corners."""
    ev = exx + eyy + ezz
    lam = K[z] - 2.0 * G[z] / 3.0
    g2 = 2.0 * G[z]
    sxx = stress[z, 0] + lam * ev + g2 * exx
    syy = stress[z, 1] + lam * ev + g2 * eyy
    szz = stress[z, 2] + lam * ev + g2 * ezz
    sxy = stress[z, 3] + g2 * exy
    sxz = stress[z, 4] + g2 * exz
    syz = stress[z, 5] + g2 * eyz
    stress[z, 0] = sxx; stress[z, 1] = syy; stress[z, 2] = szz
    stress[z, 3] = sxy; stress[z, 4] = sxz; stress[z, 5] = syz
    vol = abs(det) / 6.0
    for n in range(4):
        if n == 0:
            gx = g0x; gy = g0y; gz = g0z; r = i0
        elif n == 1:
            gx = g1x; gy = g1y; gz = g1z; r = i1
        elif n == 2:
            gx = g2x; gy = g2y; gz = g2z; r = i2
        else:
            gx = g3x; gy = g3y; gz = g3z; r = i3
        force[r, 0] -= vol * (sxx * gx + sxy * gy + sxz * gz)
        force[r, 1] -= vol * (sxy * gx + syy * gy + syz * gz)
        force[r, 2] -= vol * (sxz * gx + syz * gy + szz * gz)


@njit(cache=True)
def minimal_step(pos, vel, gp, K, G, dt, stress, force):
    """One elastic step of every zone of gp (nz, 4): the least a 4-node step must do."""
    for z in range(gp.shape[0]):
        i0 = gp[z, 0]; i1 = gp[z, 1]; i2 = gp[z, 2]; i3 = gp[z, 3]
        g0x, g0y, g0z, g1x, g1y, g1z, g2x, g2y, g2z, g3x, g3y, g3z, det = _grads(pos, i0, i1, i2, i3)
        exx, eyy, ezz, exy, exz, eyz = _strain(vel, i0, i1, i2, i3, g0x, g0y, g0z, g1x, g1y, g1z, g2x, g2y, g2z,
                                               g3x, g3y, g3z, dt)
        _hooke_forces(stress, force, z, K, G, exx, eyy, ezz, exy, exz, eyz, det, i0, i1, i2, i3,
                      g0x, g0y, g0z, g1x, g1y, g1z, g2x, g2y, g2z, g3x, g3y, g3z)


@njit(cache=True)
def minimal_nmd_step(pos, vel, gp, K, G, dt, stress, force, nsum, nvol, geo):
    """One elastic step with nodal mixed discretization (3DEC theory text Eqs. 68-73): the least
    such a step must do — a first sweep sums Δε_v V and V onto each zone's four nodes, each node's
    average is formed once, a second sweep takes each zone's volumetric strain increment as the
    mean of its four nodes' averages (deviatoric part its own), Hooke, nodal forces. The first
    sweep keeps each zone's gradients and determinant in ``geo`` (nz, 10) for the second: reading
    80 bytes a zone is cheaper than working them out again (about 30 against 40 ns per zone-step
    on the 2-core test machine)."""
    nsum[:] = 0.0
    nvol[:] = 0.0
    for z in range(gp.shape[0]):
        i0 = gp[z, 0]; i1 = gp[z, 1]; i2 = gp[z, 2]; i3 = gp[z, 3]
        g0x, g0y, g0z, g1x, g1y, g1z, g2x, g2y, g2z, g3x, g3y, g3z, det = _grads(pos, i0, i1, i2, i3)
        geo[z, 0] = g1x; geo[z, 1] = g1y; geo[z, 2] = g1z; geo[z, 3] = g2x; geo[z, 4] = g2y
        geo[z, 5] = g2z; geo[z, 6] = g3x; geo[z, 7] = g3y; geo[z, 8] = g3z; geo[z, 9] = det
        div = (vel[i0, 0] * g0x + vel[i1, 0] * g1x + vel[i2, 0] * g2x + vel[i3, 0] * g3x
               + vel[i0, 1] * g0y + vel[i1, 1] * g1y + vel[i2, 1] * g2y + vel[i3, 1] * g3y
               + vel[i0, 2] * g0z + vel[i1, 2] * g1z + vel[i2, 2] * g2z + vel[i3, 2] * g3z)
        vol = abs(det) / 6.0
        x = div * dt * vol
        nsum[i0] += x; nsum[i1] += x; nsum[i2] += x; nsum[i3] += x
        nvol[i0] += vol; nvol[i1] += vol; nvol[i2] += vol; nvol[i3] += vol
    for n in range(nsum.shape[0]):
        if nvol[n] > 0.0:
            nsum[n] /= nvol[n]
    for z in range(gp.shape[0]):
        i0 = gp[z, 0]; i1 = gp[z, 1]; i2 = gp[z, 2]; i3 = gp[z, 3]
        g1x = geo[z, 0]; g1y = geo[z, 1]; g1z = geo[z, 2]; g2x = geo[z, 3]; g2y = geo[z, 4]
        g2z = geo[z, 5]; g3x = geo[z, 6]; g3y = geo[z, 7]; g3z = geo[z, 8]; det = geo[z, 9]
        g0x = -(g1x + g2x + g3x); g0y = -(g1y + g2y + g3y); g0z = -(g1z + g2z + g3z)
        exx, eyy, ezz, exy, exz, eyz = _strain(vel, i0, i1, i2, i3, g0x, g0y, g0z, g1x, g1y, g1z, g2x, g2y, g2z,
                                               g3x, g3y, g3z, dt)
        shift = (0.25 * (nsum[i0] + nsum[i1] + nsum[i2] + nsum[i3]) - (exx + eyy + ezz)) / 3.0
        _hooke_forces(stress, force, z, K, G, exx + shift, eyy + shift, ezz + shift, exy, exz, eyz, det,
                      i0, i1, i2, i3, g0x, g0y, g0z, g1x, g1y, g1z, g2x, g2y, g2z, g3x, g3y, g3z)


def _mesh(zones: float):
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    if root not in sys.path:
        sys.path.insert(0, root)
    import dec3d

    with tempfile.TemporaryDirectory() as d:
        s = dec3d.Session(out_dir=d, stdout=io.StringIO())
        length = (5.08 / zones) ** (1.0 / 3.0)
        s.command(f"model new\nblock create brick 0 1 0 1 0 1\nblock zone generate edgelength {length:.6g}\n"
                  "block zone cmodel assign elastic\nblock zone property bulk 5e9 shear 3e9 density 2500\n")
        zs, v = s.model.store("zones"), s.model.vertices
        return (np.ascontiguousarray(v["pos"][: v.n]), np.ascontiguousarray(zs["gp"][: zs.n, :4]),
                np.ascontiguousarray(zs["prop"][: zs.n]))


def _time(fn, steps, repeat):
    out = []
    for _ in range(repeat):
        t0 = time.process_time()
        for _ in range(steps):
            fn()
        out.append((time.process_time() - t0) / steps)
    return statistics.median(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--zones", type=float, nargs="+", default=[1e5, 1e6])
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args(argv)
    import numba
    numba.set_num_threads(1)
    here = os.path.dirname(os.path.abspath(__file__))
    sys.path.insert(0, here)
    sys.path.insert(0, os.path.dirname(here))              # the checkout's dec3d and tests
    from rigid_bench import machine

    from tests.zone_step_run import Stepper
    print(f"machine: {machine()}")
    print(f"{'zones':>9} {'minimal ns':>10} {'engine ns':>10} {'min/engine':>10} {'min NMD ns':>10} "
          f"{'NMD ns':>8} {'minNMD/NMD':>10} {'min/NMD':>8}")
    for n in args.zones:
        pos, gp, prop = _mesh(n)
        nz, nv = len(gp), len(pos)
        rng = np.random.default_rng(1)
        vel = rng.normal(size=(nv, 3)) * 1e-6
        K, G = np.ascontiguousarray(prop[:, 0]), np.ascontiguousarray(prop[:, 1])
        stress, force, fmag = np.zeros((nz, 6)), np.zeros((nv, 3)), np.zeros(nv)
        state = np.zeros(nz, np.int32)
        minimal_step(pos, vel, gp, K, G, 1.0, stress, force)             # compile
        t_min = _time(lambda: minimal_step(pos, vel, gp, K, G, 1.0, stress, force), args.steps, args.repeat)
        nsum, nvol, geo = np.zeros(nv), np.zeros(nv), np.zeros((nz, 10))
        minimal_nmd_step(pos, vel, gp, K, G, 1.0, stress, force, nsum, nvol, geo)
        t_min_nmd = _time(lambda: minimal_nmd_step(pos, vel, gp, K, G, 1.0, stress, force, nsum, nvol, geo),
                          args.steps, args.repeat)
        st = Stepper(gp, np.arange(nz, dtype=np.int64), np.full(nz, -1, np.int64), np.ones(nz),
                     np.arange(nv, dtype=np.int64), nv, np.ones(nz, np.int8), prop)
        rates = []
        for nmd in (False, True):
            st.step(pos, vel, stress, state, force, fmag, 1.0, False, nmd)
            rates.append(_time(lambda: st.step(pos, vel, stress, state, force, fmag, 1.0, False, nmd),
                               args.steps, args.repeat))
        ns = [1e9 * t / nz for t in (t_min, *rates, t_min_nmd)]
        print(f"{nz:>9} {ns[0]:>10.1f} {ns[1]:>10.1f} {ns[0] / ns[1]:>10.2f} {ns[3]:>10.1f} {ns[2]:>8.1f} "
              f"{ns[3] / ns[2]:>10.2f} {ns[0] / ns[2]:>8.2f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
