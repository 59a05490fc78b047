"""No NaN in any file written: the "not set" markers of the contact property rows (NaN residual friction:
the peak friction) leave a save file as 0 with a mask beside them, and come back as NaN on restore, so a
restored run goes on bit for bit."""
import io
import json
import zipfile

import numpy as np

from dec3d.session import Session

DECK = """model new
block create brick 0 1 0 1 -1 0
block create brick 0 1 0 1 0 1
block property density 2000
block contact jmodel assign mohr
block contact property stiffness-normal 1e9 stiffness-shear 1e9 friction 30
model gravity 0 0 -9.81
block fix range id 1
model cycle 20
"""


def _arrays(path):
    with zipfile.ZipFile(path) as zf:
        meta = json.loads(zf.read("meta.json"))
        out = {}
        for name in zf.namelist():
            if name.endswith(".npy"):
                out[name[:-4]] = np.load(io.BytesIO(zf.read(name)), allow_pickle=False)
    return meta, out


def test_nan_markers_leave_the_file_as_a_mask_and_come_back(tmp_path):
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command(DECK)
    from dec3d.physics.rigid import engine
    prop = engine(s.model).contacts["prop"].copy()
    assert np.isnan(prop).any()                                # the residual friction is "not set"
    s.command("model save 'a'")
    meta, arrays = _arrays(tmp_path / "a.sav")
    assert all(np.isfinite(a).all() for a in arrays.values() if a.dtype.kind == "f")
    assert meta["nan_masks"] == {"contacts.prop": "contacts.prop~unset"}
    assert np.array_equal(arrays["contacts.prop~unset"], np.isnan(prop))
    s.command("model cycle 30")
    after = s.model.vertices["pos"].copy()
    r = Session(out_dir=tmp_path, stdout=io.StringIO())
    r.command("model restore 'a'")
    got = engine(r.model).contacts["prop"]
    assert np.array_equal(np.isnan(got), np.isnan(prop)) and np.array_equal(got[~np.isnan(got)], prop[~np.isnan(prop)])
    r.command("model cycle 30")
    assert np.array_equal(r.model.vertices["pos"], after)     # the restored run goes on bit for bit


def test_a_mask_naming_no_array_of_the_file_is_refused(tmp_path):
    # (a tampered meta.json fails its checksum first; the check behind it, on the metadata alone)
    from dec3d.io.state_meta import _meta_problem

    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command(DECK + "model save 'a'")
    meta, _ = _arrays(tmp_path / "a.sav")
    assert _meta_problem(json.loads(json.dumps(meta))) is None
    for masks in ({"blocks.nothing": "blocks.nothing~unset"}, {"contacts.prop": "blocks.mass"}, ["contacts.prop"]):
        bad = json.loads(json.dumps(meta))
        bad["nan_masks"] = masks
        assert _meta_problem(bad) == "`nan_masks` does not name arrays of the file"
