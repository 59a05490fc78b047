"""Principal values and axes of a symmetric tensor (``kernels/principal.py``): cyclic Jacobi and
the closed-form deviator values (the polynomial for cos(2 arccos(u)/3)) against numpy's eigvalsh
and libm's arccos and cos (the closed-form projectors: tests/test_zone_mohr_step_kernels.py)."""
import numpy as np
import pytest
from test_zone_mohr_kernels import _tensor, _vec6

from dec3d.kernels import principal as pr


@pytest.mark.parametrize("s", [np.array([3., -1, 2, 0.5, -0.7, 0.2]), np.array([1., 1, 1, 0, 0, 0]),
                               np.array([2., 2, 5, 0, 0, 0]), np.array([0., 0, 0, 0, 0, 0]),
                               np.array([1e7, -3e6, 2e6, 4e6, 0, 0]), np.array([1., 1, 1, 1e-9, 0, 0])])
def test_jacobi_eigen_matches_numpy(s):
    lam, vec = np.empty(3), np.empty((3, 3))
    pr.sym_eig3(s, lam, vec)
    t = _tensor(s)
    scale = max(np.abs(s).max(), 1e-300)
    assert np.allclose(lam, np.linalg.eigvalsh(t), atol=1e-14 * scale)
    assert np.abs(t @ vec - vec * lam).max() <= 1e-14 * scale + 1e-300
    assert np.allclose(vec.T @ vec, np.eye(3), atol=1e-14)
    assert np.all(np.diff(lam) >= 0)


def test_root_polynomial_is_the_cosine_of_a_third_of_the_angle():
    """``_root`` (a polynomial) against cos(2 arccos(u) / 3) from libm, on a fine grid and at
    both ends (u = 0: the two larger deviator values equal; u = 1: the two smaller)."""
    u = np.concatenate([np.linspace(0.0, 1.0, 20001), [1e-300, 1e-12, 1 - 1e-12]])
    want = np.cos(2.0 * np.arccos(u) / 3.0)
    got = np.array([pr._root(x) for x in u])
    assert np.abs(got - want).max() <= 2e-15
    assert abs(pr._root(0.0) - 0.5) <= 2.3e-16 and abs(pr._root(1.0) - 1.0) <= 2.3e-16


def test_closed_form_principal_values_match_numpy():
    """``_dev_principal`` (the polynomial root) against numpy's eigvalsh on random tensors, on
    tensors with two nearly equal and exactly equal principal values, and far off the origin."""
    rng = np.random.default_rng(7)
    cases = list(rng.normal(0.0, 1.0, (3000, 6)))
    for _ in range(300):                   # two values (nearly) repeated, random axes
        q, _r = np.linalg.qr(rng.normal(size=(3, 3)))
        lam = rng.normal(size=3)
        lam[1] = lam[rng.integers(0, 3, 1)[0] if rng.random() < 0.5 else 1] + rng.choice([0.0, 1e-9, 1e-4])
        cases.append(_vec6(q @ np.diag(lam) @ q.T))
    cases += [np.array([1e7, 1e7 + 3, 1e7 - 2, 1.0, -0.5, 0.25]), np.array([2., 2, 5, 0, 0, 0]),
              np.array([-1., 0, 0, 0, 0, 0]), np.array([1., 0, 0, 0, 0, 0])]
    for s in cases:
        m, lo, mid, hi = pr._dev_principal(*s)
        want = np.linalg.eigvalsh(_tensor(s))
        scale = np.abs(s).max()
        gap = max(min(np.diff(want)), 1e-300)
        assert lo <= mid + 1e-15 * scale and mid <= hi + 1e-15 * scale
        # the isolated value to about eps r, the two nearest each other to about eps r² / gap
        # (a square root's worth of eps r when they coincide)
        tol = 2e-14 * scale + min(4e-15 * scale ** 2 / gap, 3e-8 * scale)
        assert np.abs(m + np.array([lo, mid, hi]) - want).max() <= tol
