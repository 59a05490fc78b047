"""`model factor-of-safety`: the bracketing against a fake trial with a known threshold, the strength
reduction of the property rows, the model put back bit for bit between and after trials, bad input,
results and the failure-mechanism file. (The closed-form checks are verification/F1_strength_reduction.)"""
import math

import numpy as np
import pytest

from dec3d.errors import BindError, CommandError
from dec3d.kernels.joints import NPROP, P_KN
from dec3d.kernels.joints.mohr import P_COH, P_COH_RES, P_TANDIL, P_TANF, P_TANF_RES, P_TEN
from dec3d.physics.fos import ContactStrengthTrials, FosError, bracket_fos, reduce_defaults, reduce_rows
from dec3d.physics.rigid import engine

# a 4 x 4 x 1 m block on a fixed base, gravity tilted by 30 deg (downslope +x), phi = 40 deg, c = 0:
# FS = tan 40 / tan 30 = 1.4534
INCLINE = """model new
block create brick -1 8 -1 5 -1 0
block create brick 0 4 0 4 0 1
block property density 2000
model gravity 5.0 0 -8.660254037844386
block contact jmodel assign mohr
block contact material-table default property stiffness-normal 1e8 stiffness-shear 1e8 friction 40
block fix range position-z -1 0
model solve ratio 1e-6
"""
FS_INCLINE = math.tan(math.radians(40)) / math.tan(math.radians(30))


def _run(session, text):
    session.run_items(session.load_text(text))
    return engine(session.model)


# ------------------------------------------------------------------ bracketing logic
@pytest.mark.parametrize("threshold", [0.37, 1.0, 1.2345, 3.3])
def test_bisection_finds_a_known_threshold(threshold):
    calls = []

    def trial(f):
        calls.append(f)
        return f <= threshold

    res = bracket_fos(trial, 0.25, 4.0, resolution=0.001)
    assert res.stable <= threshold < res.unstable
    assert res.unstable - res.stable <= 0.001
    assert res.fs == res.stable
    # two bracket checks, then halvings of 3.75 down to 0.001: ceil(log2(3750)) = 12
    assert len(calls) == 2 + 12 == len(res.trials)
    assert calls[:2] == [0.25, 4.0] and calls[2] == pytest.approx(2.125)
    assert [f for f, _ in res.trials] == calls


@pytest.mark.parametrize("threshold", [0.05, 0.7, 1.0, 1.9, 37.0])
def test_automatic_bracket_doubles_or_halves_from_one(threshold):
    res = bracket_fos(lambda f: f <= threshold, resolution=0.01)
    assert res.stable <= threshold < res.unstable and res.unstable - res.stable <= 0.01
    first = [f for f, _ in res.trials]
    assert first[0] == 1.0
    if threshold >= 1.0:
        k = math.floor(math.log2(threshold)) + 1      # doublings until unstable
        assert first[1:k + 1] == [2.0 ** i for i in range(1, k + 1)]
    else:
        k = math.ceil(-math.log2(threshold))          # halvings until stable
        assert first[1:k + 1] == [0.5 ** i for i in range(1, k + 1)]


def test_bracket_that_misses_the_factor_says_which_side():
    with pytest.raises(FosError, match=r"unstable at the lower bracket F = 1\.5: the factor of safety is below"):
        bracket_fos(lambda f: f <= 1.2, 1.5, 2.0)
    with pytest.raises(FosError, match=r"stable at the upper bracket F = 2: the factor of safety is above"):
        bracket_fos(lambda f: f <= 3.0, 1.5, 2.0)
    with pytest.raises(FosError, match="still stable at F = 1024"):
        bracket_fos(lambda f: True)
    with pytest.raises(FosError, match="resolution must be > 0"):
        bracket_fos(lambda f: f < 1, 0.5, 2.0, resolution=0.0)


# ------------------------------------------------------------------ the reduction of one property row
def test_reduce_rows_divides_strengths_and_limits_dilation():
    row = np.zeros((2, NPROP))
    row[:, P_KN] = 5e8
    row[:, P_TANF] = 0.8
    row[:, P_COH] = 3e4
    row[:, P_TEN] = 1e4
    row[:, P_TANDIL] = [0.1, 0.5]
    row[:, P_TANF_RES] = [math.nan, 0.6]
    row[:, P_COH_RES] = 2e3
    nonassoc = row.copy()
    reduce_rows(nonassoc, 2.0, associated=False)
    assert nonassoc[:, P_KN].tolist() == [5e8, 5e8]                 # stiffness untouched
    assert nonassoc[:, P_TANF].tolist() == [0.4, 0.4]
    assert nonassoc[:, P_COH].tolist() == [1.5e4, 1.5e4] and nonassoc[:, P_TEN].tolist() == [5e3, 5e3]
    assert math.isnan(nonassoc[0, P_TANF_RES]) and nonassoc[1, P_TANF_RES] == 0.3
    assert nonassoc[:, P_COH_RES].tolist() == [1e3, 1e3]
    assert nonassoc[:, P_TANDIL].tolist() == [0.1, 0.4]            # kept, but never above the friction
    assoc = row.copy()
    reduce_rows(assoc, 2.0, associated=True)
    assert assoc[:, P_TANDIL].tolist() == [0.4, 0.4]               # = the reduced friction
    d = reduce_defaults({"friction": 40.0, "cohesion": 1e4, "dilation": 35.0, "stiffness-normal": 1e9}, 2.0,
                        associated=False)
    assert d["friction"] == pytest.approx(math.degrees(math.atan(math.tan(math.radians(40)) / 2)))
    assert d["cohesion"] == 5e3 and d["stiffness-normal"] == 1e9 and d["dilation"] == d["friction"]


# ------------------------------------------------------------------ trials on a real model
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


def test_trials_start_from_the_same_state_and_leave_it_bit_identical(session):
    e = _run(session, INCLINE)
    m = session.model
    before = _state(m)
    mech_before = repr(m.settings.mechanical)
    seen = []
    t = ContactStrengthTrials(e, steps=1500, on_unstable=lambda f: seen.append((f, m.time)))
    assert t(1.2) is True
    assert t(1.8) is False                                           # slides
    assert seen and seen[0][0] == 1.8 and seen[0][1] > before["time"]
    t._reset()
    _same(before, _state(m))                                         # put back between trials
    assert t(1.8) is False and t(1.2) is True
    assert t.log[0] == t.log[3] and t.log[1] == t.log[2]             # same trial, same steps and ratio
    assert len(seen) == 1                                            # the mechanism of the first failure only
    t.finish()
    _same(before, _state(m))
    assert repr(m.settings.mechanical) == mech_before                # the reduced defaults are gone too


def test_command_finds_the_incline_factor_and_stores_it(session, tmp_path):
    _run(session, INCLINE + "model factor-of-safety bracket 1.3 1.6 resolution 0.005 cycles 3000\n")
    fs = session.results["fos"]
    assert fs == session.results["fos.1"] == session.model.factor_of_safety
    assert fs <= FS_INCLINE * 1.002 and abs(fs - FS_INCLINE) / FS_INCLINE < 0.01
    assert session.results["fos.unstable"] - fs <= 0.005 and session.results["fos.unstable"] > FS_INCLINE * 0.998
    assert "model factor-of-safety: FS = " in session.output.getvalue()
    vtu = (tmp_path / "fos_mechanism.vtu").read_text()
    assert 'Name="velocity"' in vtu
    # the mechanism is the block sliding downslope (+x); its out-of-plane part grows from round-off
    # as the block rocks: one-ulp changes of the body scaling's row sums gave |v_y| / v_x from 4e-6
    # to 1.9e-3 (14 trials), hence 1e-2
    import meshio

    mesh = meshio.read(tmp_path / "fos_mechanism.vtu")
    v = mesh.point_data["velocity"]
    assert v[:, 0].max() > 1e-3 and abs(v[:, 1]).max() < 1e-2 * v[:, 0].max()
    # a second search is fos.2; the model is as before the first
    step = session.model.step
    _run(session, "model factor-of-safety bracket 1.3 1.6 resolution 0.05 cycles 3000\n")
    assert "fos.2" in session.results and session.model.step == step


def test_bad_input_names_file_and_line(session):
    with pytest.raises(BindError) as e:
        session.load_text(INCLINE + "model factor-of-safety bracket 2 1\n")
    assert e.value.location.line == 10 and "lower factor must be below the upper" in str(e.value)
    with pytest.raises(BindError) as e:
        session.load_text(INCLINE + "model factor-of-safety bracket 1 1\n")
    assert e.value.location.line == 10
    with pytest.raises(BindError) as e:
        session.load_text(INCLINE + "model factor-of-safety resolution 0\n")
    assert e.value.location.line == 10 and e.value.location.column == 35
    with pytest.raises(BindError) as e:
        session.load_text(INCLINE + "model factor-of-safety resolution -0.1\n")
    assert e.value.location.line == 10
    elastic = INCLINE.replace("jmodel assign mohr", "jmodel assign elastic").replace(" friction 40", "")
    with pytest.raises(CommandError) as e:
        _run(session, elastic + "model factor-of-safety\n")
    assert e.value.location.line == 10 and "no contact has the `mohr` joint model" in str(e.value)
    assert "fos" not in session.results
    with pytest.raises(CommandError) as e:
        _run(session, INCLINE + "model factor-of-safety range position-z 50 60\n")
    assert e.value.location.line == 10 and "no contact in range has the `mohr` joint model" in str(e.value)
    # a bracket that misses: an error at the line, the model as it was
    _run(session, INCLINE)
    before = _state(session.model)
    with pytest.raises(CommandError) as e:
        _run(session, "model factor-of-safety bracket 1.6 2.0 cycles 2000\n")
    assert e.value.location.line == 1 and "factor of safety is below the bracket" in str(e.value)
    _same(before, _state(session.model))


@pytest.mark.parametrize("points", [2, 3, 5])
def test_rounds_of_several_points_find_the_threshold(points):
    threshold = 1.2345
    rounds = []

    def run_many(fs):
        rounds.append(list(fs))
        return [f <= threshold for f in fs]

    res = bracket_fos(None, 0.25, 4.0, resolution=0.001, points=points, run_many=run_many)
    assert res.stable <= threshold < res.unstable and res.unstable - res.stable <= 0.001
    assert rounds[0] == [0.25, 4.0]                                  # both bracket ends in one round
    assert all(len(r) == points for r in rounds[1:])
    assert rounds[1] == pytest.approx([0.25 + 3.75 * i / (points + 1) for i in range(1, points + 1)])
    # each round shrinks the bracket points + 1 times: ceil(log(3750) / log(points + 1)) rounds
    assert len(rounds) - 1 == math.ceil(math.log(3750) / math.log(points + 1))


def test_parallel_rounds_do_not_depend_on_the_worker_count(session, tmp_path):
    _run(session, INCLINE)
    before = _state(session.model)
    line = "model factor-of-safety bracket 1.3 1.6 resolution 0.01 cycles 3000 trials-per-round 3 workers {}\n"
    n0 = len(session.output.getvalue())
    _run(session, line.format(1))
    n1 = len(session.output.getvalue())
    one = session.output.getvalue()[n0:n1]
    _same(before, _state(session.model))
    _run(session, line.format(2))
    two = session.output.getvalue()[n1:]
    _same(before, _state(session.model))
    trials = lambda text: [ln for ln in text.splitlines() if ln.startswith("  F = ")]  # noqa: E731
    assert trials(one) and trials(one) == trials(two)                # same factors, steps and ratios
    assert session.results["fos.1"] == session.results["fos.2"]
    assert abs(session.results["fos"] - FS_INCLINE) / FS_INCLINE < 0.01
    # the trials' state file is gone (the record of the files dec3d wrote stays: docs/safety.md)
    assert sorted(p.name for p in tmp_path.iterdir()) == [".dec3d-outputs.json", "fos_mechanism.vtu"]
    with pytest.raises(BindError) as e:
        session.load_text("model factor-of-safety trials-per-round 0\n")
    assert e.value.location.line == 1


def test_a_range_reduces_only_the_contacts_in_it(session):
    """The base contact (z = 0) in range: the same factor as without a range (the contacts in range are
    reduced and kept reduced through re-detection; the material-table defaults are not touched)."""
    _run(session, INCLINE + "model factor-of-safety bracket 1.3 1.6 resolution 0.005 cycles 3000 "
                            "range position-z -0.1 0.1\n")
    assert abs(session.results["fos"] - FS_INCLINE) / FS_INCLINE < 0.01
