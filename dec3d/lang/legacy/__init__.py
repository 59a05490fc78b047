"""3DEC 4/5 ("legacy") decks translated to 3DEC 7+ text (docs/legacy.md)."""
from .lines import LineMap, remap_error
from .translate import Translation, looks_legacy, translate_text

__all__ = ["LineMap", "Translation", "looks_legacy", "remap_error", "translate_text"]
