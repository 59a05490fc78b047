"""`block dynamic eigen modes`: natural modes of rigid blocks against closed forms and against an
independent dense assembly of the same springs and masses.

Closed forms (a block of mass m, square base a × a, height h, on a fixed base; kn, ks per unit area,
A = a²): vertical f = √(kn A / m) / 2π; torsion about z f = √(ks Σ aᵢ rᵢ² / I_z) / 2π with
Σ aᵢ rᵢ² = A a²/2 (every corner at r² = a²/2, the shares summing to A) and I_z = m a²/6; rocking about a horizontal axis d
through the centroid coupled with sliding across it, the 2-dof system
    K = [[ks A, ks A h/2], [ks A h/2, ks A h²/4 + kn Σ aᵢ (rᵢ·d⊥)²]],  M = diag(m, m (a² + h²)/12).
The sub-contacts sit at the corners with area shares that need not be equal, so the rocking axes are
the principal axes of that distribution (here the diagonals) and Σ aᵢ (rᵢ·d⊥)² is read from the
model's sub-contacts; the other sums do not depend on the shares.
"""
import io
import math

import numpy as np
import pytest
from scipy import linalg

from dec3d.errors import Dec3dError
from dec3d.physics.rigid import engine
from dec3d.session import Session

KN, KS, RHO = 1e8, 4e7, 1000.0


def _session(tmp_path):
    return Session(out_dir=tmp_path, stdout=io.StringIO())


def _base_and_block(s, a=1.0, h=0.5, more=""):
    s.command(f"block create brick {-a / 2} {a / 2} {-a / 2} {a / 2} -1 0\n"
              f"block create brick {-a / 2} {a / 2} {-a / 2} {a / 2} 0 {h}\n" + more +
              f"block property density {RHO}\nblock contact jmodel assign elastic\n"
              f"block contact property stiffness-normal {KN} stiffness-shear {KS}\nblock fix range id 1")


def _near(value, values, rel=1e-9):
    """Whether ``value`` is one of ``values`` within ``rel``."""
    return any(abs(value - v) <= rel * abs(value) for v in values)


def _pair_freqs(k11, k12, k22, m1, m2):
    """The two frequencies [Hz] of K = [[k11, k12], [k12, k22]], M = diag(m1, m2), by the quadratic."""
    b = k11 / m1 + k22 / m2
    c = (k11 * k22 - k12 * k12) / (m1 * m2)
    d = math.sqrt(b * b / 4 - c)
    return [math.sqrt(b / 2 - d) / (2 * math.pi), math.sqrt(b / 2 + d) / (2 * math.pi)]


def test_block_on_its_base_matches_the_closed_forms(tmp_path):
    a, h = 1.0, 0.5
    s = _session(tmp_path)
    _base_and_block(s, a, h)
    s.command("block dynamic eigen modes 6")
    m = RHO * a * a * h
    A = a * a
    ss = engine(s.model).subcontacts
    pos, area = ss["pos"][:, :2], ss["area"]
    assert area.sum() == pytest.approx(A, rel=1e-12)      # the vertices of both faces share the contact area
    # springs as the eigen assembly takes them: every sub-contact with its own area
    expected = [math.sqrt(KN * area.sum() / m) / (2 * math.pi),                           # vertical
                math.sqrt(KS * (area * (pos ** 2).sum(1)).sum() / (m * a * a / 6)) / (2 * math.pi)]   # torsion
    for d in (np.array([1.0, 1.0]) / math.sqrt(2), np.array([1.0, -1.0]) / math.sqrt(2)):
        perp = np.array([-d[1], d[0]])
        assert (area * (pos @ d) * (pos @ perp)).sum() == pytest.approx(0.0, abs=1e-12)   # a principal axis
        kr = KN * (area * (pos @ perp) ** 2).sum()
        ksa = KS * area.sum()
        expected += _pair_freqs(ksa, ksa * h / 2, ksa * h * h / 4 + kr, m, m * (a * a + h * h) / 12)
    got = [s.results[f"eigen.f{i}"] for i in range(1, 7)]
    assert got == pytest.approx(sorted(expected), rel=1e-9)
    # the sums that do not depend on the area shares: vertical √(kn A / m) / 2π, torsion √(3 ks A / m) / 2π
    assert _near(math.sqrt(KN * A / m) / (2 * math.pi), got)
    assert _near(math.sqrt(3 * KS * A / m) / (2 * math.pi), got)


def _dense_reference(model, kn=KN, ks=KS):
    """K and M of the free dofs built here, independently of dec3d.physics.eigen: each unit motion of a
    body moves a sub-contact point by e_i (translations) or e_i × (p − c) (rotations); the spring energy
    ½ Δᵀ k Δ of the relative motion Δ gives K_ij = Σ Δ_iᵀ k Δ_j."""
    e = engine(model)
    b, c, ss = model.blocks, e.contacts, e.subcontacts
    free_rows = [r for r in range(b.n) if b["fixity"][r] == 0]
    index = {r: k for k, r in enumerate(free_rows)}
    n = 6 * len(free_rows)
    K = np.zeros((n, n))
    for si in range(ss.n):
        ci = ss["contact"][si]
        nrm = c["normal"][ci]
        k = ss["area"][si] * (kn * np.outer(nrm, nrm) + ks * (np.eye(3) - np.outer(nrm, nrm)))
        p = ss["pos"][si]
        moves = []            # (dof, relative point motion per unit dof)
        for row, sign in ((c["a"][ci], -1.0), (c["b"][ci], 1.0)):
            if row not in index:
                continue
            for j in range(6):
                unit = np.zeros(3)
                unit[j % 3] = 1.0
                mv = unit if j < 3 else np.cross(unit, p - b["centroid"][row])
                moves.append((6 * index[row] + j, sign * mv))
        for i, di in moves:
            for j, dj in moves:
                K[i, j] += di @ k @ dj
    M = np.zeros((n, n))
    for r, k in index.items():
        M[6 * k:6 * k + 3, 6 * k:6 * k + 3] = b["mass"][r] * np.eye(3)
        M[6 * k + 3:6 * k + 6, 6 * k + 3:6 * k + 6] = b["inertia"][r]
    return K, M


def test_two_block_column_chain_and_dense_reference(tmp_path):
    s = _session(tmp_path)
    _base_and_block(s, 1.0, 0.5, more="block create brick -0.5 0.5 -0.5 0.5 0.5 1\n")
    s.command("block dynamic eigen modes 12")
    got = np.array([s.results[f"eigen.f{i}"] for i in range(1, 13)])
    # vertical chain: equal masses m and springs k = kn × contact area: ω² = (k/m)(3 ∓ √5)/2
    m, k = RHO * 0.5, KN * 1.0
    for w2 in ((3 - math.sqrt(5)) / 2 * k / m, (3 + math.sqrt(5)) / 2 * k / m):
        assert _near(math.sqrt(w2) / (2 * math.pi), list(got))
    K, M = _dense_reference(s.model)
    ref = np.sqrt(linalg.eigh(K, M, eigvals_only=True)) / (2 * math.pi)
    assert got == pytest.approx(ref, rel=1e-9)


def test_mode_shapes_in_vtk(tmp_path):
    import meshio

    s = _session(tmp_path)
    _base_and_block(s)
    s.command("block dynamic eigen modes 6 file 'modes'")
    mesh = meshio.read(tmp_path / "modes.vtu")
    freqs = [s.results[f"eigen.f{i}"] for i in range(1, 7)]
    assert mesh.field_data["frequency"].tolist() == pytest.approx(freqs, rel=1e-12)
    vertical = int(np.argmin([abs(f - math.sqrt(KN * 1.0 / 500.0) / (2 * math.pi)) for f in freqs]))
    shape = mesh.point_data[f"mode_{vertical + 1}"]
    v = s.model.vertices
    upper = v["block"] == 1
    assert shape[upper] == pytest.approx(np.tile([0.0, 0.0, 1.0], (int(upper.sum()), 1)), abs=1e-9)
    assert np.abs(shape[~upper]).max() == 0.0           # the fixed base does not move
    for i in range(6):
        assert np.abs(mesh.point_data[f"mode_{i + 1}"]).max() == pytest.approx(1.0, rel=1e-12)


def test_joined_blocks_vibrate_as_one_body(tmp_path):
    s = _session(tmp_path)
    s.command("block create brick -0.5 0.5 -0.5 0.5 -1 0\nblock create brick -0.5 0.5 -0.5 0.5 0 0.5\n"
              "block create brick -0.5 0.5 -0.5 0.5 0.5 1\nblock join range id-list 2 3\n"
              f"block property density {RHO}\nblock contact jmodel assign elastic\n"
              f"block contact property stiffness-normal {KN} stiffness-shear {KS}\nblock fix range id 1\n"
              "block dynamic eigen modes 6")
    got = [s.results[f"eigen.f{i}"] for i in range(1, 7)]
    # one 1 × 1 × 1 body of 1000 kg on the base: vertical √(kn A / m) / 2π
    assert _near(math.sqrt(KN * 1.0 / 1000.0) / (2 * math.pi), got)
    assert s.model.eigen_modes.shapes.shape == (6, 2, 6)       # two bodies: the base and the joined pair


@pytest.mark.parametrize("deck, message", [
    ("block dynamic eigen modes 1", r"there are no blocks"),
    ("block create brick 0 1\nblock property density 1\nblock fix\nblock dynamic eigen modes 1",
     r"every degree of freedom is fixed"),
    ("block create brick 0 1\nblock property density 1\nblock dynamic eigen modes 7",
     r"7 modes asked for, but the free blocks have only 6 degrees of freedom"),
    ("block create brick 0 1\nblock dynamic eigen modes 2", r"block 1 has no mass"),
    ("block create brick 0 1\nblock property density 1\nblock zone generate edgelength 0.5\n"
     "block dynamic eigen modes 2", r"zoned \(deformable\) blocks"),
    ("block create brick 0 1\nblock dynamic eigen modes 0", r"`n` must be in \[1, 10000\], got 0"),
    ("block create brick 0 1\nblock dynamic eigen setmode", r"no modes yet"),
    ("block create brick 0 1\nblock property density 1\nblock dynamic eigen modes 1 file '../x.vtu'",
     r"outside"),
])
def test_bad_input(tmp_path, deck, message):
    s = _session(tmp_path)
    with pytest.raises(Dec3dError, match=message):
        s.command(deck)


def test_free_block_has_six_zero_modes_and_nothing_is_nan(tmp_path):
    s = _session(tmp_path)
    s.command("block create brick 0 1\nblock property density 1\nblock dynamic eigen modes 6")
    assert [s.results[f"eigen.f{i}"] for i in range(1, 7)] == [0.0] * 6


GEOMETRY = """; stand-in for the geometry.dat that compas_3dec's V8_eigen example calls (not published): a portal
block create brick -1.5 -0.5 0 0.5 -0.5 0 group 'Supports'
block create brick 0.5 1.5 0 0.5 -0.5 0 group 'Supports'
block create brick -1.5 -0.5 0 0.5 0 1 group 'Blocks'
block create brick 0.5 1.5 0 0.5 0 1 group 'Blocks'
block create brick -1.5 1.5 0 0.5 1 1.4 group 'Blocks'
"""


def test_public_eigen_deck_runs_to_the_end(tmp_path):
    from conftest import DECKS, NO_DECKS

    src = DECKS / "BlockResearchGroup__compas_3dec__docs__examples__V8_eigen__eigen.dat"
    if not src.is_file():
        pytest.skip(NO_DECKS)
    (tmp_path / "eigen.dat").write_bytes(src.read_bytes())
    (tmp_path / "geometry.dat").write_text(GEOMETRY, encoding="utf-8")
    s = Session(out_dir=tmp_path / "out", stdout=io.StringIO())
    s.run_items(s.load_file(tmp_path / "eigen.dat"))
    got = np.array([s.results[f"eigen.f{i}"] for i in range(1, 9)])
    # the deck's stiffnesses (100e9, 50e9) on the triangulated faces, against the dense assembly here
    K, M = _dense_reference(s.model, 100e9, 50e9)
    ref = np.sqrt(np.clip(linalg.eigh(K, M, eigvals_only=True), 0, None)) / (2 * math.pi)
    assert got == pytest.approx(ref[:8], rel=1e-9)
    assert (tmp_path / "out" / "eigen_modes.vtu").is_file() and (tmp_path / "out" / "sqpmodes.sav").is_file()


def test_sparse_shift_invert_path_agrees_with_the_dense_one(tmp_path, monkeypatch):
    from dec3d.physics import eigen

    (tmp_path / "d").mkdir()
    (tmp_path / "s").mkdir()
    dense = _session(tmp_path / "d")
    _base_and_block(dense, 1.0, 0.5, more="block create brick -0.5 0.5 -0.5 0.5 0.5 1\n")
    dense.command("block dynamic eigen modes 5")
    monkeypatch.setattr(eigen, "DENSE_LIMIT", 0)
    sparse = _session(tmp_path / "s")
    _base_and_block(sparse, 1.0, 0.5, more="block create brick -0.5 0.5 -0.5 0.5 0.5 1\n")
    sparse.command("block dynamic eigen modes 5")
    got = [sparse.results[f"eigen.f{i}"] for i in range(1, 6)]
    assert got == pytest.approx([dense.results[f"eigen.f{i}"] for i in range(1, 6)], rel=1e-8)


def test_open_sub_contacts_carry_no_spring(tmp_path):
    # the block hangs 1 mm above its base: the contact exists (gap within the contact tolerance) but is
    # open, so the block is free and all six frequencies are zero
    s = _session(tmp_path)
    s.command("block create brick -0.5 0.5 -0.5 0.5 -1 0\nblock create brick -0.5 0.5 -0.5 0.5 0.001 0.501\n"
              f"block property density {RHO}\nblock contact jmodel assign elastic\n"
              f"block contact property stiffness-normal {KN} stiffness-shear {KS}\nblock fix range id 1\n"
              "block contact tolerance 0.01\nblock dynamic eigen modes 6")
    assert engine(s.model).subcontacts.n > 0
    assert [s.results[f"eigen.f{i}"] for i in range(1, 7)] == [0.0] * 6
