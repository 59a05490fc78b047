"""`model factor-of-safety` with zones: the zone strengths are reduced by each model's registry
``reduce`` together with the `mohr` joints (Itasca, "Strength Reduction Procedure in FLAC3D and
3DEC"), the model is put back bit for bit after a trial, a zones-only model gets its factor of
safety (closed form), and a model with nothing to reduce is refused. The slope and cut checks are
verification/F2_griffiths_lane_slope and F3_vertical_cut."""

import numpy as np
import pytest

from dec3d.errors import CommandError
from dec3d.kernels.joints.mohr import CODE as MOHR
from dec3d.kernels.joints.mohr import P_COH, P_TANF
from dec3d.physics.cmodels import MODEL_BY_CODE, NZPROP, P_COHESION, P_SRF, P_TANDIL, P_TANFRIC, P_TENSION
from dec3d.physics.fos import StrengthTrials, reduce_zone_rows, reducible_zones
from dec3d.physics.rigid import engine

# One hexahedral zone (two overlaid 5-tetrahedron sets), 1 m cube, phi = 0 (Tresca), free to expand
# sideways (rollers on x = 0, y = 0 and the base z = 0), under its own weight. Lumped gravity puts
# half the weight on the top gridpoints, so the zone carries the uniform uniaxial stress
# sigma_zz = -rho g h / 2 = -1e4 Pa (sigma_xx = sigma_yy = 0). Tresca (Mohr-Coulomb, phi = 0) yields at
# |sigma_zz| = 2 c, and then nothing holds the top's weight: the column collapses once
# c / F < rho g h / 4, so FS = 4 c / (rho g h) = 4 * 7500 / 2e4 = 1.5.
COLUMN = """model new
block create brick 0 1 0 1 0 1
block zone generate hexahedra divisions 1 1 1
block zone cmodel assign mohr-coulomb
block zone property young 1e8 poisson 0.3 density 2000 cohesion 7500 friction 0 tension 1e10
model gravity 0 0 -10
block gridpoint apply velocity-z 0 range position-z 0
block gridpoint apply velocity-x 0 range position-x 0
block gridpoint apply velocity-y 0 range position-y 0
model solve ratio 1e-6
"""
FS_COLUMN = 4 * 7500 / (2000 * 10 * 1.0)

# Two zoned blocks, the upper one (Mohr-Coulomb) resting on the lower one (elastic) on a `mohr` joint
STACK = """model new
block create brick 0 2 0 2 -1 0
block create brick 0 2 0 2 0 1
block zone generate edgelength 1
block zone cmodel assign elastic range position-z -1 0
block zone cmodel assign mohr-coulomb range position-z 0 1
block zone property young 1e8 poisson 0.25 density 2000
block zone property cohesion 2e4 friction 30 dilation 10 tension 5e3 range position-z 0 1
model gravity 0 0 -10
block contact jmodel assign mohr
block contact material-table default property stiffness-normal 1e9 stiffness-shear 1e9 friction 35 cohesion 1e3
block gridpoint apply velocity 0 0 0 range position-z -1
model cycle 300
"""


def _run(session, text):
    session.run_items(session.load_text(text))
    return engine(session.model)


def _state(m):
    out = {f"{name}.{k}": a.copy() for name, st in m.stores.items() for k, a in st.to_arrays().items()}
    out["time"], out["step"] = m.time, m.step
    return out


def _same(a, b):
    assert a.keys() == b.keys()
    for k in a:
        x, y = np.asarray(a[k]), np.asarray(b[k])
        assert x.shape == y.shape and x.dtype == y.dtype, k
        assert x.tobytes() == y.tobytes(), f"{k} differs"


# ------------------------------------------------------------------ the reduction of a row
def test_a_reduced_mohr_coulomb_row_is_c_tanphi_and_tension_over_f():
    rng = np.random.default_rng(7)
    mc = MODEL_BY_CODE[2]
    el = MODEL_BY_CODE[1]
    assert mc.name == "mohr-coulomb" and mc.reduce is not None and el.reduce is None
    rows = rng.uniform(1.0, 1e6, size=(6, NZPROP))
    rows[:, P_TANFRIC] = np.tan(np.radians([10, 20, 30, 40, 0, 35]))
    rows[:, P_TANDIL] = np.tan(np.radians([0, 20, 5, 40, 0, 30]))
    rows[:, P_SRF] = 0.0
    codes = np.array([2, 2, 2, 2, 2, 1], np.int8)
    before = rows.copy()
    F = 1.37
    out = reduce_zone_rows(rows, codes, F)
    assert rows.tobytes() == before.tobytes()                       # the input is not touched
    mcr = out[:5]
    assert np.array_equal(mcr[:, P_COHESION], before[:5, P_COHESION] / F)
    assert np.array_equal(mcr[:, P_TANFRIC], before[:5, P_TANFRIC] / F)
    assert np.array_equal(mcr[:, P_TENSION], before[:5, P_TENSION] / F)
    # the dilation is kept, but never above the reduced friction (the 20 and 40 deg rows, psi = phi)
    assert np.array_equal(mcr[:, P_TANDIL], np.minimum(before[:5, P_TANDIL], before[:5, P_TANFRIC] / F))
    assert mcr[1, P_TANDIL] < before[1, P_TANDIL] and mcr[2, P_TANDIL] == before[2, P_TANDIL]
    assert np.all(mcr[:, P_SRF] == F)                               # the factor tables are divided by
    other = [k for k in range(NZPROP) if k not in (P_COHESION, P_TANFRIC, P_TENSION, P_TANDIL, P_SRF)]
    assert np.array_equal(mcr[:, other], before[:5, other])         # moduli, density, own columns kept
    assert out[5].tobytes() == before[5].tobytes()                  # elastic: nothing to reduce


# ------------------------------------------------------------------ trials on a real model
def test_a_trial_reduces_zones_and_joints_together_and_puts_everything_back(session):
    e = _run(session, STACK)
    m = session.model
    zs = m.store("zones")
    assert set(np.unique(zs["cmodel"])) == {1, 2}
    before = _state(m)
    assert np.any(before["zones.stress"] != 0.0) and np.any(before["vertices.disp"] != 0.0)
    mc = np.flatnonzero(zs["cmodel"] == 2)
    assert np.array_equal(reducible_zones(m), mc)
    seen = {}
    real_cycle = e.cycle

    def cycle(n, stop=None, **kw):                                  # look at the model the trial cycles
        c = e.contacts
        seen["zprop"] = zs["prop"].copy()
        seen["cprop"] = c["prop"][c["jmodel"] == MOHR].copy() if c.n else None
        return real_cycle(200, stop, **kw)

    e.cycle = cycle
    F = 1.7
    t = StrengthTrials(e, steps=200)
    assert t.zone_rows.size == len(mc) and t.rows.size > 0
    t(F)
    z0 = before["zones.prop"]
    zr = seen["zprop"]
    assert np.array_equal(zr[mc, P_COHESION], z0[mc, P_COHESION] / F)
    assert np.array_equal(zr[mc, P_TANFRIC], z0[mc, P_TANFRIC] / F)
    assert np.array_equal(zr[mc, P_TENSION], z0[mc, P_TENSION] / F)
    el = np.flatnonzero(zs["cmodel"] == 1)
    assert zr[el].tobytes() == z0[el].tobytes()
    c0 = before["contacts.prop"][before["contacts.jmodel"] == MOHR]
    assert np.allclose(seen["cprop"][:, P_COH], c0[:, P_COH] / F, rtol=1e-15)
    assert np.allclose(seen["cprop"][:, P_TANF], c0[:, P_TANF] / F, rtol=1e-15)
    assert m.step > before["step"]                                  # the trial did cycle
    t._reset()
    _same(before, _state(m))                                        # zones (prop, stress, state, ...) too
    t(2.5)
    t.finish()
    e.cycle = real_cycle
    _same(before, _state(m))


def test_zone_history_and_plastic_state_are_put_back(session):
    """A trial that yields (F = 3 on the column: c / F far below the stress) changes the zone's
    stress and plastic state; after it every zone field (``hist`` too where the store has it) and
    every gridpoint field is as before, bit for bit."""
    e = _run(session, COLUMN)
    m = session.model
    zs = m.store("zones")
    if "hist" in zs.fields:                          # the plug-in engine's per-zone history
        zs["hist"][:] = np.arange(zs["hist"].size, dtype=float).reshape(zs["hist"].shape) + 0.5
    before = _state(m)
    t = StrengthTrials(e, steps=400)
    assert t(3.0) is False
    assert np.any(zs["state"] != before["zones.state"]) and np.any(zs["stress"] != before["zones.stress"])
    t.finish()
    _same(before, _state(m))


def test_a_zones_only_model_gets_its_factor_of_safety(session):
    _run(session, COLUMN + "model factor-of-safety bracket 1.0 2.1 resolution 0.005 cycles 3000\n")
    fs, un = session.results["fos"], session.results["fos.unstable"]
    assert fs <= FS_COLUMN < un + 1e-12 and un - fs <= 0.005
    assert session.model.factor_of_safety == fs
    out = session.output.getvalue()
    assert "failure mechanism" in out and "model factor-of-safety: FS = " in out


def test_nothing_to_reduce_is_refused(session):
    with pytest.raises(CommandError) as err:
        _run(session, COLUMN.replace("cmodel assign mohr-coulomb", "cmodel assign elastic")
             .replace(" cohesion 7500 friction 0 tension 1e10", "")
             + "model factor-of-safety\n")
    msg = str(err.value)
    assert "nothing to reduce" in msg and "no zone has a constitutive model with a strength" in msg
    assert "fos" not in session.results


def test_rounds_of_trials_from_a_state_file_reduce_the_zones_too(session):
    """`trials-per-round`: each trial runs on the model read from a state file (here in this process,
    one worker); the zones read back are reduced as in the serial search."""
    _run(session, COLUMN + "model factor-of-safety bracket 1.0 2.1 resolution 0.005 cycles 3000 "
                           "trials-per-round 3 workers 1\n")
    fs, un = session.results["fos"], session.results["fos.unstable"]
    assert fs <= FS_COLUMN < un + 1e-12 and un - fs <= 0.005
