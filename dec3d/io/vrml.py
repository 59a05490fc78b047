"""VRML 2.0 (VRML97) geometry as blocks: `block generate from-vrml filename '<f>.wrl'`.

What is read (VRML97, ISO/IEC 14772-1, clauses 5 and 6): the node tree of the file, with
``DEF``/``USE``; every ``IndexedFaceSet`` (its ``coord Coordinate { point [...] }`` and
``coordIndex [...]``, faces ended by -1, the last one possibly without) becomes one
convex block; ``Transform`` nodes (translation, rotation, scale, scaleOrientation, center)
place their children, nested transforms composed; ``Group``, ``Anchor``, ``Collision``
and ``Switch`` (all children) are plain groups; appearance, normals, colours, texture
coordinates, lights, viewpoints and backgrounds are skipped. Other geometry nodes
(``Box``, ``Sphere``, ``Extrusion``...), ``PROTO``, ``EXTERNPROTO`` and ``Inline`` are
refused by name with their line.

A face set may come as triangles (CAD exporters split every planar face): neighbouring
faces that lie in one plane (within the model tolerance) are merged back into one face
before the polyhedron is checked (closed, planar faces, convex; ``polyhedron_from_faces``),
so an error names the shape (counted from 1 in the file) and the file's line.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from ..errors import Dec3dError
from ..geometry.errors import GeometryError
from ..geometry.polyhedron import Poly, _merge_points, polyhedron_from_faces


class VrmlError(Dec3dError):
    """A VRML file that cannot be read as blocks; the message names the file and its line."""


_TOKEN = re.compile(r"""
    (?P<ws>[\s,]+)
  | (?P<comment>\#[^\n]*)
  | (?P<punct>[{}\[\]])
  | (?P<string>"(?:[^"\\\n]|\\.)*")
  | (?P<number>[+-]?(?:0[xX][0-9a-fA-F]+|(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?))(?![^\s,{}\[\]\#])
  | (?P<word>[^\s,{}\[\]\#"]+)
""", re.X)


@dataclass
class _Tok:
    kind: str        # punct, string, number, word
    text: str
    line: int


def _tokens(text: str, fname: str) -> list[_Tok]:
    out: list[_Tok] = []
    line = 1
    pos = 0
    n = len(text)
    while pos < n:
        m = _TOKEN.match(text, pos)
        if m is None:          # an unterminated string
            raise VrmlError(f"{fname}:{line}: a string is not closed on its line")
        kind = m.lastgroup
        s = m.group()
        if kind not in ("ws", "comment"):
            out.append(_Tok(kind, s, line))
        line += s.count("\n")
        pos = m.end()
    return out


@dataclass
class _Node:
    type: str
    line: int
    fields: dict = field(default_factory=dict)      # name -> list of values (numbers, words, strings, nodes)


_IGNORED_NODES = {"Background", "Viewpoint", "NavigationInfo", "WorldInfo", "DirectionalLight", "PointLight",
                  "SpotLight", "Fog", "Sound", "AudioClip", "Script", "TimeSensor", "ProximitySensor",
                  "TouchSensor", "VisibilitySensor", "CylinderSensor", "PlaneSensor", "SphereSensor",
                  "PositionInterpolator", "OrientationInterpolator", "ColorInterpolator",
                  "ScalarInterpolator", "CoordinateInterpolator", "NormalInterpolator", "LOD", "Billboard"}
_GROUPS = {"Transform", "Group", "Anchor", "Collision", "Switch"}
_OTHER_GEOMETRY = {"Box", "Sphere", "Cone", "Cylinder", "Extrusion", "ElevationGrid", "IndexedLineSet",
                   "PointSet", "Text"}


class _Parser:
    def __init__(self, toks: list[_Tok], fname: str):
        self.t = toks
        self.i = 0
        self.fname = fname
        self.defs: dict[str, _Node] = {}

    def err(self, msg: str, line: int | None = None) -> VrmlError:
        if line is None:
            line = self.t[self.i].line if self.i < len(self.t) else (self.t[-1].line if self.t else 1)
        return VrmlError(f"{self.fname}:{line}: {msg}")

    def peek(self) -> _Tok | None:
        return self.t[self.i] if self.i < len(self.t) else None

    def next(self, what: str) -> _Tok:
        if self.i >= len(self.t):
            raise self.err(f"the file ends where {what} was expected")
        tok = self.t[self.i]
        self.i += 1
        return tok

    def expect(self, text: str, what: str) -> _Tok:
        tok = self.next(what)
        if tok.text != text:
            raise self.err(f"expected '{text}' ({what}), found '{tok.text}'", tok.line)
        return tok

    def nodes(self) -> list[_Node]:
        out = []
        while self.peek() is not None:
            tok = self.peek()
            if tok.text == "ROUTE":         # ROUTE a.b TO c.d: events, no geometry
                self.i += 4
                continue
            out.append(self.node())
        return out

    def node(self) -> _Node:
        tok = self.next("a node")
        if tok.kind != "word":
            raise self.err(f"expected a node, found '{tok.text}'", tok.line)
        if tok.text == "USE":
            name = self.next("a DEF name after USE")
            if name.text not in self.defs:
                raise self.err(f"USE of '{name.text}', which no DEF before it names", name.line)
            return self.defs[name.text]
        defname = None
        if tok.text == "DEF":
            defname = self.next("a name after DEF").text
            tok = self.next("a node after DEF " + defname)
        if tok.text in ("PROTO", "EXTERNPROTO"):
            raise self.err(f"{tok.text} is not supported in VRML geometry input: define the shapes directly",
                           tok.line)
        if tok.kind != "word" or not tok.text[:1].isalpha():
            raise self.err(f"expected a node type, found '{tok.text}'", tok.line)
        node = _Node(tok.text, tok.line)
        if defname is not None:
            self.defs[defname] = node
        self.expect("{", f"the body of {tok.text}")
        while True:
            f = self.next(f"a field of {node.type} (opened on line {node.line}) or '}}'")
            if f.text == "}":
                return node
            if f.kind != "word":
                raise self.err(f"expected a field name of {node.type}, found '{f.text}'", f.line)
            if f.text == "ROUTE":
                self.i += 3
                continue
            node.fields[f.text] = (f.line, self.value(node, f.text))

    def value(self, node: _Node, name: str) -> list:
        tok = self.peek()
        if tok is None:
            raise self.err(f"the file ends inside field '{name}' of {node.type} (line {node.line})")
        if tok.text == "[":
            self.i += 1
            vals: list = []
            while True:
                tok = self.peek()
                if tok is None:
                    raise self.err(f"the list of field '{name}' is not closed with ']'")
                if tok.text == "]":
                    self.i += 1
                    return vals
                vals.append(self.item(node, name))
        if tok.kind == "word" and (tok.text in ("DEF", "USE", "NULL") or self._is_node_start()):
            if tok.text == "NULL":
                self.i += 1
                return []
            return [self.node()]
        vals = []
        while True:       # an SF/MF value without brackets: numbers, booleans, strings
            tok = self.peek()
            if tok is None or tok.text in ("{", "}", "[", "]"):
                break
            if tok.kind == "word" and tok.text not in ("TRUE", "FALSE"):
                break
            vals.append(self._scalar(self.next("a value")))
        if not vals:
            raise self.err(f"field '{name}' of {node.type} has no value")
        return vals

    def _is_node_start(self) -> bool:
        j = self.i + 1
        return j < len(self.t) and self.t[j].text == "{"

    def item(self, node: _Node, name: str):
        tok = self.peek()
        if tok.kind == "word" and tok.text not in ("TRUE", "FALSE"):
            return self.node()
        if tok.text in ("{", "}", "["):
            raise self.err(f"unexpected '{tok.text}' in the list of field '{name}' of {node.type}")
        return self._scalar(self.next("a value"))

    def _scalar(self, tok: _Tok):
        if tok.kind == "number":
            try:
                v = float(int(tok.text, 16)) if tok.text.lower().lstrip("+-").startswith("0x") else float(tok.text)
            except ValueError:
                raise self.err(f"'{tok.text}' is not a number", tok.line) from None
            return _Num(v, tok.line)
        return tok.text


@dataclass(frozen=True)
class _Num:
    v: float
    line: int


@dataclass
class VrmlShape:
    """One IndexedFaceSet: its faces' corner coordinates (after the transforms) and where it is."""

    faces: list            # list of (k, 3) arrays
    line: int              # line of the IndexedFaceSet


def _numbers(parser: _Parser, node: _Node, name: str, count: int | None = None) -> list[float] | None:
    if name not in node.fields:
        return None
    line, vals = node.fields[name]
    out = []
    for v in vals:
        if not isinstance(v, _Num):
            raise parser.err(f"field '{name}' of {node.type} must hold numbers, found '{v}'", line)
        out.append(v.v)
    if count is not None and len(out) != count:
        raise parser.err(f"field '{name}' of {node.type} needs {count} numbers, {len(out)} given", line)
    if not all(np.isfinite(out)):
        raise parser.err(f"field '{name}' of {node.type} holds a number that is not finite", line)
    return out


def _rotation(axis_angle) -> np.ndarray:
    x, y, z, a = axis_angle
    ax = np.array([x, y, z], dtype=np.float64)
    n = np.linalg.norm(ax)
    if n == 0.0:
        return np.eye(3)
    ax /= n
    k = np.array([[0, -ax[2], ax[1]], [ax[2], 0, -ax[0]], [-ax[1], ax[0], 0]])
    return np.eye(3) + np.sin(a) * k + (1 - np.cos(a)) * (k @ k)


def _transform_matrix(parser: _Parser, node: _Node) -> np.ndarray:
    """4x4 matrix of a Transform: P' = T C R SR S -SR -C P (VRML97 6.52)."""
    t = _numbers(parser, node, "translation", 3) or [0.0, 0.0, 0.0]
    c = _numbers(parser, node, "center", 3) or [0.0, 0.0, 0.0]
    r = _numbers(parser, node, "rotation", 4) or [0.0, 0.0, 1.0, 0.0]
    s = _numbers(parser, node, "scale", 3) or [1.0, 1.0, 1.0]
    so = _numbers(parser, node, "scaleOrientation", 4) or [0.0, 0.0, 1.0, 0.0]
    if any(v == 0.0 for v in s):
        raise parser.err("a Transform with a zero scale flattens its shapes", node.line)

    def h(m3=None, tr=None):
        m = np.eye(4)
        if m3 is not None:
            m[:3, :3] = m3
        if tr is not None:
            m[:3, 3] = tr
        return m
    sr = _rotation(so)
    return (h(tr=t) @ h(tr=c) @ h(_rotation(r)) @ h(sr) @ h(np.diag(s)) @ h(sr.T) @ h(tr=-np.asarray(c)))


def _face_set(parser: _Parser, node: _Node, m: np.ndarray) -> VrmlShape:
    if "coord" not in node.fields or not node.fields["coord"][1]:
        raise parser.err("IndexedFaceSet has no 'coord Coordinate { point [...] }'", node.line)
    cline, cval = node.fields["coord"]
    coord = cval[0]
    if not isinstance(coord, _Node) or coord.type != "Coordinate":
        raise parser.err("the 'coord' of an IndexedFaceSet must be a Coordinate node", cline)
    pts = _numbers(parser, coord, "point") or []
    if len(pts) % 3:
        raise parser.err(f"Coordinate 'point' holds {len(pts)} numbers, not a multiple of 3",
                         coord.fields["point"][0])
    p = np.asarray(pts, dtype=np.float64).reshape(-1, 3)
    p = p @ m[:3, :3].T + m[:3, 3]
    if "coordIndex" not in node.fields:
        raise parser.err("IndexedFaceSet has no 'coordIndex'", node.line)
    iline, ivals = node.fields["coordIndex"]
    faces: list[np.ndarray] = []
    cur: list[int] = []
    for v in ivals:
        if not isinstance(v, _Num) or v.v != int(v.v):
            raise parser.err(f"coordIndex must hold whole numbers, found '{getattr(v, 'v', v)}'",
                             getattr(v, "line", iline))
        k = int(v.v)
        if k == -1:
            if cur:
                faces.append(p[cur])
            cur = []
            continue
        if k < 0 or k >= len(p):
            raise parser.err(f"coordIndex {k} points past the {len(p)} coordinates of this shape", v.line)
        cur.append(k)
    if cur:
        faces.append(p[cur])       # the last face may end without -1 (VRML97 6.23)
    if not faces:
        raise parser.err("IndexedFaceSet has no faces", node.line)
    return VrmlShape(faces, node.line)


def _walk(parser: _Parser, nodes, m: np.ndarray, out: list[VrmlShape], depth: int = 0) -> None:
    if depth > 200:
        raise parser.err("nodes nested more than 200 deep")
    for node in nodes:
        if not isinstance(node, _Node):
            continue
        t = node.type
        if t in _GROUPS:
            mm = m @ _transform_matrix(parser, node) if t == "Transform" else m
            kids = node.fields.get("children", (node.line, []))[1]
            if t == "Switch":
                kids = node.fields.get("choice", (node.line, []))[1]
            _walk(parser, kids, mm, out, depth + 1)
        elif t == "Shape":
            if "geometry" not in node.fields or not node.fields["geometry"][1]:
                continue
            gline, g = node.fields["geometry"]
            g = g[0]
            if not isinstance(g, _Node):
                raise parser.err("the 'geometry' of a Shape must be a node", gline)
            if g.type == "IndexedFaceSet":
                out.append(_face_set(parser, g, m))
            else:
                raise parser.err(f"geometry node {g.type} is not supported: only IndexedFaceSet polyhedra "
                                 "become blocks", g.line)
        elif t in _OTHER_GEOMETRY or t == "IndexedFaceSet":
            raise parser.err(f"{t} outside a Shape: geometry must sit in a Shape's 'geometry' field", node.line)
        elif t == "Inline":
            raise parser.err("Inline (a second VRML file) is not supported: put the shapes in one file",
                             node.line)
        elif t in _IGNORED_NODES:
            continue
        else:
            raise parser.err(f"unknown VRML node '{t}'", node.line)


def read_vrml_shapes(text: str, fname: str) -> list[VrmlShape]:
    """The IndexedFaceSets of a VRML 2.0 file, transformed to world coordinates, in file order."""
    first = text.lstrip("\ufeff").split("\n", 1)[0]
    if not first.startswith("#VRML V2.0"):
        if first.startswith("#VRML V1.0"):
            raise VrmlError(f"{fname}:1: VRML 1.0 is not supported: save the file as VRML 2.0 (VRML97)")
        raise VrmlError(f"{fname}:1: not a VRML 2.0 file: the first line must start with '#VRML V2.0'")
    parser = _Parser(_tokens(text, fname), fname)
    nodes = parser.nodes()
    out: list[VrmlShape] = []
    _walk(parser, nodes, np.eye(4), out)
    return out


# --------------------------------------------------------------- faces -> polyhedron
def _plane_groups(pts: np.ndarray, loops: list[list[int]], tol: float) -> list[int]:
    """Group label per face: neighbouring faces (sharing an edge) in one plane share a label."""
    nf = len(loops)
    parent = list(range(nf))

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a
    normals = []
    for lp in loops:
        q = pts[lp]
        c = q.mean(axis=0)
        nv = 0.5 * np.cross(q - c, np.roll(q, -1, axis=0) - c).sum(axis=0)
        nn = np.linalg.norm(nv)
        normals.append((nv / nn if nn > 0 else nv, c))
    edges: dict[tuple[int, int], list[int]] = {}
    for fi, lp in enumerate(loops):
        for a, b in zip(lp, lp[1:] + lp[:1]):
            edges.setdefault((min(a, b), max(a, b)), []).append(fi)
    for owners in edges.values():
        if len(owners) != 2:
            continue
        f, g = owners
        (nf_, cf), (ng, cg) = normals[f], normals[g]
        if np.linalg.norm(nf_) == 0 or np.linalg.norm(ng) == 0:
            continue
        if (np.abs((pts[loops[g]] - cf) @ nf_).max() <= tol and np.abs((pts[loops[f]] - cg) @ ng).max() <= tol):
            ra, rb = find(f), find(g)
            if ra != rb:
                parent[max(ra, rb)] = min(ra, rb)
    return [find(f) for f in range(nf)]


def _merged_loop(loops: list[list[int]], what: str, face_no: int) -> list[int]:
    """The outline of faces merged into one: the edges used once, chained into one loop."""
    count: dict[tuple[int, int], int] = {}
    for lp in loops:
        for a, b in zip(lp, lp[1:] + lp[:1]):
            k = (min(a, b), max(a, b))
            count[k] = count.get(k, 0) + 1
    boundary = [k for k, c in count.items() if c == 1]
    nxt: dict[int, list[int]] = {}
    for a, b in boundary:
        nxt.setdefault(a, []).append(b)
        nxt.setdefault(b, []).append(a)
    if any(len(v) != 2 for v in nxt.values()) or not boundary:
        raise GeometryError(f"{what}: the faces in the plane of face {face_no} do not form one simple polygon")
    start = boundary[0][0]
    loop = [start]
    prev, cur = None, start
    while True:
        a, b = nxt[cur]
        step = b if a == prev else a
        if step == start:
            break
        loop.append(step)
        prev, cur = cur, step
        if len(loop) > len(nxt):
            break
    if len(loop) != len(nxt):
        raise GeometryError(f"{what}: the faces in the plane of face {face_no} leave a hole or are "
                            "split in two: a block face must be one convex polygon")
    return loop


def shape_to_poly(shape: VrmlShape, tol: float, what: str) -> Poly:
    """One convex polyhedron from a face set: coplanar neighbours merged, then checked."""
    allpts = np.concatenate(shape.faces)
    if not np.all(np.isfinite(allpts)):
        raise GeometryError(f"{what}: a corner has a coordinate that is not a finite number")
    # weld corners closer than tol so shared edges are found by index
    pts, inv = _merge_points(allpts, tol)
    inv = np.asarray(inv).reshape(-1)
    loops = []
    start = 0
    for fi, f in enumerate(shape.faces, start=1):
        lp: list[int] = []
        for k in inv[start:start + len(f)].tolist():
            if not lp or lp[-1] != k:
                lp.append(k)
        start += len(f)
        if len(lp) > 1 and lp[0] == lp[-1]:
            lp.pop()
        if len(lp) < 3:
            raise GeometryError(f"{what}: face {fi} has fewer than 3 distinct corners")
        loops.append(lp)
    labels = _plane_groups(pts, loops, tol)
    faces = []
    done: dict[int, int] = {}
    for fi, lab in enumerate(labels):
        if lab in done:
            continue
        done[lab] = fi
        members = [loops[g] for g in range(len(loops)) if labels[g] == lab]
        lp = members[0] if len(members) == 1 else _merged_loop(members, what, fi + 1)
        faces.append(pts[lp])
    return polyhedron_from_faces(faces, tol, what)


#: default planarity/convexity tolerance of a VRML shape, relative to its size (bounding-box diagonal):
#: CAD exports of curved masonry fold brick faces by a fraction of a millimetre (dec3d's choice: 0.5 %)
RELATIVE_TOLERANCE = 0.005


def vrml_polys(text: str, fname: str, tol: float, relative: float = 0.0) -> list[Poly]:
    """Every IndexedFaceSet of the file as a checked convex polyhedron. Errors name the shape and line.

    Each shape is checked with the tolerance max(tol, relative × its bounding-box diagonal)."""
    shapes = read_vrml_shapes(text, fname)
    if not shapes:
        raise VrmlError(f"{fname}: the file holds no IndexedFaceSet: no block to make")
    polys = []
    for k, s in enumerate(shapes, start=1):
        what = f"{fname}:{s.line}: shape {k}"
        t = tol
        if relative > 0:
            pts = np.concatenate(s.faces)
            if np.all(np.isfinite(pts)):
                t = max(tol, relative * float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0))))
        try:
            polys.append(shape_to_poly(s, t, what))
        except GeometryError as exc:
            raise VrmlError(str(exc.args[0]) if exc.args else str(exc)) from None
    return polys
