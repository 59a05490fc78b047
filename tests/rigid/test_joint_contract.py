"""The joint-model contract beyond the law (issue 27): the sub-contacts' history goes through
detection, `jmodel assign`, save and restore; `jmodel load` accepts only models dec3d has built in;
every joint stiffness the engine reads comes through the models' stiffness hook."""
import numpy as np
import pytest

from dec3d.errors import Dec3dError
from dec3d.io.state import restore_state, save_state
from dec3d.kernels.joints import NJHIST
from dec3d.physics.jmodels import contact_stiffness, stiffness
from dec3d.physics.rigid import engine

STACK = """
model new
block create brick 0 1 0 1 0 1
block create brick 0 1 0 1 1 2
block create brick 0 1 0 1 2 3
block property density 2000
block contact jmodel assign mohr
block contact property stiffness-normal 1e9 stiffness-shear 5e8 friction 30
block fix range position-z 0 0.5
model gravity 0 0 -10
"""

#: the continuously yielding model keeps a history; with both exponents 0 its stiffnesses are kn, ks
CY = "block contact jmodel assign cyjm\nblock contact property kn-initial 1e9 ks-initial 5e8 friction 30 roughness 1e-3"


def _stack(session, extra=""):
    session.run_items(session.load_text(STACK + extra))
    e = engine(session.model)
    e.ensure_contacts()
    return e


def _mark(e):
    """Distinct history values per sub-contact."""
    ss = e.subcontacts
    ss["hist"][:] = np.arange(ss.n * NJHIST, dtype=float).reshape(ss.n, NJHIST) + 0.5


def test_history_columns_only_while_a_model_keeps_one(session):
    """A model of mohr joints carries no history (detection copies nothing); assigning a model that
    keeps one gives every sub-contact NJHIST zero columns, and a detection with none in use drops them."""
    e = _stack(session)
    assert e.subcontacts["hist"].shape == (e.subcontacts.n, 0)
    session.run_items(session.load_text(CY))
    assert e.subcontacts["hist"].shape == (e.subcontacts.n, NJHIST) and (e.subcontacts["hist"] == 0).all()
    session.run_items(session.load_text("block contact jmodel assign mohr"))
    e.detect()
    assert e.subcontacts["hist"].shape == (e.subcontacts.n, 0)


def test_jmodel_assign_starts_the_history_afresh_in_its_range_only(session):
    e = _stack(session, CY)
    _mark(e)
    session.run_items(session.load_text("block contact jmodel assign cy range position-z 1.9 2.1"))
    cs, ss = e.contacts, e.subcontacts
    upper = (cs["ida"][ss["contact"]] == 2) & (cs["idb"][ss["contact"]] == 3)
    assert upper.any() and (~upper).any()
    assert (ss["hist"][upper] == 0.0).all()
    assert (ss["hist"][~upper] > 0.0).all()


def test_history_round_trips_through_save_and_restore(session, tmp_path):
    e = _stack(session, CY)
    _mark(e)
    path = save_state(session.model, tmp_path / "h.sav")
    restored, _ = restore_state(path)
    got = restored.store("subcontacts")["hist"]
    np.testing.assert_array_equal(got, e.subcontacts["hist"])


def test_a_save_without_history_restores_and_runs(session, tmp_path):
    """A file from before the history existed: the field is added when the engine starts, and the
    columns a history model needs are there before its first step."""
    e = _stack(session, CY)
    n = e.subcontacts.n
    path = save_state(session.model, tmp_path / "old.sav")
    restored, _ = restore_state(path)
    ss = restored.store("subcontacts")
    del ss._fields["hist"], ss._data["hist"]         # (the store has no public way to drop a field)
    assert "hist" not in ss
    e2 = engine(restored)
    assert e2.subcontacts["hist"].shape == (n, 0)
    e2.cycle(3)
    assert e2.subcontacts["hist"].shape == (n, NJHIST) and np.isfinite(e2.subcontacts["hist"]).all()


def test_stiffness_of_linear_models_is_their_columns(session):
    e = _stack(session)
    kn, ks = stiffness(e.contacts, e.subcontacts)
    assert kn.shape == (e.subcontacts.n,) and (kn == 1e9).all() and (ks == 5e8).all()
    ckn, cks = contact_stiffness(e.contacts, e.subcontacts)
    assert (ckn == 1e9).all() and (cks == 5e8).all()


@pytest.mark.parametrize("name", ["mohr", "'jmodelmohr.dll'", "'C:/itasca/plugins/jmodel_elastic.dll'"])
def test_jmodel_load_of_a_built_in_model_does_nothing(session, name):
    session.run_items(session.load_text(f"model new\nblock contact jmodel load {name}"))


@pytest.mark.parametrize("name", ["'jmodelmyweirdmodel.dll'", "ubiquitous"])
def test_jmodel_load_of_anything_else_is_refused_with_where_and_why(session, name):
    with pytest.raises(Dec3dError) as err:
        session.run_items(session.load_text(f"model new\nblock contact jmodel load {name}", filename="deck.dat"))
    msg = str(err.value)
    assert "cannot be loaded" in msg and "runs no compiled plugins" in msg
    assert "deck.dat:2:27" in msg or (err.value.location is not None and err.value.location.line == 2)


def test_power_law_creep_is_refused_saying_what_is_missing(session):
    """3DEC's `power` joint: the reference text stops before its creep-rate law and its keywords."""
    with pytest.raises(Dec3dError) as err:
        session.run_items(session.load_text("model new\nblock contact jmodel assign power", filename="deck.dat"))
    msg = str(err.value)
    assert "`power` is not supported yet" in msg and "creep-rate law" in msg and "property keywords" in msg
    assert "deck.dat:2" in msg or (err.value.location is not None and err.value.location.line == 2)
