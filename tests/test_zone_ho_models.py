"""10-node tetrahedra with zone models (kernels/zones_ho_models.py, issue 26 item 2) against a numpy twin.

The twin takes its Gauss points, B matrices and random 10-node zones from the elastic 10-node twin
(``test_zone_ho_kernels``: shape functions as plain polynomials, derivatives by central differences)
and its Mohr-Coulomb return from ``zmodel_twins`` (principal stresses, every plane combination tried);
it never calls a kernel. Per Gauss point: the strain increment B (v dt), Hooke's trial, the return;
the forces −Σ w det J Bᵀ σ; the zone stress is the mean of the four, its state the union of theirs.
"""
import math

import numpy as np
import pytest

from dec3d.kernels.bundles import ZoneMaterial
from dec3d.kernels.zmodels import CODES, NZHIST, NZPROP, make_tables, model_mask
from dec3d.kernels.zones_ho_models import tet10_model_step_for
from test_zone_ho_kernels import b_matrix, gauss_points, random_tets
from zmodel_twins import tensor, twin_hooke, twin_mc, vec6

MC = CODES["mohr-coulomb"]
SS = CODES["strain-softening"]        # without tables: Mohr-Coulomb with constant strengths


def twin_step(pos, vel, gp, models, K, G, c, tanphi, ten, dt, gstress):
    """Returns (gstress after, zone stress, plastic-now flags per zone, forces)."""
    pts, w = gauss_points()
    gs = gstress.copy()
    force = np.zeros_like(pos)
    stress = np.zeros((len(gp), 6))
    yielded = np.zeros(len(gp), bool)
    for z in range(len(gp)):
        x = pos[gp[z]]
        u = (vel[gp[z]] * dt).ravel()
        f = np.zeros(30)
        for g, (p, wg) in enumerate(zip(pts, w)):
            B, dj = b_matrix(x, p)
            e = B @ u                                  # engineering strain increment
            d = np.array([e[0], e[1], e[2], e[3] / 2, e[4] / 2, e[5] / 2])
            trial = twin_hooke(gs[z, g], d, K[z], G[z])
            new, mult = twin_mc(trial, K[z], G[z], c[z], tanphi[z], ten[z], 0.0)[:2]
            yielded[z] |= bool(mult)
            gs[z, g] = vec6(new)
            f -= wg * dj * B.T @ np.array([gs[z, g, 0], gs[z, g, 1], gs[z, g, 2], gs[z, g, 3], gs[z, g, 4],
                                           gs[z, g, 5]])
        stress[z] = gs[z].mean(axis=0)
        force[gp[z]] += f.reshape(10, 3)
    return gs, stress, yielded, force


@pytest.mark.parametrize("curved", [0.0, 0.05])
def test_mohr_coulomb_and_strain_softening_ten_node_zones_match_the_twin(curved):
    """Mohr-Coulomb zones and strain-softening ones without tables (constant strengths: the same return)
    in one step; the model set {mohr-coulomb, strain-softening} is D15's, so one compile serves both."""
    rng = np.random.default_rng(5)
    m = 8
    pos, gp = random_tets(rng, m, curved)
    vel = rng.normal(size=pos.shape) * 2.0
    K = 1e9 * (1 + rng.random(m))
    G = 5e8 * (1 + rng.random(m))
    c = 2e5 * (0.5 + rng.random(m))
    tanphi = np.tan(np.radians(20 + 20 * rng.random(m)))
    ten = c / tanphi * rng.random(m)
    cmodel = np.where(np.arange(m) % 2 == 1, SS, MC).astype(np.int8)
    prop = np.zeros((m, NZPROP))
    prop[:, 0], prop[:, 1], prop[:, 2] = K, G, 2000.0
    prop[:, 3], prop[:, 4], prop[:, 5] = c, tanphi, ten
    g0 = np.zeros((m, 4, 6))
    g0[:, :, :3] = -1e5 * (1 + rng.random((m, 4, 1)))       # compressive start, then random strain
    g0[:, :, 3:] = 2e4 * rng.normal(size=(m, 4, 3))
    dt = 1e-4
    gs_twin, s_twin, y_twin, f_twin = twin_step(pos, vel, gp, cmodel, K, G, c, tanphi, ten, dt, g0)
    gs = g0.copy()
    mat = ZoneMaterial(cmodel, prop, np.zeros((m, NZHIST)), K.copy(), G.copy(), np.zeros((m, 6)),
                       np.zeros(m, np.int32), make_tables([]))
    force = np.zeros_like(pos)
    step = tet10_model_step_for(model_mask({MC, SS}))
    assert step(pos, vel, gp, np.arange(m, dtype=np.int64), mat, np.zeros((m, 4, NZHIST)), dt, gs, force) == -1
    scale = np.abs(gs_twin).max()
    assert np.abs(gs - gs_twin).max() <= 1e-9 * scale
    assert np.abs(mat.stress - s_twin).max() <= 1e-9 * scale
    assert np.abs(force - f_twin).max() <= 1e-9 * np.abs(f_twin).max()
    now = (mat.state & 3) != 0
    assert y_twin.sum() >= 3 and (now == y_twin).all()        # some zones yield, the same ones


def _session(tmp_path, extra):
    from dec3d.session import Session

    s = Session(out_dir=tmp_path)
    s.command("model new\nmodel configure highorder\nblock create brick 0 1 0 1 0 1\nblock zone generate edgelength 1\n"
              "block zone generate high-order-tetra\n" + extra)
    return s


def test_assigning_a_model_clears_the_gauss_point_histories_and_a_failed_run_puts_them_back(tmp_path):
    from dec3d.errors import Dec3dError

    s = _session(tmp_path, "table 'coh' add 0 1e6 0.005 2e5\nblock zone cmodel assign mohr-coulomb\n"
                           "block zone cmodel assign strain-softening range position-z 0 0.5\n"
                           "block zone property young 1e9 poisson 0.25 density 2000 cohesion 1e6 friction 30 "
                           "tension 1e6\nblock zone property table-cohesion 'coh' range position-z 0 0.5\n"
                           "block gridpoint apply velocity 0 0 0 range position-z 0\n"
                           "block gridpoint apply velocity-z -2e-6 range position-z 1\nmodel cycle 3000")
    zs = s.model.store("zones")
    gh = zs["ghist"][: zs.n].copy()
    assert gh[:, :, 0].max() > 0.0                              # κs grew at the Gauss points
    np.testing.assert_allclose(zs["hist"][: zs.n, 0], gh[:, :, 0].mean(axis=1), rtol=1e-12)
    s.command("block mechanical damping none\nblock mechanical timestep 10\n"
              "block gridpoint apply velocity-z -1 range position-z 1")
    with pytest.raises(Dec3dError, match="unstable"):
        s.command("model cycle 5000")
    np.testing.assert_array_equal(zs["ghist"][: zs.n], gh)
    s.command("block zone cmodel assign strain-softening")
    assert not zs["ghist"][: zs.n].any() and not zs["hist"][: zs.n].any()
    assert (zs["cmodel"][: zs.n] == SS).all()
    assert math.isfinite(float(np.abs(zs["stress"][: zs.n]).max()))
