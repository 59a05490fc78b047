"""The model: every store of the simulation plus its settings.

`model new` replaces the session's Model with a fresh one.
"""
from __future__ import annotations

from .settings import Settings


class Model:
    """All state of one simulation. Stores are added by the geometry and physics layers."""

    def __init__(self) -> None:
        self.settings = Settings()
