"""FE blocks cycling in the engine (``model solve`` through the zone step): the seed's
fem_beam.dat as written (3x3x3 integration) and a self-weight column with consistent gravity."""
import io

import numpy as np
import pytest

from dec3d.kernels.feblock import feb_gauss_positions
from dec3d.session import Session

FEM_BEAM = """model new
model config feblock
[a = 1.0]
[force = 100.0]
[E = 1e6]
[L = 10.0]
block create brick 0 [L] 0 [a] 0 [a]
feblock generate 1 1 1 integration 3
block zone cmodel assign el
block zone prop dens 2000 young [E] poiss 0.2
block gridpoint apply vel 0 0 0 range pos-x 0
; divide force by 3 since it is being applied to 3 gridpoints
block gridpoint apply force-z [-1.0*force/3.0] range pos-x [L] pos-z [a]
model large-strain off
model solve
"""


def test_fem_beam_deck_solves_to_the_calculix_deflection(tmp_path):
    """F1 (3x3x3): `model solve` (ratio 1e-5) gives the tip deflection of CalculiX C3D20 on the
    same mesh, 0.3996 m, within 0.2 %, and WL^3/(3EI) = 0.400 m within 1 %."""
    out = io.StringIO()
    s = Session(out_dir=tmp_path, stdout=out)
    s.command(FEM_BEAM)
    v = s.model.vertices
    tip = np.flatnonzero(np.all(abs(v["pos"] - [10, 1, 1]) < 1e-9, axis=1))
    assert len(tip) == 1
    u = -v["disp"][tip[0], 2]
    assert abs(u - 0.3996) < 0.002 * 0.3996 and abs(u - 0.4) < 0.01 * 0.4, u
    assert "model solve: converged" in out.getvalue()
    # slave nodes moved with the masters: the tip-face centre node carries the tip deflection
    cen = np.flatnonzero(np.all(abs(v["pos"] - [10, 0.5, 0.5]) < 1e-9, axis=1))[0]
    assert v["feslave"][cen] and abs(-v["disp"][cen, 2] - u) < 0.01 * u


@pytest.mark.parametrize("nq", [2, 3])
def test_self_weight_column_in_the_engine(tmp_path, nq):
    """`model gravity` on an FE column (sides on rollers, base fixed in z): consistent gravity
    (Eq. 8) gives sigma_zz = -rho g (H - z) and sigma_xx = sigma_yy = nu/(1-nu) sigma_zz at every
    Gauss point, to the solve ratio."""
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command(f"""model configure feblock
block create brick 0 1 0 1 0 4
feblock generate 1 1 1 integration {nq}
feblock change cmodel elastic young 1e7 poisson 0.25 density 2000
model gravity 0 0 -10
block gridpoint apply velocity-z 0 range position-z 0
block gridpoint apply velocity-x 0 range position-x 0
block gridpoint apply velocity-x 0 range position-x 1
block gridpoint apply velocity-y 0 range position-y 0
block gridpoint apply velocity-y 0 range position-y 1
model solve ratio 1e-9""")
    m = s.model
    es = m.store("feblocks")
    gpos = np.zeros((4, 27, 3))
    feb_gauss_positions(np.ascontiguousarray(m.vertices["pos"]), np.ascontiguousarray(es["nodes"]),
                        np.arange(4, dtype=np.int64), gpos, nq)
    ng = nq ** 3
    sg = es["gstress"][:4, :ng]
    expect = -2000 * 10 * (4 - gpos[:, :ng, 2])
    scale = 2000 * 10 * 4
    assert np.abs(sg[..., 2] - expect).max() < 1e-5 * scale
    assert np.abs(sg[..., 0] - expect / 3).max() < 1e-5 * scale
    assert np.abs(sg[..., 3:]).max() < 1e-5 * scale


@pytest.mark.parametrize("large", ["off", "on"])
def test_rigid_block_resting_on_an_fe_block(tmp_path, large):
    """As the zoned-block test of the zone step: a rigid 1 m cube (rho = 2000) on an FE cube of
    2 x 2 x 2 elements (E = 1 GPa, nu = 0.25, rho = 2000) on rollers (one-dimensional compression,
    M = 1.2 GPa), joint kn = ks = 10 GPa/m. Contact forces reach the FE nodes through the surface
    triangles (slave mid-face nodes, Eq. 9): the contact carries the weight W = 20 kN, the FE
    block's mean sigma_zz is -(W + its own weight / 2) / A, and the rigid block settles by about
    W/M H + rho g H^2/(2M) + W/(kn A) = 27.0 micro-m: measured 27.23 (+0.84 %, small strain; the FE
    side carries the whole overlap at its surface nodes, as a zoned side does against a rigid face:
    `contacts.zoned_side_carries`; with both sides' nodes carrying half it was 29.1, +7.8 %, the
    rigid corners denting the quadratic surface): bar 2 %."""
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    for line in ["model configure feblock", "block create brick 0 1 0 1 0 1", "block create brick 0 1 0 1 1 2",
                 "block property density 2000", "feblock generate 0.5 0.5 0.5 integration 3 range position-z 0 1",
                 "block zone cmodel assign elastic", "block zone property young 1e9 poisson 0.25 density 2000",
                 "model gravity 0 0 -10", f"model large-strain {large}", "block contact jmodel assign elastic",
                 "block contact material-table default property stiffness-normal 1e10 stiffness-shear 1e10",
                 "block gridpoint apply velocity-z 0 range position-z 0",
                 *[f"block gridpoint apply velocity-{a} 0 range position-{a} {c}" for a in "xy" for c in (0, 1)],
                 "model solve ratio 1e-6"]:
        s.command(line)
    b, ss = s.model.blocks, s.model.store("subcontacts")
    rigid = int(np.flatnonzero(b["kind"] == 0)[0])
    W, M = 2e4, 1.2e9
    assert ss["fn"].sum() == pytest.approx(W, rel=1e-4)
    es = s.model.store("feblocks")
    mean = (es["stress"][:, 2] * es["volume"]).sum() / es["volume"].sum()
    assert mean == pytest.approx(-(W + 2000 * 10 / 2), rel=1e-3)
    settle = W / M + 2000 * 10 / (2 * M) + W / 1e10
    assert -b["disp"][rigid, 2] == pytest.approx(settle, rel=0.02)
