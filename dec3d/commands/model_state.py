"""`model save` / `model restore`: the whole model in one state file."""
from __future__ import annotations

from ..io.state import StateFileError, restore_state, save_state
from .fish_cmds import attach_fish, fish_state, read_fish_state
from .registry import command
from .values import FLAG, InPath, OutPath, P

SAVE_NAME = OutPath(suffix=".sav")       # 3DEC adds .sav
RESTORE_NAME = InPath(exts=(".sav",))


@command("model save", positional=[P("file", SAVE_NAME, "file name in the output folder (.sav added when there is no extension)",
                                     required=True)],
         keywords=[P("compress", FLAG, "accepted for 3DEC compatibility (files are always compressed)", bare=True)],
         doc="Save the model (every store, settings, groups and the commands run so far) to a file.",
         details="The file is a zip of numpy arrays (`.npz` layout) and `meta.json` (format version, units, "
                 "settings, command record). Saving the same model twice gives the same bytes.",
         examples=["model save 'ElasticHole-Hex'", "model save 'stage1.sav' compress"])
def model_save(session, call):
    where = call.locations.get("file", call.location)
    target = session.out_path(SAVE_NAME.final(call.args["file"]), where)
    try:
        save_state(session.model, target, records=list(session.record), extra={"fish": fish_state(session, where)})
    except StateFileError as exc:
        raise exc.with_location(where) from None
    session.written.add(target)


@command("model restore", positional=[P("file", RESTORE_NAME, "file written by `model save` (.sav tried when "
                                        "there is no extension): beside the deck, else in the output folder",
                                        required=True)],
         doc="Replace the model (and the FISH globals, functions, tables and callbacks) by one saved with "
             "`model save`.",
         details="A file from a newer dec3d, or one that is damaged, is refused and the current model is kept.",
         examples=["model restore 'ElasticHole-Hex'"])
def model_restore(session, call):
    where = call.locations.get("file", call.location)
    try:
        # everything is read and checked first: a file that fails leaves the model and record as they were
        model, meta = restore_state(session.in_path(call.args["file"], where, RESTORE_NAME.exts, "state file"))
        # FISH globals and functions come back too (a file without them leaves the session's FISH as it is)
        fish = meta.get("extra", {}).get("fish")
        put_fish = None
        if fish is not None:
            try:
                put_fish = read_fish_state(session, fish)
            except ValueError as exc:
                raise StateFileError(f"'{call.args['file']}': the FISH state is inconsistent: {exc}") from None
    except StateFileError as exc:
        raise exc.with_location(where) from None
    session.model = model
    session.record[:] = list(meta.get("records", []))
    if put_fish is not None:
        put_fish()
    attach_fish(session)
