"""`model save` / `model restore`: the whole model in one state file."""
from __future__ import annotations

from pathlib import Path

from ..io.state import restore_state, save_state
from .registry import command
from .values import FLAG, P, Text


def _state_path(session, name: str) -> Path:
    p = session.out_path(name)
    return p if p.suffix else p.with_suffix(".sav")    # 3DEC adds .sav


@command("model save", positional=[P("file", Text(), "file name (.sav added when there is no extension)",
                                     required=True)],
         keywords=[P("compress", FLAG, "accepted for 3DEC compatibility (files are always compressed)", bare=True)],
         doc="Save the model (every store, settings, groups and the commands run so far) to a file.",
         details="The file is a zip of numpy arrays (`.npz` layout) and `meta.json` (format version, units, "
                 "settings, command record). Saving the same model twice gives the same bytes.",
         examples=["model save 'ElasticHole-Hex'", "model save 'stage1.sav' compress"])
def model_save(session, call):
    save_state(session.model, _state_path(session, call.args["file"]), records=list(session.record))


@command("model restore", positional=[P("file", Text(), "file written by `model save`", required=True)],
         doc="Replace the model by one saved with `model save`.",
         details="A file from a newer dec3d, or one that is damaged, is refused and the current model is kept.",
         examples=["model restore 'ElasticHole-Hex'"])
def model_restore(session, call):
    model, meta = restore_state(_state_path(session, call.args["file"]))
    session.model = model
    session.record[:] = list(meta.get("records", []))
