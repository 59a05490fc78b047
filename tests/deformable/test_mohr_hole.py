"""Cylindrical hole in an infinite Mohr-Coulomb medium (verification D6): the closed form of
Salençon (1969) as Itasca's verification problem writes it, the measures `dec3d verify` takes of
the model (``verify_fields.salencon_measures``), and the same model without nodal mixed
discretization.

The closed form is checked here against what it must satisfy, written out independently:
radial equilibrium dσ_r/dr = (σ_θ − σ_r)/r, the Mohr-Coulomb yield condition
σ_θ = K_p σ_r + 2c√K_p inside the plastic zone, σ_r = p_i at the wall, continuity of both
stresses at R0 and σ → p0 far away.
"""
import math

import numpy as np
import pytest

from conftest import ROOT
from dec3d.session import Session
from dec3d.verify_fields import salencon_exact, salencon_measures

P0, C, PHI, A = 30e6, 3.45e6, 30.0, 1.0
DECK = ROOT / "verification" / "D6_mohr_hole" / "deck.dat"


@pytest.mark.parametrize("p_i, phi", [(0.0, 30.0), (2e6, 30.0), (0.0, 40.0), (1e6, 20.0)])
def test_salencon_closed_form_is_in_equilibrium_at_yield_and_continuous(p_i, phi):
    kp = (1 + math.sin(math.radians(phi))) / (1 - math.sin(math.radians(phi)))
    qu = 2 * C * math.sqrt(kp)                        # unconfined strength
    r0, sr_a, _ = salencon_exact(np.array([A]), P0, p_i, A, C, phi)
    assert sr_a[0] == pytest.approx(p_i, abs=1e-6 * P0)
    # R0 is where the elastic solution with σ_r = σ_re first meets the yield condition:
    # σ_θ + σ_r = 2 p0 and σ_θ = K_p σ_r + q_u give σ_re = (2 p0 − q_u) / (K_p + 1)
    _, sr0, st0 = salencon_exact(np.array([r0 * (1 - 1e-12), r0 * (1 + 1e-12)]), P0, p_i, A, C, phi)
    assert np.ptp(sr0) < 1e-6 * P0 and np.ptp(st0) < 1e-6 * P0
    assert sr0[0] == pytest.approx((2 * P0 - qu) / (kp + 1), rel=1e-9)
    r = np.linspace(A, 3 * r0, 4001)
    _, sr, st = salencon_exact(r, P0, p_i, A, C, phi)
    plastic = r < r0
    np.testing.assert_allclose(st[plastic], kp * sr[plastic] + qu, rtol=1e-12, atol=1e-6)
    assert np.all(st[~plastic] < kp * sr[~plastic] + qu + 1e-6)            # elastic zone below yield
    h = 1e-6
    _, srp, _ = salencon_exact(r + h, P0, p_i, A, C, phi)
    _, srm, _ = salencon_exact(r - h, P0, p_i, A, C, phi)
    inner = np.abs(r - r0) > 10 * h
    dsr = (srp - srm) / (2 * h)
    np.testing.assert_allclose(dsr[inner], ((st - sr) / r)[inner], rtol=1e-5)
    _, sfar, tfar = salencon_exact(np.array([1e4 * r0]), P0, p_i, A, C, phi)
    assert sfar[0] == pytest.approx(P0, rel=1e-6) and tfar[0] == pytest.approx(P0, rel=1e-6)


def test_salencon_radius_of_itascas_problem():
    """p0 = 30 MPa, c = 3.45 MPa, φ = 30°: K_p = 3, q = 2c√3, R0 = √(1/2 (p0 + q/2) / (q/2))."""
    q = 2 * C * math.sqrt(3.0)
    r0, _, _ = salencon_exact(np.array([A]), P0, 0.0, A, C, PHI)
    assert r0 == pytest.approx(math.sqrt(0.5 * (P0 + q / 2) / (q / 2)), rel=1e-12)
    assert r0 == pytest.approx(1.7349981445794187, rel=1e-12)            # the value problem.toml holds


def _zoned_quarter(tmp_path):
    """The D6 quarter model, zoned and set up, not run (the deck without `model solve`)."""
    deck = tmp_path / "setup.dat"
    deck.write_text(DECK.read_text().replace("model solve", ""))
    s = Session(out_dir=tmp_path)
    s.call(deck)
    return s


def test_salencon_measures_on_the_exact_field(tmp_path):
    """Zone stresses set from the closed form at each zone's centroid: zero stress errors, and a
    uniform 1 % of p0 more compression in x and z gives exactly 1 %; the plastic radius from the
    yielded area: all zones yielded fill the 10 m x 10 m quarter, R² = 4 · 100 / π; the zones
    with centroid inside R0 give R0 to within a zone."""
    s = _zoned_quarter(tmp_path)
    zs, pos = s.model.store("zones"), s.model.vertices["pos"]
    cen = pos[zs["gp"][:, :4]].mean(axis=1)
    r, th = np.hypot(cen[:, 0], cen[:, 2]), np.arctan2(cen[:, 2], cen[:, 0])
    r0, sr, st = salencon_exact(r, P0, 0.0, A, C, PHI)
    c, sn = np.cos(th), np.sin(th)
    zs["stress"][:] = 0.0
    zs["stress"][:, 0] = -(sr * c * c + st * sn * sn)            # compression positive (r, θ) -> xx, zz
    zs["stress"][:, 2] = -(sr * sn * sn + st * c * c)
    zs["stress"][:, 4] = -(sr - st) * sn * c
    zs["state"][:] = np.where(r < r0, 4, 0)
    m = salencon_measures(s.model, P0, 0.0, A, C, PHI, 45.0)
    assert m["sigr_line"] < 1e-9 and m["sigt_line"] < 1e-9 and m["sigr"] < 1e-9 and m["sigt"] < 1e-9
    assert m["line_zones"] >= 10
    assert m["radius_exact"] == pytest.approx(r0)
    assert abs(m["radius"] - r0) < 0.25 and m["radius_far"] < r0
    zs["stress"][:, 0] -= 0.01 * P0
    zs["stress"][:, 2] -= 0.01 * P0
    m = salencon_measures(s.model, P0, 0.0, A, C, PHI, 45.0)
    assert m["sigr_line"] == pytest.approx(1.0, rel=1e-9) and m["sigt"] == pytest.approx(1.0, rel=1e-9)
    zs["state"][:] = 8
    m = salencon_measures(s.model, P0, 0.0, A, C, PHI, 45.0)
    assert m["radius"] == pytest.approx(math.sqrt(400.0 / math.pi), rel=1e-9)


def test_salencon_measures_refuse_a_model_without_the_hole(tmp_path):
    s = Session(out_dir=tmp_path)
    with pytest.raises(ValueError, match="no zones"):
        salencon_measures(s.model, P0, 0.0, A, C, PHI, 45.0)
    s.command("block create brick 2 4 0 1 2 4")
    s.command("block zone generate edgelength 1")
    with pytest.raises(ValueError, match="no hole wall"):
        salencon_measures(s.model, P0, 0.0, A, C, PHI, 45.0)


def _run(tmp_path, nmd: str):
    s = Session(out_dir=tmp_path)
    text = DECK.read_text().replace("nodal-mixed-discretization on", f"nodal-mixed-discretization {nmd}")
    deck = tmp_path / f"hole_{nmd}.dat"
    deck.write_text(text)
    s.call(deck)
    return s, salencon_measures(s.model, P0, 0.0, A, C, PHI, 45.0)


def test_mohr_hole_without_nmd_scatters_the_plastic_stresses(tmp_path):
    """The D6 deck with nodal mixed discretization (its default, meets the folder's bars) and the
    same deck with `block zone nodal-mixed-discretization off`: the constant-strain tetrahedra,
    each with its own volumetric strain, lock in the dilatant plastic flow, and the zone stresses
    scatter about the closed form (the mean error over all zones of σ_θ grows from 2.7 % to 5.0 % of
    p0 and of σ_r from 2.1 % to 3.3 %, measured); the plastic radius hardly changes."""
    s_on, on = _run(tmp_path, "on")
    s_off, off = _run(tmp_path, "off")
    assert abs(on["radius"] / on["radius_exact"] - 1) < 0.05
    assert on["sigr_line"] < 5 and on["sigt_line"] < 5
    assert off["sigt"] > 1.5 * on["sigt"] and off["sigr"] > 1.3 * on["sigr"]
    assert abs(off["radius"] / off["radius_exact"] - 1) < 0.05
    # without NMD more zones reach the tension cut-off (tension 0, the default) at the wall
    t_on = int(((s_on.model.store("zones")["state"] & 8) != 0).sum())
    t_off = int(((s_off.model.store("zones")["state"] & 8) != 0).sum())
    assert t_off > 3 * max(t_on, 1)


def test_salencon_measures_take_a_hexahedral_zone_as_one(tmp_path):
    """Hexahedral zones (ten overlaid tetrahedra each, two sets of five): a zone's stress and
    centroid are those of its set, and its area counts once: with every zone yielded the plastic
    radius is again that of the whole 10 m x 10 m quarter; with the closed form at each hexahedron's
    centroid the stress errors vanish."""
    deck = tmp_path / "hex.dat"
    text = ROOT.joinpath("verification", "D3_elastic_hole_hex", "deck.dat").read_text()
    deck.write_text(text.replace("model cycle 2000", ""))
    s = Session(out_dir=tmp_path)
    s.call(deck)
    zs, pos = s.model.store("zones"), s.model.vertices["pos"]
    assert (zs["hex"] >= 0).all()
    cen4 = pos[zs["gp"][:, :4]].mean(axis=1)
    for h in np.unique(zs["hex"]):
        rows = np.flatnonzero(zs["hex"] == h)
        w = zs["volume"][rows]
        cen4[rows] = (cen4[rows] * w[:, None]).sum(axis=0) / w.sum()
    r, th = np.hypot(cen4[:, 0], cen4[:, 2]), np.arctan2(cen4[:, 2], cen4[:, 0])
    _, sr, st = salencon_exact(r, P0, 0.0, A, C, PHI)
    c, sn = np.cos(th), np.sin(th)
    zs["stress"][:] = 0.0
    zs["stress"][:, 0] = -(sr * c * c + st * sn * sn)
    zs["stress"][:, 2] = -(sr * sn * sn + st * c * c)
    zs["stress"][:, 4] = -(sr - st) * sn * c
    zs["state"][:] = 4
    m = salencon_measures(s.model, P0, 0.0, A, C, PHI, 45.0)
    assert m["sigr_line"] < 1e-9 and m["sigt_line"] < 1e-9 and m["sigt"] < 1e-9
    assert m["radius"] == pytest.approx(math.sqrt(400.0 / math.pi), rel=1e-9)
