"""``dec3d.physics.feblocks.FeStepper`` (element forces, HRZ masses, Gershgorin stiffness,
consistent gravity, slave nodes) composed with the zone step's gridpoint motion kernel
(``kernels.zonestep.gp_motion``: local damping 0.8, density scaling m = k Δt²/4 at Δt = 1), on
models built by commands: the seed's fem_beam.dat cantilever and a column under its own weight."""
import math

import numpy as np
import pytest

from dec3d.errors import Dec3dError
from dec3d.kernels.feblock import feb_gauss_positions
from dec3d.kernels.zonestep import gp_externals, gp_motion
from dec3d.physics.feblocks import FeStepper


class Stop(Dec3dError):
    pass


def relax(model, gravity=(0.0, 0.0, 0.0), tol=1e-7, maxsteps=200000):
    st = FeStepper(model, Stop)
    v = model.vertices
    n = v.n
    pos, vel, disp = v["pos"], v["velocity"], v["disp"]
    imass = st.stiff / 4.0                          # m = k dt^2 / 4 at dt = 1 (the zone step's scaling)
    held = v["apply_fix"].astype(np.uint8)
    vapp = v["vapp"].copy()
    fprev = np.zeros((n, 3))
    force = np.zeros((n, 3))
    fmag = np.zeros(n)
    out = np.zeros(4)
    none = np.zeros(0, np.int64)
    nomass = np.zeros(n)
    g = np.asarray(gravity, float)
    fscale = max(np.abs(v["fapp"]).max(), np.abs(st.gweight[:, None] * g).max())
    for step in range(1, maxsteps + 1):
        facc = np.zeros((n, 3))
        assert st.forces(pos, vel, 1.0, g, facc) == -1
        gp_externals(st.masters, v["link"], nomass, np.zeros(3), v["fapp"], v["fface"], facc, fmag)
        st.slave_forces(facc)
        gp_motion(st.masters, none, v["link"], facc, fprev, st.mass, imass, held, vapp, vel, disp, pos, 1.0,
                  1, 0.8, False, math.inf, out)
        st.follow(vel, disp)
        if step % 500 == 0 and out[0] < tol * fscale:
            return st, step
        force[:] = facc
    raise AssertionError("did not converge")


BEAM = """model configure feblock
block create brick 0 10 0 1 0 1
feblock generate 1 1 1 integration 3
block zone cmodel assign el
block zone prop dens 2000 young 1e6 poiss 0.2
block gridpoint apply vel 0 0 0 range pos-x 0
block gridpoint apply force-z [-1.0*100.0/3.0] range pos-x 10 pos-z 1
"""


def test_stepper_masses_and_checks(session):
    session.command(BEAM)
    m = session.model
    st = FeStepper(m, Stop)
    v = m.vertices
    assert abs(st.mass.sum() - 2000 * 10) < 1e-8 and (st.mass[st.masters] > 0).all()
    assert not st.mass[st.slave_rows].any() and len(st.slave_rows) == 42 and len(st.masters) == 128
    assert (st.stiff[st.masters] > 0).all()
    assert abs(st.gweight.sum() - 2000 * 10) < 1e-8                  # rho V: sum of N_a is 1
    assert not v["feslave"][st.masters].any()


def test_stepper_refuses_missing_properties_naming_the_block(session):
    session.command("model configure feblock\nblock create brick 0 1 0 1 0 1\nfeblock generate 1 1 1")
    with pytest.raises(Stop, match=r"FE blocks 1 have no element with a constitutive model"):
        FeStepper(session.model, Stop)
    session.command("block zone cmodel assign elastic\nblock zone property density 1000")
    with pytest.raises(Stop, match=r"1 elastic FE elements of blocks 1 lack bulk, shear or density"):
        FeStepper(session.model, Stop)


def test_fem_beam_relaxes_to_calculix_with_the_zone_motion_kernel(session):
    """F1 with 3x3x3 integration: CalculiX C3D20 0.3996 m within 0.2 %, WL^3/(3EI) = 0.4 within 1 %;
    the slave node at the centre of the tip face moves with the tip."""
    session.command(BEAM)
    m = session.model
    relax(m)
    v = m.vertices
    tip = np.flatnonzero(np.all(abs(v["pos"] - [10, 1, 1]) < 1e-9, axis=1))[0]
    u = -v["disp"][tip, 2]
    assert abs(u - 0.3996) < 0.002 * 0.3996 and abs(u - 0.4) < 0.01 * 0.4, u
    cen = np.flatnonzero(np.all(abs(v["pos"] - [10, 0.5, 0.5]) < 1e-9, axis=1))[0]
    assert v["feslave"][cen] and abs(-v["disp"][cen, 2] - u) < 0.01 * u


@pytest.mark.parametrize("nq", [2, 3])
def test_column_under_its_own_weight_has_the_exact_linear_stress(session, nq):
    """A 1 x 1 x 4 m column of four elements, sides on rollers (u_x = 0 at x = 0 and 1, u_y = 0
    at y = 0 and 1), base u_z = 0, rho = 2000, g = 10 downwards, consistent gravity (Eq. 8): the
    exact solution (u_z quadratic in z) is in the element's space, so at every Gauss point
    sigma_zz = -rho g (H - z) and sigma_xx = sigma_yy = nu / (1 - nu) sigma_zz, to the
    relaxation tolerance."""
    session.command(f"model configure feblock\nblock create brick 0 1 0 1 0 4\nfeblock generate 1 1 1 integration {nq}\n"
                    "feblock change cmodel elastic young 1e7 poisson 0.25 density 2000\n"
                    "block gridpoint apply vel-x 0 range pos-x 0\nblock gridpoint apply vel-x 0 range pos-x 1\n"
                    "block gridpoint apply vel-y 0 range pos-y 0\nblock gridpoint apply vel-y 0 range pos-y 1\n"
                    "block gridpoint apply vel-z 0 range pos-z 0")
    m = session.model
    relax(m, gravity=(0.0, 0.0, -10.0), tol=1e-9)
    es = m.store("feblocks")
    gpos = np.zeros((4, 27, 3))
    feb_gauss_positions(np.ascontiguousarray(m.vertices["pos"]), np.ascontiguousarray(es["nodes"]),
                        np.arange(4, dtype=np.int64), gpos, nq)
    ng = nq ** 3
    s = es["gstress"][:4, :ng]
    expect = -2000 * 10 * (4 - gpos[:, :ng, 2])
    scale = 2000 * 10 * 4
    assert np.abs(s[..., 2] - expect).max() < 1e-6 * scale
    assert np.abs(s[..., 0] - expect / 3).max() < 1e-6 * scale and np.abs(s[..., 1] - expect / 3).max() < 1e-6 * scale
    assert np.abs(s[..., 3:]).max() < 1e-6 * scale
