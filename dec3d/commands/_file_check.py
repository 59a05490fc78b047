"""Bind time: no literal file name of a deck may write over one of the run's inputs or a file dec3d
did not write (the rules of ``dec3d.io.guard.FileRecord``, applied in deck order)."""
from __future__ import annotations

from ..io.guard import file_key
from ..io.paths import PathError, find_input, output_path, printable
from .binder import CommandCall
from .values import InPath, OutPath


def path_params(cmd) -> tuple:
    """The parameters of ``cmd`` whose values name files (OutPath, InPath), in declaration order."""
    return cmd.file_params


def bind_check(session, items) -> None:
    """The rules of ``FileRecord.refusal`` for the literal file names of the bound ``items`` of
    ``session``, in deck order (a save the deck writes before it restores it is the run's own file,
    not an input). Every deck read so far is an input already (``Session.load_file``)."""
    record = session.files
    created = set(record.created)
    inputs, keys = dict(record.inputs), dict(record.input_keys)
    for item in items:
        if type(item) is not CommandCall and not isinstance(item, CommandCall):
            continue
        for p in item.command.file_params:
            value = item.args.get(p.key)
            if not isinstance(value, str):
                continue
            where = item.locations.get(p.key, item.location)
            try:
                if isinstance(p.value, OutPath):
                    real = output_path(p.value.final(value), session.out_dir, session.allow_outside_paths)
                else:
                    real = find_input(value, session._read_bases(where), session._read_roots(where),
                                      session.allow_outside_paths, p.value.exts, prefer=created)
            except PathError:
                continue             # not there yet (a read), or refused when it runs
            if isinstance(p.value, InPath):
                if real not in created and real not in inputs:
                    inputs[real] = f"the file `{printable(value)}`"
                    k = file_key(real)
                    if k is not None:
                        keys[k] = real
                continue
            exc = record.refusal(real, p.value.final(value), created, inputs, keys)
            if exc is not None:
                raise exc.with_location(where)
            created.add(real)
