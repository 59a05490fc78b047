"""3DEC 4/5 commands -> 3DEC 7+ (the rest of the table: properties, conditions, solving, output)."""
from __future__ import annotations

from .commands import O, _jset, _pairs, _poly, _range, _split_range, _v
from .lines import Out, Tok
from .ranges import is_value, legacy_word, q

#: joint property words of `prop jmat=n` -> `block contact property` keywords
_JPROPS = {"jkn": "stiffness-normal", "jks": "stiffness-shear", "jfriction": "friction", "jcohesion": "cohesion",
           "jtension": "tension", "jdilation": "dilation", "jrfriction": "friction-residual",
           "jrcohesion": "cohesion-residual", "jrtension": "tension-residual", "zdilation": "dilation-zero"}
#: block and zone property words of `prop mat=n`
_ZPROPS = {"k": "bulk", "g": "shear", "bulk": "bulk", "shear": "shear", "young": "young", "poisson": "poisson",
           "cohesion": "cohesion", "friction": "friction", "tension": "tension", "dilation": "dilation"}


def _new(toks, state):
    return [[O("model new", toks[0])] + [_v(t) for t in toks[1:]]], ""


def _prop(toks, state):
    head, rng = _split_range(toks[1:])
    if rng:
        return None, "`range` on `prop` (3DEC 5 properties belong to material numbers)"
    pairs = list(_pairs(head))
    if not pairs or pairs[0][1] is None or not legacy_word(pairs[0][0].low, {"material": (3, 0), "jmaterial": (4, 0)}):
        return None, "`prop` without `mat=<n>` or `jmat=<n>`"
    key, num = pairs[0]
    if key.low.startswith("j"):
        props = []
        for k, v in pairs[1:]:
            hit = legacy_word(k.low, {w: (len(w) if len(w) < 4 else 4, m) for w, m in _JPROPS.items()})
            if v is None or hit is None:
                return None, f"joint property `{k.text}`"
            props.append((hit[1], v))
        state.jmats[num.text] = props
        cmd = [O("block contact property", toks[0])] + [x for m, v in props for x in (O(m, v), _v(v))]
        if num.text != "1":        # contacts have joint material 1 until `change jmat=`
            return [[O(f"; joint material {num.text} is given to contacts by `change jmat={num.text}`", toks[0])]], ""
        return [cmd, [O("block contact material-table default property", toks[0])] + cmd[1:]], ""
    dens, zprops = None, []
    for k, v in pairs[1:]:
        if v is None:
            return None, f"block property `{k.text}` without a value"
        if legacy_word(k.low, {"density": (3, 0)}):
            dens = v
        elif k.low in _ZPROPS:
            zprops.append((_ZPROPS[k.low], v))
        else:
            return None, f"block property `{k.text}`"
    state.mats[num.text] = (dens, zprops)
    rng = O(f"range group {q('mat' + num.text)} slot 'material'", key)
    out = []
    if dens is not None:
        out.append([O("block property density", toks[0]), _v(dens), rng])
    if zprops:
        out.append([O("block zone property", toks[0])] + [x for m, v in zprops for x in (O(m, v), _v(v))] + [rng])
    return out, ""


def _change(toks, state):
    head, rng = _split_range(toks[1:])
    r, why = _range(rng, state)
    if r is None:
        return None, why
    out = []
    for k, v in _pairs(head):
        hit = legacy_word(k.low, {"material": (3, "mat"), "jmaterial": (4, "jmat"), "constitutive": (3, "cons"),
                                  "jconstitutive": (5, "jcons")})
        if hit is None or v is None:
            return None, f"`change {k.text}`"
        if hit[1] == "mat":
            out.append([O(f"block group {q('mat' + v.text)} slot 'material'", k)] + r)
            dens, zprops = state.mats.get(v.text, (None, []))
            if dens is not None:
                out.append([O("block property density", k), _v(dens)] + r)
            if zprops:
                out.append([O("block zone property", k)] + [x for m, p in zprops for x in (O(m, p), _v(p))] + r)
        elif hit[1] == "jmat":
            props = state.jmats.get(v.text)
            if props is None:
                return None, f"joint material {v.text} has no properties yet (`prop jmat={v.text} ...` first)"
            cmd = [O("block contact property", k)] + [x for m, p in props for x in (O(m, p), _v(p))]
            out.append(cmd + r)
            if not r:          # every contact, and the contacts made later
                out.append([O("block contact material-table default property", k)] + cmd[1:])
        elif hit[1] == "cons":
            model = {"0": "null", "1": "elastic", "2": "mohr-coulomb"}.get(v.text)
            if model is None:
                return None, f"`cons={v.text}`"
            out.append([O(f"block zone cmodel assign {model}", k)] + r)
        else:
            model = {"1": "mohr", "2": "softening-mohr"}.get(v.text)
            if model is None:
                return None, f"`jcons={v.text}`"
            out.append([O(f"block contact jmodel assign {model}", k)] + r)
    if not out:
        return None, "`change` without a property"
    if state.zoned is False:        # a rigid model: zone models mean nothing yet
        out = [c for c in out if not c[0].text.startswith("block zone")] or out
    return out, ""


def _hide(toks, state, off=False):
    r, why = _range(toks[1:], state)
    if r is None:
        return None, why
    cmd = [O("block hide off" if off else "block hide", toks[0])] + r
    if off and not r:
        state.hides, state.shown = [], False
    else:
        state.hides = state.hides + [cmd]
    return [cmd], ""


_SHOWN = ("; dec3d translate: the hidden blocks take part in the mechanics, as in 3DEC 5 (`hide` only hid them "
          "from view and from cutting; dec3d's `block hide` leaves them out): shown from here, hidden again before "
          "the next `jset`")


def _cycling(cmds, toks, state):
    """A cycling command with the deck's hidden blocks shown from there on (see _SHOWN; `rehide`)."""
    if not state.hides or state.shown or not cmds:
        return cmds, ""
    state.shown = True
    return [[O("block hide off", toks[0]), O(_SHOWN, toks[-1])]] + cmds, ""


def rehide(cmds, toks, state):
    """Before a cut: the blocks the deck hid are hidden again (3DEC 5 cut only what was visible)."""
    if not state.shown or cmds is None:
        return cmds
    state.shown = False
    return [[Out(p.text, toks[0].line, toks[0].col) for p in h] for h in state.hides] + cmds


def _seek(toks, state):
    return _hide(toks, state, off=True)


def _grav(toks, state):
    vals = toks[1:]
    if len(vals) != 3 or not all(is_value(t) for t in vals):
        return None, "`gravity` takes three components"
    return [[O("model gravity", toks[0])] + [_v(t) for t in vals]], ""


def _damp(toks, state):
    rest = [t.low for t in toks[1:]]
    if rest[:1] == ["auto"] and len(rest) == 1:
        return [[O("block mechanical damping global", toks[0])]], ""
    for word, mode in (("local", "local"), ("combined", "combined")):
        if rest and word.startswith(rest[0]) and len(rest[0]) >= 3:
            return [[O(f"block mechanical damping {mode}", toks[0])] + [_v(t) for t in toks[2:] if is_value(t)]], ""
    return None, "this form of `damp` (mass- and stiffness-proportional damping: use `block mechanical damping rayleigh`)"


def _cycle(toks, state):
    if len(toks) != 2:
        return None, "`cycle` takes the number of steps"
    return _cycling([[O("model cycle", toks[0]), _v(toks[1])]], toks, state)


def _solve(toks, state):
    out = [O("model solve", toks[0])]
    for k, v in _pairs(toks[1:]):
        hit = legacy_word(k.low, {"ratio": (3, "ratio"), "time": (2, "time"), "cycles": (3, "cycles"),
                                  "force": (1, "unbalanced-maximum"), "clock": (3, "clock"), "age": (3, "time")})
        if hit is None or v is None:
            return None, f"`solve {k.text}`"
        out += [O(hit[1], k), _v(v)]
    return _cycling([out], toks, state)


_HIST = {"time": "model history mechanical time-total", "unbalanced": "model history mechanical unbalanced-maximum",
         "ratio": "model history mechanical ratio"}
_HIST_POS = {"nf_sum": "block contact history force-normal", "sf_sum": "block contact history force-shear",
             "xdisplacement": "block history displacement-x", "ydisplacement": "block history displacement-y",
             "zdisplacement": "block history displacement-z", "xvelocity": "block history velocity-x",
             "yvelocity": "block history velocity-y", "zvelocity": "block history velocity-z"}


def _hist(toks, state):
    rest = toks[1:]
    if rest and rest[0].low in ("interval", "name", "rename", "delete", "export", "list", "purge"):
        return [[O("history", toks[0])] + [_v(t) for t in rest]], ""        # 3DEC 7+ `history …` as it is
    if len(rest) == 1 and rest[0].text.startswith("@"):
        return [[O("fish history", toks[0]), _v(rest[0])]], ""
    if len(rest) == 1 and rest[0].low in state.fish:
        return [[O("fish history", toks[0]), O("@" + rest[0].text, rest[0])]], ""
    hit = legacy_word(rest[0].low, {k: (3, v) for k, v in _HIST.items()}) if len(rest) == 1 else None
    if hit:
        return [[O(hit[1], toks[0])]], ""
    if len(rest) == 4 and all(is_value(t) for t in rest[1:]):
        key = rest[0].low
        hit = _HIST_POS.get(key) or next((v for k, v in _HIST_POS.items() if k[0] == key[0] and
                                          k[1:].startswith(key[1:]) and len(key) >= 4), None)
        if hit:
            return [[O(hit + " position", toks[0])] + [_v(t) for t in rest[1:]]], ""
    return None, "this `hist` quantity"


def _fix(toks, state, word="block fix"):
    r, why = _range(toks[1:], state)
    if r is None:
        return None, why
    return [[O(word, toks[0])] + r], ""


def _free(toks, state):
    return _fix(toks, state, "block free")


def _file_cmd(word):
    def handler(toks, state):
        if len(toks) != 2:
            return None, f"`{toks[0].text}` takes one file name"
        name = toks[1].text
        if not name.startswith(("@", "'", '"', "[")):
            name = q(name)
        return [[O(word, toks[0]), O(name, toks[1])]], ""
    return handler


def _plot(toks, state):
    words = [t.low for t in toks[1:]]
    if words[:1] == ["hist"] or (words and "history".startswith(words[0]) and len(words[0]) >= 4):
        vals = [t.text for t in toks[2:] if t.low not in ("v", "vs")]
        if len(vals) == 2:
            return [[O(f"plot item create chart-history history '{vals[0]}' vs '{vals[1]}'", toks[0])]], ""
    return [[O("plot", toks[0])] + [_v(t) for t in toks[1:]]], ""        # dec3d skips plots with a notice


def _gen(toks, state):
    head, rng = _split_range(toks[1:])
    r, why = _range(rng, state)
    if r is None:
        return None, why
    if len(head) == 2 and legacy_word(head[0].low, {"edge": (3, 0)}) and is_value(head[1]):
        state.zoned = True
        return [[O("block zone generate edgelength", toks[0]), _v(head[1])] + r], ""
    return None, "this form of `gen`"


def _range_cmd(toks, state):
    if len(toks) < 3 or toks[1].low != "name":
        return None, "`range` without `name`"
    name = toks[2].text.strip("'\"")
    state.ranges.add(name.lower())
    r, why = _range(toks[3:], state)
    if r is None or not r:
        return None, why or "an empty named range"
    return [[O(f"block group {q(name)} slot {q(name)}", toks[0])] + r], ""


def _set(toks, state):
    words = [t.low for t in toks[1:]]
    if words and legacy_word(words[0], {"gravity": (3, 0)}) and len(words) == 4:
        return _grav(toks[1:], state)
    if words[:1] == ["large"]:
        return [[O("model large-strain on", toks[0])]], ""
    if words[:1] == ["small"]:
        return [[O("model large-strain off", toks[0])]], ""
    if words[:1] == ["echo"] and len(words) == 2:
        return [[O(f"program echo {words[1]}", toks[0])]], ""
    return None, "this `set`"


def _list(toks, state):
    if len(toks) == 2 and toks[1].text.startswith("@"):
        return [[O("fish list", toks[0]), _v(toks[1])]], ""
    if len(toks) == 2 and toks[1].low in state.fish:
        return [[O("fish list", toks[0]), O("@" + toks[1].text, toks[1])]], ""
    return None, "this `print`/`list`"


def _bound(toks, state):
    head, rng = _split_range(toks[1:])
    r, why = _range(rng, state)
    if r is None:
        return None, why
    words = {"xvelocity": "velocity-x", "yvelocity": "velocity-y", "zvelocity": "velocity-z",
             "xload": "force-x", "yload": "force-y", "zload": "force-z"}
    if head and legacy_word(head[0].low, {"stress": (3, 0)}) and len(head) == 7 and all(is_value(t) for t in head[1:]):
        return [[O("block face apply stress", toks[0])] + [_v(t) for t in head[1:]] + r], ""
    out = []
    for k, v in _pairs(head):
        hit = legacy_word(k.low, {w: (4, m) for w, m in words.items()})
        if hit is None or v is None:
            return None, f"`bound {k.text}`"
        out.append([O(f"block gridpoint apply {hit[1]}", k), _v(v)] + r)
    return (out, "") if out else (None, "`bound` without a condition")


def _insitu(toks, state):
    head, rng = _split_range(toks[1:])
    r, why = _range(rng, state)
    if r is None:
        return None, why
    if head and legacy_word(head[0].low, {"stress": (3, 0)}) and len(head) == 7 and all(is_value(t) for t in head[1:]):
        return [[O("block insitu stress", toks[0])] + [_v(t) for t in head[1:]] + r], ""
    return None, "this form of `insitu` (gradients: write `block insitu stress … gradient-z …`)"


def _title(toks, state):
    return [[O("model title", toks[0]), O(q(" ".join(t.text for t in toks[1:])), toks[1] if len(toks) > 1 else toks[0])]], ""


def _simple(word):
    def handler(toks, state):
        r, why = _range(_split_range(toks[1:])[1], state)
        if r is None or len(_split_range(toks[1:])[0]):
            return None, why or f"`{toks[0].text}` with arguments"
        return [[O(word, toks[0])] + r], ""
    return handler


#: legacy command word -> (shortest abbreviation, handler)
COMMANDS = {
    "new": (3, _new), "polyhedron": (4, _poly), "jset": (4, _jset), "property": (4, _prop), "change": (3, _change),
    "hide": (3, _hide), "seek": (3, _seek), "gravity": (4, _grav), "damping": (4, _damp), "cycle": (3, _cycle),
    "step": (3, _cycle), "solve": (3, _solve), "history": (4, _hist), "fix": (3, _fix), "free": (3, _free),
    "save": (3, _file_cmd("model save")), "restore": (3, _file_cmd("model restore")),
    "call": (3, _file_cmd("program call")), "plot": (2, _plot), "generate": (3, _gen), "range": (3, _range_cmd),
    "set": (3, _set), "list": (4, _list), "print": (3, _list), "boundary": (3, _bound), "title": (3, _title), "insitu": (3, _insitu),
    "return": (3, _simple("program return")), "delete": (3, _simple("block delete")),
}


def translate_command(toks: list[Tok], state):
    """(commands, why) for one legacy logical command; (None, why) when it has no translation."""
    hit = legacy_word(toks[0].low, COMMANDS)
    if hit is None:
        return None, f"the command `{toks[0].text}`"
    cmds, why = hit[1](toks, state)
    if hit[0] == "jset":
        cmds = rehide(cmds, toks, state)
    return cmds, why


def is_legacy_word(word: str) -> bool:
    return legacy_word(word, COMMANDS) is not None
