"""Two cores (issue 9): the parallel kernels give bit-identical results whatever the number of
threads; the thread count is set by `model configure threads n` or DEC3D_THREADS and reported;
dec3d's worker processes are spawned (GNU OpenMP, the first threading layer, aborts a forked child)
and run the kernels after the parent did."""
import io
import multiprocessing
import os
import subprocess
import sys
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

from conftest import ROOT
from dec3d import config
from dec3d.errors import BindError, CommandError
from dec3d.kernels import cycle
from dec3d.kernels.jointlaw import block_lists, block_sums

TWO = pytest.mark.skipif(config.max_threads() < 2, reason="numba may use only one thread here")

#: a 3 x 3 x 3 stack of unit cubes on a fixed base (the bench scene), mohr joints
STACK = ["model new", "block create brick 0 3 0 3 -1 0"] + [
    f"block create brick {i} {i + 1} {j} {j + 1} {k} {k + 1}" for i in range(3) for j in range(3) for k in range(3)
] + ["block property density 2600", "block fix range position-z -1 0",
     "block contact jmodel assign mohr",
     "block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 friction 34 "
     "cohesion 0 tension 0"]

#: the damping modes and body kinds the kernels branch on; each runs 200 steps
SCENES = {
    "local": ["model gravity 0 0 -9.81", "block mechanical damping local 0.8"],
    # every block slides and keeps moving: no damping, full inertia (Euler's equations)
    "sliding": ["model gravity 4 0 -9.81", "block mechanical damping none",
                "block contact material-table default property friction 5"],
    "combined": ["model gravity 0.5 0 -9.81", "block mechanical damping combined 0.7"],
    "global": ["model gravity 0 0.5 -9.81", "block mechanical damping global"],
    # joined blocks move as groups of several members
    "joined": ["block join on range position-z 1 3", "model gravity 1 0.5 -9.81", "block mechanical damping none"],
}


@pytest.fixture
def restore_threads():
    n = config.threads()
    yield
    config.set_threads(n)


def _state(scene: str, threads: int, tmp_path) -> dict:
    """Every array of the model after the scene's 200 steps at ``threads`` threads."""
    from dec3d.session import Session

    config.set_threads(threads)
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command("\n".join(STACK + SCENES[scene] + ["model cycle 200"]) + "\n")
    m = s.model
    out = {f"blocks/{k}": np.array(m.blocks[k]) for k in m.blocks.fields}
    out["vertices/pos"] = np.array(m.vertices["pos"])
    for st in ("contacts", "subcontacts"):
        out.update({f"{st}/{k}": np.array(a) for k, a in m.stores[st].to_arrays().items()})
    out["time"] = np.array([m.time, m.step, m.rigid_engine.kinetic])
    return out


@TWO
@pytest.mark.parametrize("scene", sorted(SCENES))
def test_one_and_two_threads_give_the_same_bits(scene, tmp_path, restore_threads, monkeypatch):
    # one thread runs the serial twins of the kernels; these scenes are small, so the parallel
    # kernels run on two threads only when the size switch is lowered
    monkeypatch.setattr(cycle, "SERIAL_BELOW", 0)
    one = _state(scene, 1, tmp_path)
    two = _state(scene, 2, tmp_path)
    assert one.keys() == two.keys()
    assert one["time"][1] == 200 and len(one["subcontacts/fn"]) > 0
    # the blocks did move (a scene at rest would compare nothing)
    assert np.abs(one["blocks/disp"]).max() > 1e-6
    assert [k for k in one if not np.array_equal(one[k], two[k], equal_nan=True)] == []


def _scatter_twin(nb, ca, cb, owner, pos, centroid, g):
    """The sums as a plain serial scatter over the sub-contacts: force g[s] on B, −g[s] on A,
    moments (x − centroid) × force, in sub-contact order."""
    f = np.zeros((nb, 3))
    m = np.zeros((nb, 3))
    for s in range(len(owner)):
        a, b = ca[owner[s]], cb[owner[s]]
        rb = pos[s] - centroid[b]
        ra = pos[s] - centroid[a]
        for i in range(3):
            f[b, i] = f[b, i] + g[s, i]
        for i in range(3):
            f[a, i] = f[a, i] - g[s, i]
        mb = (rb[1] * g[s, 2] - rb[2] * g[s, 1], rb[2] * g[s, 0] - rb[0] * g[s, 2], rb[0] * g[s, 1] - rb[1] * g[s, 0])
        ma = (ra[1] * g[s, 2] - ra[2] * g[s, 1], ra[2] * g[s, 0] - ra[0] * g[s, 2], ra[0] * g[s, 1] - ra[1] * g[s, 0])
        for i in range(3):
            m[b, i] = m[b, i] + mb[i]
            m[a, i] = m[a, i] - ma[i]
    return f, m


@pytest.mark.parametrize("threads", [1, 2])
def test_block_sums_equal_a_serial_scatter_bit_for_bit(threads, restore_threads):
    """Per-block lists summed in parallel give exactly the serial scatter's sums (same order)."""
    if threads > config.max_threads():
        pytest.skip("numba may use only one thread here")
    config.set_threads(threads)
    rng = np.random.default_rng(7)
    nb, nc = 40, 150
    ca = rng.integers(0, nb, nc)
    cb = (ca + rng.integers(1, nb, nc)) % nb              # never the same block
    owner = np.sort(rng.integers(0, nc, 700))
    pos = rng.normal(size=(700, 3)) * 3.0
    centroid = rng.normal(size=(nb, 3))
    g = rng.normal(size=(700, 3)) * 1e5
    bstart, bent = block_lists(nb, ca, cb, owner)
    # the lists: every sub-contact twice (once per side), ascending per block
    assert bstart[-1] == 2 * len(owner)
    for x in range(nb):
        ent = bent[bstart[x]:bstart[x + 1]]
        assert list(ent) == sorted(ent)
        assert all((cb[owner[e >> 1]] if e % 2 == 0 else ca[owner[e >> 1]]) == x for e in ent)
    f = np.zeros((nb, 3))
    m = np.zeros((nb, 3))
    block_sums(centroid, f, m, pos, g, bstart, bent)
    tf, tm = _scatter_twin(nb, ca, cb, owner, pos, centroid, g)
    assert np.array_equal(f, tf) and np.array_equal(m, tm)
    assert np.abs(f.sum(axis=0)).max() < 1e-6 * np.abs(g).sum()        # action = reaction


# ------------------------------------------------------------------ the thread count
@TWO
def test_model_configure_threads_sets_and_reports(session, restore_threads):
    session.command("model configure threads 1\n")
    assert config.threads() == 1
    assert f"threads 1 of {config.max_threads()}" in session.output.getvalue()
    session.command("model configure threads 2\nmodel configure threads\n")
    assert config.threads() == 2
    assert session.output.getvalue().count(f"threads 2 of {config.max_threads()}") == 2
    # a setting of the program: `model new` keeps it, the model's options do not hold it
    session.command("model new\n")
    assert config.threads() == 2 and "threads" not in session.model.settings.configure
    session.command("\n".join(STACK + ["model gravity 0 0 -9.81", "model cycle 3 timing"]) + "\n")
    tail = session.output.getvalue().rstrip().splitlines()
    cut = max(i for i, ln in enumerate(tail) if "model cycle 3 timing" in ln or ln.startswith("model cycle:"))
    assert any("threads 2 of" in ln for ln in tail[cut - 8:]), tail[-10:]    # the timing report, then the cycle's


@pytest.mark.parametrize("line, err, col, text", [
    ("model configure threads 0", BindError, 25, "`n` must be ≥ 1, got 0"),
    ("model configure threads 1.5", BindError, 25, "expected an integer"),
    ("model configure threads x", BindError, 25, "unknown keyword `x`"),
    ("model configure dynamic 2", BindError, 25, "`model configure dynamic` takes no value"),
])
def test_bad_thread_counts_are_bind_errors(session, line, err, col, text, restore_threads):
    n = config.threads()
    with pytest.raises(err) as e:
        session.load_text(line + "\n")
    assert e.value.location.line == 1 and e.value.location.column == col
    assert text in str(e.value)
    assert config.threads() == n


def test_more_threads_than_cores_is_a_command_error(session, restore_threads):
    n = config.threads()
    top = config.max_threads()
    with pytest.raises(CommandError) as e:
        session.command(f"model configure threads {top + 1}\n")
    assert f"from 1 to {top}" in str(e.value) and f"got {top + 1}" in str(e.value)
    assert e.value.location.line == 1
    assert config.threads() == n


def _omp_loads() -> bool:
    """Whether numba's OpenMP layer loads here (it needs the system's libgomp)."""
    r = subprocess.run([sys.executable, "-c", "import numba.np.ufunc.omppool"], capture_output=True, timeout=600)
    return r.returncode == 0


def _fresh(env_extra: dict) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_THREADING_LAYER")}
    env.update(env_extra, PYTHONPATH=str(ROOT))
    code = ("import dec3d, numpy as np\n"
            "from dec3d.config import threads, threading_layer\n"
            "from dec3d.kernels.cycle import _move_points\n"
            "p = np.zeros((4, 3)); z = np.zeros((2, 3))\n"
            "_move_points(1.0, np.array([0]), np.array([1]), np.zeros(4, np.int64), p, z, z, z)\n"
            "print(threads(), threading_layer())\n")
    return subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=600)


@TWO
def test_dec3d_threads_environment_variable(tmp_path):
    r = _fresh({"DEC3D_THREADS": "1"})
    assert r.returncode == 0, r.stderr
    n, layer = r.stdout.split()
    assert n == "1"
    # GNU OpenMP where the system has libgomp, else numba's workqueue (TBB hung in numba's fork handler)
    assert layer == ("omp" if _omp_loads() else "workqueue")
    r = _fresh({"DEC3D_THREADS": "two"})
    assert r.returncode == 0 and "DEC3D_THREADS='two' is not a whole number" in r.stderr
    r = _fresh({"DEC3D_THREADS": "999"})
    assert r.returncode == 0 and "more than the" in r.stderr
    assert r.stdout.split()[0] == str(config.max_threads())


def test_init_threads_reads_the_variable_and_keeps_a_chosen_layer(restore_threads):
    env = {"NUMBA_THREADING_LAYER": "workqueue", "DEC3D_THREADS": "1"}
    assert config.init_threads(env) is None
    assert config.threads() == 1
    assert "NUMBA_THREADING_LAYER_PRIORITY" not in env          # the user's choice is left alone
    env = {"DEC3D_THREADS": "0"}
    assert "not a whole number ≥ 1" in config.init_threads(env)
    assert env["NUMBA_THREADING_LAYER_PRIORITY"].split() == ["omp", "workqueue", "tbb"]
    assert config.init_threads({}) is None


def test_init_threads_shortens_openmp_spinning_unless_the_user_set_it():
    """GNU OpenMP's idle workers spin 1 000 rounds, not libgomp's 300 000, before they sleep (two
    processes on two cores held each other's cores); a count or a wait policy of the user stays."""
    env = {}
    config.init_threads(env)
    assert env["GOMP_SPINCOUNT"] == "1000"
    env = {"GOMP_SPINCOUNT": "50"}
    config.init_threads(env)
    assert env["GOMP_SPINCOUNT"] == "50"
    env = {"OMP_WAIT_POLICY": "active"}
    config.init_threads(env)
    assert "GOMP_SPINCOUNT" not in env
    code = "import os, dec3d; print(os.environ['GOMP_SPINCOUNT'])"
    # a process started without it gets it at import
    env = {k: v for k, v in os.environ.items() if k not in ("GOMP_SPINCOUNT", "OMP_WAIT_POLICY")}
    out = subprocess.run([sys.executable, "-c", code], env=dict(env, PYTHONPATH=str(ROOT)), capture_output=True,
                         text=True, timeout=600)
    assert out.returncode == 0 and out.stdout.strip() == "1000", out.stderr


def _child_run(scene: str, out: str) -> dict:
    from pathlib import Path

    cycle.SERIAL_BELOW = 0                  # the parallel kernels, however small the model
    return _state(scene, 2, Path(out))


@TWO
def test_a_spawned_worker_runs_the_kernels_after_the_parent_did(tmp_path, restore_threads, monkeypatch):
    """dec3d's worker processes are spawned, not forked: a child forked after GNU OpenMP ran aborts
    in its first parallel kernel. The factor-of-safety pool says so, and a spawned child's run, after
    the parent's parallel kernels, gives the parent's numbers."""
    from dec3d.physics import fos

    monkeypatch.setattr(cycle, "SERIAL_BELOW", 0)          # the parallel kernels
    mine = _state("sliding", 2, tmp_path)
    import concurrent.futures as cf

    made = []

    class Made(Exception):
        pass

    def pool(**kw):
        made.append(kw)
        raise Made

    monkeypatch.setattr(cf, "ProcessPoolExecutor", pool)
    trials = fos.FileTrials.__new__(fos.FileTrials)
    trials.path, trials.args, trials.workers, trials.log, trials._pool = "x", (), 2, [], None
    with pytest.raises(Made):
        trials([1.0, 2.0])
    assert made[0]["mp_context"].get_start_method() == "spawn"
    with ProcessPoolExecutor(max_workers=1, mp_context=multiprocessing.get_context("spawn")) as pool:
        theirs = pool.submit(_child_run, "sliding", str(tmp_path)).result(timeout=600)
    assert [k for k in mine if not np.array_equal(mine[k], theirs[k], equal_nan=True)] == []


def test_the_serial_threshold_follows_the_threading_layer(monkeypatch):
    """OpenMP's spinning workers start a loop at once, the workqueue's are woken for each: a small
    model runs its parallel kernel from 1 000 units of work with OpenMP, 60 000 with the workqueue;
    a threshold set by hand wins."""
    import numba

    monkeypatch.setattr(cycle, "SERIAL_BELOW", None)
    below = cycle.serial_below()                    # (starts the layer if nothing parallel ran yet)
    layer = numba.threading_layer()
    assert below == {"omp": 1000}.get(layer, 60000)
    monkeypatch.setattr(cycle, "SERIAL_BELOW", 7)
    assert cycle.serial_below() == 7
