"""A command that fails validation leaves the model exactly as it was."""
import copy

import pytest

from dec3d.errors import Dec3dError


@pytest.mark.parametrize("bad", [
    "model gravity 1 2",                       # wrong count (bind time)
    "model gravity 0 0 [s]",                   # wrong type (run time)
    "model large-strain [s]",
    "model configure [s]",
    "model title 'x' extra",
    "model gravity 0 0 [1/0]",
])
def test_failing_command_changes_nothing(session, bad):
    session.command("model gravity 0 0 -9.81\nmodel large-strain on\nmodel configure dynamic\nmodel title 't'\n"
                    "[s = 'text']")
    before = copy.deepcopy(session.model.settings)
    vars_before = dict(session.variables)
    with pytest.raises(Dec3dError):
        session.command(bad)
    assert session.model.settings == before
    assert session.variables == vars_before


def test_a_bad_line_stops_the_deck_before_any_work(session, tmp_path):
    deck = tmp_path / "d.dat"
    deck.write_text("model gravity 0 0 -1\n[a = 5]\nmodel title 'ok'\nmodel gravity 0 0 -9.81 extra\n")
    with pytest.raises(Dec3dError):
        session.call(deck)
    assert session.model.settings.gravity == (0.0, 0.0, 0.0) and "a" not in session.variables


def test_program_exit_keeps_the_model(session):
    session.command("model title 'kept'\nexit()\nmodel title 'never'")
    assert session.model.settings.title == "kept"


def test_model_new_clears_everything(session):
    session.command("[a = 1]\nmodel gravity 0 0 -9.81\nfish def f\n x = 1\nend\nmodel new")
    assert session.variables == {} and session.fish == {} and session.model.settings.gravity == (0.0, 0.0, 0.0)
