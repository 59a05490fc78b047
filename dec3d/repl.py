"""`dec3d repl`: an interactive prompt on a Session (prompt_toolkit).

Persistent history, completion of command words, keywords and range elements from
the registry (3DEC commands dec3d does not run yet are marked "not supported yet"),
`help <command>` showing the `docs/commands/` page rendered by rich, continuation lines
(`&`, `...`) and FISH blocks read until `end`. An error is printed and the session
goes on; Ctrl-D (or `program exit`) ends it.
"""
from __future__ import annotations

import re
from pathlib import Path

from prompt_toolkit import PromptSession
from prompt_toolkit.completion import Completer, Completion
from prompt_toolkit.history import FileHistory, InMemoryHistory

from .commands import load_all
from .commands.registry import REGISTRY
from .errors import Dec3dError
from .lang.abbrev import matches

_CONTINUED = re.compile(r"(&|\.\.\.)\s*(;.*)?$")
_FISH_START = re.compile(r"^\s*(fish\s+)?def(i(n(e)?)?)?\s+\w", re.I)
_FISH_END = re.compile(r"^\s*end\s*(;.*)?$", re.I)


class RegistryCompleter(Completer):
    """Completes the word under the cursor from the command tree, then the command's keywords."""

    def get_completions(self, document, complete_event):
        text = document.text_before_cursor
        words = text.split()
        current = "" if text.endswith((" ", "\t")) or not words else words[-1]
        done = words if current == "" else words[:-1]
        if done[:1] == ["help"]:
            done = done[1:]
        cands = self.candidates_with_notes(done)
        for cand in sorted(cands):
            if cand.startswith(current.lower()):
                yield Completion(cand, start_position=-len(current), display_meta=cands[cand])

    @staticmethod
    def candidates(done: list[str]) -> list[str]:
        return list(RegistryCompleter.candidates_with_notes(done))

    @staticmethod
    def candidates_with_notes(done: list[str]) -> dict[str, str]:
        """Each candidate word and its note: "not supported yet" for a 3DEC command (or group of
        commands, or keyword) that dec3d knows by name but does not run, else ""."""
        from .docs import READER_PAGES

        load_all()
        node = REGISTRY.root
        path: tuple[str, ...] = ()
        i = 0
        while i < len(done):
            hits = matches(done[i], node.children) if node.children else []
            if len(hits) != 1:
                break
            node = node.children[hits[0]]
            path = tuple(node.alias_of) if node.alias_of else path + (hits[0],)
            if node.alias_of:
                node = REGISTRY.node(node.alias_of)
            i += 1
        if i == len(done) and node.children:
            out = {name: ("" if _runs(child) else _NOT_YET) for name, child in node.children.items()}
            for name in out:
                if path + (name,) in READER_PAGES:
                    out[name] = "FISH function definition"
            if node is REGISTRY.root:
                out["help"] = ""
            return out
        cmd = node.command
        if cmd is None:
            return {}
        names = {p.name: ("" if p.supported else _NOT_YET) for p in cmd.keywords}
        for p in cmd.positional:
            choices = getattr(p.value, "options", None)
            if choices:
                names.update(dict.fromkeys(choices, ""))
        if cmd.range:
            names["range"] = ""
            names.update({n: "" for n, e in REGISTRY.range_elements.items() if e.supported})
        return names


_NOT_YET = "not supported yet"


def _runs(node) -> bool:
    """Whether the command word leads to at least one command dec3d runs."""
    if node.alias_of:
        node = REGISTRY.node(node.alias_of)
    return node.command is not None or any(_runs(c) for c in node.children.values())


def run_repl(out_dir=None, history_file=None, input=None, output=None) -> int:
    from .session import Session, StopDeck

    session = Session(out_dir=out_dir or Path.cwd())
    if history_file is None:
        history = FileHistory(str(Path.home() / ".dec3d_history")) if input is None else InMemoryHistory()
    else:
        history = FileHistory(str(history_file))
    prompt = PromptSession(history=history, completer=RegistryCompleter(), input=input, output=output,
                           complete_while_typing=False)
    session.write("dec3d interactive session: 3DEC commands, `help <command>`, Ctrl-D to leave")
    while True:
        try:
            text = _read_command(prompt)
        except EOFError:
            break
        except KeyboardInterrupt:
            continue
        if not text.strip():
            continue
        words = text.split()
        if words[0].lower() == "help":
            _help(session, words[1:])
            continue
        try:
            items = session.load_text(text, "<repl>")
            session.run_items(items)
            if any(getattr(getattr(i, "command", None), "path", None) in (("program", "exit"), ("program", "quit"))
                   for i in items):
                break
        except StopDeck:
            break
        except KeyboardInterrupt as exc:   # Ctrl-C while a command ran: cycling stops at a batch end
            step = getattr(exc, "step", None)
            session.write(f"interrupted at step {step}; the model is consistent and can cycle again"
                          if step is not None else "interrupted")
        except Dec3dError as exc:
            session.write(exc.format())
        except Exception as exc:  # a bug in dec3d must not cost the user the session and its model
            import traceback

            session.write("internal error (please report it with the command that caused it):")
            session.write("".join(traceback.format_exception_only(type(exc), exc)).rstrip())
    session.close_log()
    session.files.finish([session.log_path])     # the record of the files dec3d wrote (docs/safety.md)
    return 0


def _read_command(prompt: PromptSession) -> str:
    """One command: a line, its continuation lines, or a whole FISH block."""
    lines = [prompt.prompt("dec3d> ")]
    if _FISH_START.match(lines[0]):
        while not _FISH_END.match(lines[-1]):
            lines.append(prompt.prompt("  fish> "))
    else:
        while _CONTINUED.search(lines[-1]):
            lines.append(prompt.prompt("   ...> "))
    return "\n".join(lines)


def _help(session, words: list[str]) -> None:
    from .docs import page_for

    if not words:
        load_all()
        session.write("Commands: " + ", ".join(sorted(REGISTRY.root.children)))
        session.write("Type `help <command>` (abbreviations work), e.g. `help model gravity`.")
        return
    folder = Path(__file__).resolve().parent.parent / "docs" / "commands"
    page = page_for(words, folder if folder.is_dir() else None)
    if page is None:
        session.write(f"no command `{' '.join(words)}`; type `help` for the list")
        return
    _print_markdown(session, page)


def _print_markdown(session, text: str) -> None:
    """Render a Markdown page (headings, tables, code) with rich on the session's output."""
    from rich.console import Console
    from rich.markdown import Markdown

    out = session.stdout
    tty = bool(getattr(out, "isatty", lambda: False)())
    Console(file=out, force_terminal=tty, width=None if tty else 100, highlight=False).print(Markdown(text))
