"""Rayleigh damping's stiffness term (C = β K, `block mechanical damping rayleigh ξ f stiffness`: β = 2ξ/ω_f)
on 10-node zones, FE blocks and contacts between rigid and zoned blocks (physics.dynamic,
kernels.rayleigh.mixed_stiffness_damping). With every stiffness of the model damped, each mode ω of the
undamped system keeps its shape and takes the damping ratio ξ(ω) = β ω / 2 (Itasca 3DEC "Dynamic
Analysis", Damping): a free vibration in one mode, measured by its logarithmic decrement
(``verify.damping_ratio``), gives β ω / 2 at the frequency measured from its zero crossings — within 2 %
(the DY1 style; the central-difference scheme's own error at ωΔt ≲ 0.05 is below 0.2 %). Were a part
of the stiffness left undamped, the ratio would fall short by that part's share of the strain energy
(the whole of it for the contact of the last test). The kernel's twin is in
tests/deformable/test_rayleigh_mixed_kernel.py; the 4-node zones in tests/test_dynamic.py."""
import math

import numpy as np
import pytest

from dec3d.physics.dynamic import rayleigh_coefficients
from dec3d.session import Session
from dec3d.verify import damping_ratio

ROLLERS = ("block gridpoint apply velocity-x 0 range position-x 0",
           "block gridpoint apply velocity-x 0 range position-x 0.5",
           "block gridpoint apply velocity-y 0 range position-y 0",
           "block gridpoint apply velocity-y 0 range position-y 0.5",
           "block gridpoint apply velocity-z 0 range position-z 0")


def _measure(s, name: str):
    """(ω [rad/s] from the zero crossings, damping ratio from the decrement) of history ``name``."""
    h = s.model.history_set.find(name)
    t, vel = np.array(h.times), np.array(h.values)
    sg = np.sign(vel)
    zc = np.flatnonzero(sg[1:] * sg[:-1] < 0)
    assert len(zc) >= 8, "fewer than four periods recorded"
    w = 2 * math.pi * (len(zc) - 1) / 2 / (t[zc[-1]] - t[zc[0]])
    return w, damping_ratio(vel)


def _column(s, kind: str):
    """A 0.5 × 0.5 × 2 m column (E = 1 GPa, ν = 0.25, ρ = 2500), sides on rollers, base fixed, in its first
    axial mode (initial velocity 0.01 sin(πz/4) m/s); first-mode estimate c/4L = 86.6 Hz."""
    if kind == "tet10":
        lines = ("model configure highorder", "block create brick 0 0.5 0 0.5 0 2",
                 "block zone generate edgelength 0.5", "block zone generate high-order-tetra",
                 "block zone cmodel assign elastic", "block zone property young 1e9 poisson 0.25 density 2500")
    else:
        lines = ("model configure feblock", "block create brick 0 0.5 0 0.5 0 2", "feblock generate 0.5 0.5 0.5",
                 "feblock change cmodel elastic young 1e9 poisson 0.25 density 2500")
    for line in lines + ROLLERS + ("model dynamic active on", "block mechanical damping rayleigh 0.05 86.6 stiffness"):
        s.command(line)
    v = s.model.vertices
    z = v["pos"][:, 2]
    v["velocity"][:, 2] = np.where(v["zoned"] & (z > 1e-9), 0.01 * np.sin(math.pi * z / 4.0), 0.0)
    for line in ("block history name 'vt' velocity-z position 0.25 0.25 2", "history interval 1",
                 "model solve time 0.1"):
        s.command(line)
    return _measure(s, "vt")


@pytest.mark.parametrize("kind", ["tet10", "fe"])
def test_stiffness_damping_on_tet10_and_fe_columns(tmp_path, kind):
    s = Session(out_dir=tmp_path)
    w, xi = _column(s, kind)
    assert w / (2 * math.pi) == pytest.approx(86.6, rel=0.05)
    _, beta = rayleigh_coefficients(s.model)
    assert beta == pytest.approx(2 * 0.05 / (2 * math.pi * 86.6), rel=1e-12)
    assert xi == pytest.approx(beta * w / 2, rel=0.02)


def test_stiffness_damping_on_a_rigid_block_on_a_zoned_base(tmp_path):
    """A rigid 1 m cube (ρ 2000, m = 2000 kg) on an elastic joint kn = ks = 10 MPa/m (k = 10⁷ N/m) over a
    zoned base 1 × 1 × 0.5 m (E = 50 MPa, about ten times stiffer than the joint) fixed at its bottom,
    released at rest under gravity (the joint stays closed: its force swings between 0 and 2 m g): the
    vertical mode is mostly the block on the joint spring, f a little below √(k/m)/2π = 11.25 Hz (the
    base's compliance), most of its strain energy in the contact — damped only through the
    mixed-contact term (without it ξ would fall to the base's share)."""
    s = Session(out_dir=tmp_path)
    for line in ("block create brick 0 1 0 1 -0.5 0", "block create brick 0 1 0 1 0 1",
                 "block property density 2000",
                 "block zone generate edgelength 0.5 range position-z -0.5 0",
                 "block zone cmodel assign elastic range position-z -0.5 0",
                 "block zone property young 5e7 poisson 0.25 density 2000 range position-z -0.5 0",
                 "block gridpoint apply velocity 0 0 0 range position-z -0.5",
                 "block contact jmodel assign elastic",
                 "block contact material-table default property stiffness-normal 10e6 stiffness-shear 10e6",
                 "model gravity 0 0 -10", "model dynamic active on",
                 "block mechanical damping rayleigh 0.01 11.254 stiffness",
                 "block history name 'v' velocity-z position 0.5 0.5 0.5", "history interval 1",
                 "model solve time 0.45"):
        s.command(line)
    assert s.model.rigid_engine._zone_contacts_check()
    w, xi = _measure(s, "v")
    f_spring = math.sqrt(1e7 / 2000) / (2 * math.pi)
    assert 0.9 * f_spring < w / (2 * math.pi) < f_spring
    _, beta = rayleigh_coefficients(s.model)
    assert xi == pytest.approx(beta * w / 2, rel=0.02)
