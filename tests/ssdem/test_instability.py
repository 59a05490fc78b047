"""Detection and removal of unstable blocks (thesis Sec. 3.2.2)."""
import numpy as np
import pytest
import scipy.sparse as sp

from dec3d.ssdem import safety, solve
from dec3d.ssdem.build import from_polygons
from dec3d.ssdem.linsolve import Factor, floating_blocks


def box(x0, y0, w=1.0, h=1.0):
    return np.array([[x0, y0], [x0 + w, y0], [x0 + w, y0 + h], [x0, y0 + h]])


def test_unsupported_block_is_removed_and_the_rest_solved():
    """Block 2 floats in the air; blocks 1 and 3 stand on the fixed base 0."""
    polys = [box(0, -1, 3, 1), box(0, 0), box(5, 3), box(2, 0)]
    p = from_polygons(polys, [True, False, False, False], kn=1e7, ks=5e6, c=1e9, phi=30, gamma=20e3, n_steps=2)
    st = solve.run(p)
    assert st.removed.tolist() == [False, False, True, False]
    assert st.removed_step[2] == 1
    assert np.all(st.u[2] == 0.0)
    s = safety.evaluate(p, st)
    # the two standing blocks carry their own weight, 20 kN each
    assert np.sum(s.sigma_n * p.interfaces.length) == pytest.approx(40e3, rel=1e-9)
    assert s.surface_kind == "none" and not s.failure.any()    # nothing removed touched a remaining block


def test_block_on_a_frictionless_joint_is_found_by_the_pivot_test():
    """Connected (k_n > 0), yet free to slide (k_s = 0): the graph test passes, a pivot is zero."""
    polys = [box(0, -1), box(0, 0), box(1, 0)]
    p = from_polygons(polys, [True, False, False], kn=1e7, ks=1e6, c=1e9, phi=30, gamma=20e3, n_steps=1)
    itf = p.interfaces
    base_of_2 = (itf.a == 0) & (itf.b == 2) | (itf.a == 2) & (itf.b == 0)
    assert not base_of_2.any()                               # block 2 only touches block 1, from the side
    side = ((itf.a == 1) & (itf.b == 2)) | ((itf.a == 2) & (itf.b == 1))
    itf.ks[side] = 0.0                                        # block 2 hangs on block 1 by a normal spring only
    carries = (itf.kn > 0) | (itf.ks > 0)
    assert not floating_blocks(3, itf.a, itf.b, carries, np.array([True, False, False])).any()
    st = solve.run(p)
    assert st.removed.tolist() == [False, False, True]
    assert not st.removed[1] and abs(st.u[1, 1]) > 0


def test_pivot_test_flags_exactly_the_dependent_dof():
    """A 3-DOF SPD matrix plus a DOF with no stiffness: only that DOF is flagged."""
    A = np.array([[4.0, 1.0, 0.0, 0.0], [1.0, 3.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 2.0]])
    fac = Factor(sp.csr_matrix(A), 1e-9, scale=np.array([4.0, 3.0, 5.0, 2.0]))
    assert fac.bad.tolist() == [2]
    # a rank-deficient coupled pair (a rigid-body mode of two springs in series): one flag
    B = np.array([[1.0, -1.0, 0.0], [-1.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    fac = Factor(sp.csr_matrix(B), 1e-9)
    assert len(fac.bad) == 1 and fac.bad[0] in (0, 1)
    assert fac.ratio[2] == pytest.approx(1.0)


def test_overloaded_column_in_a_row_slides_off():
    """Three columns on a base; the right one is pushed sideways beyond its base strength.

    Its base and its joint with the middle column open towards the right: the push exceeds
    c L + N tan(phi) of the base, so a plastic mechanism forms and the column is removed;
    the others stay, and the joint it left is reported as the displacement discontinuity.
    """
    polys = [box(0, -1, 3, 1), box(0, 0, 1, 3), box(1, 0, 1, 3), box(2, 0, 1, 3)]
    p = from_polygons(polys, [True, False, False, False], force=[[0, 0, 0]] * 3 + [[60e3, 0, 0]],
                      kn=1e7, ks=5e6, c=5e3, phi=30, gamma=20e3, tensile=0.0, cutoff=True, n_steps=4)
    st = solve.run(p)
    s = safety.evaluate(p, st)
    assert st.removed.tolist() == [False, False, False, True]
    assert s.surface_kind == "yield"
    itf = p.interfaces
    touching = (itf.a == 3) | (itf.b == 3)
    assert s.failure[touching].all() and np.isnan(s.fs[touching]).all()
    assert all(np.isfinite([r.max_displacement for r in st.steps]))
