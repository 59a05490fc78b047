"""Input readers: the thesis's Appendix A text format and dec3d's TOML slope format."""
from __future__ import annotations

from pathlib import Path


def read(path: str | Path, fmt: str = "auto", **options):
    """Read an input file into a `Problem`; `fmt` is "toml", "appendix-a" or "auto" (by suffix)."""
    path = Path(path)
    if fmt == "auto":
        fmt = "toml" if path.suffix.lower() == ".toml" else "appendix-a"
    if fmt == "toml":
        from .toml_input import read_toml
        return read_toml(path, **options)
    from .appendix_a import read_appendix_a
    return read_appendix_a(path, **options)
