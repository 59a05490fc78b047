"""`dec3d run` of a 3DEC 4/5 deck: the session translates legacy text in memory (dec3d.lang.legacy)
before binding it, for the deck and the files it calls, and moves the location of every error back
to the original file, line and column. `dec3d run --no-legacy` uses the plain Session, which refuses
legacy syntax with its precise error."""
from __future__ import annotations

import sys
from pathlib import Path

from .errors import Dec3dError
from .lang.legacy import looks_legacy, remap_error, translate_text
from .lang.legacy.translate import State
from .session import Session


class LegacySession(Session):
    """A Session that reads 3DEC 4/5 decks through the translator (with a notice for each)."""

    def __init__(self, *args, notice=None, **kwargs):
        super().__init__(*args, **kwargs)
        self.legacy_maps = []
        self.legacy_state = State()          # materials, named ranges, hidden blocks: carried from deck to deck
        self._notice = notice if notice is not None else (lambda text: print(text, file=sys.stderr))

    def load_text(self, text, filename="<input>", base_dir: Path | None = None, stack=()):
        if not looks_legacy(text):
            return super().load_text(text, filename, base_dir, stack)
        tr = translate_text(text, filename, self.legacy_state)
        self.legacy_maps.append(tr.map)
        left = f"; {tr.untranslated} line(s) could not be translated (kept as comments)" if tr.untranslated else ""
        self._notice(f"notice: {filename} is 3DEC 4/5 (legacy) syntax: running its 3DEC 7+ translation "
                     f"(`dec3d translate` shows it{left}; `--no-legacy` refuses such decks)")
        try:
            return super().load_text(tr.text, filename, base_dir, stack)
        except Dec3dError as exc:
            raise remap_error(exc, self.legacy_maps) from None

    def run_items(self, items):
        try:
            return super().run_items(items)
        except Dec3dError as exc:
            raise remap_error(exc, self.legacy_maps) from None


def translate_main(deck: str, out: str | None) -> int:
    """`dec3d translate old.dat [--out new.dat]`: the 3DEC 7+ text on stdout (or in the file)."""
    p = Path(deck)
    try:
        text = p.read_bytes().decode("utf-8", errors="replace").lstrip("\ufeff")
    except OSError as exc:
        print(f"dec3d translate: error: cannot read `{deck}`: {exc.strerror or exc}", file=sys.stderr)
        return 2
    tr = translate_text(text, str(p))
    if out:
        try:
            Path(out).write_text(tr.text, encoding="utf-8")
        except OSError as exc:
            print(f"dec3d translate: error: cannot write `{out}`: {exc.strerror or exc}", file=sys.stderr)
            return 2
    else:
        sys.stdout.write(tr.text)
    if tr.text == text.replace("\r\n", "\n").replace("\r", "\n"):
        print(f"dec3d translate: `{deck}` has no 3DEC 4/5 commands (the text is unchanged)", file=sys.stderr)
    if tr.untranslated:
        print(f"dec3d translate: {tr.untranslated} line(s) could not be translated: they are kept as "
              "`; dec3d translate: could not translate: ...` comments", file=sys.stderr)
    return 0
