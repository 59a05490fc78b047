"""Array modules (shapes, dtypes, zero-copy read-only views that follow cycling and refuse to be read
once the model state they came from is gone), Python callbacks at each position, several models."""
import traceback

import numpy as np
import pytest

import dec3d
import dec3d.itasca as it
from dec3d.itasca import blockarray as ba
from it_fixture import fresh_it  # noqa: F401  (autouse: no model bound, a fresh working folder)

STACK = """
model new
block create brick 0 1 0 1 0 1
block create brick 0 1 0 1 1 2
block create brick 0 1 0 1 2 3
block property density 1000
block contact jmodel assign mohr
block contact property stiffness-normal 1e9 stiffness-shear 1e9 friction 30
model gravity 0 0 -10
block fix range position-z 0 0.5
"""

SHAPES = {"ids": ((3,), np.int64), "pos": ((3, 3), np.float64), "vel": ((3, 3), np.float64),
          "rvel": ((3, 3), np.float64), "disp": ((3, 3), np.float64), "vol": ((3,), np.float64),
          "mass": ((3,), np.float64), "density": ((3,), np.float64), "force_app": ((3, 3), np.float64),
          "fixity": ((3,), np.uint8), "hidden": ((3,), np.bool_)}


def test_blockarray_shapes_dtypes_and_zero_copy_views():
    it.command(STACK)
    store = it.current().session.model.blocks
    for name, (shape, dtype) in SHAPES.items():
        a = getattr(ba, name)()
        assert a.shape == shape and a.dtype == dtype, name
        assert not a.flags.writeable, name
        with pytest.raises(ValueError):
            a[...] = 0
    assert np.shares_memory(ba.pos(), store.full("centroid"))          # zero copy
    np.testing.assert_array_equal(ba.ids(), [1, 2, 3])
    np.testing.assert_array_equal(ba.in_group("nothing"), [False] * 3)
    # a view taken before cycling shows the state after it
    z = ba.pos()[:, 2]
    v = ba.vel()
    gz = it.gridpointarray.pos()[:, 2]
    top = gz.max()
    it.cycle(30)
    assert z[2] < 2.5 and v[2, 2] != 0 and gz.max() < top      # the rigid vertices moved with their blocks
    np.testing.assert_array_equal(z, store["centroid"][:, 2])
    # arithmetic on views gives plain arrays that stay valid
    moved = ba.pos() - np.array([0.5, 0.5, 0.5])
    assert type(moved) is np.ndarray


def test_views_and_objects_refuse_a_replaced_model(tmp_path):
    it.command(STACK)
    it.cycle(5)
    it.command("model save 's.sav'")
    p, b, c = ba.pos(), it.block.find(3), next(it.block.contact.list())
    row = p[0]                                      # a sub-view is checked as well
    it.command("model restore 's.sav'")
    for use in (lambda: p[0, 0], lambda: repr(p), lambda: p + 1, lambda: row[0], lambda: p.sum(),
                lambda: b.pos(), lambda: c.force_norm(), lambda: float(p[0, 0])):
        with pytest.raises(it.StaleError, match="model state that is gone"):
            use()
    assert it.block.find(3).pos()[2] == ba.pos()[2, 2]        # found again: fine
    p = ba.pos()
    it.command("model new")
    with pytest.raises(it.StaleError):
        p.tolist()
    assert ba.pos().shape == (0, 3)


def test_views_go_out_of_date_when_blocks_are_made_or_deleted():
    it.command(STACK)
    p = ba.pos()
    f = it.block.find(1).faces()[0]
    it.command("block create brick 2 3 0 1 0 1")
    with pytest.raises(it.StaleError, match="3 rows then, 4 now"):
        p[0]
    with pytest.raises(it.StaleError, match="faces changed"):
        f.pos()
    assert ba.pos().shape == (4, 3)


def test_array_setters_check_shape_dtype_and_finiteness():
    it.command(STACK)
    it.command("model gravity 0 0 0")
    v = np.zeros((3, 3))
    v[2] = (0.25, 0, 0)
    ba.set_vel(v)
    np.testing.assert_array_equal(ba.vel(), v)
    with pytest.raises(ValueError, match=r"shape \(3, 3\).*got \(3,\)"):
        ba.set_vel([0, 0, 0])                               # no broadcasting
    with pytest.raises(ValueError, match=r"shape \(3, 3\).*got \(2, 3\)"):
        ba.set_vel(np.zeros((2, 3)))
    bad = v.copy()
    bad[1, 1] = np.nan
    with pytest.raises(ValueError, match="row 1 .*not finite"):
        ba.set_vel(bad)
    with pytest.raises(TypeError, match="numbers"):
        ba.set_vel([["a", "b", "c"]] * 3)
    with pytest.raises(ValueError, match="density"):
        ba.set_density([1000, 0, 1000])
    np.testing.assert_array_equal(ba.vel(), v)           # refused writes changed nothing
    ba.set_density([1000, 1000, 3000])
    assert it.block.find(3).mass() == pytest.approx(3000.0)


def test_callbacks_at_each_position_see_the_documented_step():
    it.command(STACK)
    seen = []

    def before():
        seen.append(("before", it.step()))

    def after():
        seen.append(("after", it.step()))

    def late():
        seen.append(("late", it.step()))

    it.set_callback(after, 1.0)
    it.set_callback(late, 5.0)
    it.set_callback(before, -1.0)
    it.cycle(3)
    # before runs ahead of step s (it sees s - 1), after and late once step s is done, in position order
    assert seen == [("before", 0), ("after", 1), ("late", 1), ("before", 1), ("after", 2), ("late", 2),
                    ("before", 2), ("after", 3), ("late", 3)]
    it.remove_callback(late)
    it.remove_callback("before", -1.0)
    seen.clear()
    it.cycle(1)
    assert seen == [("after", 4)]
    with pytest.raises(ValueError, match="not a callback"):
        it.remove_callback(late)


def test_a_callback_that_sets_velocity_acts_in_that_step():
    it.command("model new\nblock create brick 0 1 0 1 0 1\nblock property density 1000\n"
               "block mechanical damping local 0")
    b = it.block.find(1)

    def push():
        b.set_vel((1.0, 0, 0))

    it.set_callback(push, -1)
    it.cycle(4)
    np.testing.assert_allclose(b.disp()[0], it.mech_age(), rtol=1e-12)


def test_a_raising_callback_stops_cycling_with_the_users_traceback():
    it.command(STACK)
    it.cycle(3)
    before = ba.pos().copy()

    def boom():
        if it.step() == 7:
            raise ZeroDivisionError("user bug")

    it.set_callback(boom, 0)
    with pytest.raises(it.CallbackError, match="'boom' .* step 7: ZeroDivisionError: user bug") as info:
        it.cycle(20)
    assert isinstance(info.value.__cause__, ZeroDivisionError)
    assert any(f.name == "boom" for f in traceback.extract_tb(info.value.__cause__.__traceback__))
    # the model is intact: back at its state before the cycle command (as for any error while cycling)
    assert it.step() == 3
    np.testing.assert_array_equal(ba.pos(), before)
    it.remove_callback(boom)
    it.cycle(5)                                             # and it cycles on
    assert it.step() == 8 and np.all(np.isfinite(ba.pos())) and not np.array_equal(before, ba.pos())


def test_several_models_in_one_interpreter(tmp_path):
    models = [dec3d.Model(out_dir=tmp_path / f"m{k}") for k in range(2)]
    for m, rho in zip(models, (1000, 3000)):
        with m.bound():
            it.command(STACK.replace("density 1000", f"density {rho}"))
            it.cycle(10)
    with models[1].bound():
        assert it.block.find(2).mass() == pytest.approx(3000.0)
        p1 = ba.pos()
    prev = it.bind(models[0])
    assert prev is None and it.current() is models[0]
    assert it.block.find(2).mass() == pytest.approx(1000.0)
    it.cycle(10)
    assert models[0].session.model.step == 20 and models[1].session.model.step == 10
    assert p1.shape == (3, 3)                                # a view of the other model stays its own
    # each model writes into its own output folder
    for k, m in enumerate(models):
        m.command("model save 'x.sav'")
        assert (tmp_path / f"m{k}" / "x.sav").exists()
    with pytest.raises(TypeError, match="dec3d.Model"):
        it.bind("model")


def test_a_callback_may_not_cycle_or_change_the_blocks():
    it.command(STACK)

    def nested():
        it.command("block apply force 0 0 1 range id 3")          # allowed: a load
        it.cycle(1)                                               # refused: the cycle is still going on

    it.set_callback(nested, 0)
    with pytest.raises(it.CallbackError, match="ItascaError") as info:
        it.cycle(2)
    assert "`model cycle` cannot run in a Python callback" in str(info.value.__cause__)
    assert it.step() == 0


def test_array_setters_then_a_cycle():
    """Two free unit cubes far apart, no gravity, no damping: what the setters write is what the cycle moves
    with (x = v t, v = F/m t, a cube's spin is kept: its inertia is isotropic)."""
    it.command("model new\nblock create brick 0 1 0 1 0 1\nblock create brick 5 6 0 1 0 1\n"
               "block property density 1000\nblock mechanical damping local 0")
    ba.set_vel([[0.5, 0, 0], [0, 0, 0]])
    ba.set_force_app([[0, 0, 0], [0, 0, 200.0]])
    ba.set_rvel([[0, 0, 0], [0, 0, 0.1]])
    p0 = ba.pos().copy()
    it.cycle(20)
    t = it.mech_age()
    np.testing.assert_allclose(ba.pos()[0] - p0[0], [0.5 * t, 0, 0], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(ba.vel()[1], [0, 0, 200.0 / 1000.0 * t], rtol=1e-9)
    np.testing.assert_allclose(ba.rvel()[1], [0, 0, 0.1], rtol=1e-12)
    np.testing.assert_array_equal(ba.force_app()[1], [0, 0, 200.0])
