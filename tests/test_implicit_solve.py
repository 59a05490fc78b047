"""`model solve … implicit` (``physics.implicit``): the static answer of linear elastic FE blocks
by one sparse direct solve. The element stiffness it assembles from the engine's element pass
against a textbook 20-node brick (a slow twin written from the formulas); the answer against the
explicit cycle's on the same decks and against CalculiX; the models it refuses."""
import io
import itertools

import numpy as np
import pytest

from dec3d.physics.implicit_stiffness import element_stiffness
from dec3d.session import Session


# ------------------------------------------------------------------ the twin: a textbook 20-node brick
def _serendipity(xi, node):
    """N_a(ξ) of the 20-node serendipity brick (Hughes 1987, §3.5) for a node at natural
    coordinates ``node`` (corners ±1, mid-edge nodes one coordinate 0)."""
    x, y, z = xi
    a, b, c = node
    if a == 0:
        return 0.25 * (1 - x * x) * (1 + y * b) * (1 + z * c)
    if b == 0:
        return 0.25 * (1 - y * y) * (1 + x * a) * (1 + z * c)
    if c == 0:
        return 0.25 * (1 - z * z) * (1 + x * a) * (1 + y * b)
    return 0.125 * (1 + x * a) * (1 + y * b) * (1 + z * c) * (x * a + y * b + z * c - 2)


def _dn(xi, nodes):
    """dN_a/dξ_j (20, 3): central differences, exact up to rounding (each N_a is at most quadratic
    in any one coordinate)."""
    h = 1e-3
    out = np.zeros((20, 3))
    for j in range(3):
        e = np.zeros(3)
        e[j] = h
        for a, nd in enumerate(nodes):
            out[a, j] = (_serendipity(xi + e, nd) - _serendipity(xi - e, nd)) / (2 * h)
    return out


def _textbook_stiffness(x, nodes, bulk, shear):
    """K = Σ_g w_g det J_g Bᵀ D B, 3×3×3 Gauss rule, isotropic D from bulk and shear moduli, engineering
    shear strains; dof 3a + i."""
    lam = bulk - 2.0 * shear / 3.0
    D = np.zeros((6, 6))
    D[:3, :3] = lam
    D[range(3), range(3)] += 2 * shear
    D[range(3, 6), range(3, 6)] = shear
    pts = [(-np.sqrt(0.6), 5 / 9), (0.0, 8 / 9), (np.sqrt(0.6), 5 / 9)]
    K = np.zeros((60, 60))
    for (p, wp), (q, wq), (r, wr) in itertools.product(pts, pts, pts):
        dn = _dn(np.array([p, q, r]), nodes)
        J = x.T @ dn                          # J[i, j] = dx_i/dξ_j
        dx = dn @ np.linalg.inv(J)            # dN_a/dx_i
        B = np.zeros((6, 60))
        for a in range(20):
            gx, gy, gz = dx[a]
            B[0, 3 * a], B[1, 3 * a + 1], B[2, 3 * a + 2] = gx, gy, gz
            B[3, 3 * a], B[3, 3 * a + 1] = gy, gx          # γxy
            B[4, 3 * a], B[4, 3 * a + 2] = gz, gx          # γxz
            B[5, 3 * a + 1], B[5, 3 * a + 2] = gz, gy      # γyz
        K += wp * wq * wr * np.linalg.det(J) * B.T @ D @ B
    return K


def _one_element(tmp_path, nq):
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command(f"model configure feblock\nblock create brick 0 2 0 1 0 1\nfeblock generate 2 1 1 integration {nq}")
    m = s.model
    es = m.store("feblocks")
    assert es.n == 1
    return m, np.ascontiguousarray(es["nodes"][:1])


def test_element_stiffness_is_the_textbook_20_node_brick(tmp_path):
    """3×3×3 integration: the stiffness probed from the engine's element pass equals Σ w det J Bᵀ D B
    of the textbook serendipity brick on a distorted element within 1e-9 (relative to its largest
    entry); symmetric; the six rigid motions give no force."""
    m, nodes = _one_element(tmp_path, 3)
    pos0 = m.vertices["pos"][nodes[0]]
    # natural coordinates of each node from the undistorted 2 x 1 x 1 box
    nat = np.rint((pos0 - [1.0, 0.5, 0.5]) / [1.0, 0.5, 0.5]).astype(int)
    assert {tuple(n) for n in nat} == {n for n in itertools.product((-1, 0, 1), repeat=3)
                                       if sum(abs(c) for c in n) >= 2}
    rng = np.random.default_rng(3)
    A = np.array([[1.1, 0.2, -0.1], [0.05, 0.9, 0.15], [-0.1, 0.1, 1.2]])
    pos = m.vertices["pos"].copy()
    pos[nodes[0]] = pos0 @ A.T + 0.04 * rng.standard_normal((20, 3))
    bulk, shear = np.array([5e6]), np.array([3e6])
    ke, ok = element_stiffness(np.ascontiguousarray(pos), nodes, np.array([0]), bulk, shear, np.int64(3), 0.0)
    assert ok.all()
    twin = _textbook_stiffness(pos[nodes[0]], [tuple(n) for n in nat], 5e6, 3e6)
    scale = np.abs(twin).max()
    assert np.abs(ke[0] - twin).max() < 1e-9 * scale
    assert np.abs(ke[0] - ke[0].T).max() < 1e-9 * scale
    x = pos[nodes[0]]
    for mode in [np.tile(np.eye(3)[i], 20) for i in range(3)] + [np.cross(np.eye(3)[i], x).ravel() for i in range(3)]:
        assert np.abs(ke[0] @ mode).max() < 1e-9 * scale * np.abs(mode).max()


def test_element_stiffness_with_hourglass_control_is_symmetric_and_stable(tmp_path):
    """2×2×2 integration with the hourglass control (the default): symmetric, no force for the six rigid
    motions, and no other zero-energy mode (54 positive eigenvalues)."""
    m, nodes = _one_element(tmp_path, 2)
    es = m.store("feblocks")
    hg = float(es["hourglass"][0])
    assert hg > 0.0
    ke, ok = element_stiffness(np.ascontiguousarray(m.vertices["pos"]), nodes, np.array([0]), np.array([5e6]),
                               np.array([3e6]), np.int64(2), hg)
    k = ke[0]
    scale = np.abs(k).max()
    assert ok.all() and np.abs(k - k.T).max() < 1e-9 * scale
    ev = np.linalg.eigvalsh(0.5 * (k + k.T))
    assert np.abs(ev[:6]).max() < 1e-9 * scale and ev[6] > 1e-6 * scale


# ------------------------------------------------------------------ the answer against the explicit cycle
FEM_BEAM = """model new
model config feblock
block create brick 0 10 0 1 0 1
feblock generate 1 1 1 integration {nq}
block zone cmodel assign el
block zone prop dens 2000 young 1e6 poiss 0.2
block gridpoint apply vel 0 0 0 range pos-x 0
block gridpoint apply force-z [-100.0/3.0] range pos-x 10 pos-z 1
model large-strain off
model solve ratio 1e-6 {how}
"""


def _tip(m):
    v = m.vertices
    tip = np.flatnonzero(np.all(abs(v["pos"] - [10, 1, 1]) < 1e-9, axis=1))
    return -float(v["disp"][tip[0], 2])


def test_fem_beam_implicit_gives_the_calculix_deflection(tmp_path):
    """The seed's fem_beam.dat (ten 3×3×3 elements) with `implicit`: tip deflection 0.3996 m (CalculiX
    2.20 C3D20 on the same mesh) within 0.2 %, converged after one batch of steps, and the model at
    rest (velocities zero)."""
    out = io.StringIO()
    s = Session(out_dir=tmp_path, stdout=out)
    s.command(FEM_BEAM.format(nq=3, how="implicit"))
    text = out.getvalue()
    assert "model solve implicit: 360 unknowns solved directly" in text
    assert "model solve: converged" in text and s.model.step <= 10
    u = _tip(s.model)
    assert abs(u - 0.3996) < 0.002 * 0.3996
    v = s.model.vertices
    assert np.abs(v["velocity"]).max() < 1e-9
    # the state is the explicit scheme's equilibrium: 500 more explicit steps leave it where it is
    s.command("model cycle 500")
    assert abs(_tip(s.model) - u) < 1e-9 * u


def test_implicit_equals_explicit_on_the_hourglass_controlled_beam(tmp_path):
    """The same beam with 2×2×2 elements and hourglass control: the implicit tip deflection and element
    stresses are the explicit solve's (ratio 1e-9) within 1e-5 (relative to the largest)."""
    runs = []
    for how in ("implicit", ""):
        s = Session(out_dir=tmp_path, stdout=io.StringIO())
        s.command(FEM_BEAM.format(nq=2, how=how).replace("ratio 1e-6", "ratio 1e-9"))
        runs.append((_tip(s.model), s.model.store("feblocks")["gstress"][:, :14].copy(), s.model.step))
    (ui, si, ni), (ue, se, ne) = runs
    assert ni <= 10 < ne
    assert abs(ui - ue) < 1e-5 * ue
    assert np.abs(si - se).max() < 1e-5 * np.abs(se).max()


JOINED = """model configure feblock
block create brick 0 1 0 1 0 1
block create brick 0 1 0 1 1 2
block join
feblock generate 0.5 0.5 0.5
feblock change cmodel elastic young 1e7 poisson 0.25 density 2000
model gravity 0 0 -10
block gridpoint apply velocity 0 0 0 range position-z 0
block gridpoint apply velocity-x 0 range position-x 0
block gridpoint apply velocity-y 0 range position-y 0
block face apply stress 0 0 -1e5 2e4 0 0 range position-z 2
model large-strain off
model solve ratio 1e-9 {how}"""


def test_implicit_equals_explicit_on_joined_blocks_with_gravity_and_face_stress(tmp_path):
    """Two joined FE blocks (linked nodes), consistent gravity, a face stress on the top (carried by slave
    nodes to the masters, Eq. 9), rollers: every node displacement and element stress of the implicit
    solve is the explicit solve's (ratio 1e-9) within 1e-5 of the largest."""
    runs = []
    for how in ("implicit", ""):
        s = Session(out_dir=tmp_path, stdout=io.StringIO())
        s.command(JOINED.format(how=how))
        v, es = s.model.vertices, s.model.store("feblocks")
        runs.append((v["disp"].copy(), es["gstress"].copy()))
    (ui, si), (ue, se) = runs
    assert np.abs(ue).max() > 1e-3
    assert np.abs(ui - ue).max() < 1e-5 * np.abs(ue).max()
    assert np.abs(si - se).max() < 1e-5 * np.abs(se).max()


# ------------------------------------------------------------------ what it refuses
@pytest.mark.parametrize("setup, why", [
    ("block create brick 0 1 0 1 0 1\nblock zone generate edgelength 0.5\nblock zone cmodel assign mohr-coulomb\n"
     "block zone property density 2000 young 1e7 poisson 0.25 cohesion 1e5 friction 30",
     "zones have a constitutive model other than elastic"),
    ("model configure feblock\nblock create brick 0 1 0 1 0 1\nfeblock generate 0.5 0.5 0.5\n"
     "feblock change cmodel elastic young 1e7 poisson 0.25 density 2000\nmodel large-strain on",
     "large strain is on"),
    ("model configure feblock\nblock create brick 0 1 0 1 0 1\nfeblock generate 0.5 0.5 0.5\n"
     "feblock change cmodel elastic young 1e7 poisson 0.25 density 2000\nblock create brick 0 1 0 1 1 2",
     "the model has rigid blocks"),
])
def test_models_it_cannot_take_are_solved_by_cycling(tmp_path, setup, why):
    """Plastic zones, large strain, rigid blocks: a line says why, and the solve cycles as before."""
    out = io.StringIO()
    s = Session(out_dir=tmp_path, stdout=out)
    s.command(setup + "\nmodel gravity 0 0 -10\nblock gridpoint apply velocity 0 0 0 range position-z 0\n"
                      "block property density 2000\nmodel solve cycles 20 implicit")
    text = out.getvalue()
    assert f"model solve implicit: {why}" in text and "solving by cycling alone" in text
    assert s.model.step == 20


def test_a_block_free_to_move_is_refused_and_left_unchanged(tmp_path):
    """An FE block held nowhere under gravity has no static answer: the solve says so and cycles, the
    model as it was before the command when the cycling starts."""
    out = io.StringIO()
    s = Session(out_dir=tmp_path, stdout=out)
    s.command("model configure feblock\nblock create brick 0 1 0 1 0 1\nfeblock generate 0.5 0.5 0.5\n"
              "feblock change cmodel elastic young 1e7 poisson 0.25 density 2000\nmodel gravity 0 0 -10\n"
              "model solve cycles 1 implicit")
    text = out.getvalue()
    assert "model solve implicit: " in text and "rigid motion" in text and "solving by cycling alone" in text
    v = s.model.vertices
    # one explicit step from rest: the displacement is that of one step of gravity, nothing more
    assert np.abs(v["disp"]).max() < 1e-3


# ------------------------------------------------------------------ zoned blocks: conjugate gradients
ZONED = """model new
{configure}
block create brick 0 1 0 1 0 1
block create brick 0 1 0 1 1 2
block join
{generate}
block zone cmodel assign elastic
block zone property young 1e7 poisson 0.3 density 2000
model gravity 0 0 -10
block gridpoint apply velocity 0 0 0 range position-z 0
block gridpoint apply velocity-x 0 range position-x 0
block gridpoint apply velocity-y 0 range position-y 0
block face apply stress 0 0 -1e5 2e4 0 0 range position-z 2
model large-strain off
model solve ratio 1e-9 {how}"""


@pytest.mark.parametrize("configure, generate", [
    ("", "block zone generate edgelength 0.5"),                                   # 4-node, nodal mixed discretization
    ("", "block zone generate hexahedra divisions 2 2 2"),                        # mixed discretization in hexahedra
    ("model configure highorder", "block zone generate edgelength 0.5\nblock zone generate high-order-tetra"),
])
def test_implicit_equals_explicit_on_joined_zoned_blocks(tmp_path, configure, generate):
    """Two joined zoned blocks (linked gridpoints) under gravity, a face stress and rollers, 4-node zones
    (NMD or hexahedral sets: the conjugate gradients of the zone step's own operator) and 10-node zones
    (direct): every gridpoint displacement and zone stress of the implicit solve is the explicit solve's
    (ratio 1e-9) within 1e-5 of the largest, and the implicit solve took one batch of steps."""
    runs = []
    for how in ("implicit", ""):
        out = io.StringIO()
        s = Session(out_dir=tmp_path, stdout=out)
        s.command(ZONED.format(configure=configure, generate=generate, how=how))
        zs, v = s.model.store("zones"), s.model.vertices
        runs.append((v["disp"].copy(), zs["stress"][: zs.n].copy(), s.model.step, out.getvalue()))
    (ui, si, ni, ti), (ue, se, ne, _) = runs
    assert "model solve implicit: " in ti and ni <= 10 < ne
    assert ("conjugate gradients" in ti) == ("high-order" not in generate)
    assert np.abs(ue).max() > 1e-3
    assert np.abs(ui - ue).max() < 1e-5 * np.abs(ue).max()
    assert np.abs(si - se).max() < 1e-5 * np.abs(se).max()


def test_a_held_gridpoint_moving_is_refused(tmp_path):
    """A gridpoint held at a non-zero velocity (a loading platen) has no static answer: refused with the
    reason, and the explicit cycle moves it as before."""
    out = io.StringIO()
    s = Session(out_dir=tmp_path, stdout=out)
    s.command("model configure feblock\nblock create brick 0 1 0 1 0 1\nfeblock generate 0.5 0.5 0.5\n"
              "feblock change cmodel elastic young 1e7 poisson 0.25 density 2000\n"
              "block gridpoint apply velocity 0 0 0 range position-z 0\n"
              "block gridpoint apply velocity-z -1e-6 range position-z 1\nmodel solve cycles 10 implicit")
    assert "model solve implicit: a held gridpoint moves at a non-zero velocity" in out.getvalue()
    v = s.model.vertices
    top = np.flatnonzero(np.abs(v["pos"][: v.n, 2] - 1) < 1e-9)
    assert np.allclose(v["disp"][top, 2], -1e-5)        # ten steps of Δt = 1 s at 1e-6 m/s


def test_fe1_verification_deck_with_implicit_meets_its_calculix_values(tmp_path):
    """verification/FE1_cantilever as written but for `implicit` on its solve (FE beams of 10, 5 and 2
    3×3×3 elements, one of ten 2×2×2 elements with hourglass control and a zoned hexahedral beam, in one
    model): tips at CalculiX C3D20's 0.3996, 0.3963 and 0.3745 m within 0.2 %, the 2×2×2 beam at
    WL³/(3EI) = 0.400 m within 1 %, the zoned beam stiffer than half of it, after one batch of steps."""
    from conftest import ROOT

    deck = (ROOT / "verification" / "FE1_cantilever" / "deck.dat").read_text()
    assert deck.count("model solve ratio 1e-6\n") == 1
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command(deck.replace("model solve ratio 1e-6\n", "model solve ratio 1e-6 implicit\n"))
    v = s.model.vertices
    assert s.model.step == 10 + 10 + 20          # the solve's one batch, then the deck's drift cycles

    def tip(y):
        r = np.argmin(np.linalg.norm(v["pos"][: v.n] - [10.0, y, 1.0], axis=1))
        return -float(v["disp"][r, 2])
    for y, ref in ((1, 0.3996), (4, 0.3963), (7, 0.3745)):
        assert abs(tip(y) - ref) < 0.002 * ref, (y, tip(y))
    assert abs(tip(10) - 0.4) < 0.01 * 0.4
    assert tip(13) < 0.2


def test_fe_blocks_in_contact_are_refused(tmp_path):
    """Two FE blocks stacked without `block join`: the contact between them carries force, which the
    implicit solve does not model; refused with the reason, and the solve cycles."""
    out = io.StringIO()
    s = Session(out_dir=tmp_path, stdout=out)
    s.command(JOINED.replace("block join\n", "block contact jmodel assign elastic\n"
                             "block contact material-table default property stiffness-normal 1e8 "
                             "stiffness-shear 1e8\n").format(how="implicit").replace("ratio 1e-9", "cycles 5"))
    assert "model solve implicit: contacts act on deformable blocks: solving by cycling alone" in out.getvalue()
    assert s.model.step == 5


def test_constant_strain_tetrahedron_stores_the_strain_energy_of_a_linear_field():
    """``tet4_stiffness`` (the preconditioner of the zoned solve): for u = A x on a skewed tetrahedron,
    uᵀ K u = V (λ (tr ε)² + 2 G ε:ε) with ε = sym(A), V from the corner coordinates; rigid motions give
    no force; the weight scales it."""
    from dec3d.physics.implicit_stiffness import tet4_stiffness

    x = np.array([[0.1, 0.0, 0.2], [1.3, 0.2, 0.0], [0.3, 0.9, 0.1], [0.2, 0.4, 1.1]])
    A = np.array([[1e-3, 2e-4, -5e-4], [3e-4, -2e-3, 1e-4], [0.0, 6e-4, 1.5e-3]])
    bulk, shear = 5e9, 3e9
    lam = bulk - 2 * shear / 3
    k = tet4_stiffness(x[None], np.array([bulk]), np.array([shear]), np.array([0.5]))[0]
    u = (x @ A.T).ravel()
    eps = 0.5 * (A + A.T)
    vol = abs(np.linalg.det(x[1:] - x[0])) / 6
    energy = vol * (lam * np.trace(eps) ** 2 + 2 * shear * np.sum(eps * eps))
    assert abs(u @ k @ u - 0.5 * energy) < 1e-12 * energy
    for mode in [np.tile(np.eye(3)[i], 4) for i in range(3)] + [np.cross(np.eye(3)[i], x).ravel() for i in range(3)]:
        assert np.abs(k @ mode).max() < 1e-9 * np.abs(k).max()


def test_a_second_implicit_solve_after_a_load_change_is_incremental(tmp_path):
    """Staged: the beam solved under 100 N, the tip load then doubled and solved again from the stressed
    state (the first solve's stresses in F(0)): the tip deflection and element stresses double (linear
    elasticity) within 1e-8."""
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command(FEM_BEAM.format(nq=3, how="implicit"))
    u1, s1 = _tip(s.model), s.model.store("feblocks")["gstress"].copy()
    s.command("block gridpoint apply force-z [-200.0/3.0] range pos-x 10 pos-z 1\nmodel solve ratio 1e-6 implicit")
    u2, s2 = _tip(s.model), s.model.store("feblocks")["gstress"]
    assert abs(u2 - 2 * u1) < 1e-8 * u1
    assert np.abs(s2 - 2 * s1).max() < 1e-8 * np.abs(s1).max()
