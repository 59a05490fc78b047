"""Every verification/S*/problem.toml through dec3d.ssdem.verify.quantities."""
import math
import tomllib
from pathlib import Path

import pytest

from dec3d.ssdem.verify import quantities

ROOT = Path(__file__).resolve().parents[2]
PROBLEMS = sorted(p.parent for p in (ROOT / "verification").glob("S*/problem.toml"))


def test_problems_exist():
    names = {p.name for p in PROBLEMS}
    assert {"S1_fredlund_krahn_slope", "S1_ru025", "S2_kim_dam"} <= names


@pytest.mark.parametrize("folder", PROBLEMS, ids=lambda p: p.name)
def test_expectations(folder):
    spec = tomllib.loads((folder / "problem.toml").read_text())
    assert spec["kind"] == "ssdem"
    q = quantities(folder, spec)
    checked = 0
    for e in spec["expect"]:
        if e.get("report_only"):
            continue
        got = q[e["quantity"]]
        if "below" in e:
            assert got < q[e["below"]], f"{e['quantity']} = {got} not below {e['below']} = {q[e['below']]}"
        elif "rel_tol" in e:
            assert math.isclose(got, e["value"], rel_tol=e["rel_tol"]), f"{e['quantity']} = {got}, expected {e['value']}"
        else:
            assert abs(got - e["value"]) <= e["abs_tol"], f"{e['quantity']} = {got}, expected {e['value']}"
        checked += 1
    assert checked >= 1
