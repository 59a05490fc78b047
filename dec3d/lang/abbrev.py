"""Unique-prefix abbreviation of command words and keywords (3DEC "command shaping").

A word may be cut to any prefix that selects one candidate. Hyphenated words are cut
part by part: `gen-sub` is `generate-subcontacts`, `a-r` is `apply-remove`, `v-y` is
`velocity-y`. An abbreviation matches only candidates with the same number of parts
(`fric` is `friction`, never `friction-residual`); when none has, a plain prefix of
the whole word is tried. An exact match always wins.
"""
from __future__ import annotations

from difflib import get_close_matches
from typing import Iterable


_CACHE: dict[tuple[str, tuple[str, ...]], list[str]] = {}


def matches(word: str, candidates: Iterable[str]) -> list[str]:
    """All candidates `word` may abbreviate; [exact] when one equals it (memoised: decks repeat words)."""
    cands = tuple(candidates)
    key = (word, cands)
    hit = _CACHE.get(key)
    if hit is None:
        if len(_CACHE) > 100_000:
            _CACHE.clear()
        hit = _CACHE[key] = _matches(word.lower(), cands)
    return list(hit)


def _matches(w: str, cands: tuple[str, ...]) -> list[str]:
    if w in cands:
        return [w]
    parts = w.split("-")
    hits = []
    for c in cands:
        cparts = c.split("-")
        if len(cparts) == len(parts) and all(cp.startswith(p) for cp, p in zip(cparts, parts)):
            hits.append(c)
    if not hits:
        hits = [c for c in cands if c.startswith(w)]
    return sorted(hits)


def suggest(word: str, candidates: Iterable[str], n: int = 3) -> list[str]:
    """Close spellings of `word` among the candidates, for "did you mean" hints."""
    return get_close_matches(word.lower(), list(candidates), n=n, cutoff=0.6)
