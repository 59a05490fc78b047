"""The nine public 3DEC 4/5 decks (shared/decks/legacy_v5) through the translator, the demifang arch
chain run with the same physics, and `dec3d translate` / `dec3d run` of legacy decks (docs/legacy.md)."""
import math
import subprocess
import sys
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from dec3d.check import check_text
from dec3d.lang.legacy import translate_text
from dec3d.lang.legacy.translate import State

from conftest import DECKS, NO_DECKS, ROOT

LEGACY = DECKS / "legacy_v5"
ARCH, BOUNDARY = "demifang__3DEC-code__0_2_arch.3dec.dat", "demifang__3DEC-code__boundary.3ddat.dat"
GRAV, GRAV_NS = "demifang__3DEC-code__grav.3dec.dat", "demifang__3DEC-code__grav_normal_and_shear.3dec.dat"
#: what stays beyond dec3d in each deck: FISH functions using 3DEC 5 intrinsics with no 3DEC 7+ equivalent in
#: dec3d (they stop a run only when called)
NOT_RUNNABLE = {
    "absterguy__Itasca-3dec2Tecplot__3dec2tecplot360.3ddat.dat": {"b_zone", "z_next", "z_sig1", "z_sig3", "b_gp"},
    "rkn2__generate3DEC__getstress.txt.dat": {"b_zone", "z_next", "z_sig1", "z_sig3"},
}


def _needs_decks():
    if not LEGACY.is_dir():
        pytest.skip(NO_DECKS)


def _chain_text(names):
    """The translations of decks run one after the other in one session (3DEC 5 users ran them so)."""
    state = State()
    return "\n".join(translate_text((LEGACY / n).read_text(errors="replace"), n, state).text for n in names)


@pytest.mark.parametrize("name", sorted(p.name for p in LEGACY.glob("*.dat")) if LEGACY.is_dir() else ["-"])
def test_legacy_deck_translates_and_binds(name):
    _needs_decks()
    names = [ARCH, name] if name in (BOUNDARY, GRAV, GRAV_NS) else [name]      # the chain decks need the arch
    reports = check_text(_chain_text(names), "translated", LEGACY)
    bad = [r for r in reports if r.status not in ("runnable", "does nothing")]
    # every line binds; the only lines that are not runnable are FISH functions (and the lines calling them)
    # that use the intrinsics listed in NOT_RUNNABLE, and the line of each that could not be translated says so
    assert all(r.status != "error" for r in reports), [r for r in reports if r.status == "error"]
    missing = NOT_RUNNABLE.get(name, set())
    if not missing:
        assert not bad, bad
    for r in bad:
        assert "FISH" in r.what, r
    text = translate_text((LEGACY / name).read_text(errors="replace"), name).text
    noted = {w for w in missing if f"`{w}`" in text}
    assert noted == missing


def test_arch_stands_under_gravity_on_its_hidden_base(tmp_path):
    """demifang's chain: the arch deck builds 21 voussoirs on a fixed base and saves; boundary sets density and
    joint stiffness; grav applies gravity and solves. The arch stands: the solve converges, the blocks move
    by less than 0.1 mm, and the base carries the whole weight of the 21 voussoirs."""
    _needs_decks()
    from dec3d.legacy_run import LegacySession

    s = LegacySession(out_dir=tmp_path, notice=lambda t: None)
    for name in (ARCH, BOUNDARY):
        s.run_items(s.load_file(LEGACY / name))
    # grav.dat solves 1 s of model time (44720 steps, a minute and a half); the test stops at equilibrium
    text = (LEGACY / GRAV).read_text().replace("solve time 1", "solve ratio 1e-6")
    s.run_items(s.load_text(text, str(LEGACY / GRAV), LEGACY))
    m = s.model
    assert m.blocks.n == 22 and m.step < 20000
    assert np.abs(m.blocks["disp"]).max() < 1e-4
    weight = m.blocks["volume"][:21].sum() * 1220.5 * 9.81        # 21 voussoirs of 0.97775 m³: 245.8 kN
    cs, ss = m.stores["contacts"], m.stores["subcontacts"]
    on_base = (cs["ida"][: cs.n] == 22) | (cs["idb"][: cs.n] == 22)
    rows = np.isin(ss["contact"][: ss.n], np.flatnonzero(on_base))
    assert math.isclose(abs(float(ss["fn"][: ss.n][rows].sum())), weight, rel_tol=1e-3)


def _cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "dec3d", *args], capture_output=True, text=True, cwd=cwd or ROOT,
                          env={"PYTHONPATH": str(ROOT), "NUMBA_NUM_THREADS": "1", "DEC3D_WARMUP": "0",
                               "PATH": "/usr/bin:/bin"})


def test_cli_translate_stdout_and_out(tmp_path):
    old = tmp_path / "old.dat"
    old.write_text("new\npoly brick 0 1 0 1 0 1\nfrobnicate\n")
    r = _cli("translate", str(old))
    assert r.returncode == 0
    assert r.stdout.split("\n")[:2] == ["model new", "block create brick 0 1 0 1 0 1 group 'mat1' slot 'material'"]
    assert "1 line(s) could not be translated" in r.stderr
    r = _cli("translate", str(old), "--out", str(tmp_path / "new.dat"))
    assert r.returncode == 0 and (tmp_path / "new.dat").read_text().startswith("model new\n")


def test_cli_run_translates_or_refuses_and_errors_point_at_the_original(tmp_path):
    old = tmp_path / "old.dat"
    old.write_text("new\npoly brick 0 1 0 1 0 1\n; a comment\nprop mat=1   dens=-5\n")
    r = _cli("run", str(old), "-q", "--out", str(tmp_path / "o"), "--no-legacy")
    assert r.returncode == 2 and "is 3DEC 5 (legacy) syntax" in r.stderr and "old.dat:1:1" in r.stderr
    r = _cli("run", str(old), "-q", "--out", str(tmp_path / "o"))
    assert "is 3DEC 4/5 (legacy) syntax: running its 3DEC 7+ translation" in r.stderr
    # the bad density is in the translation's `block property density -5`; the error names the original
    assert r.returncode == 2 and "old.dat:4:19: error" in r.stderr, r.stderr
    assert "prop mat=1   dens=-5" in r.stderr
    old.write_text("new\npoly brick 0 1 0 1 0 1\nprop mat=1 dens=2000\ngrav 0 0 -10\nfix\ncycle 2\n")
    r = _cli("run", str(old), "-q", "--out", str(tmp_path / "o"))
    assert r.returncode == 0, r.stderr


def test_grav_normal_and_shear_sums_the_support_contact_forces(tmp_path):
    """grav_normal_and_shear.dat: the contact nearest a point (`c_near` -> block.contact.near) and the walk over
    its sub-contacts (`c_cx`, `cx_next`, `cx_nforce`, `cx_sforce`) as FISH histories. Its point is never set (the
    deck's `sup_face_pos` is not called: 0, 0, 0), so the contact is that of the voussoir at x = 17.5 on the base
    (its sub-contacts' centre is the nearest): by symmetry it carries half the arch's weight; the shear force is the arch's thrust."""
    _needs_decks()
    from dec3d.legacy_run import LegacySession

    s = LegacySession(out_dir=tmp_path, notice=lambda t: None)
    for name in (ARCH, BOUNDARY):
        s.run_items(s.load_file(LEGACY / name))
    text = (LEGACY / GRAV_NS).read_text().replace("solve time 1", "solve ratio 1e-6")
    s.run_items(s.load_text(text, str(LEGACY / GRAV_NS), LEGACY))
    weight = s.model.blocks["volume"][:21].sum() * 1220.5 * 9.81
    s.command("[probe_nf = nf_sum2]")
    nf, sf = s.variables["probe_nf"], s.variables["sf_sum2"]     # sf_sum2: set by nf_sum2, as in 3DEC 5
    assert math.isclose(nf, weight / 2, rel_tol=5e-3)
    assert 0.05 * weight < sf < 0.5 * weight


def test_dec3d_check_reads_a_legacy_deck_through_its_translation():
    """`dec3d check old.dat` checks what `dec3d run` runs; its reports stand on the original lines."""
    _needs_decks()
    from dec3d.check import check_file

    arch = check_file(LEGACY / ARCH)
    assert {r.status for r in arch} == {"runnable"}
    assert [r.line for r in arch][-2:] == [1587, 1588]         # `fix reg @base_reg`, `save 0_2_cyc0`
    raw = check_file(LEGACY / ARCH, legacy=False)
    assert "legacy syntax" in {r.status for r in raw}
    # grav_normal_and_shear alone: the arch deck's FISH variables are missing, named on the original line
    alone = [r for r in check_file(LEGACY / GRAV_NS) if r.status not in ("runnable", "does nothing")]
    assert alone and all("sup_face_pos_x" in r.what for r in alone)
    assert (alone[0].line, alone[0].column) == (11, 14)         # `hist nf_sum @sup_face_pos_x …`
