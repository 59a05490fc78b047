"""`block zone generate edgelength`: zones installed on blocks, volumes sum to block volume,
already zoned blocks skipped, budget refused before allocating."""
import numpy as np
import pytest

from dec3d.errors import Dec3dError


def test_zone_generate_brick(session):
    session.command("block create brick 0 1 0 1 0 1\nblock zone generate edgelength 0.25")
    zs = session.model.store("zones")
    n1 = zs.n
    assert n1 > 0
    assert abs(zs["volume"][:n1].sum() - 1.0) < 1e-12
    assert (zs["volume"][:n1] > 0).all()
    session.command("block zone generate edge-length 0.1")
    assert session.model.store("zones").n == n1


def test_zone_budget_refused(session):
    session.command("block create brick 0 10 0 10 0 10")
    with pytest.raises(Dec3dError, match=r"would make about .* zones"):
        session.command("block zone generate edgelength 0.01")
    assert "zones" not in session.model.stores or session.model.store("zones").n == 0
