"""A model with a rigid block resting on a zoned block: a run split into two `model cycle`
commands, or saved and restored between them, takes exactly the steps of one run — also when
the split falls between two contact detections (Δt and the surface-triangle weights of the
contact points are the ones the last run was using, kept in the settings and contact stores)."""
import io

import numpy as np
import pytest

import dec3d

DECK = """model new
block create brick 0 1 0 1 0 1
block create brick 0 1 0 1 1 2
block property density 2000
block zone generate edgelength 0.5 range position-z 0 1
block zone cmodel assign elastic
block zone property bulk 5e8 shear 3e8 density 2000
block gridpoint apply velocity 0 0 0 range position-z 0
model gravity 0 0 -10
block contact jmodel assign elastic
block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9
"""


def run(tmp_path, chunks, save_at=None):
    s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command(DECK)
    for i, c in enumerate(chunks):
        s.command(f"model cycle {c}")
        if save_at == i:
            s.command("model save 'z'")
            s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
            s.command("model restore 'z'")
    m = s.model
    return (m.vertices["pos"].copy(), m.vertices["velocity"].copy(), m.stores["zones"]["stress"].copy(),
            m.blocks["velocity"].copy(), m.stores["subcontacts"]["fn"].copy())


@pytest.mark.parametrize("save", [False, True])
def test_mixed_model_split_between_detections_is_one_run(tmp_path, save):
    one = run(tmp_path, [120])
    split = run(tmp_path, [47, 73], save_at=0 if save else None)
    assert np.abs(one[3]).max() > 1e-6 and one[4].sum() > 0      # the rigid block is moving and in contact
    for a, b in zip(one, split):
        assert np.array_equal(a, b)


# ------------------------------------------------------------------ large strain
# In large strain the zones' stiffness (hence Δt and the density-scaled masses), the quiet
# dashpots and the contact weights follow the geometry at every detection step (a multiple of
# the update interval), and the real masses stay those of the reference geometry: a new run
# takes what the last run was using, so the split point changes no bit.
_ROLL = ["block gridpoint apply velocity-z 0 range position-z 0",
         *[f"block gridpoint apply velocity-{a} 0 range position-{a} {c}" for a in "xy" for c in (0, 1)]]

LARGE = {
    # (a) zones alone, dynamic (Δt from the gridpoint stiffness), a soft column squeezed by a face stress
    "zones": ["block create brick 0 1 0 1 0 1", "block zone generate edgelength 0.5",
              "block zone cmodel assign elastic", "block zone property young 2e7 poisson 0.3 density 2000",
              *_ROLL, "model gravity 0 0 -10", "block mechanical damping none",
              "block face apply stress-zz -1e6 range position-z 1"],
    # (a') zones alone, static (local damping, density scaling), hexahedral mixed zones
    "zones-static": ["block create brick 0 1 0 1 0 1", "block zone generate hexahedra divisions 2 2 2",
                     "block zone cmodel assign elastic", "block zone property young 2e7 poisson 0.3 density 2000",
                     *_ROLL, "model gravity 0 0 -10", "block face apply stress-zz -1e6 range position-z 1"],
    # (a'') zones alone, 10-node zones (consistent gravity loads on the reference geometry)
    "zones-10node": ["model configure highorder", "block create brick 0 1 0 1 0 1",
                     "block zone generate high-order-tetra edgelength 0.5", "block zone cmodel assign elastic",
                     "block zone property young 2e7 poisson 0.3 density 2000", *_ROLL, "model gravity 0 0 -10",
                     "block mechanical damping none", "block face apply stress-zz -1e6 range position-z 1"],
    # (b) a rigid block on a zoned one
    "rigid-on-zoned": [ln for ln in DECK.splitlines()[1:] if ln] + ["block zone property young 2e7 poisson 0.3"],
    # (c) two zoned blocks pressed and sheared across a Coulomb joint, no damping
    "zoned-zoned": ["block create brick 0 1 0 1 0 1", "block create brick 0 1 0 1 1 2",
                    "block zone generate edgelength 0.5 range position-z 0 1",
                    "block zone generate edgelength 0.34 range position-z 1 2",
                    "block zone cmodel assign elastic", "block zone property young 2e7 poisson 0.3 density 2000",
                    "block contact jmodel assign mohr",
                    "block contact material-table default property stiffness-normal 1e10 stiffness-shear 1e10 "
                    "friction 20", *_ROLL, "block face apply stress -1e6 -1e6 -1e6 0 0 -3e5 range position-z 2",
                    "block mechanical damping none"],
    # (d) a rigid block on an FE block (FE blocks move their nodes in large strain too)
    "rigid-on-fe": ["model configure feblock", "block create brick 0 1 0 1 0 1", "block create brick 0 1 0 1 1 2",
                    "block property density 2000", "feblock generate 0.5 0.5 0.5 integration 2 range position-z 0 1",
                    "block zone cmodel assign elastic", "block zone property young 2e7 poisson 0.25 density 2000",
                    "model gravity 0 0 -10", "block contact jmodel assign elastic",
                    "block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9", *_ROLL],
}


def run_large(tmp_path, case, chunks, save_at=None):
    s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command("model new")
    s.command("model large-strain on")
    for line in LARGE[case]:
        s.command(line)
    for i, c in enumerate(chunks):
        s.command(f"model cycle {c}")
        if save_at == i:
            s.command("model save 'z'")
            s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
            s.command("model restore 'z'")
    m = s.model
    out = [m.vertices["pos"].copy(), m.vertices["velocity"].copy(), m.vertices["imass"].copy(),
           m.blocks["velocity"].copy(), np.array([m.time])]
    for st, key in (("zones", "stress"), ("feblocks", "stress"), ("subcontacts", "fn")):
        if st in m.stores:
            out.append(m.stores[st][key].copy())
    return out


@pytest.mark.parametrize("case, split, save", [("zones", 47, True), ("zones", 40, False), ("zones-static", 47, True),
                                               ("zones-10node", 47, True),
                                               ("rigid-on-zoned", 47, False), ("rigid-on-zoned", 53, True),
                                               ("zoned-zoned", 47, True), ("rigid-on-fe", 47, True)])
def test_large_strain_split_and_restored_runs_are_one_run(tmp_path, case, split, save):
    """120 steps in one `model cycle`, or split (between two detection steps or on one), with
    `model save`/`model restore` in between: the same bits. The gridpoints really moved (the
    geometry-dependent quantities changed on the way) so that large strain is exercised."""
    one = run_large(tmp_path, case, [120])
    split_ = run_large(tmp_path, case, [split, 120 - split], save_at=0 if save else None)
    s0 = run_large(tmp_path, case, [1])
    assert np.abs(one[0] - s0[0]).max() > 1e-6                  # gridpoints moved
    for a, b in zip(one, split_):
        assert np.array_equal(a, b)


def _tet_volumes(pos, gp):
    a, b, c, d = (pos[gp[:, i]] for i in range(4))
    return np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) / 6.0


def _node_stiffness(pos, gp, bulk, shear, n):
    """Eq. (86)-style node stiffness of 4-node zones written out here (3DEC theory text, "Time
    step"): per zone k = 8/3 (K + 4G/3) b_max² / h, b_max its longest edge, h = 3V / (largest face
    area), added to each of its four gridpoints."""
    out = np.zeros(n)
    for z in range(len(gp)):
        p = pos[gp[z]]
        vol = abs(np.linalg.det(p[1:] - p[0])) / 6.0
        edges = max(np.linalg.norm(p[i] - p[j]) for i in range(4) for j in range(i + 1, 4))
        face = max(0.5 * np.linalg.norm(np.cross(p[j] - p[i], p[k] - p[i]))
                   for i, j, k in ((0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)))
        out[gp[z]] += 8.0 / 3.0 * (bulk[z] + 4.0 * shear[z] / 3.0) * edges ** 2 / (3.0 * vol / face)
    return out


def test_large_strain_masses_are_conserved_and_stiffness_follows_the_detection_steps(tmp_path):
    """Large strain, the soft column squeezed by 1 MPa, no damping: after 115 steps the zones
    have changed their volume by more than 1 %, yet the real gridpoint masses still sum to
    ρ V0 = 2000 kg (mass is conserved: the lumped masses stay those of the undeformed zones).
    The zones' stiffness was last worked out at step 110 (a detection step, a multiple of the
    update interval 10): it is the node stiffness of the positions of step 110, not of step 115,
    and these positions are kept in ``gpos_geo`` for the next run."""
    s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command("model new")
    s.command("model large-strain on")
    for line in LARGE["zones"]:
        s.command(line)
    s.command("model cycle 110")
    m = s.model
    p110 = m.vertices["pos"].copy()
    s.command("model cycle 5")
    v, zs = m.vertices, m.stores["zones"]
    zst = m.rigid_engine._zstep
    gp = zs["gp"][:, :4]
    assert (zs["nnode"] == 4).all() and (zs["overlay"] < 0).all() and (v["link"] < 0).all()
    assert abs(_tet_volumes(v["pos"], gp).sum() - 1.0) > 0.01          # the column changed its volume
    assert v["mass"][zst.masters].sum() == pytest.approx(2000.0, rel=1e-12)
    assert np.array_equal(v["gpos_geo"][zst.rows], p110[zst.rows])
    k110 = _node_stiffness(p110, gp, zs["prop"][:, 0], zs["prop"][:, 1], v.n)
    k115 = _node_stiffness(v["pos"], gp, zs["prop"][:, 0], zs["prop"][:, 1], v.n)
    r = zst.masters
    assert np.allclose(zst.kzone[r], k110[r], rtol=1e-12, atol=0)
    assert np.abs(k115[r] / k110[r] - 1).max() > 1e-4                  # (the geometry did change the stiffness)
    # dynamic run: Δt = 2 min (m/k)^½ over the masters (Eq. 84) with those masses and stiffness
    dt = 2.0 * np.sqrt(v["mass"][r] / k110[r]).min()
    assert m.rigid_engine.dt == pytest.approx(dt, rel=1e-12)
