"""Joint models are plug-ins (issue 9): a model is a kernel file in dec3d/kernels/joints and a host
file in dec3d/physics/joints, found by listing the folders. Adding one touches no other file."""
import os
import shutil
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from conftest import ROOT

from dec3d.kernels import joints
from dec3d.physics.jmodels import JOINT_MODELS, MODEL_BY_CODE

KERNEL = '''
"""Test model: linear elastic joint that also carries tension (no cut-off), remembers the largest
opening of each sub-contact (its history) and answers a softer normal stiffness while open."""
from numba import njit

from ._common import P_KN, P_KS, elastic_trial

NAME = "linear-tension"
CODE = 40
NCOLS = 3
NHIST = 1
HIST_NAMES = ("max-opening",)
P_FACTOR = 2      # tension stiffness as a fraction of kn


@njit(cache=True)
def law(p, c, h, s, area, dun, dus0, dus1, dus2, un, udil, fs0, fs1, fs2, us0, us1, us2, state):
    fn, fs0, fs1, fs2, un, us0, us1, us2 = elastic_trial(p[c, P_KN], p[c, P_KS], area, dun, dus0, dus1, dus2, un,
                                                         udil, fs0, fs1, fs2, us0, us1, us2)
    if fn < 0.0:
        fn *= p[c, P_FACTOR]
    if un > h[s, 0]:
        h[s, 0] = un
    return fn, fs0, fs1, fs2, un, udil, us0, us1, us2, state


@njit(cache=True)
def stiffness(p, c, h, s):
    return p[c, P_KN] * (p[c, P_FACTOR] if h[s, 0] > 0.0 else 1.0), p[c, P_KS]
'''

HOST = '''
from dec3d.kernels.joints import linear_tension as kernel
from dec3d.physics.jmodels import STIFFNESS, Prop, jmodel

jmodel(kernel, "elastic joint carrying tension", STIFFNESS + [
    Prop("tension-factor", kernel.P_FACTOR, "tension stiffness / kn", default=1.0)])
'''

DECK = '''
model new
block create brick 0 1 0 1 0 1
block create brick 0 1 0 1 1 2
block property density 2000
block contact jmodel assign linear-tension
block contact property stiffness-normal 1e9 stiffness-shear 1e9 tension-factor 0.5
block fix range position-z 0 0.5
block initialize velocity-z 1e-3 range position-z 1 2
block mechanical damping none
model cycle 20
'''


def test_models_found_by_listing_and_registered_once():
    assert [m.NAME for m in joints.MODELS][:2] == ["elastic", "mohr"]
    assert [m.CODE for m in joints.MODELS] == sorted(m.CODE for m in joints.MODELS)
    assert set(JOINT_MODELS) == {m.NAME for m in joints.MODELS}
    assert {c: m.name for c, m in MODEL_BY_CODE.items()} == {m.CODE: m.NAME for m in joints.MODELS}
    assert joints.NPROP == max(m.NCOLS for m in joints.MODELS)


def test_dispatch_calls_each_models_own_law():
    """The chain picks the law by code: elastic drops tension, mohr limits shear. (A chain of these
    two, as ``joint_law_for`` builds one per mask: the chain of every model compiles for 20 s.)"""
    two = tuple(m for m in joints.MODELS if m.NAME in ("elastic", "mohr"))
    chain = joints._link(0, two)
    p = np.zeros(joints.NPROP)
    p[0] = p[1] = 1e9
    h = np.zeros((1, joints.NJHIST))
    opened = chain(joints.CODES["elastic"], p[None, :], 0, h, 0, 1.0, 1e-6, 0.0, 0.0, 0.0, 0.0, 0.0,
                              0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0)
    assert opened[0] == 0.0 and opened[4] == pytest.approx(1e-6)
    p[joints.mohr.P_TANF] = 0.5
    p[joints.mohr.P_TANF_RES] = np.nan          # residual friction = the friction
    sheared = chain(joints.CODES["mohr"], p[None, :], 0, h, 0, 1.0, -1e-6, 1e-5, 0.0, 0.0, 0.0, 0.0,
                               0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0)
    assert sheared[0] == pytest.approx(1e3) and abs(sheared[1]) == pytest.approx(500.0)   # Fs = Fn tan φ


def test_a_new_model_is_two_new_files(tmp_path):
    """A copy of the package with one kernel file and one host file added runs a deck with the
    new model and its new property; no other file changes. (Plain Python: NUMBA_DISABLE_JIT.)"""
    pkg = tmp_path / "dec3d"
    shutil.copytree(ROOT / "dec3d", pkg, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    (pkg / "kernels" / "joints" / "linear_tension.py").write_text(KERNEL)
    (pkg / "physics" / "joints" / "linear_tension.py").write_text(HOST)
    (tmp_path / "pull.dat").write_text(DECK)
    script = textwrap.dedent('''
        import dec3d
        from dec3d.session import Session
        s = Session()
        s.call("pull.dat")
        from dec3d.physics.jmodels import stiffness
        e = s.model.rigid_engine
        sc = e.subcontacts
        kn = stiffness(e.contacts, sc)[0]
        print("FN", sc["fn"].sum(), "N", sc.n, "H", sc["hist"][:, 0].min(), sc["hist"][:, 0].max(), "KN", kn.min(), kn.max(),
              "DT", e.timestep())
    ''')
    env = dict(os.environ, NUMBA_DISABLE_JIT="1", PYTHONPATH=str(tmp_path))
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env,
                         cwd=tmp_path, timeout=600)
    assert out.returncode == 0, out.stdout[-2000:] + out.stderr[-3000:]
    fn = float(out.stdout.split("FN")[1].split()[0])
    # opening 19-20 steps at 1e-3 m/s over 1 m² at 0.5 kn: a tensile force, which mohr/elastic would drop
    assert fn < 0.0
    # the history: every sub-contact remembers its opening (un starts at the gap, 0, and grows by v Δt a step)
    words = out.stdout.split()
    hmin, hmax = float(words[words.index("H") + 1]), float(words[words.index("H") + 2])
    assert 0.0 < hmin <= hmax < 20 * 1e-3 * 1.0
    # and the stiffness hook answers for the open sub-contacts: kn × tension-factor
    assert float(words[words.index("KN") + 1]) == float(words[words.index("KN") + 2]) == pytest.approx(0.5e9)


def _string_constants(path):
    from source_scan import string_constants
    return string_constants(path)


def test_no_file_outside_a_joint_models_two_files_names_it():
    """Every joint model after the first two is its kernel and host file alone: no other module of
    dec3d names it, by name, alias or module. (``elastic`` and ``mohr`` predate the plug-ins: the
    defaults and the factor of safety name them.)"""
    import pathlib
    import re

    import dec3d
    from dec3d.physics.jmodels import ALIASES

    root = pathlib.Path(dec3d.__file__).parent
    mine = {}
    for m in joints.MODELS:
        if m.NAME in ("elastic", "mohr"):
            continue
        stem = pathlib.Path(m.__file__).stem
        files = {root / "kernels" / "joints" / f"{stem}.py", root / "physics" / "joints" / f"{stem}.py"}
        for name in (m.NAME, *(a for a, target in ALIASES.items() if target == m.NAME)):
            mine[name] = (stem, files)
    found = []
    for f in root.rglob("*.py"):
        for line, value in _string_constants(f):
            if value in mine and f not in mine[value][1]:
                found.append(f"{f.relative_to(root)}:{line} names {value}")
        text = f.read_text(encoding="utf-8")
        for name, (stem, files) in mine.items():
            if f not in files and re.search(rf"joints import [^\n]*\b{stem}\b|joints\.{stem} import", text):
                found.append(f"{f.relative_to(root)} imports the {name} model's files")
    assert not found, found
