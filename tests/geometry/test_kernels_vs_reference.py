"""Each geometry kernel against its slow twin in tests/reference."""
import numpy as np
import pytest
from scipy.spatial import ConvexHull

from dec3d.geometry.assemble import block_poly
from dec3d.geometry.cutting import cut_by_planes
from dec3d.geometry.planes import plane_basis
from dec3d.geometry.polyhedron import Poly, polyhedron_from_faces
from dec3d.kernels.polycut import split_convex
from dec3d.model.blocks import add_blocks
from dec3d.model.model import Model
from reference.massprops_ref import block_mass_properties_ref, face_geometry_ref
from reference.polycut_ref import clip_below_ref


def random_convex(rng, n=14) -> Poly:
    pts = rng.normal(size=(n, 3)) * rng.uniform(0.5, 3.0, size=3) + rng.uniform(-5, 5, size=3)
    hull = ConvexHull(pts)
    return polyhedron_from_faces([pts[s] for s in hull.simplices], tol=1e-9)


@pytest.fixture(scope="module")
def model():
    rng = np.random.default_rng(7)
    m = Model()
    m.tolerance = 1e-9
    add_blocks(m, [random_convex(rng) for _ in range(12)], density=1.0)
    for _ in range(3):
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        cut_by_planes(m, n, rng.uniform(-3, 3, size=2))
    return m


def test_mass_properties_kernel_matches_twin(model):
    assert model.blocks.n > 12
    for r in range(model.blocks.n):
        p = block_poly(model, r)
        vol, cen, j = block_mass_properties_ref(p.vertices, p.faces())
        b = model.blocks
        assert b["volume"][r] == pytest.approx(vol, rel=1e-11)
        np.testing.assert_allclose(b["centroid"][r], cen, rtol=0, atol=1e-11 * (1 + np.abs(cen).max()))
        inertia = np.trace(j) * np.eye(3) - j
        np.testing.assert_allclose(b["inertia"][r], inertia, rtol=0, atol=1e-10 * np.abs(inertia).max())


def test_face_geometry_kernel_matches_twin(model):
    f = model.faces
    for face in range(f.n):
        loop = model.face_vertices["vertex"][f["vstart"][face]:f["vstart"][face] + f["nvert"][face]]
        n, a, c = face_geometry_ref(model.vertices["pos"][loop])
        np.testing.assert_allclose(f["normal"][face], n, atol=1e-9)
        assert f["area"][face] == pytest.approx(a, rel=1e-10)
        np.testing.assert_allclose(f["centroid"][face], c, atol=1e-10)


@pytest.mark.parametrize("seed", range(20))
def test_split_kernel_matches_convex_hull_twin(seed):
    rng = np.random.default_rng(100 + seed)
    p = random_convex(rng)
    n = rng.normal(size=3)
    n /= np.linalg.norm(n)
    s = p.vertices @ n
    d = rng.uniform(s.min(), s.max())
    u, w = plane_basis(n)
    fn = np.diff(p.face_ptr)
    res = split_convex(p.vertices, np.arange(len(p.vertices)), fn, np.arange(len(fn)), p.face_idx,
                       n, d, 1e-9, u, w)
    assert res[0] == 0
    ref_pts, ref_vol = clip_below_ref(p.vertices, p.faces(), n, d)
    below = res[1]
    # same corner set (the twin's hull drops nothing here: points are in general position)
    assert len(below) == len(ref_pts)
    for q in ref_pts:
        assert np.min(np.linalg.norm(below - q, axis=1)) < 1e-12
    m = Model()
    m.tolerance = 1e-9
    add_blocks(m, [p])
    cut_by_planes(m, n, [d])
    vols = m.blocks["volume"]
    assert m.blocks.n == 2
    assert vols[0] == pytest.approx(ref_vol, rel=1e-10)
    ref_above = clip_below_ref(p.vertices, p.faces(), -n, -d)[1]
    assert vols[1] == pytest.approx(ref_above, rel=1e-10)
