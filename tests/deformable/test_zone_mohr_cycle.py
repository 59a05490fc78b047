"""Mohr-Coulomb zones through the engine: commands, the check at cycle time, triaxial and tension
answers (closed form of the Mohr-Coulomb criterion), the plastic state in lists, VTK and save
files, and the nodal mixed discretization switch."""
import io
import math

import meshio
import numpy as np
import pytest

from dec3d.errors import Dec3dError
from dec3d.model.zones import ZMODEL_ELASTIC, ZP_COHESION, ZP_TANDIL, ZP_TANFRIC, ZP_TENSION
from dec3d.physics.cmodels import ZONE_MODELS

ZMODEL_MOHR = ZONE_MODELS["mohr-coulomb"].code
from dec3d.session import Session

C, PHI = 1e6, 30.0
NPHI = 3.0                                    # (1 + sin 30°) / (1 − sin 30°)


def _session(tmp_path, lines=()):
    out = io.StringIO()
    s = Session(out_dir=tmp_path, stdout=out)
    s.out = out
    for line in lines:
        s.command(line)
    return s


def _specimen(s3, vel, tension=5e5, dilation=0.0, extra=()):
    """A 1 m cube of six tetrahedra under confining stress s3 [Pa, compression positive], its top
    gridpoints moved at ``vel`` [m/step]."""
    lines = ["block create brick 0 1 0 1 0 1", "block zone generate edgelength 1",
             "block zone cmodel assign mohr-c",
             f"block zone property young 1e10 poisson 0.25 density 2500 cohesion {C:g} friction {PHI:g} "
             f"tension {tension:g} dilation {dilation:g}",
             *extra,
             "block gridpoint apply velocity-z 0 range position-z 0",
             "block gridpoint apply velocity-x 0 range position-x 0",
             "block gridpoint apply velocity-y 0 range position-y 0",
             f"block gridpoint apply velocity-z {vel:g} range position-z 1"]
    if s3:
        lines[-1:-1] = [f"block zone initialize stress-xx {-s3:g} stress-yy {-s3:g} stress-zz {-s3:g}",
                        f"block face apply stress-xx {-s3:g} range position-x 1",
                        f"block face apply stress-yy {-s3:g} range position-y 1"]
    return lines


def _mean_szz(s):
    zs = s.model.store("zones")
    return float((zs["stress"][:, 2] * zs["volume"]).sum() / zs["volume"].sum())


# ------------------------------------------------------------------ commands
def test_assign_mohr_by_its_abbreviation_clears_the_plastic_state(tmp_path):
    s = _session(tmp_path, ["block create brick 0 1 0 1 0 1", "block zone generate edgelength 0.5"])
    zs = s.model.store("zones")
    zs["state"][:] = 5
    s.command("block zone cmodel assign mohr-c range position-z 0 0.5")
    low = s.model.vertices["pos"][zs["gp"][:, :4]].mean(axis=1)[:, 2] < 0.5
    assert low.any() and (~low).any()
    assert (zs["cmodel"][low] == ZMODEL_MOHR).all() and (zs["state"][low] == 0).all()
    assert (zs["cmodel"][~low] == 0).all() and (zs["state"][~low] == 5).all()
    s.command("block zone cmodel assign mohr-coulomb")
    s.command("block zone cmodel assign elastic range position-z 0.5 1")
    assert (zs["cmodel"][low] == ZMODEL_MOHR).all() and (zs["cmodel"][~low] == ZMODEL_ELASTIC).all()
    assert (zs["state"] == 0).all()


def test_strength_properties_are_stored_in_si_and_tangents(tmp_path):
    s = _session(tmp_path, ["block create brick 0 1 0 1 0 1", "block zone generate edgelength 0.5",
                            "block zone cmodel assign mohr-c",
                            "block zone property cohesion 2e5 friction 30 tension 1e5 dilation 45"])
    p = s.model.store("zones")["prop"]
    assert np.all(p[:, ZP_COHESION] == 2e5) and np.all(p[:, ZP_TENSION] == 1e5)
    np.testing.assert_allclose(p[:, ZP_TANFRIC], 1.0 / math.sqrt(3.0), rtol=1e-14)   # tan 30°
    np.testing.assert_allclose(p[:, ZP_TANDIL], 1.0, rtol=1e-14)                      # tan 45°


@pytest.mark.parametrize("line,msg", [
    ("block zone property friction 90", r"`friction` must be in \[0, 90\)"),
    ("block zone property friction -1", r"`friction` must be in \[0, 90\)"),
    ("block zone property dilation 95", r"`dilation` must be in \[0, 90\)"),
    ("block zone property cohesion -1", "`cohesion` must be ≥ 0"),
    ("block zone property tension -5", "`tension` must be ≥ 0"),
    ("block zone cmodel assign mohr-x", r"needs model null\|.*mohr-coulomb.* here, got `mohr-x`"),
])
def test_bad_strength_input_is_a_clear_error_with_its_location(tmp_path, line, msg):
    s = _session(tmp_path, ["block create brick 0 1 0 1 0 1", "block zone generate edgelength 0.5"])
    before = s.model.store("zones")["prop"].copy()
    with pytest.raises(Dec3dError, match=msg) as exc:
        s.command(line)
    assert ":1:" in str(exc.value) or exc.value.location is not None
    np.testing.assert_array_equal(s.model.store("zones")["prop"], before)


def test_cycle_checks_the_mohr_properties(tmp_path):
    base = ["block create brick 0 1 0 1 0 1", "block zone generate edgelength 1", "block zone cmodel assign mohr-c"]
    s = _session(tmp_path, base + ["block zone property cohesion 1e6 friction 30 density 2000"])
    with pytest.raises(Dec3dError, match=r"mohr-coulomb zones: bulk must be > 0 Pa \(not set\): 6 zone\(s\) of blocks 1"):
        s.command("model cycle 1")
    s = _session(tmp_path, base + ["block zone property young 1e9 poisson 0.2 density 2000 cohesion 1e6 "
                                   "friction 30 dilation 35"])
    with pytest.raises(Dec3dError, match="dilation must not exceed friction"):
        s.command("model cycle 1")
    assert s.model.step == 0
    # tension above the apex c / tan φ = 1.732 MPa: a warning, and the run goes on
    s.command("block zone property dilation 0 tension 5e6")
    s.command("model cycle 2")
    assert s.model.step == 2
    assert "tension above c/tan(friction) in 6 zone(s)" in s.out.getvalue()


# ------------------------------------------------------------------ answers
@pytest.mark.parametrize("s3", [1e6, 4e6])
def test_triaxial_peak_is_the_mohr_coulomb_strength(tmp_path, s3):
    s = _session(tmp_path, _specimen(s3, -2e-7))
    peak = 0.0
    for _ in range(16):
        s.command("model cycle 500")
        peak = max(peak, -_mean_szz(s))
    want = s3 * NPHI + 2 * C * math.sqrt(NPHI)
    assert abs(peak / want - 1) < 5e-3
    zs = s.model.store("zones")
    # lateral stresses held at the confinement, every zone yielding in shear now
    np.testing.assert_allclose(zs["stress"][:, :2], -s3, rtol=2e-3)
    assert (zs["state"] == 5).all()
    s.command("block zone list")
    r = s.results
    assert (r["zones_shear_now"], r["zones_shear_past"], r["zones_tension_now"]) == (6.0, 6.0, 0.0)
    assert "plastic state: shear-now 6, tension-now 0, shear-past 6, tension-past 0, never yielded 0" \
        in s.out.getvalue()
    s.results.clear()
    s.command("block zone list information")
    assert s.results["zones_shear_past"] == 6.0 and s.results["zones"] == 6.0


def test_pure_tension_reaches_the_cut_off(tmp_path):
    s = _session(tmp_path, _specimen(0.0, 2e-7, tension=5e5))
    s.command("model cycle 3000")
    assert abs(_mean_szz(s) / 5e5 - 1) < 5e-3
    zs = s.model.store("zones")
    assert ((zs["state"] & 2) != 0).all() and ((zs["state"] & 1) == 0).all()
    # unloading: the "now" bits clear, the "past" bits stay
    s.command("block gridpoint apply velocity-z -2e-7 range position-z 1")
    s.command("model cycle 50")
    assert (zs["state"] == 8).all()


def test_dilation_makes_the_specimen_expand_in_volume(tmp_path):
    """Shear flow with ψ > 0 is dilatant (potential g_s = σ1 − σ3 N_ψ, N_ψ > 1): for the same
    axial shortening the specimen's volume grows by more than the non-dilatant one's (whose
    plastic flow keeps the volume)."""
    vols = []
    for psi in (0.0, 20.0):
        s = _session(tmp_path, _specimen(1e6, -2e-7, dilation=psi))
        s.command("model cycle 8000")
        d = s.model.vertices["disp"]
        p = s.model.vertices["pos"]
        corner = np.argmin(np.abs(p - [1, 1, 1]).sum(axis=1))
        ux, uy, uz = d[corner]
        vols.append((1 + ux) * (1 + uy) * (1 + uz) - 1)
    assert vols[1] > vols[0] + 5e-4


# ------------------------------------------------------------------ state kept, written, saved
def test_plastic_state_in_vtk_and_save_restore_exact_continuation(tmp_path):
    s = _session(tmp_path, _specimen(1e6, -2e-7))
    s.command("model cycle 6000")
    zs = s.model.store("zones")
    assert (zs["state"] == 5).all()
    s.command("block vtk 'mc'")
    mesh = meshio.read(tmp_path / "mc_0000.vtu")
    np.testing.assert_array_equal(mesh.cell_data["plastic_state"][0], zs["state"])
    s.command(f"model save '{tmp_path / 'mc'}'")
    s.command("model cycle 300")
    after = (zs["stress"].copy(), zs["state"].copy(), s.model.vertices["disp"].copy())
    s2 = _session(tmp_path, [f"model restore '{tmp_path / 'mc'}'"])
    assert (s2.model.store("zones")["state"] == 5).all()
    s2.command("model cycle 300")
    z2 = s2.model.store("zones")
    np.testing.assert_array_equal(z2["stress"], after[0])
    np.testing.assert_array_equal(z2["state"], after[1])
    np.testing.assert_array_equal(s2.model.vertices["disp"], after[2])


def test_failed_run_puts_the_plastic_state_back(tmp_path):
    s = _session(tmp_path, _specimen(1e6, -2e-7))
    s.command("model cycle 200")
    zs = s.model.store("zones")
    keep = zs["state"].copy()
    assert (keep == 0).all()
    s.command("block mechanical damping none")
    s.command("block mechanical timestep 1")
    s.command("block gridpoint apply velocity-z -1e-2 range position-z 1")
    with pytest.raises(Dec3dError, match="unstable"):
        s.command("model cycle 5000")
    np.testing.assert_array_equal(zs["state"], keep)


# ------------------------------------------------------------------ nodal mixed discretization
def test_nmd_switch_is_kept_and_saved(tmp_path):
    s = _session(tmp_path, ["block create brick 0 1 0 1 0 1"])
    assert s.model.settings.mechanical.get("nmd", True) is True
    s.command("block zone nodal-mixed-discretization off")
    assert s.model.settings.mechanical["nmd"] is False
    s.command(f"model save '{tmp_path / 'n'}'")
    s2 = _session(tmp_path, [f"model restore '{tmp_path / 'n'}'"])
    assert s2.model.settings.mechanical["nmd"] is False
    with pytest.raises(Dec3dError, match="on|off"):
        s.command("block zone nodal-mixed-discretization maybe")
