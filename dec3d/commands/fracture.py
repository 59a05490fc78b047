"""`fracture …`: discrete fracture networks of disks (3DEC 7's DFN command words).

Stores ``dec3d.model.fractures``; generation ``dec3d.geometry.dfn_gen``; measures
``dec3d.geometry.dfn_measure``; files ``dec3d.io.dfnfile``; cutting ``block cut dfn``
(``commands/block_cut_dfn.py``).

Confirmed in Itasca's pages: `fracture template create s` with `orientation`, `size`, `size-limits`,
`dip-limits`, `dip-direction-limits`, `position`; `fracture generate` with `template`, `dfn`,
`fracture-count`, `mass-density` (P32), `p10`, `generation-box`; `fracture import from-file`,
`fracture export file … format`, `fracture intersections compute`, `fracture compute`, `fracture list`,
`fracture delete`. The sub-words of `orientation` (`uniform`, `fisher`, `bootstrapped`) and of `size`
(`power-law`, `uniform`, `log-normal`, `gauss`) and their arguments, and the keywords of
`fracture compute`, could not be read in full: they are dec3d's reading (see each command page).
dec3d's own: `seed`, `maximum`, `scanline` and `set` (3DEC seeds with `model random`).
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import BindError, CommandError
from ..geometry import dfn_gen
from ..io import dfnfile
from ..lang.abbrev import matches
from ..model import fractures as FR
from .registry import command
from .values import Choice, InPath, Num, Nums, OutPath, P, Text, ValueType

_ORIENT = {"uniform": 0, "fisher": 3, "bootstrapped": "file"}
_SIZE = {"power-law": 1, "uniform": 0, "log-normal": 2, "gauss": 2}


class Dist(ValueType):
    """A distribution word and its arguments: `fisher 40 120 20`, `power-law 3.5`, `bootstrapped 'f'`."""

    fits_types = ("WORD",)

    def __init__(self, options: dict):
        self.options = options

    @property
    def label(self):
        return "/".join(self.options)

    def fits(self, tok):
        return tok.type == "WORD" and len(matches(str(tok), self.options)) == 1

    def take(self, toks, i, binder):
        hits = matches(str(toks[i]), self.options)
        if len(hits) != 1:
            raise BindError(f"`{toks[i]}` is not one of {', '.join(self.options)}", binder.where(toks[i]))
        kind = hits[0]
        need = self.options[kind]
        out = [kind]
        j = i + 1
        if need == "file":
            if j >= len(toks) or toks[j].type not in ("STRING", "WORD"):
                raise BindError(f"`{kind}` needs a file name", binder.where(toks[min(j, len(toks) - 1)]))
            s = str(toks[j])
            out.append(s[1:-1] if toks[j].type == "STRING" else s)
            return tuple(out), j + 1
        for _ in range(need):
            if j >= len(toks) or toks[j].type not in ("NUMBER", "EXPR", "ATNAME"):
                raise BindError(f"`{kind}` needs {need} number(s)", binder.where(toks[min(j, len(toks) - 1)]))
            v, j = Num().take(toks, j, binder)
            out.append(v)
        return tuple(out), j

    def convert(self, value, where):
        return tuple([value[0], *[x if isinstance(x, str) else float(x) for x in value[1:]]])

    def describe(self):
        return " / ".join(f"{k} " + ("<file>" if v == "file" else " ".join(["<f>"] * v)) for k, v in self.options.items())


def _template(session, call) -> dict:
    a = call.args
    t = dfn_gen.default_template()
    loc = call.locations
    if a["orientation"] is not None:
        o = a["orientation"]
        if o[0] == "fisher":
            t["orientation"] = {"kind": "fisher", "dip": math.radians(o[1]), "ddir": math.radians(o[2]), "kappa": o[3]}
        elif o[0] == "bootstrapped":
            where = loc.get("orientation", call.location)
            path = session.in_path(o[1], where)
            try:
                d, dd, w = dfnfile.read_bootstrapped(path.read_text(encoding="utf-8", errors="replace"))
            except dfnfile.DfnFileError as exc:
                raise CommandError(f"'{o[1]}' {exc}", where) from None
            t["orientation"] = {"kind": "bootstrapped", "dip": d, "ddir": dd, "weight": w}
        else:
            t["orientation"] = {"kind": "uniform"}
    if a["size"] is not None:
        s = a["size"]
        t["size"] = {"kind": s[0]}
        if s[0] == "power-law":
            t["size"]["exponent"] = s[1]
        elif s[0] in ("log-normal", "gauss"):
            t["size"].update(mean=s[1], std=s[2])
        if s[0] == "uniform" and a["size_limits"] is None:
            t["size_limits"] = [1.0, None]
    if a["size_limits"] is not None:
        lim = a["size_limits"]
        t["size_limits"] = [float(lim[0]), float(lim[1]) if len(lim) > 1 else None]
    if a["dip_limits"] is not None:
        t["dip_limits"] = [float(x) for x in a["dip_limits"]]
    if a["dip_direction_limits"] is not None:
        t["ddir_limits"] = [float(x) for x in a["dip_direction_limits"]]
    t["set"] = int(a["set"]) if a["set"] is not None else None
    try:
        dfn_gen.check_template(t)
    except dfn_gen.GenerationError as exc:
        import re

        word = re.match(r"`([a-z-]+)", str(exc))            # the messages start with the keyword
        key = word.group(1).replace("-", "_") if word else None
        raise CommandError(str(exc), loc.get(key, call.location) if key else call.location) from None
    return t


_TKW = [P("orientation", Dist(_ORIENT), "orientation law: `uniform` (isotropic normals), `fisher dip dip-direction "
          "kappa` (degrees), or `bootstrapped 'file'` (Itasca's bootstrapped list: id dip dip-direction [quantity])"),
        P("size", Dist(_SIZE), "size (disk diameter) law: `power-law a` (n(l) ∝ l^-a), `uniform` (on the size "
          "limits), `log-normal mean std`, `gauss mean std` (of the diameter, truncated to the limits)"),
        P("size-limits", Nums(1, 2, item=Num(lo=0, lo_open=True)), "smallest and largest diameter (no largest: "
          "unbounded)", units="m"),
        P("dip-limits", Nums(2, 2, item=Num(angle=True)), "dips kept, min max (degrees)"),
        P("dip-direction-limits", Nums(2, 2, item=Num(angle=True)), "dip directions kept, min max (degrees)"),
        P("position", Choice(("uniform",)), "position law: uniform in the generation box"),
        P("set", Num(integer=True, lo=0), "set id of the fractures made from this template (dec3d keyword; "
          "default: the template's number)")]


@command("fracture template create", positional=[P("name", Text(), "template name", required=True)], keywords=_TKW,
         doc="Create a fracture generation template: orientation, size and position laws of disk fractures.",
         details="Defaults are 3DEC's: uniform positions and orientations, sizes (disk diameters) following a "
                 "power law of exponent 4 from 1 m with no largest size. `uniform` orientations are isotropic "
                 "(normals uniform on the sphere). Fisher: density ∝ exp(κ cos θ) about the mean normal of the "
                 "given dip/dip direction. Refused: kappa ≤ 0, reversed size limits, a power-law exponent ≤ 1 "
                 "with no largest size (no finite mean), `uniform` sizes without a largest size. Sub-words of "
                 "`orientation` and `size` and their arguments are dec3d's reading of 3DEC's (only the primary "
                 "keywords could be confirmed).",
         examples=["fracture template create 'steep' orientation fisher 70 120 25 size power-law 3.5 size-limits 1 20",
                   "fracture template create 'bg' size uniform size-limits 2 6",
                   "fracture template create 'sub' orientation fisher 10 0 40 size log-normal 4 1.5 size-limits 1 12"])
def template_create(session, call):
    st = FR.dfn_state(session.model)
    name = call.args["name"]
    if name in st["templates"]:
        raise CommandError(f"there is a template '{name}' already", call.locations.get("name", call.location))
    t = _template(session, call)
    if t["set"] is None:
        t["set"] = len(st["templates"]) + 1
    st["templates"][name] = t


@command("fracture template delete", positional=[P("name", Text(), "template name", required=True)],
         doc="Delete a fracture generation template.", examples=["fracture template delete 'steep'"])
def template_delete(session, call):
    st = FR.dfn_state(session.model)
    if st["templates"].pop(call.args["name"], None) is None:
        raise CommandError(f"there is no template '{call.args['name']}'", call.location)


def _blocks_box(session):
    m = session.model
    if m.blocks.n == 0:
        return None
    p = m.vertices["pos"]
    lo, hi = p.min(axis=0), p.max(axis=0)
    return [lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]]


def _box(session, call, key="generation_box"):
    b = call.args.get(key)
    if b is not None:
        b = [float(x) for x in b]
        if not (b[0] < b[1] and b[2] < b[3] and b[4] < b[5]):
            raise CommandError("the box must be x1 x2 y1 y2 z1 z2 with x1 < x2, y1 < y2, z1 < z2",
                               call.locations.get(key, call.location))
        return b
    b = _blocks_box(session)
    if b is None:
        raise CommandError(f"give `{key.replace('_', '-')} x1 x2 y1 y2 z1 z2` (there are no blocks to take it from)",
                           call.location)
    return b


def _check_generate(call):
    n = sum(call.args[k] is not None for k in ("fracture_count", "mass_density", "p10"))
    if n != 1:
        raise BindError("`fracture generate` needs exactly one of `fracture-count`, `mass-density`, `p10`",
                        call.location)


@command("fracture generate",
         keywords=[P("template", Text(), "template name (default: the default template)"),
                   P("dfn", Text(), "name of the new DFN (default dfn<id>)"),
                   P("fracture-count", Num(integer=True, lo=1), "stop at this many fractures"),
                   P("mass-density", Num(lo=0, lo_open=True), "stop when P32 (fracture area inside the box per "
                     "volume) reaches this", units="1/m"),
                   P("p10", Num(lo=0, lo_open=True), "stop when fractures crossing the scanline per its length "
                     "reach this", units="1/m"),
                   P("scanline", Nums(6, 6), "the P10 scanline x1 y1 z1 x2 y2 z2 (dec3d keyword; default: "
                     "along x through the box centre)", units="m"),
                   P("generation-box", Nums(6, 6), "x1 x2 y1 y2 z1 z2 of the centres (default: the blocks' box)",
                     units="m"),
                   P("seed", Num(integer=True, lo=0), "random seed (dec3d keyword; 3DEC: `model random`)", default=1),
                   P("maximum", Num(integer=True, lo=1), "most fractures one generation may make (dec3d keyword)",
                     default=dfn_gen.DEFAULT_MAXIMUM)],
         check=_check_generate,
         doc="Generate a DFN of disk fractures from a template until a count, a P32 or a P10 is reached.",
         details="Centres are uniform in the generation box; disks may reach out of it (P32 counts only the "
                 "area inside, clipped exactly). The same seed gives the same fractures on every machine "
                 "(numpy PCG64). A target that would need more than `maximum` fractures is refused, saying "
                 "how many it would need. Results: `fractures_made`.",
         examples=["fracture generate template 'steep' dfn 'rock' mass-density 0.3 generation-box 0 50 0 50 0 50 seed 7",
                   "fracture generate fracture-count 200 generation-box 0 10 0 10 0 10",
                   "fracture generate template 'steep' p10 1.5 scanline 0 5 5 10 5 5 generation-box 0 10 0 10 0 10"])
def fracture_generate(session, call):
    a = call.args
    m = session.model
    st = FR.dfn_state(m)
    if a["template"] is not None:
        t = st["templates"].get(a["template"])
        if t is None:
            raise CommandError(f"there is no template '{a['template']}'", call.locations.get("template", call.location))
    else:
        t = dfn_gen.default_template()
    box = _box(session, call)
    if a["dfn"] is not None and FR.dfn_id(m, a["dfn"], create=False) is not None and \
            FR.select(m, FR.dfn_id(m, a["dfn"], create=False)).size:
        raise CommandError(f"DFN '{a['dfn']}' is not empty", call.locations.get("dfn", call.location))
    line = a["scanline"]
    if a["p10"] is not None and line is None:
        y, z = (box[2] + box[3]) / 2, (box[4] + box[5]) / 2
        line = (box[0], y, z, box[1], y, z)
    try:
        c, n, r = dfn_gen.generate(t, box, int(a["seed"]), count=a["fracture_count"], p32=a["mass_density"],
                                   p10=a["p10"], scanline=line, maximum=int(a["maximum"]))
    except dfn_gen.GenerationError as exc:
        key = "mass_density" if a["mass_density"] is not None else "p10" if a["p10"] is not None else "fracture_count"
        raise CommandError(str(exc), call.locations.get(key, call.location)) from None
    did = FR.dfn_id(m, a["dfn"], create=True)
    FR.add_fractures(m, did, c, n, r, int(t.get("set") or 1))
    st.setdefault("dfn_templates", {})[str(did)] = t
    session.results["fractures_made"] = float(len(r))
    session.write(f"DFN '{FR.dfn_name(m, did)}' (id {did}): {len(r)} fractures")


def _dfn_rows(session, call, key="dfn"):
    m = session.model
    name = call.args.get(key)
    if name is None:
        return FR.select(m), None
    did = FR.dfn_id(m, name, create=False)
    if did is None:
        raise CommandError(f"there is no DFN '{name}'", call.locations.get(key, call.location))
    return FR.select(m, did), did


def _arrays(m, rows):
    fs = FR.fracture_store(m)
    return fs["center"][rows], fs["normal"][rows], fs["radius"][rows]


@command("fracture import",
         keywords=[P("from-file", InPath(exts=(".dat", ".csv", ".txt")), "the file: Itasca-style text (`disk id x y z "
                     "diameter dip dip-direction [set]`) or .csv (id,x,y,z,nx,ny,nz,radius[,set])", required=True),
                   P("dfn", Text(), "name of the new DFN (default: the file's stem)")],
         doc="Import disk fractures from a file into a new DFN.",
         details="The file is looked for beside the calling deck, then in the output folder. A malformed line "
                 "is refused naming the file and line; nothing is imported then. The disk line of the Itasca "
                 "text format is dec3d's reading (Itasca's format page could not be read in full).",
         examples=["fracture import from-file 'joints.csv' dfn 'mapped'", "fracture import from-file 'rock.dat'"])
def fracture_import(session, call):
    m = session.model
    name = call.args["from_file"]
    where = call.locations.get("from_file", call.location)
    path = session.in_path(name, where, exts=(".dat", ".csv", ".txt"))
    text = path.read_text(encoding="utf-8", errors="replace")
    try:
        ids, c, n, r, sets = dfnfile.read_csv(text) if path.suffix.lower() == ".csv" else dfnfile.read_itasca(text)
    except dfnfile.DfnFileError as exc:
        raise CommandError(f"'{name}' {exc}", where) from None
    dname = call.args["dfn"] or path.stem
    if FR.dfn_id(m, dname, create=False) is not None:
        raise CommandError(f"there is a DFN '{dname}' already", call.locations.get("dfn", call.location))
    did = FR.dfn_id(m, dname, create=True)
    FR.add_fractures(m, did, c, n, r, sets)
    session.results["fractures_made"] = float(len(r))
    session.write(f"DFN '{dname}' (id {did}): {len(r)} fractures imported")


@command("fracture export",
         keywords=[P("file", OutPath(suffix=".dat"), "the file, in the output folder (.csv: CSV)", required=True),
                   P("format", Choice(("itasca", "csv")), "itasca (default; .dat) or csv"),
                   P("dfn", Text(), "only this DFN")],
         doc="Write disk fractures to a file: Itasca-style text or CSV of centre, normal, radius and set.",
         examples=["fracture export file 'rock'", "fracture export file 'rock.csv' format csv dfn 'rock'"])
def fracture_export(session, call):
    m = session.model
    rows, _ = _dfn_rows(session, call)
    name = call.args["file"]
    fmt = call.args["format"] or ("csv" if name.lower().endswith(".csv") else "itasca")
    path = session.out_path(OutPath(suffix=".csv" if fmt == "csv" else ".dat").final(name),
                            call.locations.get("file", call.location))
    fs = FR.fracture_store(m)
    c, n, r = _arrays(m, rows)
    if fmt == "csv":
        dfnfile.write_csv(path, fs["id"][rows], c, n, r, fs["set"][rows])
    else:
        d, dd = FR.dips_from_normals(n) if len(rows) else (np.zeros(0), np.zeros(0))
        dfnfile.write_itasca(path, fs["id"][rows], c, np.degrees(d), np.degrees(dd), r, fs["set"][rows])


@command("fracture vtk", positional=[P("file", OutPath(stem=True), "file name stem (default 'fractures')")],
         keywords=[P("sides", Num(integer=True, lo=3, hi=256), "sides of the polygon of each disk", default=24),
                   P("dfn", Text(), "only this DFN")],
         doc="Write the disks to `<file>_0000.vtu` (polygons) listed in `<file>.pvd` (dec3d command).",
         details="Each disk is a regular polygon inscribed in it. Cell data: fracture_id, dfn_id, set, radius, "
                 "dip, dip_direction (degrees), cluster (of the last `fracture intersections compute`, −1 before), normal.",
         examples=["fracture vtk", "fracture vtk 'dfn' sides 32"])
def fracture_vtk(session, call):
    from ..io.vtk import write_pvd

    m = session.model
    rows, _ = _dfn_rows(session, call)
    stem = OutPath(stem=True).final(call.args["file"] or "fractures")
    where = call.locations.get("file", call.location)
    pvd = session.out_path(stem, where)
    vtu = session.out_path(str(pvd.with_suffix("")) + "_0000.vtu", where)
    fs = FR.fracture_store(m)
    c, n, r = _arrays(m, rows)
    d, dd = FR.dips_from_normals(n) if len(rows) else (np.zeros(0), np.zeros(0))
    dfnfile.write_vtu(vtu, fs["id"][rows], fs["dfn"][rows], fs["set"][rows], c, n, r, np.degrees(d), np.degrees(dd),
                      sides=int(call.args["sides"]), cluster=fs["cluster"][rows])
    write_pvd(pvd, [(m.time, str(vtu))])
