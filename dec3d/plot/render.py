"""Off-screen pictures of a ``Scene`` with PyVista (VTK): what 3DEC's plot items show.

One call draws the items of one plot into one PNG: blocks by group, contours of displacement,
velocity or zone stress (on the gridpoints: the volume-weighted ``stress_gp``), the plastic state with
3DEC's categories, the joint planes coloured by a contact quantity, vectors, cables. Colours run blue
(low) to red (high), 3DEC's default. No display is needed (VTK renders off screen)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .items import Item

#: the view: from the front (−y), right and above, z up
VIEW = (1.0, -1.6, 0.8)
SIZE = (800, 600)
CMAP = "jet"
#: colours of the plastic-state categories (3DEC's legend order)
STATE_COLOURS = {"none": "#c0c0c0", "shear-n": "#e41a1c", "tension-n": "#ff7f00", "shear-p": "#377eb8",
                 "tension-p": "#984ea3", "shear-n tension-n": "#a65628", "shear-n shear-p": "#f781bf",
                 "tension-n shear-p": "#ffd92f", "shear-n tension-n shear-p": "#8c510a",
                 "shear-n tension-p": "#4daf4a", "tension-n tension-p": "#fdae61",
                 "shear-n tension-n tension-p": "#762a83", "shear-p tension-p": "#66c2a5",
                 "shear-n shear-p tension-p": "#e7298a", "tension-n shear-p tension-p": "#1b9e77",
                 "shear-n tension-n shear-p tension-p": "#000000"}
GROUP_COLOURS = ("#c8a878", "#7fa6c9", "#9fc98a", "#d98c8c", "#b39ddb", "#e6c96b", "#80cbc4", "#bcaaa4")
_STRESS_COL = {"xx": 0, "yy": 1, "zz": 2, "xy": 3, "yz": 4, "xz": 5}     # VTK's order in the files


@dataclass
class Picture:
    path: str
    image: np.ndarray            # (rows, columns, 3) uint8
    matrix: np.ndarray           # world -> normalized view coordinates (4 x 4)

    def pixel_of(self, point) -> tuple[int, int]:
        """(row, column) of the image where the world point ``point`` is drawn."""
        p = self.matrix @ np.append(np.asarray(point, dtype=float), 1.0)
        x, y = p[0] / p[3], p[1] / p[3]
        h, w = self.image.shape[:2]
        return int(round((1 - (y + 1) / 2) * (h - 1))), int(round((x + 1) / 2 * (w - 1)))


def _add(pl, mesh, **kw):
    """add_mesh without lighting (a colour is the colour of its value, as on 3DEC's contour plots),
    with dark edges unless told otherwise."""
    kw.setdefault("show_edges", kw.get("style") != "wireframe")
    kw.setdefault("edge_color", "#404040")
    return pl.add_mesh(mesh, lighting=False, **kw)


def _legend(pl, entries) -> None:
    """A legend box in the upper right corner, sized to its longest label."""
    longest = max(len(t) for t, _ in entries)
    w, h = min(0.5, 0.05 + 0.018 * longest), 0.045 * len(entries) + 0.02
    actor = pl.add_legend(entries, bcolor="white", face="rectangle", size=(w, h))
    actor.SetPosition(0.99 - w, 0.9 - h)          # inside the picture, under the title
    actor.SetPosition2(w, h)


def _quiet():
    from vtkmodules.vtkCommonCore import vtkLogger, vtkObject
    vtkObject.GlobalWarningDisplayOff()            # "bad X server connection": off screen needs none
    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)


def _magnitude_or_component(arr: np.ndarray, comp: str) -> np.ndarray:
    if arr.ndim == 1:
        return arr
    if comp in ("x", "y", "z"):
        return arr[:, "xyz".index(comp)]
    return np.linalg.norm(arr, axis=1)


def _zone_cells(grid):
    """The cells of a grid that are zones (not polyhedra of rigid blocks)."""
    ct = np.asarray(grid.celltypes)
    return grid.extract_cells(np.flatnonzero(ct != 42)) if (ct == 42).any() else grid


def _stress_values(grid, q: str):
    """Point values of the stress quantity ``q`` on ``grid`` (from stress_gp), or cell values."""
    if "stress_gp" in grid.point_data:
        s, where = np.asarray(grid.point_data["stress_gp"]), "point"
    elif "stress" in grid.cell_data:
        s, where = np.asarray(grid.cell_data["stress"]), "cell"
    else:
        return None, None
    comp = q.split("-", 1)[1]
    if comp in _STRESS_COL:
        return s[:, _STRESS_COL[comp]], where
    t = np.zeros((len(s), 3, 3))
    for (i, j), c in {(0, 0): 0, (1, 1): 1, (2, 2): 2, (0, 1): 3, (1, 2): 4, (0, 2): 5}.items():
        t[:, i, j] = t[:, j, i] = s[:, c]
    if comp == "mean":
        return np.trace(t, axis1=1, axis2=2) / 3.0, where
    if comp == "mises":
        d = t - np.eye(3) * (np.trace(t, axis1=1, axis2=2) / 3.0)[:, None, None]
        return np.sqrt(1.5 * np.einsum("nij,nij->n", d, d)), where
    ev = np.linalg.eigvalsh(t)                    # ascending; tension positive: min = most compressive
    return ev[:, {"min": 0, "int": 1, "max": 2}[comp]], where


def _bar(title: str) -> dict:
    return dict(title=title, n_labels=5, fmt="%.3g", vertical=True, position_x=0.07, position_y=0.12,
                width=0.07, height=0.7, title_font_size=13, label_font_size=12)


def _clim(values) -> list:
    lo, hi = float(np.min(values)), float(np.max(values))
    if hi - lo <= 1e-12 * max(abs(lo), abs(hi), 1e-30):
        # one value: the scale runs from 0 to it (0 alone: 0 to 1, blue)
        return [0.0, hi] if hi > 0 else ([lo, 0.0] if lo < 0 else [0.0, 1.0])
    return [lo, hi]


def _draw_item(pl, scene, item: Item, notices: list, text_colour: str) -> None:
    grids = scene.grids()
    if item.kind == "blocks":
        _draw_groups(pl, scene, grids)
    elif item.kind == "contour":
        q = item.quantity
        if q.startswith(("stress", "von-mises")):
            qq = "stress-mises" if q == "von-mises" else q
            drawn = False
            for g in grids:
                if "zone_id" not in g.cell_data and "stress" not in g.cell_data:
                    _add(pl, g, color="#d9d9d9", opacity=0.35)
                    continue
                z = _zone_cells(g) if "zone_id" in g.cell_data else g
                vals, where = _stress_values(z, qq)
                if vals is None or not z.n_cells:
                    continue
                z = z.copy()
                (z.point_data if where == "point" else z.cell_data)[q] = vals
                _add(pl, z, scalars=q, preference=where, cmap=CMAP, clim=_clim(vals),
                            scalar_bar_args=_bar(f"{q} (tension +)"), show_edges=False)
                drawn = True
            if not drawn:
                notices.append(f"{q}: the model has no zones (stresses are zone values); blocks drawn plain")
                _draw_groups(pl, scene, grids)
        else:
            base, _, comp = q.partition("-")
            vals_all = [np.asarray(g.point_data[base]) for g in grids if base in g.point_data]
            if not vals_all:
                notices.append(f"{q}: no such point data; blocks drawn plain")
                _draw_groups(pl, scene, grids)
                return
            allv = np.concatenate([_magnitude_or_component(v, comp) for v in vals_all])
            clim = _clim(allv)
            for k, g in enumerate(grids):
                if base not in g.point_data:
                    continue
                g = g.copy()
                g.point_data[q] = _magnitude_or_component(np.asarray(g.point_data[base]), comp)
                _add(pl, g, scalars=q, preference="point", cmap=CMAP, clim=clim,
                            scalar_bar_args=_bar(q if comp else f"{base} magnitude"), show_scalar_bar=k == 0)
    elif item.kind == "state":
        _draw_state(pl, scene, grids, notices)
    elif item.kind == "joints":
        _draw_joints(pl, scene, grids, item, notices)
    elif item.kind == "vector":
        _draw_vectors(pl, grids, item.quantity)
    elif item.kind == "cable":
        if scene.cables is None or not scene.cables.n_cells:
            notices.append("cable: the model has no cables")
            return
        for g in grids:
            _add(pl, g, color="#d9d9d9", opacity=0.25)
        f = np.asarray(scene.cables.cell_data["axial_force"])
        _add(pl, scene.cables, scalars="axial_force", cmap=CMAP, clim=_clim(f), line_width=5,
                    scalar_bar_args=_bar("cable axial force (tension +)"))


def _draw_groups(pl, scene, grids) -> None:
    names = scene.group_names
    # 3DEC colours by the Default slot; when that has one group, by the first slot that has more
    slots = ["group:Default"] + sorted({k for g in grids for k in g.cell_data.keys()
                                        if k.startswith("group:") and k != "group:Default"})
    key = slots[0]
    for k in slots:
        codes = {int(c) for g in grids if k in g.cell_data for c in np.unique(np.asarray(g.cell_data[k])) if c >= 0}
        if len(codes) > 1:
            key = k
            break
    codes = np.concatenate([np.asarray(g.cell_data[key]) for g in grids if key in g.cell_data]) \
        if any(key in g.cell_data for g in grids) else np.zeros(0)
    used = sorted(set(int(c) for c in codes if c >= 0))
    if len(used) <= 1:
        for g in grids:
            _add(pl, g, color=GROUP_COLOURS[0], show_edges=True, edge_color="#555555")
        return
    for g in grids:
        c = np.asarray(g.cell_data[key]) if key in g.cell_data else np.full(g.n_cells, -1)
        for code in np.unique(c):
            sub = g.extract_cells(np.flatnonzero(c == code))
            _add(pl, sub, color=GROUP_COLOURS[used.index(code) % len(GROUP_COLOURS)] if code >= 0 else "#bbbbbb",
                        show_edges=True, edge_color="#555555")
    _legend(pl, [(names[c] if c < len(names) else str(c), GROUP_COLOURS[i % len(GROUP_COLOURS)])
                 for i, c in enumerate(used)])


def _draw_state(pl, scene, grids, notices) -> None:
    from dec3d.io.vtk import PLASTIC_LABELS
    zoned = [g for g in grids if "plastic_label" in g.cell_data]
    if not zoned:
        notices.append("state: the model has no zones (the plastic state is a zone value); blocks drawn plain")
        _draw_groups(pl, scene, grids)
        return
    for g in grids:
        if "plastic_label" not in g.cell_data:
            _add(pl, g, color="#d9d9d9", opacity=0.35)
    seen = []
    for g in zoned:
        z = _zone_cells(g)
        lab = np.asarray(z.cell_data["plastic_label"])
        for code in np.unique(lab):
            text = PLASTIC_LABELS[int(code)]
            colour = STATE_COLOURS[text]          # one colour per combination, as 3DEC's legend lists them
            _add(pl, z.extract_cells(np.flatnonzero(lab == code)), color=colour, show_edges=False)
            if text not in seen:
                seen.append(text)
    order = {t: i for i, t in enumerate(PLASTIC_LABELS)}
    seen.sort(key=lambda t: order[t])
    _legend(pl, [(t, STATE_COLOURS[t]) for t in seen])


_JOINT_ARRAYS = {"normal-stress": "normal_stress", "shear-stress": "shear_stress", "slip": "slip",
                 "state": "state", "opening": "opening", "normal-displacement": "normal_displacement",
                 "shear-displacement": "shear_displacement_magnitude", "pressure": "pressure"}


def _draw_joints(pl, scene, grids, item, notices) -> None:
    j = scene.joints
    for g in grids:
        _add(pl, g, style="wireframe", color="#888888", opacity=0.4)
    if j is None or not j.n_cells:
        notices.append(f"joint {item.quantity}: the model has no contacts")
        return
    name = _JOINT_ARRAYS[item.quantity]
    if name not in j.cell_data:
        notices.append(f"joint {item.quantity}: the joints carry no {name} (no water in the joints)")
        return
    vals = np.asarray(j.cell_data[name])
    if item.quantity == "slip":
        _add(pl, j.extract_cells(np.flatnonzero(vals == 0)), color="#377eb8") if (vals == 0).any() else None
        _add(pl, j.extract_cells(np.flatnonzero(vals != 0)), color="#e41a1c") if (vals != 0).any() else None
        _legend(pl, [("no slip", "#377eb8"), ("slip", "#e41a1c")])
        return
    _add(pl, j, scalars=name, preference="cell", cmap=CMAP, clim=_clim(vals),
                scalar_bar_args=_bar(f"joint {item.quantity}" + (" (compression +)" if "normal-stress" == item.quantity
                                                                 else "")))


def _draw_vectors(pl, grids, quantity: str) -> None:
    import pyvista as pv
    pts, vec = [], []
    for g in grids:
        _add(pl, g, color="#d9d9d9", opacity=0.3)
        if quantity in g.point_data:
            pts.append(np.asarray(g.points))
            vec.append(np.asarray(g.point_data[quantity]))
    if not pts:
        return
    p, v = np.concatenate(pts), np.concatenate(vec)
    mag = np.linalg.norm(v, axis=1)
    if mag.max() <= 0:
        return
    size = max(np.ptp(p, axis=0).max(), 1e-12)
    cloud = pv.PolyData(p)
    cloud["v"] = v
    cloud["magnitude"] = mag
    arrows = cloud.glyph(orient="v", scale="magnitude", factor=0.12 * size / mag.max())
    _add(pl, arrows, scalars="magnitude", cmap=CMAP, show_edges=False, scalar_bar_args=_bar(f"{quantity} magnitude"))


def render(scene, items: list[Item], path, title: str = "", background: str = "white",
           size=SIZE) -> tuple[Picture, list[str]]:
    """Draw ``items`` of ``scene`` into the PNG ``path``; returns the picture and notices for what
    could not be drawn (a plot of nothing draws the blocks)."""
    import pyvista as pv

    _quiet()
    notices: list[str] = []
    pl = pv.Plotter(off_screen=True, window_size=list(size))
    try:
        pl.set_background(background)
    except ValueError:
        notices.append(f"background '{background}' is not a colour dec3d knows (a name like 'white' or "
                       "'#rrggbb'): white")
        background = "white"
        pl.set_background(background)
    text_colour = "white" if background.lower() in ("black", "#000000", "k") else "black"
    solid = [i for i in items if i.kind != "chart"]
    colours_geometry = any(i.kind in ("contour", "state") for i in solid)
    for it in solid:
        if it.kind == "blocks" and colours_geometry:
            continue                              # the contour draws the same faces
        _draw_item(pl, scene, it, notices, text_colour)
    if not solid or not pl.renderer.actors:
        if not scene.grids():
            notices.append("nothing to draw: the model has no blocks")
        _draw_groups(pl, scene, scene.grids())
    rgb = (1.0, 1.0, 1.0) if text_colour == "white" else (0.0, 0.0, 0.0)
    for bar in pl.scalar_bars.values():          # (not the global theme: a user's own PyVista stays as it was)
        bar.GetTitleTextProperty().SetColor(*rgb)
        bar.GetLabelTextProperty().SetColor(*rgb)
    if title:
        pl.add_text(title, position="upper_edge", font_size=12, color=text_colour)
    pl.view_vector(VIEW, viewup=(0, 0, 1))
    pl.reset_camera()
    pl.camera.zoom(0.95)
    img = pl.screenshot(str(path), return_img=True)
    cam = pl.camera
    aspect = size[0] / size[1]
    m = cam.GetCompositeProjectionTransformMatrix(aspect, -1, 1)
    matrix = np.array([[m.GetElement(i, j) for j in range(4)] for i in range(4)])
    pl.close()
    return Picture(str(path), np.asarray(img)[:, :, :3], matrix), notices
