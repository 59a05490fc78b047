"""What the joint-model test files share: a deck whose last line sets a property out of its range
is refused when the line is bound, at the value's own file, line and column, before anything ran."""
import pytest

from dec3d.commands.values import ValueRangeError


def assert_refused_at_binding(session, tmp_path, text, message, column):
    """``text``: the deck (its last line the bad one); ``message``: the error's text; ``column``:
    where the value starts on that line."""
    deck = tmp_path / "deck.dat"
    deck.write_text(text + "\n")
    with pytest.raises(ValueRangeError) as e:
        session.call(deck)
    line = text.count("\n") + 1
    assert e.value.message == message
    assert (e.value.location.file, e.value.location.line, e.value.location.column) == (str(deck), line, column)
    assert session.model.blocks.n == 0
