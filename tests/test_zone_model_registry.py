"""The zone-model plug-ins as a whole: the registry, the guard that a model lives in its two files,
what `block zone cmodel assign` and `block zone property` do with models' own properties, the
history block through save/restore, VTK and FISH, and save files from before the model library."""
import io
import pathlib

import numpy as np
import pytest

import dec3d
from dec3d.errors import Dec3dError
from dec3d.io.state import restore_state, save_state
from dec3d.kernels.zmodels import CODES, MODELS, NZHIST, NZPROP, P_OWN
from dec3d.physics.cmodels import MODEL_BY_CODE, MODEL_NAMES, ZONE_MODELS

ROOT = pathlib.Path(dec3d.__file__).parent


def _string_constants(path: pathlib.Path):
    from source_scan import string_constants
    return string_constants(path)


def test_every_kernel_has_its_host_and_codes_are_unique():
    assert sorted(CODES.values()) == sorted(set(CODES.values())) and 0 not in CODES.values()
    assert set(ZONE_MODELS) == set(CODES) and all(MODEL_BY_CODE[c].name == n for n, c in CODES.items())
    assert MODEL_NAMES["null"] == 0 and all(MODEL_NAMES[n] == c for n, c in CODES.items())
    for m in MODELS:
        assert m.NCOLS <= NZPROP and m.NHIST <= NZHIST and len(m.HIST_NAMES) == m.NHIST
        host = ZONE_MODELS[m.NAME]
        assert all(p.column < max(m.NCOLS, P_OWN) for p in host.props.values()), m.NAME


def test_no_file_outside_a_models_two_files_names_it():
    """A model is its kernel and host file: no other module of dec3d names it (code literals are
    covered too: nothing imports a model's kernel module but its host). ``elastic`` is the one
    exception, by design: FE blocks cycle elastic only, all-elastic 10-node zones keep their Hooke step, and Rayleigh damping
    takes plastic zones as elastic."""
    mine = {}
    for m in MODELS:
        stem = pathlib.Path(m.__file__).stem
        mine[m.NAME] = {ROOT / "kernels" / "zmodels" / f"{stem}.py", ROOT / "physics" / "zmodels" / f"{stem}.py"}
    found = []
    for f in ROOT.rglob("*.py"):
        for line, value in _string_constants(f):
            if value in mine and value != "elastic" and f not in mine[value]:
                found.append(f"{f.relative_to(ROOT)}:{line} names {value}")
        text = f.read_text(encoding="utf-8")
        for name, files in mine.items():
            stem = next(iter(files)).stem
            if f not in files and (f"zmodels import {stem}" in text or f"zmodels.{stem} import" in text):
                found.append(f"{f.relative_to(ROOT)} imports the {name} model's files")
    assert not found, found


_BRICKS = """model new
block create brick 0 1 0 1 0 1
block create brick 2 3 0 1 0 1
block zone generate edgelength 0.5
block zone cmodel assign elastic
block zone property bulk 2e9 shear 1e9 density 2000
"""


def _session(tmp_path, text=_BRICKS):
    s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command(text)
    return s


def test_own_properties_go_to_the_zones_whose_model_has_them(tmp_path):
    s = _session(tmp_path, _BRICKS + "block zone cmodel assign hoek-brown range position-x 0 1\n")
    zs = s.model.store("zones")
    hb = ZONE_MODELS["hoek-brown"]
    left = zs["cmodel"][: zs.n] == hb.code
    assert left.any() and not left.all()
    s.command("block zone property constant-mb 10 constant-s 1 constant-a 0.5 strength-compression 2e7 "
              "cohesion 3e5")
    col = hb.props["constant-mb"].column
    assert (zs["prop"][: zs.n][left, col] == 10.0).all() and (zs["prop"][: zs.n][~left, col] == 0.0).all()
    assert (zs["prop"][: zs.n][left, hb.props["constant-sci"].column] == 2e7).all()
    assert (zs["prop"][: zs.n][:, 3] == 3e5).all()              # a shared property: every zone in range
    # a model's own property where no zone in range has that model: refused, nothing changed
    before = zs["prop"][: zs.n].copy()
    with pytest.raises(Dec3dError, match=r"`block zone property constant-mb`: no zone in range has a model with "
                                         r"this property \(it belongs to hoek-brown; the zones in range are "
                                         r"elastic \d+\)") as e:
        s.command("block zone property constant-mb 3 cohesion 1 range position-x 2 3")
    loc = e.value.location                                        # the keyword's own place
    assert loc is not None and loc.line == 1 and loc.column == len("block zone property constant-mb ") + 1
    np.testing.assert_array_equal(zs["prop"][: zs.n], before)


def test_out_of_range_own_property_is_refused_with_its_location(tmp_path):
    s = _session(tmp_path, _BRICKS + "block zone cmodel assign hoek-brown\n")
    with pytest.raises(Dec3dError, match=r"`constant-a` must be in \(0, 1\], got 1.5") as e:
        s.command("block zone property constant-a 1.5")
    assert e.value.location is not None and e.value.location.line == 1
    with pytest.raises(Dec3dError, match="unknown keyword `constant-mz`") as e:
        s.command("block zone property constant-mz 1")
    assert "`constant-mb`" in e.value.hint and e.value.location.column == len("block zone property ") + 1
    with pytest.raises(Dec3dError, match="needs model") as e:
        s.command("block zone cmodel assign hoek-brwn")
    assert e.value.hint == "did you mean `hoek-brown`?" and e.value.location.column == len("block zone cmodel assign ") + 1


def test_assigning_a_model_resets_its_own_columns_and_history_and_keeps_the_stress(tmp_path):
    s = _session(tmp_path, _BRICKS + "block zone cmodel assign hoek-brown\n"
                 "block zone property constant-mb 10 constant-s 1 constant-a 0.5 constant-sci 2e7 cohesion 1e5\n"
                 "block zone initialize stress-xx -1e6\n")
    zs = s.model.store("zones")
    zs["hist"][: zs.n] = 1.0
    zs["state"][: zs.n] = 5
    s.command("block zone cmodel assign hoek-brown")               # the same model: properties kept
    hb = ZONE_MODELS["hoek-brown"]
    assert (zs["prop"][: zs.n, hb.props["constant-mb"].column] == 10.0).all()
    s.command("block zone cmodel assign mohr-coulomb\nblock zone cmodel assign hoek-brown")
    p = zs["prop"][: zs.n]
    assert (p[:, P_OWN:] == 0.0).all()                           # its own columns back to their defaults
    assert (p[:, 0] == 2e9).all() and (p[:, 3] == 1e5).all()     # shared ones kept
    assert (zs["hist"][: zs.n] == 0.0).all() and (zs["state"][: zs.n] == 0).all()
    assert (zs["stress"][: zs.n, 0] == -1e6).all()


def test_history_block_round_trips_and_reaches_vtk_and_fish(tmp_path):
    s = _session(tmp_path)
    zs = s.model.store("zones")
    rng = np.random.default_rng(3)
    zs["hist"][: zs.n] = rng.normal(size=(zs.n, NZHIST))
    path = save_state(s.model, tmp_path / "h.sav")
    r, _ = restore_state(path)
    np.testing.assert_array_equal(r.store("zones")["hist"], zs["hist"][: zs.n])
    np.testing.assert_array_equal(r.store("zones")["prop"], zs["prop"][: zs.n])
    # FISH: the model's name, a property in user units
    s.command("fish define f\n  global nm = block.zone.model(1)\n  global k = block.zone.prop(1, 'bulk')\nend\n"
              "[f]")
    assert s.fish_rt.globals["nm"] == "elastic" and s.fish_rt.globals["k"] == 2e9
    with pytest.raises(Dec3dError, match=r"zone model `elastic` has no property 'cohesion'"):
        s.command("[block.zone.prop(1, 'cohesion')]")


def test_a_save_from_before_the_model_library_gets_the_new_columns(tmp_path):
    s = _session(tmp_path)
    zs = s.model.store("zones")
    zs.resize_field("prop", (8,))                                 # the layout of older files
    old = zs["prop"][: zs.n].copy()
    path = save_state(s.model, tmp_path / "old.sav")
    r, _ = restore_state(path)
    p = r.store("zones")["prop"]
    assert p.shape == (zs.n, NZPROP)
    np.testing.assert_array_equal(p[:, :8], old)
    assert (p[:, 8:] == 0.0).all()


def test_energy_tracking_refuses_anisotropic_zones(tmp_path):
    """The energy bookkeeping takes the strain energy of isotropic elasticity from the stress: a
    model with anisotropic moduli is refused before anything cycles, naming the model."""
    s = _session(tmp_path, _BRICKS + "block zone cmodel assign anisotropic range position-x 0 1\n"
                 "block zone property young-plane 30e9 young-normal 12e9 poisson-plane 0.22 poisson-normal 0.3 "
                 "shear-normal 5e9 range position-x 0 1\nmodel gravity 0 0 -10\n"
                 "block gridpoint apply velocity 0 0 0 range position-z 0\nmodel energy active on\n")
    with pytest.raises(Dec3dError, match="anisotropic models anisotropic are not supported yet"):
        s.command("model cycle 5")
    assert s.model.step == 0
    s.command("model energy active off\nmodel cycle 5")
    assert s.model.step == 5
