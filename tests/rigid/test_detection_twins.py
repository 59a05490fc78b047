"""The detection kernels with a parallel loop are compiled serial, with a parallel twin for large
models on more than one thread (``contactmap.threaded``; a cold start compiles only the one a deck
uses): the twin gives the same numbers, bit for bit, and a model detected by the twins ends in the
same state as one detected serially."""
import io

import numpy as np
import pytest

from dec3d import config
from dec3d.kernels import contactmap
from dec3d.kernels.contactmap import cp_batch, cp_batch_parallel, subcontact_gaps, subcontact_gaps_parallel

TWO = pytest.mark.skipif(config.max_threads() < 2, reason="numba may use only one thread here")

#: a 2 x 2 x 2 stack of unit cubes, a little apart and turned, on a fixed base; blocks slide
SCENE = ["model new", "block create brick -1 3 -1 3 -1 0"] + [
    f"block create brick {i + 0.1 * k} {i + 1 + 0.1 * k} {j} {j + 1} {k + 0.001 * (i + j)} {k + 1 + 0.001 * (i + j)}"
    for i in range(2) for j in range(2) for k in range(2)
] + ["block property density 2600", "block fix range position-z -1 0", "block contact jmodel assign mohr",
     "block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 friction 10",
     "model gravity 3 1 -9.81", "block mechanical damping none"]


@pytest.fixture
def restore_threads():
    n = config.threads()
    yield
    config.set_threads(n)


def test_threaded_picks_the_twin_only_for_many_items_on_several_threads(restore_threads):
    config.set_threads(1)
    assert contactmap.threaded(cp_batch, 10 ** 6) is cp_batch
    assert contactmap.threaded(subcontact_gaps, 10 ** 6) is subcontact_gaps
    if config.max_threads() >= 2:
        config.set_threads(2)
        assert contactmap.threaded(cp_batch, contactmap.PARALLEL_FROM) is cp_batch_parallel
        assert contactmap.threaded(subcontact_gaps, contactmap.PARALLEL_FROM) is subcontact_gaps_parallel
        assert contactmap.threaded(cp_batch, contactmap.PARALLEL_FROM - 1) is cp_batch


def _run(threads: int, tmp_path) -> dict:
    from dec3d.session import Session

    config.set_threads(threads)
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command("\n".join(SCENE + ["model cycle 150"]) + "\n")
    m = s.model
    out = {f"blocks/{k}": np.array(m.blocks[k]) for k in m.blocks.fields}
    out["vertices/pos"] = np.array(m.vertices["pos"])
    for st in ("contacts", "subcontacts"):
        store = m.store(st)
        out.update({f"{st}/{k}": np.array(store[k]) for k in store.fields})
    return out


@TWO
def test_a_model_detected_by_the_parallel_twins_matches_the_serial_run(tmp_path, monkeypatch, restore_threads):
    """Every pass through the twins (PARALLEL_FROM 1, two threads) against the serial kernels on one
    thread: every block, contact and sub-contact array equal bit for bit after 150 sliding steps."""
    serial = _run(1, tmp_path)
    calls = []
    for name in ("cp_batch_parallel", "subcontact_gaps_parallel"):
        twin = getattr(contactmap, name)

        def counted(*args, _twin=twin, _name=name):
            calls.append(_name)
            return _twin(*args)
        monkeypatch.setattr(contactmap, name, counted)
    monkeypatch.setattr(contactmap, "PARALLEL_FROM", 1)
    parallel = _run(2, tmp_path)
    assert {"cp_batch_parallel", "subcontact_gaps_parallel"} <= set(calls)
    assert serial.keys() == parallel.keys()
    assert len(serial["subcontacts/area"]) > 8          # the stack is in contact
    assert float(np.abs(serial["blocks/velocity"]).max()) > 1e-3    # and moving
    assert [k for k in serial if not np.array_equal(serial[k], parallel[k], equal_nan=True)] == []
