"""The engine keeps what its zone stepper derived from the model between commands
(``physics.zone_cache``): a deck that cycles in several commands, changing the model between
them, takes the same bits with the cache as with every stepper made anew, and every kind of
change between the commands acts (the numbers differ from a run without the change).

Each case runs `model cycle 5` three times on two stacked zoned blocks (elastic, gravity, base
held, jointed between them), with a change before the second and/or third command, three ways:
cache on, cache off (``zone_cache.ENABLED = False``: the stepper made anew every command) and
cache on without the change. A cache that kept a stale entry would match the run without the
change (or be off from the run with the cache off): ``test_a_cache_that_never_invalidates_
is_caught`` runs the cases that change cached inputs with a cache that takes every input for
unchanged, and checks that it gives other numbers."""
import io

import numpy as np
import pytest

import dec3d
from dec3d.model.zones import ZP_BULK, ZP_SHEAR
from dec3d.physics import zone_cache

DECK = """model new
block create brick 0 1 0 1 0 1
block create brick 0 1 0 1 1 2
block zone generate edgelength 0.4
block zone cmodel assign elastic
block zone property young 10e9 poisson 0.25 density 2500
block contact jmodel assign elastic
block contact material-table default property stiffness-normal 1e11 stiffness-shear 1e11
block gridpoint apply velocity 0 0 0 range position-z 0
model gravity 0 0 -10
"""


def _stiffer(s):
    """A Python-side write of the zones' moduli (no command: only the arrays change)."""
    zs = s.model.store("zones")
    zs["prop"][:, ZP_BULK] *= 2.0
    zs["prop"][:, ZP_SHEAR] *= 2.0


def _relink_none(s):
    """A Python-side change of the gridpoint links: the linked copies made their own masters."""
    s.model.vertices["link"][:] = -1


#: kind of change -> (before the 2nd command, before the 3rd): command text or a callable(session)
CHANGES = {
    "property": ("block zone property young 3e9 range position-z 1 2", None),
    "density": ("block zone property density 6000", None),
    "cmodel": ("block zone cmodel assign mohr-coulomb\n"
               "block zone property young 10e9 poisson 0.25 density 2500 cohesion 1e3 friction 30 tension 1e3", None),
    "excavate": ("block zone cmodel assign null range position-z 1.5 2", None),
    "delete": ("block delete range id 2", None),
    "fix": ("block gridpoint apply velocity-x 0 range position-x 1", "block gridpoint free range position-x 1"),
    "gravity": ("model gravity 0 0 -40", None),
    "python-props": (_stiffer, None),
    "restore": ("model save 'cache_a'\nblock zone property density 6000", "model restore 'cache_a'"),
    "nmd": ("block zone nodal-mixed-discretization off", None),
    "large-strain": ("model large-strain on", None),
    "insitu": ("block insitu stress -1e5 -1e5 -2e5 0 0 0", None),
}

#: the cases whose change reaches an input the cache keeps (a cache blind to it goes stale;
#: `model restore` makes a new model, whose engine starts a new cache)
CACHED_INPUTS = ["property", "density", "cmodel", "excavate", "python-props"]


def _state(s):
    m = s.model
    v, zs = m.vertices, m.store("zones")
    return {"pos": v["pos"].copy(), "velocity": v["velocity"].copy(), "disp": v["disp"].copy(),
            "imass": v["imass"].copy(), "mass": v["mass"].copy(), "stress": zs["stress"].copy(),
            "state": zs["state"].copy()}


def _run(tmp_path, kind, apply=True):
    s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command(DECK)
    s.command("model cycle 5")
    for change in CHANGES[kind]:
        if apply and change is not None:
            change(s) if callable(change) else s.command(change)
        s.command("model cycle 5")
    return _state(s), s


def _same(a, b):
    return all(a[k].shape == b[k].shape and np.array_equal(a[k], b[k]) for k in a)


@pytest.fixture
def cache_on(monkeypatch):
    monkeypatch.setattr(zone_cache, "ENABLED", True)


@pytest.mark.parametrize("kind", list(CHANGES))
def test_changes_between_commands_give_the_bits_of_fresh_steppers(tmp_path, monkeypatch, cache_on, kind):
    cached, s = _run(tmp_path, kind)
    ignored, _ = _run(tmp_path, kind, apply=False)
    monkeypatch.setattr(zone_cache, "ENABLED", False)
    fresh, _ = _run(tmp_path, kind)
    assert np.abs(cached["disp"]).max() > 0.0
    assert _same(cached, fresh), kind
    assert not _same(cached, ignored), f"{kind}: the change did nothing; the case tests nothing"


def test_unchanged_model_takes_the_kept_entries(tmp_path, cache_on):
    s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command(DECK)
    s.command("model cycle 5")
    c = s.model.rigid_engine._zcache
    first = list(c.builds)
    assert {"zones", "plan", "mass", "stiff"} <= set(first) and not c.hits
    s.command("model cycle 5")
    assert {"zones", "plan", "mass", "stiff"} <= set(c.hits) and c.builds == first
    # a property change: the zones' checks and moduli, the masses and stiffness again; the plan kept
    s.command("block zone property density 3000")
    del c.hits[:], c.builds[:]
    s.command("model cycle 5")
    assert {"zones", "mass", "stiff"} <= set(c.builds) and "plan" in c.hits


def test_a_property_warning_is_given_at_every_command(tmp_path, monkeypatch, cache_on):
    """Warnings of the property checks are not kept with the entry: each command gives them."""
    from dec3d.physics.cmodels import MODEL_BY_CODE
    from dec3d.physics.rigid import engine

    zm = next(z for z in MODEL_BY_CODE.values() if z.name == "elastic")
    old = zm.check

    def check(p, ids):
        more, warns = old(p, ids) if old is not None else ([], [])
        return more, warns + ["a warning"]
    monkeypatch.setattr(zm, "check", check)
    s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command(DECK)
    warned = []
    eng = engine(s.model)
    for _ in range(2):
        eng.cycle(2, warn=warned.append)
    assert sum("a warning" in w for w in warned) == 2


@pytest.mark.parametrize("kind", CACHED_INPUTS)
def test_a_cache_that_never_invalidates_is_caught(tmp_path, monkeypatch, cache_on, kind):
    """With ``same`` always true (inputs never seen to change) these cases give other numbers:
    the comparison of the test above would catch a cache that missed the change."""
    right, _ = _run(tmp_path, kind)
    monkeypatch.setattr(zone_cache, "same", lambda a, b: True)
    stale, _ = _run(tmp_path, kind)
    assert not _same(right, stale), kind


def test_links_changed_from_python_are_seen(tmp_path, monkeypatch, cache_on):
    """Two zoned blocks joined (linked gridpoints); the links written from Python between commands."""
    deck = DECK.replace("block zone generate edgelength 0.4", "block join\nblock zone generate edgelength 0.4")

    def run():
        s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
        s.command(deck)
        assert (s.model.vertices["link"] >= 0).any()
        s.command("model cycle 5")
        _relink_none(s)
        s.command("model cycle 5")
        return _state(s)

    cached = run()
    monkeypatch.setattr(zone_cache, "ENABLED", False)
    assert _same(cached, run())


def test_the_cache_is_off_with_the_environment_variable(tmp_path):
    import subprocess
    import sys

    code = "from dec3d.physics import zone_cache; print(zone_cache.ENABLED)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env={**__import__("os").environ, "DEC3D_NO_STEPPER_CACHE": "1"})
    assert out.stdout.strip() == "False"


def test_same_compares_bits():
    a = np.array([0.0, np.nan])
    assert zone_cache.same(a, a.copy())
    assert not zone_cache.same(a, np.array([-0.0, np.nan]))          # the sign of zero counts
    assert not zone_cache.same(a, a.astype(np.float32))              # and the dtype
    assert not zone_cache.same(a, a[:1])                             # and the shape
    assert zone_cache.same((a, 3), (a.copy(), 3)) and not zone_cache.same((a, 3), (a, 4))


def test_runs_of_rows_are_an_exact_copy():
    rng = np.random.default_rng(3)
    a = np.repeat(rng.normal(size=(4, 20)), [5, 1, 300, 7], axis=0)
    a[6:100, 3] = np.nan
    r = zone_cache.Runs.of(a)
    assert r is not None and len(r.starts) - 1 == 5          # (the NaN rows one run of their own)
    assert r.same(a.copy())
    for i, j in [(0, 0), (5, 19), (150, 3), (311, 0), (312, 19)]:
        b = a.copy()
        b[i, j] = -b[i, j] if b[i, j] != 0 else 1.0
        assert not r.same(b), (i, j)
    b = a.copy()
    b[200, 2] = np.copysign(0.0, -1.0) if a[200, 2] == 0.0 else np.nextafter(a[200, 2], np.inf)
    assert not r.same(b)                                                 # one ulp
    assert not r.same(a[:-1]) and not r.same(a.astype(np.float32))
    assert zone_cache.Runs.of(rng.normal(size=(zone_cache.MAX_RUNS + 1, 3))) is None   # (kept as a plain copy)


def test_a_property_of_one_zone_written_from_python_is_seen(tmp_path, monkeypatch, cache_on):
    """The kept runs of the properties see a change of one value of one zone in a run of equal rows."""
    def run():
        s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
        s.command(DECK)
        s.command("model cycle 5")
        zs = s.model.store("zones")
        zs["prop"][zs.n // 2, ZP_BULK] *= 3.0
        s.command("model cycle 5")
        return _state(s)

    cached = run()
    monkeypatch.setattr(zone_cache, "ENABLED", False)
    assert _same(cached, run())


#: other meshes and models: hexahedral zones (mixed discretization sets), 10-node tetrahedra,
#: Mohr-Coulomb zones that yield (the plastic step's scratch in the kept plan)
SCENES = {
    "hexahedra": DECK.replace("block zone generate edgelength 0.4", "block zone generate hexahedra divisions 2 2 2"),
    "ten-node": DECK.replace("model new\n", "model new\nmodel configure highorder\n").replace(
        "block zone generate edgelength 0.4", "block zone generate edgelength 0.5\nblock zone generate high-order-tetra"),
    "mohr": DECK.replace("block zone property young 10e9 poisson 0.25 density 2500",
                         "block zone cmodel assign mohr-coulomb\nblock zone property young 10e9 poisson 0.25 density 2500 "
                         "cohesion 2e3 friction 30 tension 1e3"),
}


@pytest.mark.parametrize("scene", list(SCENES))
@pytest.mark.parametrize("change", ["block zone property density 6000 range position-z 1 2",
                                    "block zone cmodel assign null range position-z 1.5 2"])
def test_other_meshes_and_models(tmp_path, monkeypatch, cache_on, scene, change):
    def run(apply=True):
        s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
        s.command(SCENES[scene])
        s.command("model cycle 4")
        if apply:
            s.command(change)
        s.command("model cycle 4")
        s.command("model cycle 4")
        return _state(s), s

    cached, s = run()
    assert "plan" in s.model.rigid_engine._zcache.hits or scene == "ten-node"
    ignored, _ = run(apply=False)
    monkeypatch.setattr(zone_cache, "ENABLED", False)
    fresh, _ = run()
    assert _same(cached, fresh) and not _same(cached, ignored)


@pytest.mark.skipif(__import__("numba").config.NUMBA_NUM_THREADS < 2, reason="needs two numba threads")
def test_a_new_thread_count_makes_the_plan_again(tmp_path, monkeypatch, cache_on):
    """The plan's chunks follow the thread count (one chunk per thread; any count gives the same bits)."""
    import numba

    import dec3d.physics.zones as pz

    monkeypatch.setattr(pz, "PARALLEL_MIN_ZONES", 0)
    keep = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
        s.command(DECK)
        s.command("model cycle 3")
        assert len(s.model.rigid_engine._zstep.fast.pstart) == 2
        numba.set_num_threads(2)
        s.command("model cycle 3")
        assert len(s.model.rigid_engine._zstep.fast.pstart) == 3
        numba.set_num_threads(1)
        s.command("model cycle 3")
        cached = _state(s)
    finally:
        numba.set_num_threads(keep)
    monkeypatch.setattr(zone_cache, "ENABLED", False)
    s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command(DECK)
    s.command("model cycle 9")
    assert _same(cached, _state(s))
