"""What a run tells its user (issue "What users see II", items 3-5): the report that ends a `model cycle`,
the last line of `dec3d run`, a line while a long deck is read, warnings for ranges that select nothing
(an error with --strict), for contact properties set before any contact exists, for densities no rock has."""
import io
import re

import pytest

from dec3d.cli import main
from dec3d.errors import CommandError
from dec3d.session import Session

TWO = """model new
block create brick 0 1 0 1 -1 0
block create brick 0 1 0 1 0 1
block property density 2000
block contact property stiffness-normal 1e9 stiffness-shear 1e9 friction 30
model gravity 0 0 -9.81
block fix range id 1
"""


@pytest.fixture
def session(tmp_path):
    out = io.StringIO()
    s = Session(out_dir=tmp_path, stdout=out)
    s.output = out
    return s


def test_model_cycle_ends_with_the_report_of_model_solve_but_not_inside_fish(session):
    session.command(TWO + "model cycle 50")
    lines = session.output.getvalue().splitlines()
    # no units unless the deck declares them (issue 31 item 3): a deck may be in kN and kPa
    assert lines[-2] == f"model cycle: 50 steps (to step 50), model time {session.model.time:.6g} " \
                        f"(total {session.model.time:.6g})"
    assert re.fullmatch(r"  ratio [0-9.e+-]+, ratio-average .*, unbalanced-maximum [0-9.e+-]+", lines[-1])
    n = len(lines)
    session.command("fish define f\n  loop i (1, 3)\n    command\n      model cycle 5\n    endcommand\n  endloop\n"
                    "end\n@f")
    assert not any(ln.startswith("model cycle:") for ln in session.output.getvalue().splitlines()[n:])
    assert session.model.step == 65


def test_dec3d_run_ends_with_time_files_and_warnings(tmp_path, capsys):
    deck = tmp_path / "d.dat"
    deck.write_text(TWO + "model cycle 10\nmodel save 'a'\nblock property density 3000 range position-z 50 60\n")
    assert main(["run", str(deck), "--out", str(tmp_path / "o"), "-q"]) == 0
    err = capsys.readouterr().err.splitlines()
    last = [ln for ln in err if ln.startswith("dec3d run: finished in")]
    assert len(last) == 1
    assert re.match(r"dec3d run: finished in [0-9.]+ s.*; 1 file written in .*: a\.sav; 1 warning \(below\)", last[0])
    assert err[-1].endswith("the range selects no block (of 2)")


def test_a_long_deck_says_how_far_reading_has_got(tmp_path, monkeypatch):
    import dec3d.lang.progress as progress

    monkeypatch.setattr(progress, "EVERY", 0.0)
    out = io.StringIO()
    s = Session(out_dir=tmp_path, stdout=out)
    deck = tmp_path / "long.dat"
    deck.write_text("".join(f"model title 't{i}'\n" for i in range(3000)))
    # (the first line comes after EVERY from the start: the first 1024 lines are read before the clock is read)
    s.load_file(deck)
    lines = [ln for ln in out.getvalue().splitlines() if ln.startswith("reading ")]
    assert [ln.split(":")[1].split("(")[0].strip() for ln in lines] == ["line 1024", "line 2048"]


def test_a_range_that_selects_nothing_warns_once_and_is_an_error_when_strict(session, tmp_path):
    session.command(TWO)
    for _ in range(2):
        session.command("block property density 2500 range group 'nowhere'")
    text = session.output.getvalue()
    assert text.count("the range selects no block (of 2)") == 2          # once per line (two lines here)
    session.command("fish define f\n  loop i (1, 5)\n    command\n      block fix range id 99\n    endcommand\n"
                    "  endloop\nend\n@f")
    # not inside FISH: a loop scanning positions or groups meets empty ones as a matter of course
    assert session.output.getvalue().count("the range selects no block") == 2
    session.strict = True
    with pytest.raises(CommandError) as e:
        session.command("block fix range position-x 7 8")
    assert "the range selects no block (of 2) (--strict)" in e.value.message and e.value.location.column == 17


def test_contact_properties_without_contacts_and_implausible_densities_warn(session):
    session.command("block create brick 0 1 0 1 0 1\nblock contact property friction 30 range position-z 0")
    assert "no contacts exist yet, so the range reaches none" in session.output.getvalue()
    session.command("block property density 2.65")
    session.command("block property density 2650")
    text = session.output.getvalue()
    assert text.count("is outside 100–30000 kg/m³") == 1 and "density 2.65 is outside" in text
    assert len(session.warnings) == 2


# ---------------------------------------------------------------- units (issue 31 item 3, item 2's field data)
def test_reports_name_units_only_once_the_deck_declares_them(session):
    session.command(TWO + "model cycle 20\nmodel list\nblock list information")
    bare = session.output.getvalue()
    assert "units           : not declared" in bare
    assert "gravity         : 0 0 -9.81\n" in bare and "time step       : " in bare
    assert not re.search(r"\d (s|N|m|kg|m³|m/s²)(\b|$|\))", bare, re.M), bare
    n = len(bare)
    session.command("model configure units si\nmodel cycle 20\nmodel list\nblock list information")
    si = session.output.getvalue()[n:]
    t = session.model.time
    assert f"model time {t / 2:.6g} s (total {t:.6g} s)" in si
    assert re.search(r"unbalanced-maximum [0-9.e+-]+ N$", si, re.M)
    assert "gravity         : 0 0 -9.81 m/s²" in si and "units           : SI (m, kg, s, N, Pa)" in si
    assert "total volume 2 m³, mass 4000 kg" in si and "tolerance" in si and si.count(" m\n") >= 2
    # `units none` takes it back; the setting travels in save files
    session.command("model configure units none\nmodel list units")
    assert session.output.getvalue().rstrip().endswith("reports show no units (`model configure units si` to show "
                                                       "SI units)")


def test_declared_units_go_to_the_vtk_files_and_the_save(session, tmp_path):
    import meshio

    from dec3d.io.vtk import read_text_array

    session.command(TWO + "model cycle 5\nblock vtk filename 'a'\nmodel configure units si\nmodel cycle 5\n"
                    "block vtk filename 'b'\nmodel save 'u'\nmodel new\nmodel restore 'u'\nmodel list units")
    assert "units" not in meshio.read(tmp_path / "a_0000.vtu").field_data
    units = read_text_array(meshio.read(tmp_path / "b_0000.vtu").field_data["units"])
    assert units[0] == "system=SI" and "displacement=m" in units and "spin=rad/s" in units
    joints = read_text_array(meshio.read(tmp_path / "b_joints_0000.vtu").field_data["units"])
    assert "normal_stress=Pa" in joints and "shear_displacement=m" in joints
    assert session.output.getvalue().rstrip().endswith("reports name them")     # restored with the model


@pytest.mark.parametrize("line, col, words", [
    ("model configure units", 17, "needs the system: si or none"),
    ("model configure dynamic si", 25, "takes no unit system"),
    ("model configure units kilo", 23, "kilo"),
])
def test_configure_units_bad_input_names_the_column(session, line, col, words):
    from dec3d.errors import Dec3dError

    with pytest.raises(Dec3dError) as err:
        session.command(line)
    assert err.value.location.column == col and words in err.value.format()
