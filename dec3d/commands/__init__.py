"""dec3d.commands: command handlers, one module per command family, registered by decorator.

`load_all()` imports every module of this package once (a new command family is a new
file here, with no central list to edit), then adds the names of 3DEC commands that
are not implemented yet.
"""
from __future__ import annotations

import importlib
import pkgutil

_INFRASTRUCTURE = {"registry", "binder", "bind_plan", "values", "catalogue", "legacy"}
_loaded = False


def load_all() -> None:
    global _loaded
    if _loaded:
        return
    for info in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
        if info.name not in _INFRASTRUCTURE and not info.name.startswith("_"):
            importlib.import_module(f"{__name__}.{info.name}")
    from .catalogue import install

    install()
    _loaded = True
