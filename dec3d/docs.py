"""The `docs/commands/` reference: one page per registered command, written from its declaration.

`dec3d docs` rewrites the pages; a test fails when a page differs from what the
declaration gives, so the reference can never drift from the code. The REPL's
`help <command>` shows the same page.
"""
from __future__ import annotations

from pathlib import Path

from .commands import load_all
from .commands.registry import REGISTRY, Command, Registry
from .commands.values import MISSING, Flag, Param


def page_name(cmd: Command) -> str:
    return "_".join(cmd.path) + ".md"


def _row(p: Param) -> str:
    value = p.value.describe() or "(flag)"
    if p.default not in (None, [], ()) and not isinstance(p.value, Flag):
        default = f"{p.default}"
    elif p.bare is not MISSING:
        default = f"{p.bare} when bare"
    else:
        default = "required" if p.required else ""
    doc = p.doc + ("" if p.supported else " *(not supported yet)*")
    if p.repeat:
        doc += " May be repeated."
    return f"| `{p.name}` | {value} | {default} | {p.units} | {doc.strip()} |"


def render(cmd: Command) -> str:
    usage = [cmd.name]
    for p in cmd.positional:
        usage.append(f"<{p.name}: {p.value.describe()}>" if p.required else f"[{p.name}: {p.value.describe()}]")
    if cmd.keywords:
        usage.append("[keyword value …]")
    if cmd.range:
        usage.append("[range …]")
    if cmd.accepts_anything:
        usage.append("…")
    out = [f"# {cmd.name}", "", cmd.doc, "", "    " + " ".join(usage), ""]
    if cmd.details:
        out += [cmd.details, ""]
    params = cmd.positional + cmd.keywords
    if params:
        out += ["| argument | value | default | units | description |", "|---|---|---|---|---|"]
        out += [_row(p) for p in params]
        out.append("")
    if cmd.range:
        what = {"cable_segments": "cable elements", "cable_nodes": "structural nodes (cable, beam and liner nodes)",
                "beam_elements": "beam elements", "liner_elements": "liner elements"}.get(cmd.range, f"{cmd.range}s")
        out += [f"Takes a range over {what}; `range` may be omitted before the first element. "
                "See [range elements](range.md).", ""]
    if cmd.open_keywords:
        out += ["Keywords not listed are accepted as user-model properties (`name value`).", ""]
    if cmd.examples:
        out += ["## Examples", "", "```"] + list(cmd.examples) + ["```", ""]
    out += [f"Implemented in `{cmd.module}`.", ""]
    return "\n".join(out)


def render_range(reg: Registry) -> str:
    out = ["# Range elements", "", "A range selects the entities a command acts on. Elements are ANDed; "
           "`union` ORs them; `not` after an element negates it. `range` may be omitted before the first element.",
           "", "| element | arguments | applies to | description |", "|---|---|---|---|"]
    for name in sorted(reg.range_elements):
        e = reg.range_elements[name]
        args = " ".join(f"<{p.name}: {p.value.describe()}>" for p in e.positional)
        args += "".join(f" [{p.name} {p.value.describe()}]" for p in e.keywords)
        doc = e.doc if e.supported else "*(not supported yet)*"
        out.append(f"| `{name}` | {args.strip()} | {', '.join(e.stores) or 'all'} | {doc} |")
    return "\n".join(out) + "\n"


#: 3DEC statements the deck reader itself handles (no command declaration): their help pages
READER_PAGES = {
    ("fish", "define"): (
        "# fish define\n\n"
        "`fish define <name>` … `end` (also `fish def`, or `define`/`def` alone) defines a FISH function.\n\n"
        "What dec3d does with it: the function is parsed and compiled when the deck is read (a syntax error "
        "stops the deck before anything runs, with file:line:col inside the body) and defined when the line "
        "runs. It is called by `@name` alone on a line, `[name(...)]` in a value or in a FISH statement, and "
        "its `command … endcommand` sections are bound like deck lines. FISH intrinsics dec3d lacks (zones, "
        "gridpoints, contacts) compile and fail with \"not supported yet\" when the function is called; "
        "`dec3d check` names them. The language and intrinsics are described in `docs/architecture.md` (FISH).\n\n"
        "## Examples\n\n```\nfish define area(w, h)\n  area = w * h\nend\n[a = 2.0 * 3.0]\n```\n"),
}


def render_index(reg: Registry) -> str:
    out = ["# dec3d command reference", "",
           "One page per implemented command, written from its declaration by `dec3d docs`. "
           "Words and keywords may be abbreviated to any unique prefix, hyphenated words part by part.", "",
           "## Implemented", ""]
    for path in sorted(reg.commands):
        cmd = reg.commands[path]
        out.append(f"- [`{cmd.name}`]({page_name(cmd)}) — {cmd.doc}")
    out += ["", "## Known 3DEC commands not supported yet", "",
            "These bind to a clear \"not supported yet\" message instead of \"unknown command\".", ""]
    pending = []
    for path, node in reg.walk():
        if node.known and node.command is None and not node.alias_of and not node.children \
                and tuple(path) not in READER_PAGES:
            pending.append(" ".join(path))
    out += [f"`{p}`" + ("," if k < len(pending) - 1 else "") for k, p in enumerate(pending)]
    return "\n".join(out) + "\n"


def pages(reg: Registry = REGISTRY) -> dict[str, str]:
    load_all()
    result = {page_name(c): render(c) for c in reg.commands.values()}
    result["range.md"] = render_range(reg)
    result["README.md"] = render_index(reg)
    return result


def write_pages(folder: Path) -> list[str]:
    folder.mkdir(parents=True, exist_ok=True)
    changed = []
    for name, text in pages().items():
        p = folder / name
        if not p.exists() or p.read_text(encoding="utf-8") != text:
            p.write_text(text, encoding="utf-8")
            changed.append(name)
    return changed


def page_for(words: list[str], folder: Path | None = None) -> str | None:
    """The page of the command the (possibly abbreviated) words name, for `help`."""
    from .lang.abbrev import matches

    load_all()
    node = REGISTRY.root
    path = []
    for w in words:
        hits = matches(w, node.children)
        if len(hits) != 1:
            return None
        node = node.children[hits[0]]
        if node.alias_of:
            path = list(node.alias_of)
            node = REGISTRY.node(node.alias_of)
        else:
            path.append(hits[0])
    if tuple(path) in READER_PAGES:
        return READER_PAGES[tuple(path)]
    if node.command is None:
        if node.children:
            kids = sorted(node.children)
            return f"# {' '.join(path)}\n\nSubcommands: " + ", ".join(kids) + "\n"
        return f"`{' '.join(path)}` is a 3DEC command dec3d does not support yet.\n"
    if folder is not None and (folder / page_name(node.command)).exists():
        return (folder / page_name(node.command)).read_text(encoding="utf-8")
    return render(node.command)
