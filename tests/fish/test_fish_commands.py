"""`fish history`, `fish callback`, `table` and FISH state in save files, on a small model of our own:
one 1 m brick falling under gravity (nothing below it), so every step moves it and a FISH value that
follows the block can be checked against the block's own history."""
import hashlib
import json
import zipfile

import pytest

from dec3d.errors import CommandError, Dec3dError, ExpressionError

BRICK = "block create brick 0 1 0 1 0 1\nblock property density 1000\nmodel gravity 0 0 -10\n"


def _deck(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


# ------------------------------------------------------------------ fish history

def test_fish_history_of_a_function_matches_the_block_history(session):
    session.command(BRICK + "fish define zc\n  zc = block.pos.z(1)\nend\n"
                    "history interval 4\nblock history name 'ref' position-z block-id 1\n"
                    "fish history @zc\nmodel cycle 20")
    hs = session.model.history_set
    ref, fz = hs.find("ref"), hs.find("zc")
    assert fz is not None and fz.label == "fish zc"
    assert fz.steps == [4, 8, 12, 16, 20] == ref.steps
    assert fz.values == ref.values               # the same number read two ways
    assert ref.values[-1] < 0.5 - 1e-6           # and the block did move


def test_fish_history_of_a_variable_set_by_a_callback_sees_that_step(session):
    """The callback (interval 1) counts steps; the history (interval 5) must read the count of its own step."""
    session.command(BRICK + "fish define count\n  global n = n + 1\nend\n[n = 0]\n"
                    "fish callback add count 1.0\nhistory interval 5\nfish history name 'cnt' n\nmodel cycle 15")
    h = session.model.history_set.find("cnt")
    assert h.steps == [5, 10, 15]
    assert h.values == [5.0, 10.0, 15.0]
    assert session.variables["n"] == 15


def test_history_rename_and_export_of_a_fish_history(session, tmp_path):
    session.command(BRICK + "[q = 2.5]\nfish history q\nhistory rename 'q' name '1'\nhistory interval 2\n"
                    "model cycle 4\nhistory export '1' file 'h.csv'\nhistory list")
    lines = (tmp_path / "h.csv").read_text().splitlines()
    assert len(lines) == 3 and "1" in lines[0]
    assert [float(ln.split(",")[-1]) for ln in lines[1:]] == [2.5, 2.5]
    assert session.results["1.final"] == 2.5
    assert "'1'  fish q  (2 samples, last 2.5 at step 4)" in session.output.getvalue()


def test_fish_history_bad_input(session, tmp_path):
    deck = _deck(tmp_path, "d.dat", BRICK + "fish define two(a, b)\n  two = a + b\nend\n"
                 "fish history   nothere\n")
    with pytest.raises(CommandError) as e:
        session.call(deck)
    loc = e.value.location
    assert "`nothere` is neither a FISH variable nor a FISH function" in e.value.message
    assert (loc.file, loc.line, loc.column) == (str(deck), 7, 16)
    with pytest.raises(CommandError) as e:
        session.command("fish history @two")
    assert "takes 2 argument(s)" in e.value.message
    session.command("[x = 1]\nfish history name 'h' x")
    with pytest.raises(CommandError) as e:
        session.command("fish history name 'h' x")
    assert "a history named 'h' exists already" in e.value.message
    with pytest.raises(CommandError) as e:
        session.command("history rename 'nope' name 'z'")
    assert "there is no history nope" in e.value.message


def test_a_fish_history_whose_value_is_not_a_number_stops_the_cycle_at_that_step(session, tmp_path):
    deck = _deck(tmp_path, "d.dat", BRICK + "fish define v\n  if mech.cycle >= 6 then\n    v = 'text'\n"
                 "  else\n    v = 1\n  endif\nend\nhistory interval 3\nfish history @v\nmodel cycle 12\n")
    with pytest.raises(ExpressionError) as e:
        session.call(deck)
    assert "`fish history v`: the value is a string, not a number" in e.value.message
    assert e.value.location.line == 12                     # the `fish history` line
    # the engine puts the model back as it was before `model cycle` (RigidEngine.cycle): samples too
    assert session.model.step == 0 and session.model.time == 0.0
    assert session.model.blocks["centroid"][0, 2] == 0.5
    h = session.model.history_set.find("v")
    assert h.steps == [] and h.values == []


# ------------------------------------------------------------------ fish callback

def test_callbacks_run_in_position_order_at_their_interval(session):
    session.command(BRICK + "[log = list.sequence(0)]\n"
                    "fish define a\n  log = list.append(log, 'a' + string(mech.cycle))\nend\n"
                    "fish define b\n  log = list.append(log, 'b' + string(mech.cycle))\nend\n"
                    "fish callback add b 5.0 interval 2\nfish callback add a -1.0 interval 3\nmodel cycle 6\n"
                    "fish callback list")
    # b (position 5) after steps 2, 4, 6; a (position -1) before steps 3 and 6, seeing the step before
    assert session.variables["log"] == ["b2", "a2", "b4", "a5", "b6"]
    assert session.output.getvalue().splitlines()[-2:] == ["-1  a  interval 3  (before the step's forces)",
                                                           "5  b  interval 2  (after the step's motion)"]
    session.command("fish callback remove a\n[log = list.sequence(0)]\nmodel cycle 2")
    assert session.variables["log"] == ["b8"]


# a free 1 m brick, no gravity, no damping: one step of an applied force F gives v = F Δt / m
FREE = ("block create brick 0 1 0 1 0 1\nblock property density 1000\nblock mechanical damping none\n"
        "model gravity 0 0 0\n[f0 = 500.0]\n"
        "fish define pre\n  sb = mech.cycle\n  vb = block.vel.x(block.find(1))\n"
        "  if mech.cycle = 0 then\n    block.force.app.x(block.find(1)) = f0\n  endif\nend\n"
        "fish define post\n  sa = mech.cycle\n  va = block.vel.x(block.find(1))\nend\n")


def test_a_negative_position_acts_in_the_same_step_and_a_positive_one_sees_the_motion(session):
    """`srv_update -100.0`-style: the -100 callback sets an applied force before step 1's forces, so step 1
    already moves the block (v = F Δt / m, central difference from rest); the +50 one runs after step 1's
    motion and reads that velocity with mech.cycle = 1, the -100 one read the state before it (cycle 0, v 0)."""
    session.command(FREE + "fish callback add post 50\nfish callback add pre -100\nmodel cycle 1\n"
                    "[dt = mech.timestep]\n[m = block.mass(block.find(1))]")
    v = session.variables
    assert v["m"] == pytest.approx(1000.0, rel=1e-12)        # real mass: damping none scales nothing
    assert (v["sb"], v["vb"], v["sa"]) == (0, 0.0, 1)
    assert v["va"] == pytest.approx(500.0 * v["dt"] / 1000.0, rel=1e-12)
    assert session.model.blocks["velocity"][0, 0] == v["va"]
    assert [repr(st) for st in session.model.rigid_engine.steps] == ["FishBefore", "RigidBatch", "Clock", "Hooks"]


def test_the_same_force_set_after_motion_acts_one_step_later(session):
    """The control: at +50 the force set at cycle 0 cannot be set (the first call sees cycle 1), so with the
    condition moved to cycle 1 the block is still at rest after step 1 and moves in step 2."""
    session.command(FREE.replace("mech.cycle = 0", "mech.cycle = 1") + "fish callback add pre 50\nmodel cycle 1")
    assert session.model.blocks["velocity"][0, 0] == 0.0
    session.command("model cycle 1\n[dt = mech.timestep]")
    assert session.model.blocks["velocity"][0, 0] == pytest.approx(500.0 * session.variables["dt"] / 1000.0,
                                                                    rel=1e-12)


def test_a_negative_callback_with_an_interval_runs_before_each_due_step(session):
    """interval 4 at -10: before steps 4, 8, 12 (it sees cycles 3, 7, 11); the batches end there (the split
    changes nothing: the same log for one run and for three)."""
    text = BRICK + "[log = list.sequence(0)]\nfish define a\n  log = list.append(log, mech.cycle)\nend\n" \
                   "fish callback add a -10 interval 4\n"
    session.command(text + "model cycle 13")
    assert session.variables["log"] == [3, 7, 11]
    z13 = session.model.blocks["centroid"][0, 2]
    session.command("model new\n" + text + "model cycle 5\nmodel cycle 3\nmodel cycle 5")
    assert session.variables["log"] == [3, 7, 11] and session.model.blocks["centroid"][0, 2] == z13


def test_program_list_cycle_sequence_names_the_positions_and_the_last_steps(session):
    session.command("program list cycle-sequence")
    out = session.output.getvalue().splitlines()
    assert out[0] == "position  what runs" and out[-1] == "last run's steps: none (not cycled yet)"
    assert [ln.split()[0] for ln in out[1:-1] if ln.split()[0] in ("<", "0", "≥")] == ["<", "0", "≥"]
    session.command(BRICK + "fish define a\n  a = 1\nend\nfish callback add a -3.5\nmodel cycle 2\n"
                    "program list cycle-sequence")
    out = session.output.getvalue().splitlines()
    assert out[-2:] == ["last run's steps: FishBefore -> RigidBatch -> Clock -> Hooks", "callback -3.5  a  interval 1"]


def test_an_error_in_a_callback_stops_the_cycle_with_the_fish_line(session, tmp_path):
    deck = _deck(tmp_path, "cb.dat", BRICK + "fish define bad\n  local z = block.pos.z(1)\n"
                 "  if mech.cycle == 4 then\n    z = z / 0\n  endif\nend\n"
                 "fish callback add @bad 0.0\nmodel cycle 10\n")
    with pytest.raises(ExpressionError) as e:
        session.call(deck)
    assert e.value.message == "division by zero"
    loc = e.value.location
    assert (loc.file, loc.line) == (str(deck), 7)             # `z = z / 0` in the body
    assert [s.line for s in loc.stack] == [10]                # called from the `fish callback add` line
    # the model is put back as it was before `model cycle` (RigidEngine.cycle restores it on any error)
    assert session.model.step == 0 and session.model.blocks["centroid"][0, 2] == 0.5


@pytest.mark.parametrize("cmd, err, msg, col", [
    ("fish callback add nothere 1.0", CommandError, "`nothere` is not a FISH function", 19),
    ("fish callback add f 1.0", CommandError, "takes 1 argument(s)", None),
    ("fish callback add f", Dec3dError, "needs position", None),
    ("fish callback remove f", CommandError, "`f` is not a FISH callback", None),
    ("fish define g\n  g = 1\nend\nfish callback add g 1.0 interval 0", Dec3dError, "`interval` must be ≥ 1, got 0",
     None)])
def test_fish_callback_bad_input(session, cmd, err, msg, col):
    session.command("fish define f(x)\n  f = x\nend")
    with pytest.raises(err) as e:
        session.command(cmd)
    assert msg in e.value.message
    if col is not None:
        assert e.value.location.column == col


# ------------------------------------------------------------------ table

def test_table_add_list_and_interpolate(session):
    session.command("table 1 add (0,0) (1,2) (3,2)\ntable 1 insert 2 5 label 'ramp'\ntable 1 list\n"
                    "[a = table(1, 0.25)]\n[b = table(1, 2.5)]\n[c = table(1, 9)]\n"
                    "[n = table.size(1)]\n[x3 = table.x(1, 3)]\n[y3 = table.y(1, 3)]\n[lab = table.label(1)]")
    v = session.variables
    assert (v["a"], v["b"], v["c"], v["n"], v["x3"], v["y3"], v["lab"]) == (0.5, 3.5, 2.0, 4, 2.0, 5.0, "ramp")
    assert session.output.getvalue().splitlines() == ["table 1 'ramp': 4 points", "  0  0", "  1  2", "  2  5",
                                                      "  3  2"]
    session.command("table 1 delete")
    with pytest.raises(ExpressionError) as e:
        session.command("[q = table(1, 0.5)]")
    assert "there is no table 1" in e.value.message


def test_table_import_beside_the_deck(session, tmp_path):
    (tmp_path / "INPUT").mkdir()
    (tmp_path / "INPUT" / "acc.txt").write_text("Bottom shake table\n0.0 0.0\n0.01, -1.5\n; a comment\n"
                                                "0.02\t3.0\n")
    deck = _deck(tmp_path, "d.dat", "table 'acc' import \"INPUT/acc.txt\"\n[t = table('ACC', 0.015)]\n"
                 "[lab = table.label('acc')]\n")
    session.call(deck)
    assert session.variables["t"] == pytest.approx(0.75, abs=1e-12)
    assert session.variables["lab"] == "Bottom shake table"


def test_table_bad_input(session, tmp_path):
    (tmp_path / "bad.txt").write_text("0 0\n1 one\n")
    deck = _deck(tmp_path, "d.dat", "table 2 import 'bad.txt'\n")
    with pytest.raises(CommandError) as e:
        session.call(deck)
    assert "table file 'bad.txt', line 2: expected two numbers x y" in e.value.message
    assert (e.value.location.line, e.value.location.column) == (1, 16)
    deck = _deck(tmp_path, "e.dat", "table 2 import '../outside.txt'\n")
    with pytest.raises(Dec3dError) as e:
        session.call(deck)
    assert e.value.location.line == 1 and "outside" in e.value.message
    for cmd, err, msg in (("table 3 add 0 1 2", Dec3dError, "multiple of 2"),
                          ("table 9 list", CommandError, "there is no table 9"),
                          ("table 9 delete", CommandError, "there is no table 9")):
        with pytest.raises(err) as e:
            session.command(cmd)
        assert msg in e.value.message, cmd


# ------------------------------------------------------------------ save files

STATE = ("fish define bump(k)\n  bump = k + 1\n  command\n    model gravity 0 0 [-k]\n  endcommand\nend\n"
         "[i = 7]\n[f = 2.5]\n[b = true]\n[s = 'héllo']\n[v = vector(1, 2.5, -3)]\n"
         "[l = list.append(list.sequence(2), vector(0, 0, 1))]\n[m = map('a', 1, 2, list.sequence(1))]\n"
         "table 'tt' add 0 0 1 10\n[tt = table.get('tt')]\n")


def test_fish_state_round_trips_through_a_save_file(session, tmp_path):
    session.command(BRICK + STATE + "fish automatic-create off\nmodel save 'a'")
    before = {k: repr(v) for k, v in session.variables.items()}
    session.command("model new\n[i = 0]")
    assert "bump" not in session.fish_rt.functions and session.variables == {"i": 0}
    session.command("model restore 'a'")
    v = session.variables
    assert {k: repr(x) for k, x in v.items()} == before
    assert type(v["i"]) is int and type(v["f"]) is float and v["b"] is True and v["s"] == "héllo"
    assert repr(v["v"]) == "(1,2.5,-3)" and repr(v["l"]) == "[1, 2, (0,0,1)]"
    assert v["m"] == {"a": 1, 2: [1]}
    assert session.fish_rt.auto_create is False
    session.command("[r = bump(4)]\n[y = table(tt, 0.5)]")      # the function compiled again, with its command
    assert v["r"] == 5 and v["y"] == 5.0
    assert tuple(session.model.settings.gravity) == (0.0, 0.0, -4.0)
    # restore → save gives the same bytes
    session.command("model restore 'a'\nmodel save 'b'")
    assert (tmp_path / "a.sav").read_bytes() == (tmp_path / "b.sav").read_bytes()


def test_a_restored_function_reports_errors_at_its_original_lines(session, tmp_path):
    deck = _deck(tmp_path, "d.dat", "fish define boom\n  local a = 1\n  boom = a / 0\nend\nmodel save 'x'\n")
    session.call(deck)
    session.command("model new\nmodel restore 'x'")
    with pytest.raises(ExpressionError) as e:
        session.command("[q = boom]")
    assert e.value.message == "division by zero"
    assert (e.value.location.file, e.value.location.line) == (str(deck), 3)


def _rewrite_meta(path, change):
    with zipfile.ZipFile(path) as zf:
        members = {n: zf.read(n) for n in zf.namelist()}
    meta = json.loads(members["meta.json"])
    change(meta)
    members["meta.json"] = json.dumps(meta).encode()
    # a consistent metadata checksum (anyone can make it); the HMAC no longer checks: `trust` below
    sig = json.loads(members["signature.json"])
    sig["meta_sha256"] = hashlib.sha256(members["meta.json"]).hexdigest()
    members["signature.json"] = json.dumps(sig).encode()
    with zipfile.ZipFile(path, "w") as zf:
        for n, b in members.items():
            zf.writestr(n, b)


@pytest.mark.parametrize("change, why", [
    (lambda m: m["extra"]["fish"]["globals"].update(x={"vec": [1, 2]}), "FISH variable `x`"),
    (lambda m: m["extra"]["fish"]["functions"][0].update(lines=["  if 1 then"]), "does not parse"),
    (lambda m: m["extra"]["fish"].update(format=99), "unknown format"),
    (lambda m: m["extra"]["fish"]["callbacks"].append({"function": "zz", "position": 1.0, "interval": 1}),
     "names no saved function"),
])
def test_a_bad_fish_state_is_refused_and_nothing_changes(session, tmp_path, change, why):
    session.command("fish define g\n  g = 1\nend\n[x = 1]\nmodel save 's'")
    _rewrite_meta(tmp_path / "s.sav", change)
    session.command("model new\n[keep = 3]")
    model = session.model
    with pytest.raises(Dec3dError) as e:
        session.command("model restore 's' trust")          # trusted: its FISH is read, and checked
    assert "the FISH state is inconsistent" in e.value.message and why in e.value.message
    assert session.model is model and session.variables == {"keep": 3} and not session.fish_rt.functions


def test_a_value_that_cannot_be_saved_is_named(session):
    from dec3d.fish.persist import FishStateError, encode
    with pytest.raises(FishStateError) as e:
        encode(float("inf"), "FISH variable `w`")
    assert "FISH variable `w`: inf is not a finite number" in e.value.message


def test_history_name_sets_the_label_that_export_writes(session, tmp_path):
    session.command(BRICK + "model history mechanical time-total\nhistory name '1' label 'Time'\n"
                    "[k = 1]\nfish history k\nhistory name 'k' label 'counter'\nhistory interval 1\nmodel cycle 2\n"
                    "history export 1 2 file 'n.csv'")
    hs = session.model.history_set
    assert [h.label for h in hs.items] == ["Time", "counter"]
    header = (tmp_path / "n.csv").read_text().splitlines()[0]
    assert "Time" in header and "counter" in header
    with pytest.raises(CommandError) as e:
        session.command("history name 7 label 'x'")
    assert "there is no history 7" in e.value.message


def test_history_delete(session):
    session.command(BRICK + "[a = 1]\n[b = 2]\nfish history a\nfish history b\nhistory delete 'a'")
    hs = session.model.history_set
    assert [h.name for h in hs.items] == ["b"]
    session.command("history delete\nfish history a")
    assert [(h.id, h.name) for h in hs.items] == [(1, "a")]
    with pytest.raises(CommandError) as e:
        session.command("history delete 'zz'")
    assert "there is no history zz" in e.value.message


def test_system_directory_create_stays_in_the_output_folder(session, tmp_path):
    session.command("[r = system.directory.create('NUM/run_rev1')]\n[r2 = system.directory.create('NUM/run_rev1')]")
    assert (tmp_path / "NUM" / "run_rev1").is_dir() and session.variables["r"] == session.variables["r2"] == 0
    with pytest.raises(Dec3dError) as e:
        session.command("[r = system.directory.create('../elsewhere')]")
    assert "outside the output folder" in e.value.message
    assert not (tmp_path.parent / "elsewhere").exists()


def test_a_callback_cannot_cycle_or_replace_the_model(session, tmp_path):
    deck = _deck(tmp_path, "d.dat", BRICK + "fish define again\n  command\n    model cycle 5\n  endcommand\nend\n"
                 "fish callback add again 0.0\nmodel cycle 3\n")
    with pytest.raises(ExpressionError) as e:
        session.call(deck)
    assert "`model cycle` cannot run in a FISH callback" in e.value.message
    assert (e.value.location.file, e.value.location.line) == (str(deck), 6)
    assert session.model.step == 0 and session.fish_rt.in_callback == 0
    session.command("fish callback remove again\nmodel cycle 3\n[n = mech.cycle]")   # outside callbacks it runs
    assert session.variables["n"] == 3


def test_fish_history_and_callback_go_on_after_a_restore(session):
    session.command(BRICK + "fish define count\n  global n = n + 1\nend\n[n = 0]\nfish callback add count 1.0\n"
                    "history interval 2\nfish history n\nmodel cycle 4\nmodel save 'r'\nmodel new\nmodel restore 'r'\n"
                    "model cycle 4")
    h = session.model.history_set.find("n")
    assert h.steps == [2, 4, 6, 8] and h.values == [2.0, 4.0, 6.0, 8.0]
    assert session.variables["n"] == 8


def test_a_negative_callback_goes_on_after_a_restore_before_the_forces(session):
    """A -100 callback survives `model save|restore` and still runs before the step's forces: it gives the
    block a fresh applied force before step 3 (the step after the restore), and step 3 already moves it."""
    session.command(FREE.replace("mech.cycle = 0", "mech.cycle = 2") + "fish callback add pre -100\n"
                    "model cycle 2\nmodel save 'r'\nmodel new\nmodel restore 'r'\nfish callback list\nmodel cycle 1\n"
                    "[dt = mech.timestep]")
    out = session.output.getvalue().splitlines()
    assert out[out.index("-100  pre  interval 1  (before the step's forces)") + 1].startswith("model cycle: 1 steps")
    v = session.variables
    assert (v["sb"], v["vb"]) == (2, 0.0)
    assert session.model.blocks["velocity"][0, 0] == pytest.approx(500.0 * v["dt"] / 1000.0, rel=1e-12)


@pytest.mark.parametrize("cmd, msg, col", [("program list", "`program list` without a keyword is not supported yet", 1),
                                           ("program list information",
                                            "`program list` `information` is not supported yet", 14)])
def test_other_program_list_keywords_are_not_supported_yet(session, cmd, msg, col):
    from dec3d.errors import NotSupportedError

    with pytest.raises(NotSupportedError) as e:
        session.command(cmd)
    assert e.value.message == msg and e.value.location.column == col
