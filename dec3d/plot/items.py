"""Plot items: what one picture layer shows, read from 3DEC's words or from a short name.

3DEC words (after `plot item create`)             short name (``dec3d plot --item``)
  block                                             blocks         (coloured by group)
  block contour displacement[-x|-y|-z]              displacement   (also velocity…)
  zone contour stress-zz  / block zone contour …    stress-zz      (stress-xx … stress-yz, stress-max,
                                                                     stress-int, stress-min, stress-mean,
                                                                     von-mises)
  zone label state / block zone plasticity          state          (3DEC's plastic-state legend)
  block contact [contour normal-stress]             normal-stress  (shear-stress, slip, opening,
  / block joint …                                                    normal-displacement,
                                                                     shear-displacement, pressure)
  block vector velocity / gridpoint vector …        velocity-vector, displacement-vector
  structure cable [contour force]                   cable
  chart-history history '1' [vs '2']                (decks only)
"""
from __future__ import annotations

from dataclasses import dataclass, field

SCALARS = ("displacement", "velocity")
STRESS = ("stress-xx", "stress-yy", "stress-zz", "stress-xy", "stress-xz", "stress-yz", "stress-max",
          "stress-int", "stress-min", "stress-mean", "von-mises")
JOINT = ("normal-stress", "shear-stress", "slip", "state", "opening", "normal-displacement",
         "shear-displacement", "pressure")


@dataclass
class Item:
    kind: str                 # blocks | contour | state | joints | vector | cable | chart
    quantity: str = ""        # displacement, stress-zz, normal-stress, velocity, ...
    histories: tuple = ()     # chart: history names/ids, first the y ones
    vs: object = None         # chart: the x history
    ignored: list = field(default_factory=list)   # words read but not used (told once)

    def title(self) -> str:
        if self.kind == "blocks":
            return "blocks"
        if self.kind == "state":
            return "plastic state"
        if self.kind == "vector":
            return f"{self.quantity} vectors"
        if self.kind == "cable":
            return "cable axial force"
        if self.kind == "joints":
            return f"joint {self.quantity}"
        return self.quantity


class UnknownItem(ValueError):
    """An item dec3d does not draw (the deck goes on with a notice)."""


def _quantity(words, allowed, default):
    for w in words:
        for a in allowed:
            if w == a or (len(w) >= 4 and a.startswith(w)):
                return a, [x for x in words if x != w]
    for w in words:                                   # displacement-x, velocity-z, ...
        base, _, comp = w.rpartition("-")
        if comp in ("x", "y", "z") and base in allowed:
            return w, [x for x in words if x != w]
    return default, list(words)


def _drop(words, *fillers):
    return [w for w in words if w not in fillers]


def item_from_words(words: list[str]) -> Item:
    """An item from the words after `plot item create` (lower case, quotes removed)."""
    w = [x.lower() for x in words]
    if not w:
        raise UnknownItem("`plot item create` needs an item (block, zone, …)")
    head, rest = w[0], w[1:]
    if head in ("block", "zone", "gridpoint", "block-zone", "block-contact", "block-joint", "joint",
                "contact", "structure", "cable"):
        if head == "block" and rest[:1] and rest[0] in ("zone", "gridpoint", "contact", "joint", "subcontact",
                                                        "face"):
            head, rest = rest[0], rest[1:]
        head = {"block-zone": "zone", "block-contact": "contact", "block-joint": "contact", "joint": "contact",
                "subcontact": "contact", "structure": "cable"}.get(head, head)
        if head == "cable" and rest[:1] == ["cable"]:
            rest = rest[1:]
        if head == "cable":
            return Item("cable", "axial-force", ignored=_drop(rest, "contour", "force", "axial-force"))
        if "vector" in rest:
            q, left = _quantity(_drop(rest, "vector"), SCALARS, "displacement")
            return Item("vector", q.split("-")[0], ignored=left)
        if head == "contact":
            q, left = _quantity(_drop(rest, "contour", "label", "colorby"), JOINT, "normal-stress")
            return Item("joints", q, ignored=left)
        if any(x in rest for x in ("state", "plasticity", "plastic", "plastic-state")):
            left = _drop(rest, "label", "state", "plasticity", "plastic", "plastic-state", "contour", "colorby")
            return Item("state", "state", ignored=left)
        if "stress" in rest and "quantity" in rest:              # FLAC3D's `contour stress quantity zz`
            i = rest.index("quantity")
            comp = rest[i + 1] if i + 1 < len(rest) else ""
            comp = {"maximum": "max", "intermediate": "int", "minimum": "min", "von-mises": "mises"}.get(comp, comp)
            q = "von-mises" if comp == "mises" else f"stress-{comp}"
            if q in STRESS:
                return Item("contour", q, ignored=[w for j, w in enumerate(rest) if w not in ("contour", "stress",
                                                                                            "quantity") and j != i + 1])
        if "contour" in rest or "colorby" in rest:
            q, left = _quantity(_drop(rest, "contour", "colorby"), STRESS + SCALARS, "")
            if not q:
                raise UnknownItem(f"`{' '.join(words)}`: dec3d contours displacement, velocity and zone "
                                  "stresses (stress-xx … stress-yz, stress-max, stress-min, stress-mean, von-mises)")
            return Item("contour", q, ignored=left)
        if head == "block":
            return Item("blocks", ignored=rest)
        if head == "zone":
            return Item("blocks", ignored=rest)
    if head == "chart-history":
        return _chart(w)
    raise UnknownItem(f"plot item `{words[0]}` is not drawn by dec3d (it draws block, zone, block contact, "
                      "vectors, cables and chart-history)")


def _chart(w: list[str]) -> Item:
    hs, vs, i = [], None, 1
    while i < len(w):
        if w[i] == "history":
            i += 1
            while i < len(w) and w[i] not in ("vs", "history"):
                hs.append(w[i])
                i += 1
        elif w[i] == "vs" and i + 1 < len(w):
            vs = w[i + 1]
            i += 2
        else:
            i += 1
    if not hs:
        raise UnknownItem("`plot item create chart-history` needs `history '<name>'`")
    return Item("chart", "history", histories=tuple(hs), vs=vs)


def item_from_name(name: str) -> Item:
    """An item from a short name (``dec3d plot --item``)."""
    n = name.lower()
    if n in ("block", "blocks", "geometry"):
        return Item("blocks")
    if n in ("state", "plastic", "plastic-state"):
        return Item("state", "state")
    if n in ("cable", "cables"):
        return Item("cable", "axial-force")
    if n.endswith("-vector") and n[:-7] in SCALARS:
        return Item("vector", n[:-7])
    if n in STRESS or n.rpartition("-")[0] in SCALARS or n in SCALARS:
        return Item("contour", n)
    if n in JOINT or n.startswith("joint-") and n[6:] in JOINT:
        return Item("joints", n[6:] if n.startswith("joint-") else n)
    raise UnknownItem(f"unknown item '{name}': one of blocks, displacement[-x|-y|-z], velocity[-x|-y|-z], "
                      f"{', '.join(STRESS)}, state, {', '.join(JOINT)}, displacement-vector, velocity-vector, "
                      "cable")
