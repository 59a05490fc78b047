"""3DEC 4/5 FISH lines -> 3DEC 7+ FISH (reference §9, §13).

Only the names change (the statements `loop while`, `if`, `command … endcommand` are the same);
`array a(n)` becomes `a = array.create(n)`. A legacy intrinsic dec3d has no 3DEC 7+ equivalent for
is left as it is and the line gets a `; dec3d translate: could not translate: …` note.
"""
from __future__ import annotations

import re

#: legacy intrinsic -> 3DEC 7+ name (the names dec3d supports: dec3d/fish/*intrinsics.py)
CALLS = {
    "out": "io.out", "sqrt": "math.sqrt", "abs": "math.abs", "sin": "math.sin", "cos": "math.cos",
    "tan": "math.tan", "asin": "math.asin", "acos": "math.acos", "atan": "math.atan", "atan2": "math.atan2",
    "exp": "math.exp", "ln": "math.ln", "log": "math.log", "sgn": "math.sgn", "max": "math.max",
    "min": "math.min", "round": "math.round", "mag": "math.mag",
    "b_next": "block.next", "b_x": "block.pos.x", "b_y": "block.pos.y", "b_z": "block.pos.z",
    "b_vol": "block.vol", "b_mass": "block.mass", "b_dens": "block.density", "b_id": "block.id",
    "b_region": "block.region", "b_xvel": "block.vel.x", "b_yvel": "block.vel.y", "b_zvel": "block.vel.z",
    "b_xdis": "block.disp.x", "b_ydis": "block.disp.y", "b_zdis": "block.disp.z",
    "b_xrvel": "block.rvel.x", "b_yrvel": "block.rvel.y", "b_zrvel": "block.rvel.z",
    "b_xfob": "block.force.unbal.x", "b_yfob": "block.force.unbal.y", "b_zfob": "block.force.unbal.z",
    "gp_next": "block.gp.next",
    "gp_x": "block.gp.pos.x", "gp_y": "block.gp.pos.y", "gp_z": "block.gp.pos.z",
    "gp_xdis": "block.gp.disp.x", "gp_ydis": "block.gp.disp.y", "gp_zdis": "block.gp.disp.z",
    "gp_xvel": "block.gp.vel.x", "gp_yvel": "block.gp.vel.y", "gp_zvel": "block.gp.vel.z",
    "z_sxx": "block.zone.stress.xx", "z_syy": "block.zone.stress.yy", "z_szz": "block.zone.stress.zz",
    "z_sxy": "block.zone.stress.xy", "z_sxz": "block.zone.stress.xz", "z_syz": "block.zone.stress.yz",
    "z_vol": "block.zone.vol", "z_x": "block.zone.pos.x", "z_y": "block.zone.pos.y", "z_z": "block.zone.pos.z",
    "open": "file.open", "write": "file.write", "read": "file.read", "close": "file.close",
    "c_next": "block.contact.next", "c_near": "block.contact.near", "c_b1": "block.contact.b1", "c_b2": "block.contact.b2",
    "c_x": "block.contact.pos.x", "c_y": "block.contact.pos.y", "c_z": "block.contact.pos.z",
    "cx_next": "block.subcontact.next", "cx_nforce": "block.subcontact.force.norm",
    "cx_sforce": "block.subcontact.force.shear", "cx_area": "block.subcontact.area",
    "cx_x": "block.subcontact.pos.x", "cx_y": "block.subcontact.pos.y", "cx_z": "block.subcontact.pos.z",
}
#: legacy names used without parentheses
BARE = {"block_head": "block.head", "contact_head": "block.contact.head", "pi": "math.pi",
        "clock": "time.clock", "gp_head": None, "close": "file.close"}
_LOSE = re.compile(r"(?<![.\w])lose_array\s*\([^()]*\)", re.IGNORECASE)    # arrays are freed automatically
#: legacy intrinsics with no 3DEC 7+ equivalent in dec3d (kept, with a note)
MISSING = {
    "b_zone": "3DEC 5 zone pointer walks (no block.zone.head/next in dec3d: use loop foreach over block.zone.list)",
    "z_next": "3DEC 5 zone pointer walks (no block.zone.next in dec3d: use loop foreach over block.zone.list)",
    "z_sig1": "principal stresses of a zone (no block.zone.stress.prin in dec3d)",
    "z_sig2": "principal stresses of a zone (no block.zone.stress.prin in dec3d)",
    "z_sig3": "principal stresses of a zone (no block.zone.stress.prin in dec3d)",
    "gp_head": "the global gridpoint list head (use loop foreach over block.gp.list)",
    "b_gp": "the first gridpoint of a block (loop foreach over block.gplist(b): a list, not a pointer)",
    "c_cx": "the first sub-contact of a contact (loop foreach over block.contact.subcontactlist(c))",
}

_CX = re.compile(r"^(\s*)(local\s+)?([A-Za-z_]\w*)\s*=\s*c_cx\s*\((.+)\)\s*$", re.IGNORECASE)
_WORD = re.compile(r"""('[^']*'|"[^"]*")|(?<![.\w])([A-Za-z_]\w*)(\s*\()?""")
_ARRAY = re.compile(r"^(\s*)array\s+(.*)$", re.IGNORECASE)
_DECL = re.compile(r"([A-Za-z_]\w*)\s*\(([^()]*)\)")


def translate_fish_line(code: str, known: set[str]) -> tuple[str, list[str]]:
    """(3DEC 7+ code, notes) for one line of a legacy FISH function body. ``known`` holds the deck's own
    FISH names (a function of the deck called `open` stays the deck's)."""
    m = _CX.match(code)
    if m and "c_cx" not in known:      # `x = c_cx(c)`: the first sub-contact, 0 when there is none
        ind, loc, x, c = m.groups()
        c = translate_fish_line(c, known)[0]
        return "\n".join([f"{ind}{loc or ''}{x} = 0", f"{ind}local {x}_subs = block.contact.subcontactlist({c})",
                          f"{ind}if list.size({x}_subs) > 0 then", f"{ind}  {x} = {x}_subs(1)",
                          f"{ind}endif"]), []
    m = _ARRAY.match(code)
    if m:
        decls = _DECL.findall(m.group(2))
        if not decls:
            return code, ["`array` without a size"]
        parts, notes = [], []
        for name, dims in decls:
            if "," in dims:
                notes.append(f"the 2-D array `{name}({dims})` (dec3d arrays have one index: array.create(n))")
                parts.append(f"{name} = array.create({dims.split(',')[0].strip()})")
            else:
                parts.append(f"{name} = array.create({dims.strip()})")
        if len(parts) > 1:
            return code, ["several arrays on one `array` line (write one per line)"]
        return m.group(1) + parts[0], notes
    notes: list[str] = []

    def sub(mt):
        if mt.group(1):
            return mt.group(1)
        name, paren = mt.group(2), mt.group(3) or ""
        low = name.lower()
        if low in known:
            return mt.group(0)
        if low in MISSING and (paren or low in ("close", "gp_head")):
            notes.append(f"`{name}`: {MISSING[low]}")
            return mt.group(0)
        if paren and low in CALLS:
            return CALLS[low] + paren
        if not paren and low in BARE and BARE[low]:
            return BARE[low]
        return mt.group(0)

    if "lose_array" not in known:
        code = _LOSE.sub("0", code)
    return _WORD.sub(sub, code), notes
