"""Assembly of the interface stiffness (thesis Ch. 3 as rebuilt in ERRATA)."""
import numpy as np
import pytest

from dec3d.ssdem.assemble import assemble_full, relative_motion, transfer_matrices
from dec3d.ssdem.build import from_polygons

SQ = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def two_blocks(angle_deg=0.0):
    """Unit squares A = [0,1]^2 and B = [1,2]x[0,1], optionally rotated about the origin."""
    a = np.radians(angle_deg)
    Q = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    polys = [SQ @ Q.T, (SQ + [1.0, 0.0]) @ Q.T]
    return from_polygons(polys, [False, False], kn=3.0, ks=2.0), Q


# By hand, k_n = 3, k_s = 2, L = 1, P = (1, 0.5), r_A = (0.5, 0), r_B = (-0.5, 0), alpha = 0:
#   K_L = diag(3, 2, 3/12); R_A = [[1,0,0],[0,1,0.5],[0,0,1]]; R_B = [[1,0,0],[0,1,-0.5],[0,0,1]]
#   C_AA = R_A^T K_L R_A, C_AB = -R_A^T K_L R_B, C_BB = R_B^T K_L R_B
HAND = np.array([
    [3, 0, 0, -3, 0, 0],
    [0, 2, 1, 0, -2, 1],
    [0, 1, 0.75, 0, -1, 0.25],
    [-3, 0, 0, 3, 0, 0],
    [0, -2, -1, 0, 2, -1],
    [0, 1, 0.25, 0, -1, 0.75],
])


def test_two_blocks_match_hand_computation():
    prob, _ = two_blocks()
    itf = prob.interfaces
    assert itf.m == 1 and itf.length[0] == pytest.approx(1.0)
    np.testing.assert_allclose(itf.normal[0], [1.0, 0.0])
    K = assemble_full(prob.blocks, itf, itf.kn, itf.ks).toarray()
    np.testing.assert_allclose(K, HAND, atol=1e-14)


@pytest.mark.parametrize("angle", [30.0, 117.0, -60.0])
def test_rotated_pair_is_the_rotated_hand_matrix(angle):
    """lambda and R at an inclined interface: K' = Q6 K Q6^T with Q6 = diag(Q, 1, Q, 1)."""
    prob, Q = two_blocks(angle)
    itf = prob.interfaces
    Q3 = np.eye(3)
    Q3[:2, :2] = Q
    Q6 = np.kron(np.eye(2), Q3)
    K = assemble_full(prob.blocks, itf, itf.kn, itf.ks).toarray()
    np.testing.assert_allclose(K, Q6 @ HAND @ Q6.T, atol=1e-12)


def grid_problem():
    from pathlib import Path

    from dec3d.ssdem.readers.toml_input import read_toml
    text = """
[profile]
points = [[0.0, 0.0], [7.3, 0.0], [15.1, 6.2], [19.0, 6.9], [30.0, 6.9]]
[[layer]]
c = 10.0
phi = 25.0
gamma = 19.0
kn = 2.0e5
ks = 7.0e4
[[layer]]
top = [[0.0, -2.5], [30.0, -1.0]]
c = 30.0
phi = 30.0
gamma = 20.0
kn = 5.0e5
ks = 1.5e5
[mesh]
size = 1.1
bottom = -6.0
"""
    return read_toml(Path("grid.toml"), text=text)


def test_assembled_matrix_is_symmetric_to_round_off():
    """A non-conforming grid mesh (hanging vertices) with two layers: K = K^T."""
    prob = grid_problem()
    itf = prob.interfaces
    K = assemble_full(prob.blocks, itf, itf.kn, itf.ks)
    asym = abs(K - K.T).max()
    assert asym <= 1e-13 * abs(K).max()
    assert K.shape == (3 * prob.blocks.n,) * 2


@pytest.mark.parametrize("motion", ["translation", "rotation"])
def test_rigid_motion_gives_zero_interface_forces(motion):
    """Every block moving with one rigid body motion stretches no spring: K u = 0."""
    prob = grid_problem()
    blk, itf = prob.blocks, prob.interfaces
    if motion == "translation":
        u = np.tile([0.013, -0.021, 0.0], (blk.n, 1))
    else:
        theta, centre = 2e-3, np.array([11.0, -3.0])
        r = blk.ref - centre
        u = np.column_stack([-theta * r[:, 1], theta * r[:, 0], np.full(blk.n, theta)])
    Ta, Tb = transfer_matrices(blk, itf)
    rel = relative_motion(u, itf.a, itf.b, Ta, Tb)
    assert np.abs(rel).max() < 1e-15
    K = assemble_full(blk, itf, itf.kn, itf.ks)
    f = K @ u.ravel()
    scale = abs(K).max() * np.abs(u).max()
    assert np.abs(f).max() < 1e-12 * scale
