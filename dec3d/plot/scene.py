"""What a picture is drawn from: the model's VTK data as PyVista grids, by part.

A ``Scene`` holds up to five grids: ``solids`` (the blocks: polyhedra of rigid blocks and the tetra of
zones, one grid or the two of a mixed model), ``fe`` (FE-block elements), ``joints`` (the joint planes of
``dec3d.io.jointvtk``), ``cables`` and nothing else. A scene is made from the model in memory (the
same text ``block vtk`` writes, read back by VTK: the pictures show what the files hold) or from
files written by an earlier run (a ``.pvd``: its last time; a ``.vtu``; a ``.sav``)."""
from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path


@dataclass
class Scene:
    solids: list = field(default_factory=list)      # pyvista UnstructuredGrid of blocks and zones
    fe: object = None
    joints: object = None
    cables: object = None
    histories: object = None                        # dec3d HistorySet (decks only)
    group_names: list = field(default_factory=list)

    def grids(self) -> list:
        """The grids to draw: blocks and zones, and FE elements in place of their blocks' polyhedra."""
        import numpy as np
        solids = self.solids
        if self.fe is not None and self.fe.n_cells:
            solids = [g.extract_cells(np.flatnonzero(np.asarray(g.cell_data["kind"]) != 2))
                      if "kind" in g.cell_data and (np.asarray(g.cell_data["kind"]) == 2).any() else g for g in solids]
        return [g for g in solids + [self.fe] if g is not None and g.n_cells]


def _read_text(text: str):
    import pyvista as pv
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

    reader = vtkXMLUnstructuredGridReader()
    reader.ReadFromInputStringOn()
    reader.SetInputString(text)
    reader.Update()
    return pv.wrap(reader.GetOutput())


def _names(grid) -> list:
    from dec3d.io.vtk import read_text_array
    if grid is not None and "group_names" in grid.field_data:
        return read_text_array(grid.field_data["group_names"])
    return []


def scene_from_model(model) -> Scene:
    """The model now, as ``block vtk`` would write it."""
    from dec3d.io.vtk import mixed, vtu_text

    sc = Scene()
    if mixed(model):
        sc.solids = [_read_text(vtu_text(model, cells="blocks")), _read_text(vtu_text(model, cells="zones"))]
    elif model.blocks.n:
        sc.solids = [_read_text(vtu_text(model))]
    if "feblocks" in model.stores and model.store("feblocks").n:
        import tempfile
        from dec3d.io.fevtk import write_feblocks_vtu
        with tempfile.TemporaryDirectory() as tmp:     # (the FE writer writes a file: read it back at once)
            import pyvista as pv
            sc.fe = pv.read(write_feblocks_vtu(model, os.path.join(tmp, "fe.vtu")))
    from dec3d.io.jointvtk import has_joints, joints_vtu_text
    if has_joints(model):
        sc.joints = _read_text(joints_vtu_text(model))
    if "cable_segments" in model.stores and model.store("cable_segments").n:
        import tempfile
        from dec3d.io.cablevtk import write_cables_vtu
        with tempfile.TemporaryDirectory() as tmp:
            import pyvista as pv
            sc.cables = pv.read(write_cables_vtu(model, os.path.join(tmp, "cables.vtu")))
    from dec3d.physics.history import histories
    sc.histories = histories(model)
    sc.group_names = list(model.groups.names)
    return sc


def _add_file(sc: Scene, path: Path) -> None:
    import pyvista as pv

    name = path.stem
    grid = pv.read(str(path))
    if "_joints_" in name:
        sc.joints = grid
    elif "_cables_" in name:
        sc.cables = grid
    elif "_fe_" in name:
        sc.fe = grid
    elif "_contacts_" in name:
        return                                   # the points: the joints file draws them as planes
    else:
        sc.solids.append(grid)
        sc.group_names = sc.group_names or _names(grid)


def scene_from_files(path, restore=None) -> Scene:
    """The scene of a ``.pvd`` (its last time, every part), a ``.vtu`` or a save (``.sav``: ``restore(path)``
    gives its model; the session that reads saves is above this layer)."""
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"no such file: {path}")
    suffix = path.suffix.lower()
    if suffix == ".sav" and restore is not None:
        return scene_from_model(restore(path))
    sc = Scene()
    if suffix == ".pvd":
        sets = ET.parse(path).getroot().iter("DataSet")
        entries = [(int(d.get("part", 0)), d.get("file")) for d in sets]
        if not entries:
            raise ValueError(f"{path}: the collection lists no files")
        # the last snapshot: from the last part-0 entry on
        start = max(i for i, (part, _) in enumerate(entries) if part == 0) if any(
            p == 0 for p, _ in entries) else 0
        for _, f in entries[start:]:
            _add_file(sc, path.parent / f)
        return sc
    if suffix == ".vtu":
        _add_file(sc, path)
        return sc
    raise ValueError(f"{path}: expected a .pvd, .vtu or .sav file")
