"""Zoned blocks cycle: analytical answers (verification/PROBLEMS.md D1, D2), the engine's
handling of mixed rigid/zoned models, bad input at cycle time and the rollback of a failed run."""

import math

import numpy as np
import pytest

from dec3d.errors import Dec3dError
from dec3d.session import Session
from zoning_fixture import zone_brick

E, NU = 1e10, 0.25
K, G = E / (3 * (1 - 2 * NU)), E / (2 * (1 + NU))


def _run(tmp_path, lines):
    s = Session(out_dir=tmp_path)
    for line in lines:
        s.command(line)
    return s


_ROLLERS = ["block gridpoint apply velocity-z 0 range position-z 0",
            "block gridpoint apply velocity-x 0 range position-x 0",
            "block gridpoint apply velocity-y 0 range position-y 0"]
_ELASTIC = ["block zone cmodel assign elastic", f"block zone property young {E:g} poisson {NU:g} density 2500"]


def _uniaxial_checks(s, sigma):
    """ε_zz = σ/E, lateral −ν ε_zz, every zone's stress uniaxial and uniform."""
    v, zs = s.model.vertices, s.model.store("zones")
    ez = sigma / E
    # displacements are linear in position: u_z = ε_zz z, u_x = −ν ε_zz x, u_y = −ν ε_zz y
    p = v["pos"]
    assert np.allclose(v["disp"][:, 2], ez * p[:, 2], rtol=0, atol=1e-3 * abs(ez))
    assert np.allclose(v["disp"][:, 0], -NU * ez * p[:, 0], rtol=0, atol=1e-3 * abs(NU * ez))
    assert np.allclose(v["disp"][:, 1], -NU * ez * p[:, 1], rtol=0, atol=1e-3 * abs(NU * ez))
    want = np.array([0, 0, sigma, 0, 0, 0])
    assert np.abs(zs["stress"] - want).max() <= 1e-6 * abs(sigma)


def test_d1_uniaxial_cube_of_tetrahedra(tmp_path):
    s = _run(tmp_path, ["block create brick 0 1 0 1 0 1", "block zone generate edgelength 0.5", *_ELASTIC,
                        *_ROLLERS, "block face apply stress-zz -1e6 range position-z 1", "model solve ratio 1e-8"])
    _uniaxial_checks(s, -1e6)
    # small strain (default): positions stay where they were
    top = s.model.vertices["pos"][:, 2] > 0.5
    assert np.allclose(s.model.vertices["pos"][top, 2], 1.0, atol=1e-12)
    assert s.model.rigid_engine.dt == 1.0            # density scaling: Δt = 1 in a static run


def test_d1_uniaxial_cube_of_mixed_hexahedral_zones(tmp_path):
    s = Session(out_dir=tmp_path)
    s.command("block create brick 0 1 0 1 0 1")
    zone_brick(s.model, 0, mixed=True)
    top = s.model.vertices["pos"][:, 2] > 0.5
    # a hexahedral face triangulated along one diagonal shares a face stress unevenly between
    # the corners; the consistent load of uniform stress on one hexahedral face is σA/4 per corner
    for line in [*_ELASTIC, *_ROLLERS, "block gridpoint apply force-z -250000 range position-z 1",
                 "model large-strain on", "model solve ratio 1e-8"]:
        s.command(line)
    # large strain: the force acts on the area grown by the lateral strain (true stress)
    _uniaxial_checks(s, -1e6 / (1 + NU * 1e-4) ** 2)
    v = s.model.vertices
    # large strain: positions follow the displacement
    assert np.allclose(v["pos"][top, 2], 1.0 - 1e-4, atol=1e-9)


def test_d2_self_weight_column(tmp_path):
    H, rho, g = 10.0, 2500.0, 10.0
    s = _run(tmp_path, [f"block create brick 0 1 0 1 0 {H:g}", "block zone generate edgelength 0.5",
                        "block zone cmodel assign elastic", f"block zone property young {E:g} poisson {NU:g} "
                        f"density {rho:g}", f"model gravity 0 0 {-g:g}",
                        "block gridpoint apply velocity-z 0 range position-z 0",
                        *[f"block gridpoint apply velocity-{a} 0 range position-{a} {c}" for a in "xy" for c in (0, 1)],
                        "model solve ratio 1e-6"])
    v, zs = s.model.vertices, s.model.store("zones")
    M = E * (1 - NU) / ((1 + NU) * (1 - 2 * NU))
    settle = rho * g * H ** 2 / (2 * M)
    assert settle == pytest.approx(1.0417e-4, rel=1e-4)
    top = v["pos"][:, 2] > H - 1e-6
    assert -v["disp"][top, 2].mean() == pytest.approx(settle, rel=0.01)
    zc = v["pos"][zs["gp"][:, :4]].mean(axis=1)[:, 2]
    exact = -rho * g * (H - zc)
    err = zs["stress"][:, 2] - exact
    assert np.abs(err).max() <= 0.02 * rho * g * H          # every zone within 2 % of the largest stress
    deep = H - zc > 1.0
    assert np.mean(np.abs(err[deep] / exact[deep])) <= 0.02    # and 2 % on average, relative
    # the zones carry the column's weight: ∫σ_zz dV = −ρ g H² A / 2
    assert (zs["stress"][:, 2] * zs["volume"]).sum() == pytest.approx(-rho * g * H ** 2 / 2, rel=1e-3)
    # oedometric: σ_xx / σ_zz = ν / (1 − ν)
    sx = zs["stress"][deep, 0].sum() / zs["stress"][deep, 2].sum()
    assert sx == pytest.approx(NU / (1 - NU), rel=0.02)


def test_rigid_and_zoned_blocks_cycle_side_by_side(tmp_path):
    """A rigid block falling freely (no damping) keeps v = g t while a zoned cube far from it
    stands on its rollers; the zoned block is not moved by the rigid motion kernel."""
    s = _run(tmp_path, ["block create brick 0 1 0 1 0 1", "block create brick 5 6 0 1 0 1",
                        "block property density 2000", "block zone generate edgelength 0.5 range position-x 0 1",
                        *_ELASTIC, *_ROLLERS, "model gravity 0 0 -10", "block mechanical damping none",
                        "block mechanical timestep 1e-4", "model cycle 200"])
    b = s.model.blocks
    rigid = int(np.flatnonzero(b["kind"] == 0)[0])
    assert b["velocity"][rigid, 2] == pytest.approx(-10 * 200 * 1e-4, rel=1e-12)
    zoned = int(np.flatnonzero(b["kind"] == 1)[0])
    assert np.all(b["velocity"][zoned] == 0.0) and np.all(b["disp"][zoned] == 0.0)
    v = s.model.vertices
    gz = v["zoned"]
    assert np.all(v["disp"][gz, 2] <= 1e-15) and np.any(v["disp"][gz, 2] < -1e-9)   # it settles under gravity


def test_missing_zone_properties_name_the_blocks(tmp_path):
    s = _run(tmp_path, ["block create brick 0 1 0 1 0 1", "block create brick 2 3 0 1 0 1",
                        "block zone generate edgelength 0.5", "block zone cmodel assign elastic",
                        "block zone property young 1e9 poisson 0.2 range position-x 0 1"])
    with pytest.raises(Dec3dError, match=r"elastic zones: bulk must be > 0 Pa \(not set\): 43 zone\(s\) of blocks 2 .*"
                                         r"shear must be > 0 Pa \(not set\): 43 zone\(s\) of blocks 2 .*density must be "
                                         r"> 0 kg/m³ \(not set\): 87 zone\(s\) of blocks 1, 2 .*block zone property"):
        s.command("model cycle 5")
    s.command("block zone property density 2000")
    with pytest.raises(Dec3dError, match=r"bulk must be > 0 Pa \(not set\): 43 zone\(s\) of blocks 2 .*shear must be "
                                         r"> 0 Pa \(not set\): 43 zone\(s\) of blocks 2 \([^;]*\) \(set them"):
        s.command("model cycle 5")
    assert s.model.step == 0


def test_zoned_block_without_a_model_is_refused(tmp_path):
    s = _run(tmp_path, ["block create brick 0 1 0 1 0 1", "block zone generate edgelength 0.5"])
    with pytest.raises(Dec3dError, match=r"zoned blocks 1 have no zone with a constitutive model"):
        s.command("model cycle 5")


@pytest.mark.parametrize("large", ["on", "off"])
def test_rigid_block_resting_on_a_zoned_block(tmp_path, large):
    """A rigid 1 m cube (ρ = 2000) on a zoned 1 m cube (E = 1 GPa, ν = 0.25, ρ = 2000) on rollers
    at the base and the four sides (one-dimensional compression, M = E(1−ν)/((1+ν)(1−2ν))),
    joint kn = ks = 10 GPa/m: the contact carries the weight W = 20 kN; the rigid block settles by
    W/M·H + ρgH²/(2M) + W/(kn A) = 27.0 µm (a rigid face on a confined column: uniform pressure).
    The sub-contacts sit at the zoned face's gridpoints only, with the consistent areas of a
    uniform pressure (``contacts.zoned_side_carries``; with the rigid face's corners as well the
    settlement was 3.5 % high): bar 1 %."""
    s = _run(tmp_path, ["block create brick 0 1 0 1 0 1", "block create brick 0 1 0 1 1 2",
                        "block property density 2000", "block zone generate edgelength 0.5 range position-z 0 1",
                        "block zone cmodel assign elastic", "block zone property young 1e9 poisson 0.25 density 2000",
                        "model gravity 0 0 -10", f"model large-strain {large}", "block contact jmodel assign elastic",
                        "block contact material-table default property stiffness-normal 1e10 stiffness-shear 1e10",
                        "block gridpoint apply velocity-z 0 range position-z 0",
                        *[f"block gridpoint apply velocity-{a} 0 range position-{a} {c}" for a in "xy" for c in (0, 1)],
                        "model solve ratio 1e-6"])
    b, ss = s.model.blocks, s.model.store("subcontacts")
    rigid = int(np.flatnonzero(b["kind"] == 0)[0])
    W, M = 2e4, 1.2e9
    assert ss["fn"].sum() == pytest.approx(W, rel=1e-4)
    settle = W / M + 2000 * 10 / (2 * M) + W / 1e10
    assert -b["disp"][rigid, 2] == pytest.approx(settle, rel=0.01)
    # nine sub-contacts, at the top gridpoints of the zoned block, their areas summing to A = 1 m²
    zoned = int(np.flatnonzero(b["kind"] == 1)[0])
    v = s.model.vertices
    top = np.flatnonzero((v["block"] == zoned) & (np.abs(v["pos"][:, 2] - 1.0) < 1e-3))
    assert ss.n == len(top) == 9 and ss["area"][: ss.n].sum() == pytest.approx(1.0, rel=1e-12)
    # the zoned block carries it: mean σ_zz over its zones = −(W + its own weight / 2) / A
    zs = s.model.store("zones")
    mean = (zs["stress"][:, 2] * zs["volume"]).sum() / zs["volume"].sum()
    assert mean == pytest.approx(-(W + 2000 * 10 / 2), rel=1e-3)


def test_unstable_run_is_rolled_back(tmp_path):
    """Real masses (no damping, no density scaling) and a time step far above Eq. (84): the
    run blows up, says where, and the model is back as it was (zone stresses included)."""
    s = _run(tmp_path, ["block create brick 0 1 0 1 0 1", "block zone generate edgelength 0.5", *_ELASTIC,
                        *_ROLLERS, "block face apply stress-zz -1e6 range position-z 1", "model cycle 20"])
    zs, v = s.model.store("zones"), s.model.vertices
    keep = (zs["stress"].copy(), v["velocity"].copy(), v["disp"].copy(), s.model.step)
    s.command("block mechanical damping none")
    s.command("block mechanical timestep 1e-2")
    with pytest.raises(Dec3dError, match=r"unstable at step \d+: a gridpoint of block 1 at .* reached velocity"):
        s.command("model cycle 2000")
    assert np.array_equal(zs["stress"], keep[0]) and np.array_equal(v["velocity"], keep[1])
    assert np.array_equal(v["disp"], keep[2]) and s.model.step == keep[3]


def test_dynamic_time_step_follows_eq_84(tmp_path):
    """Without damping there is no density scaling: Δt = 2 min (m/k)^½ (Eq. 84) with the real
    lumped masses, and the step is stable (an undamped cube oscillates but stays bounded)."""
    s = _run(tmp_path, ["block create brick 0 1 0 1 0 1", "block zone generate edgelength 0.5", *_ELASTIC,
                        *_ROLLERS, "block mechanical damping none",
                        "block face apply stress-zz -1e6 range position-z 1", "model cycle 3000"])
    dt = s.model.rigid_engine.dt
    zst = s.model.rigid_engine._zstep
    m, k = zst.mtot[zst.masters], zst.ktot[zst.masters]
    assert dt == pytest.approx(2 * np.sqrt(m / k).min(), rel=1e-12)
    uz = -s.model.vertices["disp"][:, 2].min()
    assert 0 < uz < 2.5 * 1e-4                        # bounded by twice the static answer (plus margin)


@pytest.mark.parametrize("hold_copies", [False, True])
def test_joined_blocks_with_linked_gridpoints_act_as_one_continuum(tmp_path, hold_copies):
    """Two stacked bricks zoned as mixed hexahedra, joined, their coincident gridpoints linked
    (the upper block's copy points to the lower block's row, as the contract says): under a
    top load and rollers the pair deforms as one 2 m prism: ε_zz = σ/E everywhere, the top at
    2 ε_zz, and the linked copies move exactly as their masters."""
    s = Session(out_dir=tmp_path)
    s.command("block create brick 0 1 0 1 0 1")
    s.command("block create brick 0 1 0 1 1 2")
    b = s.model.blocks
    for r in range(2):
        row = int(np.flatnonzero(b["id"] == r + 1)[0])
        zone_brick(s.model, row, mixed=True)
    v = s.model.vertices
    lower, upper = (np.flatnonzero(v["block"] == int(np.flatnonzero(b["id"] == i)[0])) for i in (1, 2))
    linked = 0
    for r in upper:
        hit = lower[np.all(np.abs(v["pos"][lower] - v["pos"][r]) < 1e-9, axis=1)]
        if len(hit):
            v["link"][r] = hit[0]
            linked += 1
    assert linked == 4
    top = v["pos"][:, 2] > 1.5
    if hold_copies:
        # conditions set only on the linked copies (the upper block's rows at z = 1) hold the
        # shared gridpoints: the lower block hangs from them, the upper one stands on them
        cp = np.flatnonzero(v["link"] >= 0)
        v["apply_fix"][cp] = 7
        for line in ["block join", *_ELASTIC, "model gravity 0 0 -10", "model cycle 300"]:
            s.command(line)
        assert np.all(v["disp"][v["link"][cp]] == 0.0) and np.all(v["disp"][cp] == 0.0)
        assert np.all(v["disp"][lower[v["pos"][lower, 2] < 0.5], 2] < -1e-8)
        assert np.all(v["disp"][upper[v["pos"][upper, 2] > 1.5], 2] < -1e-8)
        return
    for line in ["block join", *_ELASTIC, *_ROLLERS, "block gridpoint apply force-z -250000 range position-z 2",
                 "model solve ratio 1e-8"]:
        s.command(line)
    ez = -1e6 / E
    assert np.allclose(v["disp"][:, 2], ez * v["pos"][:, 2], rtol=0, atol=1e-3 * abs(ez))
    assert np.allclose(v["disp"][top, 2], 2 * ez, rtol=1e-3)
    assert np.abs(s.model.store("zones")["stress"] - np.array([0, 0, -1e6, 0, 0, 0])).max() <= 1e-6 * 1e6
    cp = np.flatnonzero(v["link"] >= 0)
    assert np.array_equal(v["disp"][cp], v["disp"][v["link"][cp]])


def test_d1_uniaxial_cube_of_ten_node_tetrahedra(tmp_path):
    """10-node zones through the engine (HRZ masses, Gershgorin stiffness, Gauss-point stresses)
    with the top load as consistent 6-node face loads: ε = σ/E, lateral −ν σ/E and every Gauss
    point at the uniaxial stress."""
    from zone_fixtures import zone_convex_tet10
    s = Session(out_dir=tmp_path)
    s.command("block create brick 0 1 0 1 0 1")
    zone_convex_tet10(s.model, 0, 0.5)
    zs = s.model.store("zones")
    assert (zs["nnode"] == 10).all()
    for line in [*_ELASTIC, *_ROLLERS, "block face apply stress-zz -1e6 range position-z 1", "model solve ratio 1e-8"]:
        s.command(line)
    _uniaxial_checks(s, -1e6)
    want = np.array([0, 0, -1e6, 0, 0, 0])
    assert np.abs(zs["gstress"] - want).max() <= 1e-6 * 1e6
    # the top load is the consistent one: no force on the top corners of the 6-node faces,
    # and the whole load σ A on the top
    v = s.model.vertices
    top = np.abs(v["pos"][:, 2] - 1) < 1e-9
    assert abs(v["fface"][top, 2].sum() + 1e6) < 1e-6
    corner = np.zeros(v.n, bool)
    corner[zs["gp"][:, :4].ravel()] = True
    mids = top & ~corner
    assert np.abs(v["fface"][top & corner, 2]).max() < 1e-6 and (v["fface"][mids, 2] < 0).all()


def test_ten_node_self_weight_uses_the_consistent_body_force(tmp_path):
    """Gravity on 10-node zones: the loads of zones_ho.tet10_body_force (−W/20 at each corner,
    W/5 at each mid-edge node of a zone of weight W), summing to the block's weight; a column
    under its own weight reaches σ_zz = ρ g (H − z) at the Gauss points (linear stress, which
    quadratic zones represent exactly) and the balanced state counts its weight in the ratio."""
    from zone_fixtures import zone_convex_tet10
    s = Session(out_dir=tmp_path)
    s.command("block create brick 0 1 0 1 0 2")
    zone_convex_tet10(s.model, 0, 1.0)
    for line in [*_ELASTIC, "model gravity 0 0 -10", *_ROLLERS,
                 "block gridpoint apply velocity-x 0 range position-x 1",
                 "block gridpoint apply velocity-y 0 range position-y 1",
                 "model solve ratio 1e-9"]:
        s.command(line)
    zst = s.model.rigid_engine._zstep
    assert abs(zst.fb10[:, 2].sum() + 2500 * 10 * 2.0) < 1e-6 * 5e4
    assert (zst.gmass == 0).all()
    from dec3d.kernels.zones_ho import tet10_gauss_positions
    zs = s.model.store("zones")
    gpos = np.zeros((zs.n, 4, 3))
    tet10_gauss_positions(s.model.vertices["pos"], zs["gp"], np.arange(zs.n), gpos)
    exact = -2500 * 10 * (2.0 - gpos[:, :, 2])
    assert np.abs(zs["gstress"][:, :, 2] - exact).max() < 1e-5 * 2500 * 10 * 2
    # top settlement: u = ρ g H² / (2 M), M the constrained modulus K + 4G/3 (laterally held)
    top = np.abs(s.model.vertices["pos"][:, 2] - 2.0) < 1e-9
    M = K + 4 * G / 3
    np.testing.assert_allclose(s.model.vertices["disp"][top, 2], -2500 * 10 * 4 / (2 * M), rtol=1e-4)


def test_ten_node_face_loaded_in_part_falls_back_to_thirds(tmp_path):
    """A stress on only some of the four triangles of a 6-node face (a range through the face)
    cannot be a uniform traction on that face: those triangles share their load by thirds, and
    the total is still σ times the loaded area."""
    from zone_fixtures import zone_convex_tet10
    s = Session(out_dir=tmp_path)
    s.command("block create brick 0 1 0 1 0 1")
    zone_convex_tet10(s.model, 0, 1.0)
    s.command("block face apply stress-zz -1e6 range position-z 1 position-x 0 0.3")
    m = s.model
    f, fv, v = m.faces, m.face_vertices, m.vertices
    loaded = np.flatnonzero(f["fstress"][:, 2] != 0)
    nodes = fv["vertex"][f["vstart"][loaded][:, None] + np.arange(3)]
    p = v["pos"][nodes]
    area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    assert 0 < len(loaded) and area.sum() < 1.0
    want = np.zeros(v.n)
    for k in range(3):
        np.add.at(want, nodes[:, k], -1e6 * area / 3)
    np.testing.assert_allclose(v["fface"][:, 2], want, rtol=0, atol=1e-6)


def test_ten_node_time_step_is_below_the_stability_limit(tmp_path):
    """Eq. (84) with the 10-node stiffness (twice the Gershgorin row sums of tet10_stiffness) and
    HRZ masses gives a Δt below the explicit limit 2/ω_max of the zone, ω_max² the largest
    eigenvalue of M⁻¹K with K probed column by column from the zone's nodal forces."""
    from dec3d.kernels.zones_ho import tet10_step
    from dec3d.physics.rigid import RunError
    from dec3d.physics.zones import ZoneStepper
    from zone_fixtures import zone_tet10
    s = Session(out_dir=tmp_path)
    s.command("block create tetrahedron 0 0 0 1 0 0 0.2 1.3 0 0.4 0.3 0.9")
    zone_tet10(s.model, 0)
    for line in _ELASTIC:
        s.command(line)
    zst = ZoneStepper(s.model, RunError)
    dt = zst.natural_timestep()
    v, zs = s.model.vertices, s.model.store("zones")
    gp = zs["gp"][0]
    Kmat = np.zeros((30, 30))
    for d in range(30):
        vel = np.zeros((v.n, 3))
        vel[gp[d // 3], d % 3] = 1.0
        f = np.zeros((v.n, 3))
        tet10_step(v["pos"], vel, zs["gp"], np.array([0]), zs["prop"][:, 0].copy(), zs["prop"][:, 1].copy(), 1.0,
                   np.zeros((1, 4, 6)), np.zeros((1, 6)), f)
        Kmat[:, d] = -f[gp].ravel()
    m = np.repeat(zst.mtot[gp], 3)
    w2 = np.linalg.eigvalsh(Kmat / np.sqrt(np.outer(m, m))).max()
    limit = 2 / math.sqrt(w2)
    assert dt < limit and dt > 0.2 * limit
