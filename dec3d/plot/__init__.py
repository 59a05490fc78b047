"""Pictures: 3DEC's plot items drawn off screen (PyVista) and history charts (matplotlib).

``scene`` turns the model (or the files of a run) into PyVista grids, ``items`` reads what a plot
item asks for, ``render`` draws items into a PNG, ``draw`` serves the `plot` command and ``cli`` the
`dec3d plot` subcommand."""
