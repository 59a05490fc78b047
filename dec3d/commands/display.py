"""`plot ...`: 3DEC's plotting is interactive; dec3d writes VTK files for ParaView/PyVista instead."""
from __future__ import annotations

from .registry import command


@command("plot", accepts_anything=True,
         doc="Display-only command: accepted and skipped (a one-line notice, the first time only).",
         details="dec3d has no built-in 3-D views. Write snapshots with `block vtk` and open them in "
                 "ParaView or PyVista; histories are plotted by `history export`.",
         examples=["plot create 'Blocks'", "plot 'Blocks' export bitmap filename 'b.png'"])
def plot(session, call):
    if getattr(session, "plot_notice_shown", False):
        return                                  # once per session: a deck may have hundreds of plot lines
    session.plot_notice_shown = True
    session.write("notice: `plot` commands are display-only in dec3d and are skipped "
                  "(use `block vtk` for ParaView/PyVista output; this notice is shown once)")
