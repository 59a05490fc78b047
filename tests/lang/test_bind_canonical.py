"""Binding does not change under speed work: every line of every repository deck, public deck and
generated benchmark deck binds to the same command, values (floats by their bits), locations, range
and text — or the same error at the same file:line:column — as at commit 3c7d0d6, before the lexer's
runs of numbers and the replay on them (issue 33).

``bind_canonical.json`` holds, per deck, a digest of its text and a digest of its bound lines in the
form below, written at 3c7d0d6 by ``python tests/lang/test_bind_canonical.py --write`` (run there with
this file copied in). A deck whose text has changed since is skipped (its digest no longer says
anything); a change meant to change binding rewrites the file the same way and says so in its commit.
"""
import hashlib
import json
import sys
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

from dec3d.commands import load_all  # noqa: E402
from dec3d.commands.binder import BindContext, Binder  # noqa: E402
from dec3d.errors import Dec3dError  # noqa: E402
from dec3d.lang.parser import parse_deck  # noqa: E402
from bound_form import norm as _norm  # noqa: E402
from conftest import DECKS, NO_DECKS  # noqa: E402

STORED = HERE / "bind_canonical.json"
load_all()


def _line(binder, raw):
    try:
        call = binder.bind_line(raw)
    except Dec3dError as exc:
        loc = exc.location
        return ("error", type(exc).__name__, exc.message, exc.hint,
                (loc.file, loc.line, loc.column, loc.length, loc.text) if loc is not None else None)
    if not hasattr(call, "command"):
        return ("statement", _norm(call.node), call.location, call.source)
    rng = None
    if call.range is not None:
        rng = (call.range.union, tuple((e.element.name, _norm(e.args), e.negate, _norm(e.location))
                                       for e in call.range.elements))
    return ("call", call.command.path, _norm(call.args), call.given, rng, call.location, _norm(call.extra),
            _norm(call.locations), call.span[1:], call.text)


def bound_digest(text: str, name: str) -> str:
    """A digest of every line of ``text`` bound in order by one binder (bind plans on), as `dec3d check`
    binds a file on its own (names a calling deck may set are accepted)."""
    try:
        deck = parse_deck(text, name)
        out = []
    except Dec3dError as exc:
        loc = exc.location
        out = [("syntax", type(exc).__name__, exc.message, loc.line, loc.column)]
        deck = None
    if deck is not None:
        binder = Binder(deck, BindContext(lenient_names=True))
        for fish in deck.fish:
            binder.ctx.define_fish(fish)
        out = [_line(binder, raw) for raw in deck.lines]
    form = "\n".join(map(repr, out))
    assert " at 0x" not in form, "a bound value without a stable form"
    return hashlib.sha256(form.encode()).hexdigest()


def _text_digest(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()


def decks() -> dict:
    """name -> text: the repository's decks, the public decks (when present), and the benchmark's
    generated decks (mixed commands, bricks, polyhedra: runs of numbers, `...` and `&` inside them)."""
    out = {}
    for d in ("examples", "verification"):
        for p in sorted((ROOT / d).rglob("*.dat")):
            out[str(p.relative_to(ROOT))] = p.read_text(encoding="utf-8", errors="replace")
    if DECKS.is_dir():
        for p in sorted(DECKS.rglob("*.dat")):
            out["shared/" + str(p.relative_to(DECKS))] = p.read_text(encoding="utf-8", errors="replace")
    sys.path.insert(0, str(ROOT / "bench"))
    from geometry_bench import create_deck
    from parse_bench import generated_deck

    out["generated/mixed"] = generated_deck(3000, seed=3)
    out["generated/brick"] = create_deck("brick", 4)
    out["generated/polyhedron"] = create_deck("polyhedron", 4)
    out["generated/numbers"] = NUMBERS
    return out


# runs of numbers next to everything that may stop, split or end them; values at and past bounds
NUMBERS = "\n".join([
    "block create brick 0 1 0 1 0 1",
    "block create brick -0 1 0 1 -0.0 1",
    "block create brick 0 1 0 1 0 1e999",
    "block create brick 0 1 0 1 0 [1 + 2]",
    "block create brick 0 1 ...",
    "  0 1 0 1",
    "block create brick 0 1 &  ; a comment",
    "  0 1,0,1",
    "block create brick (0,1) (0,1) (0,1)",
    "block create brick 0 1 0 1 0 1e13",
    "block create brick 0 1 0 1 0 -1e12",
    "block create brick 0 1 0 1 0 " + "1" + "0" * 400,
    "block create polyhedron face 0,0,0 0,1,0 1,1,0 1,0,0 face 0,0,1 1,0,1 1,1,1 0,1,1 face 0,0,0 1,0,0 "
    "1,0,1 0,0,1 face 0,1,0 0,1,1 1,1,1 1,1,0 face 0,0,0 0,0,1 0,1,1 0,1,0 face 1,0,0 1,1,0 1,1,1 1,0,1",
    "block create polyhedron face 0,0,0 0,1,0 1,1,0 1,0,0 face 0,0,1 1,0,1 1,1,1 0,1,1 face 0,0,0 1,0,0 "
    "1,0,1 0,0,1 face 0,1,0 0,1,1 1,1,1 1,1,0 face 0,0,0 0,0,1 0,1,1 0,1,0 face 1,0,0 1,1,0 1,1,1 1,0,1 x",
    "block create polyhedron face 0,0,0 0,1,0 1,1,0 1,0,0 face 0,0,1 1,0,1 1,1,1 0,1,1 face 0,0,0 1,0,0 "
    "1,0,1 0,0,1 face 0,1,0 0,1,1 1,1,1 1,1,0 face 0,0,0 0,0,1 0,1,1 0,1,0 face 1,0,0 1,1,0 1,1,1 1,0,1 1",
    "model gravity 0 0 -9.81",
    "model gravity 0 0 -9.81 1",
    "model gravity 0 0",
    "model gravity 0 0 [-1]",
    "model gravity [0] 0 -1",
    "model gravity 0 [0] -1",
    "model gravity 0 0 ...",
    "  -10",
    "model gravity (0, 0, -5)",
    "model gravity 0 0 -1e999",
    "block contact property stiffness-normal 1e9 stiffness-shear 1e8 friction 30",
    "block contact property stiffness-normal 1e9 stiffness-shear 1e8 friction 90",
    "block contact property stiffness-normal 0 stiffness-shear 1e8 friction 30",
    "block contact property stiffness-normal -1 stiffness-shear 1e8 friction 30",
    "block contact jmodel assign elastic range id 1 2",
    "block fix velocity range position-z 0 0.5",
    "block fix velocity range position-z -0 1",
    "block fix velocity range position-z 1 2 position-x 3 4 not",
    "block fix velocity range position-z 1e999 2",
    "model cycle 10 20",
    "model cycle 10",
    "block initialize velocity 1 2 3 range position-x 0 1",
    "block initialize velocity 1 2 3 range position-x 0 1e999",
    "1 2 3",
    "model title 'a' 1 2",
]) * 2 + "\n"


def _stored() -> dict:
    return json.loads(STORED.read_text())


def _compare(names) -> tuple[int, list]:
    stored, here = _stored(), decks()
    compared, changed = 0, []
    for name in names(here):
        text = here[name]
        entry = stored.get(name)
        if entry is None or entry["text"] != _text_digest(text):
            changed.append(name)          # new, or edited since: its stored digest says nothing
            continue
        assert bound_digest(text, name.rsplit("/", 1)[-1]) == entry["bound"], name
        compared += 1
    return compared, changed


def test_repository_and_generated_decks_bind_as_at_3c7d0d6():
    compared, changed = _compare(lambda d: [n for n in d if not n.startswith("shared/")])
    assert compared >= 60, f"only {compared} decks compared; changed or new since the stored form: {changed}"


def test_public_decks_bind_as_at_3c7d0d6():
    if not DECKS.is_dir():
        pytest.skip(NO_DECKS)
    compared, changed = _compare(lambda d: [n for n in d if n.startswith("shared/")])
    assert compared >= 30, f"only {compared} public decks compared; changed or new: {changed}"


if __name__ == "__main__" and "--write" in sys.argv:
    STORED.write_text(json.dumps({name: {"text": _text_digest(text), "bound": bound_digest(text, name.rsplit("/", 1)[-1])}
                                  for name, text in decks().items()}, indent=1, sort_keys=True) + "\n")
    print(f"wrote {STORED}")
