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
         keywords=[P("trust", FLAG, "restore the file's FISH functions and callbacks even when this user's key did "
                                    "not sign it (dec3d keyword; `dec3d run --trust-save` for every restore)",
                     bare=True)],
         doc="Replace the model (and the FISH globals, functions, tables and callbacks) by one saved with "
             "`model save`.",
         details="A file from a newer dec3d, or one that is damaged, is refused and the current model is kept.\n\n"
                 "FISH functions and callbacks are code: they come back only from a save this user made on this "
                 "machine (its signature checks under the user's key, see docs/safety.md) or with `trust`. From "
                 "any other save the model, the FISH variables and tables come back, and one line names the "
                 "functions and callbacks left out.",
         examples=["model restore 'ElasticHole-Hex'", "model restore 'colleague_stage2' trust"])
def model_restore(session, call):
    where = call.locations.get("file", call.location)
    try:
        # everything is read and checked first: a file that fails leaves the model and record as they were
        model, meta = restore_state(session.in_path(call.args["file"], where, RESTORE_NAME.exts, "state file"))
        # FISH globals and functions come back too (a file without them leaves the session's FISH as it is)
        fish = meta.get("extra", {}).get("fish")
        put_fish, left_out = None, []
        if fish is not None:
            if not (meta.get("signed_here") or call.args.get("trust") or getattr(session, "trust_saves", False)):
                fish, left_out = _without_code(fish)
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
    if left_out:
        session.write(f"model restore: '{call.args['file']}' was not saved by this user on this machine: its FISH "
                      f"{' and '.join(left_out)} not restored (the model, FISH variables and tables are); "
                      f"`model restore '{call.args['file']}' trust` restores them from a file you trust")


def _without_code(fish):
    """The saved FISH state without its functions and callbacks, and the words naming what was left out."""
    if not isinstance(fish, dict):
        return fish, []
    names = [f.get("name") for f in fish.get("functions", []) if isinstance(f, dict)]
    names = [n for n in names if isinstance(n, str)]
    ncb = len(fish.get("callbacks", [])) if isinstance(fish.get("callbacks"), list) else 0
    words = []
    if names:
        shown = ", ".join(f"`{n}`" for n in names[:8]) + (f" and {len(names) - 8} more" if len(names) > 8 else "")
        words.append(f"function{'s' if len(names) > 1 else ''} {shown}")
    if ncb:
        words.append(f"{ncb} callback{'s' if ncb > 1 else ''}")
    return {**fish, "functions": [], "callbacks": []}, words
