"""Pore pressure in the joints (dec3d.physics.water, dec3d.kernels.water, `block water`, `block contact apply
pore-pressure`): kernels against twins written from the formulas, effective stress in the cycle, save/restore,
bad input."""
import math

import numpy as np
import pytest

from dec3d.errors import Dec3dError
from dec3d.kernels import water as kw
from dec3d.physics.rigid import engine
from dec3d.physics.water import table_pressure

STACK = """model new
block create brick 0 1 0 1 -1 0
block create brick 0 1 0 1 0 1
block property density 2000
model gravity 0 0 -10
block fix range position-z -1 0
block contact jmodel assign mohr
block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 friction 30
"""


def _run(session, text):
    session.run_items(session.load_text(text))
    return engine(session.model)


# ---------------------------------------------------------------- twins of the kernels

def _polygon_integral_twin(poly, a, b, c):
    """∫ (a + b u + c v) dA over the convex polygon `poly` (k, 2), from its area and centroid (shoelace)."""
    u, v = poly[:, 0], poly[:, 1]
    u1, v1 = np.roll(u, -1), np.roll(v, -1)
    cross = u * v1 - u1 * v
    area = cross.sum() / 2
    cu = ((u + u1) * cross).sum() / (6 * area)
    cv = ((v + v1) * cross).sum() / (6 * area)
    return area * (a + b * cu + c * cv), area


def _frame(n):
    n = np.asarray(n, float) / np.linalg.norm(n)
    t = np.cross(n, [0.3, 0.5, 0.8])
    t /= np.linalg.norm(t)
    return n, t, np.cross(n, t)


@pytest.mark.parametrize("seed", range(6))
def test_pressure_areas_integrate_a_linear_pressure_exactly(seed):
    """Random convex polygons on tilted planes, every corner given twice (as a contact's two faces give
    them) and an inner point: Σ p_i A′_i equals the exact integral of a linear p (the polygon's area
    times p at its centroid), and Σ A′ equals Σ area."""
    rng = np.random.default_rng(seed)
    k = int(rng.integers(3, 9))
    ang = np.sort(rng.uniform(0, 2 * np.pi, k))
    poly = np.c_[np.cos(ang) * rng.uniform(1, 3), np.sin(ang) * rng.uniform(1, 3)] + rng.uniform(-5, 5, 2)
    n, t1, t2 = _frame(rng.normal(size=3))
    o = rng.uniform(-10, 10, 3)
    pts2 = np.vstack([poly, poly[::-1], poly.mean(0)[None]])
    pts = o + pts2[:, :1] * t1 + pts2[:, 1:] * t2
    ns = len(pts)
    area = rng.uniform(0.1, 1.0, ns)               # stiffness lumps: any positive numbers
    area *= _polygon_integral_twin(poly, 1, 0, 0)[1] / area.sum()
    out = np.empty(ns)
    kw.pressure_areas(np.array([0]), np.array([ns]), n[None], pts, area, out)
    a, b, c = rng.normal(size=3)
    p = a + b * pts2[:, 0] + c * pts2[:, 1]
    exact, _ = _polygon_integral_twin(poly, a, b, c)
    assert (p * out).sum() == pytest.approx(exact, rel=1e-10, abs=1e-9)
    assert out.sum() == pytest.approx(area.sum(), rel=1e-12)
    assert out[-1] == 0.0                          # inside the hull: no weight
    assert np.allclose(out[:k], out[k:2 * k][::-1])  # a point given twice shares its weight


def test_pressure_areas_of_a_rectangle_are_equal_shares():
    """A parallelogram's four corners get a quarter each (the moment of a uniform pressure is right);
    a contact with fewer than three points keeps its areas."""
    pts = np.array([[0, 0, 0], [4, 0, 0], [4, 2, 0], [0, 2, 0], [9, 9, 9], [9, 9, 9.5]], float)
    area = np.array([4.0, 2, 4, 2, 0.3, 0.2])
    out = np.empty(6)
    kw.pressure_areas(np.array([0, 4]), np.array([4, 2]), np.array([[0, 0, 1.0], [1.0, 0, 0]]), pts, area, out)
    assert out[:4].tolist() == pytest.approx([3, 3, 3, 3], rel=1e-12)
    assert out[4:].tolist() == [0.3, 0.2]


def _pore_force_twin(ca, cb, cn, sc_contact, sc_pos, ppf, bpos, nb):
    """Force and moment on each block from F n on B and −F n on A at each sub-contact point."""
    f = np.zeros((nb, 3))
    m = np.zeros((nb, 3))
    for s, c in enumerate(sc_contact):
        g = ppf[s] * cn[c]
        for blk, sign in ((cb[c], 1.0), (ca[c], -1.0)):
            f[blk] += sign * g
            m[blk] += np.cross(sc_pos[s] - bpos[blk], sign * g)
    return f, m


def test_pore_forces_against_twin():
    rng = np.random.default_rng(3)
    nb, nc, ns = 4, 3, 9
    ca, cb = np.array([0, 1, 0]), np.array([1, 2, 3])
    cn = rng.normal(size=(nc, 3))
    cn /= np.linalg.norm(cn, axis=1)[:, None]
    sc_contact = np.array([0, 0, 0, 1, 1, 1, 2, 2, 2])
    sc_pos = rng.normal(size=(ns, 3))
    ppf = rng.uniform(-1e4, 1e5, ns)
    ppf[4] = 0.0
    bpos = rng.normal(size=(nb, 3))
    want_f, want_m = _pore_force_twin(ca, cb, cn, sc_contact, sc_pos, ppf, bpos, nb)
    # rigid cycle: added to each sub-contact's force on B, summed like the joint forces
    sg = np.zeros((ns, 3))
    kw.pore_forces(cn, sc_contact, ppf, sg)
    f = np.zeros((nb, 3))
    m = np.zeros((nb, 3))
    for s, c in enumerate(sc_contact):
        for blk, sign in ((cb[c], 1.0), (ca[c], -1.0)):
            f[blk] += sign * sg[s]
            m[blk] += np.cross(sc_pos[s] - bpos[blk], sign * sg[s])
    assert np.allclose(f, want_f) and np.allclose(m, want_m)
    # mixed path, every side rigid (node −1)
    none = -np.ones((ns, 3), np.int64)
    w = np.zeros((ns, 3))
    bf = np.zeros((nb, 3))
    bm = np.zeros((nb, 3))
    kw.mixed_pore_forces(bpos, bf, bm, np.zeros((1, 3)), ca, cb, cn, sc_contact, sc_pos, ppf, none, w, none, w)
    assert np.allclose(bf, want_f) and np.allclose(bm, want_m)
    # a zoned B side: its share goes to the gridpoints by the weights
    nodes_b = np.tile(np.array([0, 1, 2]), (ns, 1))
    w_b = np.tile(np.array([0.2, 0.3, 0.5]), (ns, 1))
    gf = np.zeros((3, 3))
    bf[:] = 0.0
    kw.mixed_pore_forces(bpos, bf, np.zeros((nb, 3)), gf, ca, cb, cn, sc_contact, sc_pos, ppf, none, w, nodes_b, w_b)
    on_b = (ppf[:, None] * cn[sc_contact]).sum(0)
    assert np.allclose(gf.sum(0), on_b) and np.allclose(gf[2], 0.5 * on_b)


def test_table_pressure_follows_gravity():
    """p = ρw |g| h, h the distance up to the table along −g; 0 above it; the table's tilt counts."""
    g = (0.0, 0.0, -9.81)
    pos = np.array([[0, 0, -2.0], [5, 0, 3.0], [0, 0, 1.5]])
    p = table_pressure(pos, 1000.0, [0, 0, 1, 0, 0, 1], g)
    assert p.tolist() == pytest.approx([1000 * 9.81 * 3, 0, 0])
    # a table dipping 45° (normal (1, 0, 1)) through the origin: at x = 2, z = −1 the table is at z = −2
    p = table_pressure(np.array([[2, 0, -3.0]]), 1000.0, [1, 0, 1, 0, 0, 0], g)
    assert p[0] == pytest.approx(1000 * 9.81 * 1.0)
    # tilted gravity: the depth is measured along it
    gt = (9.81 * math.sin(0.3), 0.0, -9.81 * math.cos(0.3))
    p = table_pressure(np.array([[0, 0, -1.0]]), 1000.0, [0, 0, 1, 0, 0, 0], gt)
    assert p[0] == pytest.approx(1000 * 9.81 / math.cos(0.3))


# ---------------------------------------------------------------- the cycle

def test_effective_normal_force_and_total_balance(session):
    """A cube on a fixed base with p = 5 kPa on the joint: the joint law keeps (σn − p) A, the unbalanced
    force counts the water (the solve converges), and p = σn makes the normal force zero."""
    e = _run(session, STACK + "block contact apply pore-pressure 5000\nmodel solve ratio 1e-8\n")
    ss = e.subcontacts
    assert ss["fn"].sum() == pytest.approx(20000 - 5000, rel=1e-6)
    assert ss["ppf"].sum() == pytest.approx(5000, rel=1e-12)
    assert np.all(ss["pp"] == 5000)
    e = _run(session, "block contact apply pore-pressure 15000\nmodel cycle 400\n")
    assert abs(e.subcontacts["fn"].sum()) < 1e-3 * 20000


def test_water_table_pressure_and_gravity_given_later(session):
    """`block water` before `model gravity`: the pressures come when gravity is known (before the next
    cycle); `block water clear` takes them away."""
    text = STACK.replace("model gravity 0 0 -10\n", "") + "block water density 1000\nblock water plane normal 0 0 1 origin 0 0 2\n"
    e = _run(session, text)
    assert np.all(e.subcontacts["pp"] == 0.0)           # no gravity yet
    e = _run(session, "model gravity 0 0 -10\nmodel cycle 1\n")
    assert e.subcontacts["pp"] == pytest.approx(np.full(e.subcontacts.n, 1000 * 10 * 2.0))
    e = _run(session, "model solve ratio 1e-8\n")
    assert e.subcontacts["fn"].sum() == pytest.approx(20000 - 20000, abs=1e-3)  # W = 20 kN, U = 20 kN: floating
    e = _run(session, "block water clear\nmodel cycle 1\n")
    assert np.all(e.subcontacts["pp"] == 0.0) and np.all(e.subcontacts["ppf"] == 0.0)


def test_fish_reads_the_pressures(session):
    _run(session, STACK + "block contact apply pore-pressure 3000\nmodel cycle 10\n"
                          "[c = block.contact.find(1, 2)]\n[pc = block.contact.pp(c)]\n"
                          "[sl = block.contact.subcontactlist(c)]\n[ps = block.subcontact.pp(sl(1))]\n")
    assert session.variables["pc"] == pytest.approx(3000)
    assert session.variables["ps"] == pytest.approx(3000)


def test_save_restore_keeps_the_pressures_and_continues_bit_identically(session, tmp_path):
    deck = STACK + "block contact apply pore-pressure 19000\nblock mechanical damping none\n"
    _run(session, deck + "model cycle 300\n")
    whole = session.model.blocks["centroid"].copy()
    _run(session, deck + f"model cycle 150\nmodel save '{tmp_path / 'half.d3s'}'\n")
    _run(session, f"model new\nmodel restore '{tmp_path / 'half.d3s'}'\n")
    assert np.all(engine(session.model).subcontacts["pp"] == 19000)
    _run(session, "model cycle 150\n")
    assert np.array_equal(session.model.blocks["centroid"], whole)


# ---------------------------------------------------------------- bad input

@pytest.mark.parametrize("line, message", [
    ("block water\n", "needs one of density, plane, clear, list"),
    ("block water plane normal 0 0 1\n", "needs `normal nx ny nz` and `origin x y z`"),
    ("block water normal 0 0 1 origin 0 0 0\n", "belongs to `block water plane`"),
    ("block water plane normal 0 0 0 origin 0 0 0\n", "normal is the zero vector"),
    ("block water density -1\n", "density"),
    ("block contact apply\n", "needs `pore-pressure <p>`"),
    ("block contact apply pore-pressure 1e5 range position-z 5 6\n", "no contact in range"),
])
def test_bad_input_is_refused_with_its_place(session, line, message):
    with pytest.raises(Dec3dError) as err:
        _run(session, STACK + line)
    assert message in str(err.value)
    text = err.value.format()
    assert ":9:" in text                        # the line of the command in the deck
    assert engine(session.model).subcontacts["pp"].sum() == 0.0


def test_no_contacts_refused(session):
    with pytest.raises(Dec3dError, match="no contacts"):
        _run(session, "model new\nblock create brick 0 1 0 1 0 1\nblock contact apply pore-pressure 1\n")
