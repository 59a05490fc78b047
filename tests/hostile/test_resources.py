"""Resources are estimated before they are spent: joint sets and tunnels work out their block count
first and stop with the estimate when it is over the budget (`model budget`); expressions keep
integers to 64 bits, reals finite and strings short, and nest to any depth without recursion."""
import subprocess
import sys

import pytest

from conftest import ROOT
from dec3d.check import check_text
from dec3d.commands.budget import BYTES_PER_BLOCK, Budget
from dec3d.errors import ExpressionError, ResourceError
from dec3d.geometry.cutting import joint_set_estimate

HINT = "raise it with `model budget blocks <n> memory <GiB>` if the machine has the memory"


def _refused(session, tmp_path, text):
    deck = tmp_path / "deck.dat"
    deck.write_text(text)
    with pytest.raises(ResourceError) as e:
        session.call(deck)
    return e.value


def test_tiny_spacing_on_a_10m_cube_is_refused_with_the_estimate(session, tmp_path):
    # issue 15: MemoryError after 54 s. 10 m / 1e-6 m = 1e7 planes, 9 999 999 inside the cube
    e = _refused(session, tmp_path, "block create brick 0 10 0 10 0 10\nblock cut joint-set spacing 1e-6\n")
    assert e.message == ("this joint set would make about 9,999,999 new blocks (10,000,000 in all, about 47.7 GiB); "
                         "the budget allows 1,000,000 blocks and 4 GiB")
    assert e.hint == HINT
    assert (e.location.line, e.location.column) == (2, 1)
    assert session.model.blocks.n == 1                      # nothing was cut


def test_a_huge_number_of_joints_costs_only_the_planes_that_meet_a_block(session):
    # `number 1000000000` with spacing 1 m: only z = 1 .. 9 cross the 10 m cube (z = 0 is its face)
    session.command("block create brick 0 10 0 10 0 10\nblock cut joint-set spacing 1 number 1000000000")
    assert session.model.blocks.n == 10
    assert sorted(round(v, 9) for v in session.model.blocks["volume"]) == [100.0] * 10


def test_a_huge_number_with_a_tiny_spacing_is_refused(session, tmp_path):
    # 1e9 joints 1 µm apart from z = 0: the 999 999 inside a 1 m cube make 1e6 blocks (4.8 GiB > 4 GiB)
    e = _refused(session, tmp_path, "block create brick 0 1 0 1 0 1\nblock cut joint-set spacing 1e-6 number 1000000000\n")
    assert e.message.startswith("this joint set would make about 999,999 new blocks (1,000,000 in all, about 4.8 GiB)")


def test_three_closely_spaced_sets_are_refused_at_the_set_that_is_too_many(session, tmp_path):
    # 0.5 m sets on a 10 m cube: 20, then 400, then 8 000 blocks; a budget of 5 000 stops the third
    e = _refused(session, tmp_path, "model budget blocks 5000\nblock create brick 0 10 0 10 0 10\n"
                 "block cut joint-set spacing 0.5\nblock cut joint-set spacing 0.5 dip 90\n"
                 "block cut joint-set spacing 0.5 dip 90 dip-direction 90\n")
    assert e.message == ("this joint set would make about 7,600 new blocks (8,000 in all, about 0.0 GiB); "
                         "the budget allows 5,000 blocks and 4 GiB")
    assert e.location.line == 5 and session.model.blocks.n == 400


def test_the_estimate_of_the_issue_case_is_exact(session):
    # the 0.02 m sets of issue 15: 500 slabs, then each cut by 499 planes -> 249 500 new blocks
    session.command("block create brick 0 10 0 10 0 10\nblock cut joint-set spacing 0.02")
    assert session.model.blocks.n == 500
    import math
    new = joint_set_estimate(session.model, math.radians(90), 0.0, spacing=0.02)
    assert new == 500 * 499


def test_raising_the_budget_lets_the_cut_run(session):
    session.command("model budget blocks 100\nblock create brick 0 10 0 10 0 10\n"
                    "block cut joint-set spacing 1\nblock cut joint-set spacing 1 dip 90")
    assert session.model.blocks.n == 100                    # exactly at the budget: allowed
    with pytest.raises(ResourceError, match="about 900 new blocks"):
        session.command("block cut joint-set spacing 1 dip 90 dip-direction 90")
    session.command("model budget blocks 1000\nblock cut joint-set spacing 1 dip 90 dip-direction 90")
    assert session.model.blocks.n == 1000


def test_the_memory_limit_counts_too_and_model_new_keeps_the_budget(session):
    # 0.001 GiB at 5 KiB a block allows 209 blocks
    session.command("model budget memory 0.001")
    assert session.budget.max_blocks() == int(0.001 * 1024 ** 3 / BYTES_PER_BLOCK) == 209
    session.command("model new\nblock create brick 0 10 0 10 0 10")
    with pytest.raises(ResourceError, match=r"about 999 new blocks \(1,000 in all"):
        session.command("block cut joint-set spacing 0.01")
    assert session.model.blocks.n == 1


def test_model_budget_prints_it_and_refuses_bad_values(session):
    session.command("model budget")
    assert session.output.getvalue().splitlines()[-1] == "budget: 1,000,000 blocks, 4 GiB (at most 838,860 blocks)"
    with pytest.raises(Exception) as e:
        session.command("model budget blocks 0")
    assert e.value.message == "`blocks` must be in [1, 1e+12], got 0"
    assert session.budget == Budget()


def test_a_tunnel_with_too_many_rings_is_refused_with_its_count(session, tmp_path):
    # 1000 slices x (8 x 10 rays) x (1000 rings + the opening prism) = 80 080 000 blocks
    e = _refused(session, tmp_path, "block create tunnel radius 1 length 0 10 boundary 9 blocks-axial 1000 "
                 "blocks-radial 1000 blocks-tangential 10\n")
    assert e.message == ("this tunnel would make about 80,080,000 new blocks (80,080,000 in all, about 381.9 GiB); "
                         "the budget allows 1,000,000 blocks and 4 GiB")
    assert session.model.blocks.n == 0


def test_a_tunnel_makes_the_count_it_estimated(session):
    session.command("block create tunnel radius 1 length 0 2 boundary 4 blocks-axial 2 blocks-radial 3 "
                    "blocks-tangential 1")
    assert session.model.blocks.n == 2 * 8 * 1 * (3 + 1)


@pytest.mark.parametrize("expr, message", [
    ("[x = 2^2^2^2^2^2]", "integer overflow: the result does not fit in 64 bits (write a float, e.g. 2.0)"),
    ("[x = 10^100000000]", "integer overflow: the result does not fit in 64 bits (write a float, e.g. 2.0)"),
    ("[x = 9223372036854775807 + 1]", "integer overflow: the result does not fit in 64 bits (write a float, e.g. 2.0)"),
    ("[x = 1e308 * 10]", "numeric overflow: the result is not a finite number"),
    ("[x = 10.0^400]", "numeric overflow: the result is not a finite number"),
    ("[x = math.exp(1000)]", "`math.exp`: numeric overflow: the result for 1000 is too large"),
])
def test_expression_results_are_capped(session, expr, message):
    with pytest.raises(ExpressionError) as e:
        session.command(expr)
    assert e.value.message == message
    assert "x" not in session.variables


def test_a_string_doubled_forty_times_stops_at_the_length_limit(session):
    lines = ["[s = 'ab']"] + ["[s = s + s]"] * 40
    with pytest.raises(ExpressionError) as e:
        session.command("\n".join(lines))
    # 'ab' doubled k times is 2^(k+1) characters: the 19th doubling (line 20) is the first over 1 000 000
    assert e.value.message == "string longer than 1000000 characters"
    assert e.value.location.line == 20
    assert len(session.variables["s"]) == 2 ** 19


def test_deep_expressions_evaluate_without_recursion(session):
    n = 5000
    session.command("[a = " + "+".join(["1"] * n) + "]")
    session.command("[b = " + "(" * n + "2" + ")" * n + "]")
    session.command("[c = " + "-" * (n + 1) + "3]")               # odd number of minus signs
    session.command("[d = " + "not " * n + "false]")
    session.command("[e = " + "*".join(["1.0001"] * n) + "]")
    assert session.variables["a"] == n and session.variables["b"] == 2 and session.variables["c"] == -3
    assert session.variables["d"] is False
    assert session.variables["e"] == pytest.approx(1.0001 ** n, rel=1e-9)


def test_dec3d_check_reads_a_deep_expression(tmp_path):
    reports = check_text("[a = " + "+".join(["1"] * 3000) + "]\nmodel cycle [a]\n", "deep.dat")
    assert [(r.line, r.status) for r in reports] == [(1, "runnable"), (2, "runnable")]
    deck = tmp_path / "deep.dat"
    deck.write_text("[x = 1]\n[a = " + "+".join(["x"] * 3000) + "]\n")
    r = subprocess.run([sys.executable, "-m", "dec3d", "check", str(deck)], capture_output=True, text=True,
                       cwd=ROOT, timeout=120)
    assert "Traceback" not in r.stdout + r.stderr
    assert r.returncode == 0 and r.stdout.startswith(f"{deck}: 2 runnable\n")


def test_cli_run_stops_with_the_estimate_and_no_traceback(tmp_path):
    deck = tmp_path / "cut.dat"
    deck.write_text("block create brick 0 10 0 10 0 10\nblock cut joint-set spacing 1e-6\n")
    r = subprocess.run([sys.executable, "-m", "dec3d", "run", str(deck), "-q", "--out", str(tmp_path / "o")],
                       capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert r.returncode == 1 and "Traceback" not in r.stderr
    assert r.stderr.splitlines()[0] == (f"{deck}:2:1: error: this joint set would make about 9,999,999 new blocks "
                                        "(10,000,000 in all, about 47.7 GiB); the budget allows 1,000,000 blocks "
                                        "and 4 GiB")
