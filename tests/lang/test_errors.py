"""Error reports: file:line:column, the source line, a caret, the include stack; nothing runs first."""
import pytest

from dec3d.errors import BindError, DeckSyntaxError, NotSupportedError


def test_syntax_error_on_a_continued_line(tmp_path, session):
    deck = tmp_path / "deck.dat"
    deck.write_text("model new\nmodel gravity 0 ...\n   0 $ -9.81\n")
    with pytest.raises(DeckSyntaxError) as e:
        session.call(deck)
    loc = e.value.location
    assert (loc.file, loc.line, loc.column) == (str(deck), 3, 6)
    report = e.value.format().splitlines()
    assert report[0].startswith(f"{deck}:3:6: error:")
    assert report[1] == "       0 $ -9.81"
    assert report[2] == "         ^"


def test_keyword_error_on_a_continued_line_points_at_the_token(tmp_path, session):
    deck = tmp_path / "deck.dat"
    deck.write_text("program log-file 'a.log' &\n    apend\n")
    with pytest.raises(BindError) as e:
        session.call(deck)
    assert (e.value.location.line, e.value.location.column) == (2, 5)
    assert e.value.format().splitlines()[2] == "        ^^^^^"


def test_error_inside_a_called_file_names_the_include_stack(tmp_path, session):
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "inner.dat").write_text("model new\nmodel gravity 0 0 'down'\n")
    (tmp_path / "middle.dat").write_text("; middle\nprogram call 'sub/inner.dat'\n")
    main = tmp_path / "main.dat"
    main.write_text("model title 'x'\ncall 'middle.dat'\n")
    with pytest.raises(BindError) as e:
        session.call(main)
    loc = e.value.location
    assert loc.file.endswith("inner.dat") and (loc.line, loc.column) == (2, 19)
    assert [(s.file.split("/")[-1], s.line) for s in loc.stack] == [("main.dat", 2), ("middle.dat", 2)]
    text = e.value.format()
    assert "called from" in text and "middle.dat:2:1" in text and "main.dat:2:1" in text
    # parsed and bound before anything ran: the title of the first line was never set
    assert session.model.settings.title == ""


def test_missing_called_file_is_reported_at_the_call(tmp_path, session):
    main = tmp_path / "main.dat"
    main.write_text("model new\ncall 'nowhere.dat'\n")
    with pytest.raises(Exception) as e:
        session.call(main)
    assert e.value.location.line == 2 and "cannot read deck" in e.value.message


def test_recursive_call_is_an_error(tmp_path, session):
    a = tmp_path / "a.dat"
    a.write_text("call 'b.dat'\n")
    (tmp_path / "b.dat").write_text("call 'a.dat'\n")
    with pytest.raises(BindError) as e:
        session.call(a)
    assert "calls itself" in e.value.message


def test_fish_call_runs_the_function(tmp_path, session):
    deck = tmp_path / "deck.dat"
    deck.write_text("model new\nfish define props\n  dens = 2600\nend\nmodel title 'x'\n@props\n")
    session.call(deck)
    assert session.variables["dens"] == 2600 and session.model.settings.title == "x"


def test_variable_set_by_a_fish_function_is_usable_after_the_call(session):
    session.command("fish def f\n  knj = 2.5\nend\n@f\nmodel gravity 0 0 @knj")
    assert session.model.settings.gravity == (0.0, 0.0, 2.5)


def test_cli_exit_codes(tmp_path):
    from dec3d.cli import main

    good = tmp_path / "good.dat"
    good.write_text("model new\nmodel gravity 0 0 -9.81\n")
    assert main(["run", str(good), "-q"]) == 0
    bad = tmp_path / "bad.dat"
    bad.write_text("model new\nmodel gravty 0 0 -9.81\n")
    assert main(["run", str(bad), "-q"]) == 2
    fails = tmp_path / "fails.dat"
    fails.write_text("model new\n[a = 1/0]\n")
    assert main(["run", str(fails), "-q"]) == 1


def test_call_with_a_name_from_an_expression(tmp_path, session):
    (tmp_path / "stage_2.dat").write_text("model title 'stage 2'\n")
    deck = tmp_path / "main.dat"
    deck.write_text("[n = 2]\nprogram call [string.build('stage_%1.dat', n)]\n")
    session.call(deck)
    assert session.model.settings.title == "stage 2"


def test_program_return_ends_only_the_called_file(tmp_path, session):
    (tmp_path / "sub.dat").write_text("model title 'sub'\nprogram return\nmodel title 'after return'\n")
    deck = tmp_path / "main.dat"
    deck.write_text("call 'sub.dat'\nmodel gravity 0 0 -1\n")
    session.call(deck)
    assert session.model.settings.title == "sub" and session.model.settings.gravity == (0.0, 0.0, -1.0)
