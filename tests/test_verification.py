"""Every verification folder runs and meets its bar (the same checks `dec3d verify` prints)."""
import pytest

from conftest import ROOT
from dec3d.verify import check_problem, problems

FOLDERS = problems(ROOT / "verification")


@pytest.mark.parametrize("folder", FOLDERS, ids=lambda p: p.name)
def test_problem_meets_its_bar(folder):
    checks = check_problem(folder)
    assert checks, f"{folder.name}: problem.toml has no [[expect]]"
    for c in checks:
        print(f"{c.problem}: {c.quantity} = {c.measured} (expected {c.expected})")
    failed = [c for c in checks if c.passed is False]
    assert not failed, "\n".join(f"{c.quantity}: measured {c.measured}, expected {c.expected}" for c in failed)


def test_verify_table(tmp_path, capsys):
    """`dec3d verify` on a made-up problem: passes, fails and report-only rows are shown and counted."""
    from dec3d.verify import main

    p = tmp_path / "X1_demo"
    p.mkdir()
    (p / "deck.dat").write_text("[a = 2.0 * 3]\n[b = 7.0]\n")
    (p / "problem.toml").write_text(
        'title = "demo"\nkind = "deck"\ndeck = "deck.dat"\nsource = "arithmetic"\n'
        '[[expect]]\nquantity = "a"\nvalue = 6.0\nrel_tol = 1e-12\n'
        '[[expect]]\nquantity = "a"\nbelow = "b"\n'
        '[[expect]]\nquantity = "b"\nvalue = 8.0\nabs_tol = 0.5\n'
        '[[expect]]\nquantity = "b"\nvalue = 1.0\nreport_only = true\n')
    assert main(root=tmp_path) == 1
    out = capsys.readouterr().out
    assert out.count("PASS") == 2 and out.count("FAIL") == 1 and "report" in out
    assert "2 passed, 1 failed" in out
