"""`program call|return|exit|log|log-file|echo`, `python-reset-state`: reading decks and logging."""
from __future__ import annotations

from .registry import Command, command
from .values import FLAG, ONOFF, InPath, OutPath, P, Text

#: ``PYTHON_RUNNER[0](session, path, where)`` runs a Python file a deck calls (registered by
#: dec3d.itasca.driver, which `dec3d run --allow-python` and dec3d.Model load; commands import no Python API)
PYTHON_RUNNER: list = [None]


def python_call(session, path, where) -> list:
    """What `program call` of a Python file (``*.py``) binds to: refused at the call, before anything runs,
    unless the session allows Python (`dec3d run --allow-python`); else one command that runs the file when
    the deck reaches it (dec3d.itasca bound to the deck's model)."""
    from ..errors import BindError, CommandError
    from .binder import CommandCall

    if not getattr(session, "allow_python", False):
        raise BindError(f"`{path.name}` is a Python file: a deck runs Python only when you allow it "
                        "(`dec3d run <deck> --allow-python`; Python is code, decks are data)", where,
                        hint="see docs/python.md")
    session.files.read(path, "a Python file the deck calls")

    def handler(sess, call):
        if PYTHON_RUNNER[0] is None:
            raise CommandError("running a Python file needs dec3d.itasca loaded (`dec3d run --allow-python`)",
                               call.location)
        PYTHON_RUNNER[0](sess, path, call.location)

    cmd = Command(("program", "call"), handler, doc="run a Python file (dec3d.itasca bound)")
    return [CommandCall(cmd, {"file": str(path)}, (), None, where)]


@command("program call", positional=[P("file", InPath(exts=(".dat", ".3ddat", ".fis", ".dec")),
                                       "deck to read: beside the calling deck, else in the output folder",
                                       required=True)],
         keywords=[P("suppress", FLAG, "do not echo the called file's commands"),
                   P("line", supported=False), P("label", Text(), supported=False)],
         doc="Read and run another deck file (`call` alone works too).",
         details="A literal file name is read, parsed and bound together with the calling deck, before anything "
                 "runs, so an error in a called file stops the run before any work is done; errors name the "
                 "include stack. Without an extension, .dat, .3ddat, .fis and .dec are tried. The file is looked "
                 "for beside the calling deck, then in the output folder; it must be a regular file under the "
                 "folder of the first deck or the output folder (docs/safety.md). A file that calls itself, "
                 "directly or through others, is refused.",
         examples=["program call 'geometry.dat'", "call \"01_Geometry.dat\""])
def program_call(session, call):
    # Only a file named by an expression (`program call [name]`) reaches this handler: a literal
    # name was read and bound together with the calling deck (Session._bind_deck).
    loc = call.location
    items = session.load_file(session.find_deck(call.args["file"], loc), loc.stack + (loc,))
    session.run_items(items)


@command("program return", doc="Stop reading the current file and return to the caller.",
         examples=["program return", "return"])
def program_return(session, call):
    # the binder stops reading the file at this line; nothing is left to do
    pass


@command("program exit", doc="Stop running the deck (the model is kept).", examples=["program exit", "exit"])
def program_exit(session, call):
    from ..errors import StopDeck

    raise StopDeck()


@command("program quit", doc="Stop running the deck (the model is kept).", examples=["program quit"])
def program_quit(session, call):
    program_exit(session, call)


@command("program log", positional=[P("mode", ONOFF, "on: copy the echo and output to the log file", required=True)],
         keywords=[P("append", FLAG, "add to an existing log file"), P("truncate", FLAG, "start the log file afresh (default)")],
         doc="Switch logging of commands and output to the log file (default `dec3d.log` in the output folder).",
         examples=["program log on", "log off"])
def program_log(session, call):
    if call.args["mode"]:
        if session._log_handle is None:
            session.open_log(None, append=call.args["append"], where=call.location)
        session.log_on = True
    else:
        session.log_on = False


@command("program log-file", positional=[P("file", OutPath(), "log file name, in the output folder", required=True)],
         keywords=[P("append", FLAG, "add to an existing file"), P("truncate", FLAG, "start the file afresh (default)")],
         doc="Name the log file; logging continues there if it is on.",
         examples=["program log-file 'run.log'", "log-file 'init_state.txt'"])
def program_log_file(session, call):
    where = call.locations.get("file", call.location)
    session.open_log(session.out_path(call.args["file"], where), append=call.args["append"], where=where)


@command("program echo", positional=[P("mode", ONOFF, "on: print each command before it runs", required=True)],
         doc="Switch the echo of commands as they run.", examples=["program echo off"])
def program_echo(session, call):
    session.echo = call.args["mode"]


@command("python-reset-state", positional=[P("mode", ONOFF, "accepted: dec3d never deletes Python's state", default=True)],
         doc="Accepted for 3DEC's Python scripts (which start with `python-reset-state false`); changes nothing.",
         details="In 3DEC, `model new` and `model restore` delete the Python variables unless this is off. dec3d "
                 "never touches Python's variables: objects and arrays from the model before a `model new` or "
                 "`model restore` raise a clear error when used (docs/python.md).",
         examples=["python-reset-state false"])
def python_reset_state(session, call):
    pass


def _check_autosave(call):
    from ..errors import NotSupportedError

    if call.args["active"]:
        raise NotSupportedError("dec3d does not save the model on its own: `program automatic-model-save active "
                                "on` is not supported (save with `model save`)", call.location)


@command("program automatic-model-save", keywords=[P("active", ONOFF, "off: no automatic saves (what dec3d does)",
                                                     required=True)], check=_check_autosave,
         doc="Accepted as `active off` (3DEC's Python drivers switch automatic saves off); dec3d never saves on its own.",
         examples=["program automatic-model-save active off"])
def program_autosave(session, call):
    pass
