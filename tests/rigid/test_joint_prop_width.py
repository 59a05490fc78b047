"""The contacts' property rows hold the columns the joint models in use read, no more (issue 27:
MASON's 21 columns on every contact of a mohr-only model cost detection a third more time): the
width follows `jmodel assign`, `material-table add` and detection, and saves made with other widths
(10 columns before issue 27, 21 from its first version) restore and run on."""
import numpy as np

from dec3d.io.state import restore_state, save_state
from dec3d.kernels.joints import MODELS, NPROP
from dec3d.physics.rigid import engine

NCOLS = {m.NAME: m.NCOLS for m in MODELS}

STACK = """
model new
block create brick 0 1 0 1 0 1
block create brick 0 1 0 1 1 2
block create brick 0 1 0 1 2 3
block property density 2000
block contact jmodel assign mohr
block contact property stiffness-normal 1e9 stiffness-shear 5e8 friction 30 cohesion 1e4
block fix range position-z 0 0.5
model gravity 0 0 -10
block mechanical damping none
block initialize velocity-x 0.01 range position-z 1 2
"""


def _run(session, text):
    session.run_items(session.load_text(text))
    e = engine(session.model)
    e.ensure_contacts()
    return e


def test_rows_are_as_wide_as_the_models_in_use_read(session):
    e = _run(session, STACK)
    cs = e.contacts
    assert NCOLS["mohr"] < NPROP and cs["prop"].shape == (cs.n, NCOLS["mohr"])
    assert (cs["prop"][:, 0] == 1e9).all() and (cs["prop"][:, 3] == 1e4).all()       # kn, cohesion kept
    _run(session, "block contact jmodel assign elastic")
    assert cs["prop"].shape == (cs.n, 2)
    _run(session, "block contact jmodel assign mason range position-z 1.9 2.1\n"
                  "block contact property stiffness-normal 2e9 range position-z 1.9 2.1")
    assert cs["prop"].shape == (cs.n, NCOLS["mason"])
    upper = np.abs(cs["pos"][:, 2] - 2.0) < 0.1
    assert (cs["prop"][upper, 0] == 2e9).all() and (cs["prop"][~upper, 0] == 1e9).all()
    assert (cs["prop"][~upper, 2:] == 0.0).all()         # (elastic reads two columns: the others zero)
    _run(session, "block contact jmodel assign mohr")
    e.detect()
    assert cs["prop"].shape == (cs.n, NCOLS["mohr"])


def test_a_material_table_entry_widens_the_rows_of_contacts_made_later(session):
    e = _run(session, STACK.replace("block create brick 0 1 0 1 2 3\n", "")
             + "block contact material-table add jmodel mason property stiffness-normal 3e9 stiffness-shear 1e9 "
               "range group-intersection 'a' 'b'\nblock group 'a' range position-z 1 2\n")
    _run(session, "block create brick 0 1 0 1 2 3\nblock group 'b' range position-z 2 3")
    e.detect()
    cs = e.contacts
    new = cs["idb"] == 3
    assert new.any() and cs["prop"].shape[1] == NCOLS["mason"]
    assert (cs["prop"][new, 0] == 3e9).all() and (cs["prop"][~new, 0] == 1e9).all()


def _widths_run(session, tmp_path, width):
    """Run 20 cycles, save, restore with property rows ``width`` wide (as a save of that time held
    them), run 20 more: the centroids at the end."""
    _run(session, STACK + "model cycle 20\n")
    path = save_state(session.model, tmp_path / f"w{width}.sav")
    restored, _ = restore_state(path)
    cs = restored.store("contacts")
    cs.resize_field("prop", (width,))                 # (zeros beyond the model's columns, as those saves held)
    e = engine(restored)
    assert e.contacts["prop"].shape[1] == NCOLS["mohr"]
    e.cycle(20)
    return restored.blocks["centroid"].copy()


def test_saves_with_other_row_widths_restore_and_run_on_bit_identically(session, tmp_path):
    _run(session, STACK + "model cycle 40\n")
    whole = session.model.blocks["centroid"].copy()
    for width in (NCOLS["mohr"], NPROP):              # issue-27's first saves: the widest model's columns
        np.testing.assert_array_equal(_widths_run(session, tmp_path, width), whole)


def test_rows_widened_between_runs_are_narrowed_at_the_next_run(session):
    e = _run(session, STACK)
    e.contacts.resize_field("prop", (NPROP,))
    _run(session, "model cycle 2")
    assert e.contacts["prop"].shape[1] == NCOLS["mohr"]
