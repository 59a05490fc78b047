"""3DEC 4/5 commands -> 3DEC 7+ commands (reference §13; Itasca's 3DEC 5 -> 7 command table).

Each handler takes the tokens of one logical command (``toks[0]`` is the command word) and the
translation state, and returns ``(commands, why)``: a list of commands (each a list of `Out` pieces;
the first takes the original lines, the others follow as extra lines), or ``None`` and why not.
"""
from __future__ import annotations

import math

from .lines import Out, Tok
from .ranges import is_value, legacy_word, q, translate_range


def O(text: str, t: Tok) -> Out:
    return Out(text, t.line, t.col)


def _v(t: Tok) -> Out:
    return Out(t.text, t.line, t.col)


def _split_range(toks: list[Tok]) -> tuple[list[Tok], list[Tok]]:
    for i, t in enumerate(toks):
        if t.low == "range":
            return toks[:i], toks[i:]
    return toks, []


def _range(toks, state):
    if not toks:
        return [], ""
    out, why = translate_range(toks, state)
    if out is None:
        return None, why
    return [O("range", toks[0])] + out, ""


def _pairs(toks: list[Tok]):
    """keyword value pairs (`dens=2300`, `jkn 1e9`)."""
    i = 0
    while i < len(toks):
        if i + 1 < len(toks) and is_value(toks[i + 1]):
            yield toks[i], toks[i + 1]
            i += 2
        else:
            yield toks[i], None
            i += 1


# ----------------------------------------------------------------------------- geometry
def _poly(toks, state):
    head, rng = _split_range(toks[1:])
    if rng:
        return None, "`range` on `poly`"
    groups, kind, body = [], "polyhedron", []
    i = 0
    while i < len(head):
        t = head[i]
        hit = legacy_word(t.low, {"region": (3, "region"), "material": (3, "mat"), "constitutive": (3, "con"),
                                  "brick": (2, "brick"), "prism": (2, "prism"), "face": (1, "face"),
                                  "tetra": (3, "tetra"), "drum": (2, "drum")})
        kw = hit[1] if hit else None
        if kw in ("region", "mat", "con") and i + 1 < len(head) and is_value(head[i + 1]):
            v = head[i + 1]
            if kw == "region":
                groups.append([O("region", t), _v(v)])
            elif kw == "mat":
                state.created_mats.add(v.text)
                groups.append([O(f"group {q('mat' + v.text)} slot 'material'", t)])
            i += 2            # `con` (the zone model number) means nothing to a rigid block
            continue
        if kw in ("brick", "prism") and not body:
            kind = kw
            i += 1
            continue
        if kw in ("tetra", "drum"):
            return None, f"`poly {t.text}`"
        if kw == "face":
            body.append(O("face", t))
            i += 1
            if i + 1 < len(head) and head[i].low == "id" and is_value(head[i + 1]):
                i += 2        # `face ID 12`: the face number of 3DEC 5's geometry files
            continue
        if kind == "prism" and t.low in ("a", "b"):
            body.append(O("face-1" if t.low == "a" else "face-2", t))
            i += 1
            continue
        if is_value(t):
            body.append(_v(t))
            i += 1
            continue
        return None, f"`{t.text}` in `poly`"
    if not any(p.text.startswith("group") for g in groups for p in g):
        groups.append([O("group 'mat1' slot 'material'", toks[-1])])     # 3DEC 5: every block has a material, 1 by default
        state.created_mats.add("1")
    note = None
    if kind in ("polyhedron", "prism"):
        body, note = _convex(body, kind == "prism")
        if note and kind == "prism":
            kind = "polyhedron"
    first = [O(f"block create {kind}", toks[0])] + body
    for g in groups:
        first += [Out(p.text, toks[-1].line, toks[-1].col) for p in g]
    if note:
        first.append(Out(note, toks[-1].line, toks[-1].col))
    return [first], ""


def _convex(body: list[Out], prism: bool = False) -> tuple[list[Out], str | None]:
    """The faces of a `poly … face …` block, or those of the convex hull of its corners when the block is
    clearly not convex (a corner outside a face's plane by more than 1e-4 of its size), with a note. A
    `poly prism` whose side faces are not planar (end faces of different shapes: a tapered column drum)
    is written as the hull of its two end faces the same way."""
    import numpy as np

    from .hull import convex_excess, hull_faces, solid_volume

    faces, heads = [], []
    try:
        for p in body:
            if p.text in ("face", "face-1", "face-2"):
                faces.append([])
                heads.append(p)
            else:
                faces[-1].append(float(p.text))
    except (ValueError, IndexError):
        return body, None              # computed coordinates: dec3d checks the block when it is built
    if not faces or any(len(f) % 3 or len(f) < 9 for f in faces):
        return body, None
    arrays = [np.array(f).reshape(-1, 3) for f in faces]
    if prism:
        if len(arrays) != 2 or len(arrays[0]) != len(arrays[1]):
            return body, None
        a, b = arrays
        k = len(a)
        arrays = arrays + [np.array([a[i], a[(i + 1) % k], b[(i + 1) % k], b[i]]) for i in range(k)]
    pts = np.vstack(arrays)
    size = float(np.max(np.ptp(pts, axis=0)))
    excess = convex_excess(arrays)
    if not excess > 1e-4 * size:
        return body, None
    hull, hv = hull_faces(pts, 1e-9 * max(size, 1.0))
    given = solid_volume(arrays)
    out = []
    for k, f in enumerate(hull):
        h = heads[min(k, len(heads) - 1)]
        out.append(Out("face", h.line, h.col))
        out.append(Out(" ".join(f"{c:.10g}" for c in f.ravel()), h.line, h.col))
    what = "side faces not planar" if prism else "not convex"
    return out, (f"; dec3d translate: {what} (a corner {excess:.3g} m outside a face's plane): the convex hull "
                 f"of its corners is built, volume {given:.6g} -> {hv:.6g} ({100 * (hv - given) / given:+.2f} %)")


def _jset(toks, state):
    head, rng = _split_range(toks[1:])
    r, why = _range(rng, state)
    if r is None:
        return None, why
    vals, out = {}, [O("block cut joint-set", toks[0])]
    i = 0
    while i < len(head):
        t = head[i]
        hit = legacy_word(t.low, {"dip": (2, "dip"), "dd": (2, "dd"), "origin": (2, "origin"), "spacing": (3, "spacing"),
                                  "number": (3, "number"), "join": (4, "join"), "persistence": (3, "persistence")})
        if hit is None:
            return None, f"`{t.text}` in `jset`"
        n = {"origin": 3, "join": 0}.get(hit[1], 1)
        args = head[i + 1:i + 1 + n]
        if len(args) < n or not all(is_value(a) for a in args):
            return None, f"`{t.text}` needs {n} value(s)"
        vals[hit[1]] = (t, args)
        i += 1 + n
    dip = vals.get("dip", (None, []))[1]
    dd = vals.get("dd", (None, []))[1]
    if dip or dd:
        try:
            d, a = float(dip[0].text) if dip else 0.0, float(dd[0].text) if dd else 0.0
        except ValueError:
            return None, "`jset` with a computed dip or dip direction (3DEC 5 measured them with y up)"
        dip2, dd2 = _modern_orientation(d, a)
        t = (vals.get("dip") or vals.get("dd"))[0]
        out += [O(f"dip {dip2:.10g} dip-direction {dd2:.10g}", t)]
    for key, word in (("origin", "origin"), ("spacing", "spacing"), ("number", "number"),
                      ("persistence", "persistence")):
        if key in vals:
            t, args = vals[key]
            out += [O(word, t)] + [_v(a) for a in args]
    if "join" in vals:
        out.append(O("join", vals["join"][0]))
    return [out + r], ""


def _modern_orientation(dip: float, dd: float) -> tuple[float, float]:
    """3DEC 5 measured dip from the horizontal xz-plane with y up and the dip direction clockwise from
    +z seen from above; 3DEC 7+ uses z up and +y north (reference §13). The same plane in the same
    coordinates, as 3DEC 7+ dip and dip direction."""
    d, a = math.radians(dip), math.radians(dd)
    n = (math.sin(d) * math.sin(a), math.cos(d), math.sin(d) * math.cos(a))     # upward normal, y up
    if n[2] < 0:
        n = tuple(-c for c in n)
    dip2 = math.degrees(math.acos(max(-1.0, min(1.0, n[2]))))
    dd2 = math.degrees(math.atan2(n[0], n[1])) % 360.0 if math.hypot(n[0], n[1]) > 1e-12 else 0.0
    return round(dip2, 9) + 0.0, round(dd2, 9) % 360.0 + 0.0
