"""`block vtk … contacts`: the sub-contacts written as points (dec3d/io/contactvtk.py), read back with meshio."""
import meshio
import pytest
import numpy as np

from dec3d.session import run_deck

PRESSED = """model new
block create brick 0 1 0 1 0 1
block create brick 0 1 0 1 1 2
block zone generate edgelength 0.5 range position-z 0 1
block zone generate edgelength 0.34 range position-z 1 2
block zone cmodel assign elastic
block zone property young 1e9 poisson 0.25 density 2000
block contact jmodel assign mohr
block contact material-table default property stiffness-normal 1e10 stiffness-shear 1e10 friction 30
block gridpoint apply velocity-z 0 range position-z 0
block gridpoint apply velocity-x 0 range position-x 0
block gridpoint apply velocity-x 0 range position-x 1
block gridpoint apply velocity-y 0 range position-y 0
block gridpoint apply velocity-y 0 range position-y 1
block face apply stress-zz -1e6 range position-z 2
model solve ratio 1e-7
block vtk 'pressed' contacts
"""


def _run(tmp_path, text):
    deck = tmp_path / "deck.dat"
    deck.write_text(text)
    return run_deck(deck, out_dir=tmp_path / "out")


def test_deformable_contact_points_carry_the_joint_load(tmp_path):
    """Two zoned cubes pressed by 1 MPa across a joint with non-matching gridpoints: the contact file
    holds every sub-contact of the model (positions, forces and displacements bit for bit those of the
    store), their normal forces add up to the load p A = 1 MN (0.5 %), the mean normal stress is 1 MPa,
    the joint closes by p / kn = 0.1 mm (area-weighted mean, 1 %), every
    sub-contact is within the Coulomb limit, and the .pvd lists the file as part 1."""
    s = _run(tmp_path, PRESSED)
    out = tmp_path / "out"
    m = meshio.read(out / "pressed_contacts_0000.vtu")
    sc, c = s.model.store("subcontacts"), s.model.store("contacts")
    n = int(c["sub_count"].sum())
    assert n > 20 and len(m.points) == n and len(m.cells[0].data) == n and m.cells[0].type == "vertex"
    rows = np.concatenate([np.arange(a, a + k) for a, k in zip(c["sub_start"], c["sub_count"])])
    np.testing.assert_array_equal(m.points, sc["pos"][rows])
    np.testing.assert_array_equal(m.point_data["normal_force"], sc["fn"][rows])
    np.testing.assert_array_equal(m.point_data["shear_displacement"], sc["us"][rows])
    pd = m.point_data
    assert pd["normal_force"].sum() == pytest.approx(1e6, rel=5e-3)
    loaded = pd["area"] > 0
    w = pd["area"][loaded]
    assert np.average(pd["normal_stress"][loaded], weights=w) == pytest.approx(1e6, rel=5e-3)
    assert np.average(-pd["normal_displacement"][loaded], weights=w) == pytest.approx(1e-4, rel=1e-2)
    # Coulomb's limit holds at every sub-contact (some slipped at first, while the load came in)
    assert np.all(pd["shear_force_magnitude"] <= np.tan(np.radians(30)) * pd["normal_force"] * (1 + 1e-9) + 1e-9)
    np.testing.assert_allclose(pd["shear_force_magnitude"], np.linalg.norm(pd["shear_force"], axis=1))
    np.testing.assert_allclose(np.abs(pd["normal"][:, 2]), 1.0)
    assert set(np.unique(pd["block_a"]).tolist() + np.unique(pd["block_b"]).tolist()) == set(
        s.model.blocks["id"].tolist())
    pvd = (out / "pressed.pvd").read_text()
    assert 'part="1" file="pressed_contacts_0000.vtu"' in pvd and 'part="0" file="pressed_0000.vtu"' in pvd


def test_slip_flag_follows_the_joint_state_bits(tmp_path):
    """slip is 1 exactly where the state has the failed (1) or slipping-now (2) bit, not for open (4)."""
    from dec3d.io.contactvtk import write_contacts_vtu

    s = _run(tmp_path, PRESSED)
    sc, c = s.model.store("subcontacts"), s.model.store("contacts")
    rows = np.concatenate([np.arange(a, a + k) for a, k in zip(c["sub_start"], c["sub_count"])])
    states = np.array([0, 1, 2, 3, 4, 5, 6, 7])
    sc["state"][rows] = states[np.arange(rows.size) % 8]
    write_contacts_vtu(s.model, tmp_path / "bits.vtu")
    m = meshio.read(tmp_path / "bits.vtu")
    want = states[np.arange(rows.size) % 8]
    np.testing.assert_array_equal(m.point_data["state"], want)
    np.testing.assert_array_equal(m.point_data["slip"], np.isin(want, [1, 2, 3, 5, 6, 7]).astype(np.uint8))


def test_rigid_blocks_without_contacts_write_an_empty_file(tmp_path):
    """A model with no contacts yet writes a valid file with no points (and no error)."""
    _run(tmp_path, "model new\nblock create brick 0 1 0 1 0 1\nblock vtk 'lone' contacts\n")
    text = (tmp_path / "out" / "lone_contacts_0000.vtu").read_text()
    assert 'NumberOfPoints="0" NumberOfCells="0"' in text


def test_mixed_model_lists_the_contacts_after_the_zones(tmp_path):
    """A rigid block resting on a zoned one: the snapshot is the rigid blocks (part 0), the zones
    (part 1) and the sub-contacts (part 2, the part after the others of the same time), and the
    contact file holds the rigid/deformable contact's points, all on the interface z = 1."""
    _run(tmp_path, """model new
block create brick 0 1 0 1 0 1
block create brick 0 1 0 1 1 2
block zone generate edgelength 0.5 range position-z 0 1
block zone cmodel assign elastic
block zone property young 1e9 poisson 0.25 density 2000
block property density 2000 range position-z 1 2
block contact jmodel assign elastic
block contact material-table default property stiffness-normal 1e10 stiffness-shear 1e10
model gravity 0 0 -10
block gridpoint apply velocity 0 0 0 range position-z 0
model cycle 5
block vtk 'mix' contacts
""")
    out = tmp_path / "out"
    pvd = (out / "mix.pvd").read_text()
    for part, name in enumerate(("mix_0000.vtu", "mix_zones_0000.vtu", "mix_contacts_0000.vtu")):
        assert f'part="{part}" file="{name}"' in pvd
    m = meshio.read(out / "mix_contacts_0000.vtu")
    assert len(m.points) > 4
    np.testing.assert_allclose(m.points[:, 2], 1.0, atol=1e-6)
