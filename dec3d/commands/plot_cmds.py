"""`plot …`: 3DEC's plots as pictures: each `plot … export bitmap` writes a PNG (dec3d.plot).

A plot is a named list of items (`plot create 'name'`, `plot item create …`); exporting it renders
the model as it is at that line, off screen, into the output folder. Words dec3d does not draw are
told once in a notice and the deck goes on."""
from __future__ import annotations

import re
from pathlib import Path

from ..errors import CommandError
from ..lang.abbrev import matches
from .registry import command

_TOKEN = re.compile(r"'[^']*'|\"[^\"]*\"|\S+")
_IMAGE_EXTS = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff")
#: the words after `plot ['name']` dec3d acts on (the rest are view settings: a notice)
_WORDS = ("create", "current", "destroy", "delete", "item", "clear", "background", "export", "active", "view",
          "title", "legend", "copy", "reset", "print", "movie", "hardcopy")


class _Plot:
    def __init__(self, name: str):
        self.name = name
        self.items: list = []
        self.background = "white"


def _state(session) -> dict:
    st = getattr(session, "plot_state", None)
    if st is None:
        st = session.plot_state = {"plots": {}, "current": None, "told": set(), "count": 0}
    return st


def _tell(session, st, key: str, text: str) -> None:
    if key not in st["told"]:
        st["told"].add(key)
        session.write(f"notice: {text}")


def _tokens(call) -> list[tuple[str, bool]]:
    """(word, quoted) of the line after `plot` (continuation marks dropped)."""
    out = []
    for t in _TOKEN.findall(call.text):
        if t == "...":
            continue
        quoted = t[:1] in "'\"" and t[-1:] == t[:1] and len(t) >= 2
        out.append((t[1:-1] if quoted else t, quoted))
    return out[1:]                                  # the command word itself


def _plot_named(session, st, name: str | None, create: bool = False) -> _Plot:
    if name is None:
        name = st["current"]
    if name is None or (create and name not in st["plots"]):
        if name is None:
            st["count"] += 1
            name = f"Plot{st['count']:02d}"
        st["plots"][name] = _Plot(name)
    if name not in st["plots"]:
        st["plots"][name] = _Plot(name)
        st["plots"][name].undeclared = True
    st["current"] = name
    return st["plots"][name]


@command("plot", accepts_anything=True,
         doc="3DEC's plots as pictures: `plot create`, `plot item create …`, `plot … export bitmap` writes a PNG.",
         details="`plot create ['name']` starts a plot (and makes it the current one); `plot ['name'] item create "
                 "<item>` adds an item to it: `block` (the blocks by group), `block contour displacement` "
                 "(or velocity, -x/-y/-z for a component), `zone contour stress-zz` (also `block zone contour …`; "
                 "stress-xx … stress-yz, stress-max, stress-int, stress-min, stress-mean, von-mises; tension "
                 "positive, averaged to the gridpoints), `zone label state` (the plastic state: shear-n, tension-n, "
                 "shear-p, tension-p, none), `block contact [contour normal-stress|shear-stress|slip|opening|"
                 "pressure]` (the joint planes), `block vector velocity|displacement`, `structure cable` and "
                 "`chart-history history '1' [vs '2']` (a line chart). `plot ['name'] export bitmap [filename] "
                 "'f.png' [size w h]` renders the plot off screen into the output folder (no extension: .png is "
                 "added). A plot never created in the deck (3DEC keeps plots in its project) draws the blocks "
                 "coloured by displacement. `plot clear`, `plot background 'white'`, `plot current 'name'` and "
                 "`plot destroy 'name'` do what they say; `plot active` and the other view settings are accepted "
                 "and skipped (one notice). Items dec3d does not draw are a notice, never an error. "
                 "`dec3d plot <file.pvd>` draws the same pictures after the run.",
         examples=["plot create 'Blocks'", "plot item create block contour displacement",
                   "plot item create zone contour stress-zz", "plot item create chart-history history '1' vs '2'",
                   "plot 'Blocks' export bitmap filename 'b.png'", "plot background 'white'"])
def plot(session, call):
    st = _state(session)
    toks = _tokens(call)
    name = None
    if toks and toks[0][1]:
        name, toks = toks[0][0], toks[1:]
    words = [w for w, _ in toks]
    low = [w.lower() for w in words]
    if not low:
        if name is not None:
            _plot_named(session, st, name)
        return
    hits = matches(low[0], _WORDS)
    head = hits[0] if len(hits) == 1 else low[0]          # 3DEC's abbreviations (`plot exp bitmap …`)
    if head == "create":
        nm = words[1] if len(words) > 1 else name
        p = _plot_named(session, st, nm, create=True)
        p.items, p.background = [], "white"
        return
    if head in ("current",) and len(words) > 1:
        _plot_named(session, st, words[1])
        return
    if head in ("destroy", "delete"):
        st["plots"].pop(words[1] if len(words) > 1 else (name or st["current"]), None)
        return
    if head == "item":
        return _item(session, st, call, name, words[1:])
    if head == "clear":
        _plot_named(session, st, name).items = []
        return
    if head == "background":
        if len(words) > 1:
            _plot_named(session, st, name).background = words[1]
        return
    if head == "export":
        return _export(session, st, call, name, words[1:])
    _tell(session, st, f"word:{head}", f"`plot {head}` is a view setting of 3DEC's plot window: skipped in dec3d")


def does_nothing(call) -> str | None:
    """For `dec3d check`: why this plot line does nothing in dec3d, or None when it does something."""
    from ..plot.items import UnknownItem, item_from_words

    toks = _tokens(call)
    if toks and toks[0][1]:
        toks = toks[1:]
    low = [w.lower() for w, _ in toks]
    if not low:
        return None
    hits = matches(low[0], _WORDS)
    head = hits[0] if len(hits) == 1 else low[0]
    if head in ("create", "current", "destroy", "delete", "clear", "background", "export"):
        return None
    if head == "item":
        try:
            item_from_words([w for w, _ in toks[2:]])
            return None
        except UnknownItem as exc:
            return f"plot: {exc}"
    return f"plot {head}: a view setting of 3DEC's plot window, skipped"


def _item(session, st, call, name, words) -> None:
    from ..plot.items import UnknownItem, item_from_words

    low = [w.lower() for w in words]
    if not low or matches(low[0], ("create", "remove", "delete", "list")) != ["create"]:
        _tell(session, st, f"item:{low[:1]}", f"`plot item {' '.join(words[:1])}` is skipped in dec3d "
                                               "(only `plot item create`)")
        return
    try:
        it = item_from_words(words[1:])
    except UnknownItem as exc:
        _tell(session, st, f"unknown:{' '.join(low[1:3])}", f"{exc} ({call.location}); skipped")
        return
    if it.ignored:
        _tell(session, st, f"ign:{' '.join(it.ignored)}", f"plot item words `{' '.join(it.ignored)}` are not used "
                                                          f"by dec3d ({call.location})")
    _plot_named(session, st, name).items.append(it)


def _export(session, st, call, name, words) -> None:
    low = [w.lower() for w in words]
    if not low or (matches(low[0], ("bitmap", "vrml", "vtk", "dxf")) != ["bitmap"] and low[0] not in ("bmp", "png")):
        _tell(session, st, f"export:{low[:1]}", f"`plot export {' '.join(words[:1])}`: dec3d exports bitmaps only; "
                                                "skipped")
        return
    fname, size, i = None, None, 1
    while i < len(words):
        w = low[i]
        w = {"filename": "filename", "size": "size"}.get((matches(w, ("filename", "size")) or [w])[0], w)
        if w == "filename" and i + 1 < len(words):
            fname, i = words[i + 1], i + 2
        elif w == "size" and i + 2 < len(words):
            try:
                size = (int(float(words[i + 1])), int(float(words[i + 2])))
            except ValueError:
                raise CommandError(f"`size` takes two numbers of pixels, got `{words[i + 1]} {words[i + 2]}`",
                                   call.location) from None
            if not (16 <= size[0] <= 8000 and 16 <= size[1] <= 8000):
                raise CommandError("`size`: 16 to 8000 pixels each way", call.location)
            i += 3
        elif fname is None and w not in ("filename", "size"):
            fname, i = words[i], i + 1
        else:
            i += 1
    p = _plot_named(session, st, name)
    if fname is None:
        fname = p.name
    if Path(fname).suffix.lower() not in _IMAGE_EXTS:
        fname = fname + ".png"
    path = session.out_path(fname, call.location)
    path.parent.mkdir(parents=True, exist_ok=True)
    from ..plot.draw import draw_plot
    try:
        notices = draw_plot(session.model, p, path, size)
    except (ImportError, RuntimeError, OSError) as exc:
        # no OpenGL for VTK, a broken matplotlib backend: a picture is not worth the run
        text = f"{call.location}: plot '{p.name}' was not drawn ({type(exc).__name__}: {exc})"
        session.write(f"warning: {text}")
        getattr(session, "warnings", []).append(text)
        return
    for n in notices:
        _tell(session, st, f"draw:{n}", f"plot '{p.name}': {n}")
    if getattr(p, "undeclared", False):
        _tell(session, st, f"undeclared:{p.name}", f"plot '{p.name}' was not made in this deck (3DEC keeps plots "
                                                    "in its project): drawn as the blocks coloured by displacement")
    session.written.add(path)
    session.write(f"plot '{p.name}' written to {fname}")
