"""Hostile inputs to the liner structural elements (`structure liner …`) and to structural nodes made
before their block is zoned: each is refused with the line and column, or stops the run with the model
kept, or gives the numbers of the input made in the ordinary order — never a traceback, a run that eats
the machine's memory, or a non-finite number left in the model."""
import numpy as np
import pytest

from dec3d.commands.values import ValueRangeError
from dec3d.errors import BindError, CommandError, ResourceError
from dec3d.physics.rigid import engine

RIGID = """model new
block create brick 0 1 0 1 0 1
block property density 1000
block fix
"""
QUAD = "structure liner create by-quadrilateral 0 0 1 1 0 1 1 1 1 0 1 1 size 2 2"
PROPS = ("structure liner property isotropic 30e9 0.2 thickness 0.1 density 2500 coupling-stiffness-normal 1e9 "
         "coupling-stiffness-shear 1e9")


def _deck(tmp_path, text):
    deck = tmp_path / "deck.dat"
    deck.write_text(text)
    return deck


def _finite(model):
    for name in ("liner_nodes", "liner_elements"):
        if name not in model.stores:          # (refused at binding: nothing ran)
            continue
        for k, a in model.stores[name].to_arrays().items():
            if a.dtype.kind == "f":
                assert np.isfinite(a).all(), f"{name}.{k}"


@pytest.mark.parametrize("line", [QUAD + " tolerance 1e300",
                                  "structure liner create by-block-face tolerance 1e300 range position-z 1"])
def test_a_tolerance_longer_than_every_element_is_refused(session, tmp_path, line):
    # was: IndexError (every triangle dropped as a sliver, then an empty merge)
    with pytest.raises(CommandError) as e:
        session.call(_deck(tmp_path, RIGID + line + "\n"))
    assert "shorter than twice the tolerance 1e+300 m: no liner made" in e.value.message
    assert (e.value.location.line, e.value.location.column) == (5, 1)
    assert "liner_elements" not in session.model.stores or session.model.stores["liner_elements"].n == 0


@pytest.mark.parametrize("line, kind, message", [
    # were: accepted, node masses and rotary inertias infinite (ρ t A / 3, m t² / 12 overflowed)
    ("structure liner property thickness 1e308", ValueRangeError, "`thickness` must be in (0, 1e+12], got 1e+308"),
    ("structure liner property density 1e308", ValueRangeError, "`density` must be in [0, 1e+09], got 1e+308"),
    ("structure liner property coupling-stiffness-normal 1e308", ValueRangeError,
     "`coupling-stiffness-normal` must be in [0, 1e+20], got 1e+308"),
    ("structure liner property isotropic 1e308 0.2", BindError,
     "`isotropic`: Young's modulus must be in (0, 1e+16] (got 1e+308)"),
])
def test_liner_properties_beyond_their_range_are_refused(session, tmp_path, line, kind, message):
    with pytest.raises(kind) as e:
        session.call(_deck(tmp_path, RIGID + QUAD + "\n" + PROPS + "\n" + line + "\n"))
    assert e.value.message == message
    assert (e.value.location.line, e.value.location.column) == (7, line.index("1e308") + 1)   # the value
    _finite(session.model)


def test_the_largest_values_in_range_leave_finite_numbers(session, tmp_path):
    session.call(_deck(tmp_path, RIGID + "structure liner create by-quadrilateral -1e6 -1e6 1 1e6 -1e6 1 1e6 1e6 1 "
                       "-1e6 1e6 1 size 2 2\nstructure liner property isotropic 1e16 0.2 thickness 1e12 density 1e9 "
                       "coupling-stiffness-normal 1e20 coupling-stiffness-shear 1e20 coupling-yield-normal 1e308 "
                       "coupling-cohesion-shear 1e308\nmodel cycle 3\nstructure liner list\n"))
    _finite(session.model)


@pytest.mark.parametrize("size, cross, elements, gib", [("10000 10000", "", "200,000,000", "572"),
                                                         ("1000 1000", " cross-diagonal", "4,000,000", "11.4")])
def test_a_quadrilateral_over_the_memory_budget_is_refused_before_any_element(session, tmp_path, size, cross,
                                                                               elements, gib):
    # was: `size 10000 10000` ran 65 s into a MemoryError traceback under a 4 GB limit (2e8 elements)
    line = f"structure liner create by-quadrilateral 0 0 1 1 0 1 1 1 1 0 1 1 size {size}{cross}"
    with pytest.raises(ResourceError) as e:
        session.call(_deck(tmp_path, RIGID + line + "\n"))
    assert e.value.message == (f"this liner would have {elements} elements (about {gib} GiB); the budget allows "
                               "4 GiB")
    assert "model budget memory" in e.value.hint
    assert (e.value.location.line, e.value.location.column) == (5, line.index("size") + 6)


@pytest.mark.parametrize("force", ["1e200", "1e308"])
def test_a_runaway_liner_node_stops_the_run_with_the_model_kept(session, tmp_path, force):
    # was: the run went on (node speeds ~1e190 m/s, finite) and the equilibrium ratio was NaN
    with pytest.raises(CommandError) as e:
        session.call(_deck(tmp_path, RIGID + QUAD + "\n" + PROPS + f"\nstructure node apply force-z {force}\n"
                           "model cycle 3\n"))
    assert "a liner node ran away (a speed over 1e+06 m/s, or off to infinity) at step 1" in e.value.message
    assert e.value.location.line == 8 and session.model.step == 0
    crit = engine(session.model).criteria()
    assert all(np.isfinite(v) for v in crit.values())
    assert not np.abs(session.model.stores["liner_nodes"]["disp"]).any()


def test_the_motion_kernel_counts_runaway_components():
    """``move_nodes`` returns the number of node components off to infinity or faster than VMAX (plain
    count against the kernel's)."""
    from dec3d.kernels.beam import VMAX, move_nodes

    n = 4
    z = lambda: np.zeros((n, 3))        # noqa: E731
    pos, vel, disp, rot, avel, fapp, mapp, force, moment = (z() for _ in range(9))
    force[1, 2] = 2e6        # with unit mass and Δt 1: 2e6 m/s, over the limit
    force[2, 0] = 0.5e6      # 0.5e6 m/s: under it
    moment[3, 1] = np.inf    # a rotation off to infinity
    ones = np.ones(n)
    bad = move_nodes(1.0, np.zeros(3), 0.0, 0, 0.0, pos, vel, disp, rot, avel, ones, ones, z(), z(),
                    np.zeros(n, np.uint8), fapp, mapp, force, moment, np.zeros(n), np.zeros(n), np.zeros((n, 6)))
    want = int((np.abs(vel) > VMAX).sum() + (~np.isfinite(rot)).sum())
    assert bad == want == 2


ZONE = """block zone generate edgelength 0.5
block zone cmodel assign elastic
block zone property young 1e7 poisson 0.25 density 2000
block gridpoint fix velocity range position-z 0
"""
STRUCT = {"liner": QUAD + "\n" + PROPS + "\n",
          "cable": "structure cable create by-line 0.5 0.5 0.1 0.5 0.5 0.9 segments 4\nstructure cable property "
                   "young 2e11 cross-sectional-area 1e-4 grout-stiffness 1e9 grout-cohesion 1e6 density 7800\n"}


FE = """feblock generate 0.5 0.5 0.5
block zone cmodel assign elastic
block zone property young 1e7 poisson 0.25 density 2000
block gridpoint fix velocity range position-z 0
"""


@pytest.mark.parametrize("kind", list(STRUCT) + ["liner-fe"])
def test_structural_nodes_made_before_zoning_follow_the_zones(session, tmp_path, kind):
    """A liner or cable made in a rigid block that is zoned (or made an FE block) afterwards is coupled to
    the zones (was: to the block's rigid motion, which a zoned block has not: the liner stayed where it was
    while the zones under it settled); the run gives the bits of the same deck with the structure made after
    the zoning."""
    head = "model new\nmodel gravity 0 0 -10\nblock create brick 0 1 0 1 0 1\nblock property density 2000\n"
    store = "cable_nodes" if kind == "cable" else "liner_nodes"
    code, zone = (3, FE) if kind == "liner-fe" else (1, ZONE)        # (an FE block: a brick of FE elements)
    head = head.replace("model new\n", "model new\nmodel configure feblock\n") if kind == "liner-fe" else head
    struct = STRUCT[kind.split("-")[0]]
    out = []
    for text in (head + zone + struct, head + struct + zone):
        from dec3d.session import Session
        import io
        s = Session(out_dir=tmp_path, stdout=io.StringIO())
        s.run_items(s.load_text(text + "model cycle 100\n"))
        nodes = s.model.stores[store]
        assert (nodes["hz"] == code).all()
        out.append({k: nodes[k].copy() for k in ("hz", "hzone", "hgp", "hw", "disp", "hforce")}
                   | {"gp": s.model.vertices["disp"].copy()})
    assert np.abs(out[0]["disp"][:, 2]).max() > 1e-4        # (the zones settle under gravity, and the structure)
    for k in out[0]:
        assert np.array_equal(out[0][k], out[1][k]), k


@pytest.mark.parametrize("kind, first, then", [
    ("liner", "structure liner create by-quadrilateral 0 0 1 1 0 1 1 1 1 0 1 1 id 9223372036854775807",
     "structure liner create by-quadrilateral 0 0 1 1 0 1 1 1 1 0 1 1"),
    ("cable", "structure cable create by-line 0.5 0.5 0.1 0.5 0.5 0.9 id 9223372036854775807",
     "structure cable create by-line 0.2 0.2 0.1 0.2 0.2 0.9"),
])
def test_the_id_after_the_largest_64_bit_one_is_refused(session, tmp_path, kind, first, then):
    # was: the next liner took id -9223372036854775808 (the int64 sum wrapped round), silently
    with pytest.raises(CommandError) as e:
        session.call(_deck(tmp_path, RIGID + first + "\n" + then + "\n"))
    assert e.value.message == f"{kind} ids are used up to 9223372036854775807: give the new {kind}'s `id`"
    assert e.value.location.line == 6
    store = session.model.stores["liner_elements" if kind == "liner" else "cable_segments"]
    assert (store[kind] == 2 ** 63 - 1).all()


def test_dowels_made_before_zoning_follow_the_zones(tmp_path):
    """A hybrid bolt's dowel across a joint of two rigid blocks that are zoned afterwards takes the zones
    holding its two sides (was: it went on pushing the blocks' rigid motion, which zoned blocks have not)
    and the run gives the numbers of the same deck with the bolt made after the zoning (the point each
    side is sought at differs by a micrometre: within 1e-6)."""
    import io

    from dec3d.session import Session

    head = ("model new\nmodel gravity 0 0 -10\nblock create brick 0 1 0 1 0 0.5\nblock create brick 0 1 0 1 0.5 1\n"
            "block contact jmodel assign mohr\n"
            "block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 friction 10\n")
    zone = ("block zone generate edgelength 0.25\nblock zone cmodel assign elastic\n"
            "block zone property young 1e8 poisson 0.25 density 2000\nblock gridpoint fix velocity range position-z 0\n"
            "block gridpoint apply velocity-x 1e-3 range position-z 1\n")
    bolt = ("structure hybrid create by-line 0.5 0.5 0.9 0.5 0.5 0.1 segments 4\n"
            "structure hybrid property young 2e11 cross-sectional-area 5e-4 grout-stiffness 1e9 grout-cohesion 1e9\n"
            "structure hybrid property dowel-stiffness 1e7 dowel-yield 1e9\n")
    out = []
    for text in (head + zone + bolt, head + bolt + zone):
        s = Session(out_dir=tmp_path, stdout=io.StringIO())
        s.run_items(s.load_text(text + "model cycle 200\n"))
        d = s.model.stores["cable_dowels"]
        assert d.n == 1 and (d["hz"][0] == 1).all()         # both sides on 4-node zones
        out.append((d["fs"][0].copy(), s.model.vertices["disp"].copy()))
    assert np.linalg.norm(out[0][0]) > 1.0                   # the joint slides: the dowel carries shear
    np.testing.assert_allclose(out[1][0], out[0][0], rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(out[1][1], out[0][1], rtol=0, atol=1e-6 * np.abs(out[0][1]).max())
