"""`plot ...`: 3DEC's plotting is interactive; dec3d writes VTK files for ParaView/PyVista instead."""
from __future__ import annotations

from .registry import command


@command("plot", accepts_anything=True,
         doc="Display-only command: accepted and skipped with a one-line notice.",
         details="dec3d has no built-in 3-D views. Write snapshots with `block vtk` and open them in "
                 "ParaView or PyVista; histories are plotted by `history export`.",
         examples=["plot create 'Blocks'", "plot 'Blocks' export bitmap filename 'b.png'"])
def plot(session, call):
    session.write("notice: `plot` commands are display-only in dec3d and were skipped "
                  "(use `block vtk` for ParaView/PyVista output)")
