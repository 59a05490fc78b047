"""Every line of every shared 3DEC deck is read: it parses, then binds to a registered command
or to a clear "not supported yet" (or, for 3DEC 5 decks, "legacy syntax") diagnostic.

The shared decks are stored flat (their called files are not beside them under the names they
call), so each is checked on its own (`standalone`): calls not followed, FISH names it never
assigns taken to come from its caller. tests/test_check.py follows calls."""
from collections import Counter

import pytest

from dec3d.check import ERROR, LEGACY, NOT_SUPPORTED, RUNNABLE, check_file
from conftest import DECKS, NO_DECKS

if not DECKS.is_dir():
    pytest.skip(NO_DECKS, allow_module_level=True)
MODERN = sorted(DECKS.glob("*.dat"))
LEGACY_DECKS = sorted((DECKS / "legacy_v5").glob("*.dat"))


def test_decks_are_there():
    assert len(MODERN) >= 30 and len(LEGACY_DECKS) >= 9


@pytest.mark.parametrize("path", MODERN, ids=lambda p: p.name[:60])
def test_modern_deck_binds(path):
    reports = check_file(path, standalone=True)
    counts = Counter(r.status for r in reports)
    print(f"{path.name}: {dict(counts)}")
    errors = [f"line {r.line}: {r.what}" for r in reports if r.status in (ERROR, LEGACY)]
    assert not errors, "\n".join(errors)
    # every source line holding a command was seen
    assert sum(counts.values()) > 0


@pytest.mark.parametrize("path", LEGACY_DECKS, ids=lambda p: p.name[:60])
def test_legacy_deck_gets_clear_diagnostics(path):
    # as written (`dec3d run --no-legacy`); their translations: tests/test_legacy_decks.py
    reports = check_file(path, standalone=True, legacy=False)
    counts = Counter(r.status for r in reports)
    print(f"{path.name}: {dict(counts)}")
    errors = [f"line {r.line}: {r.what}" for r in reports if r.status == ERROR]
    assert not errors, "\n".join(errors)


def test_totals(capsys):
    total = Counter()
    for p in MODERN + LEGACY_DECKS:
        total.update(r.status for r in check_file(p, standalone=True, legacy=False))
    with capsys.disabled():
        print(f"\nshared decks: {total[RUNNABLE]} runnable, {total[NOT_SUPPORTED]} not supported yet, "
              f"{total[LEGACY]} legacy syntax, {total[ERROR]} errors")
    assert total[ERROR] == 0 and total[RUNNABLE] > 0
