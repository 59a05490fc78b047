"""Input readers: the thesis's Appendix A text format and dec3d's TOML slope format."""
from __future__ import annotations

from pathlib import Path

from .errors import SsdemInputError

#: blocks a mesh or an Appendix A file may have unless the user raises it (--max-blocks):
#: about 6 GiB of memory at the measured ~31 MiB per 1000 blocks (docs/ssdem.md)
DEFAULT_MAX_BLOCKS = 200_000
#: largest input file read (an Appendix A file of DEFAULT_MAX_BLOCKS blocks is ~40 MB)
MAX_INPUT_BYTES = 256 * 2 ** 20


def read_text(path: Path) -> str:
    """The file's text: UTF-8 (a leading byte-order mark is dropped); anything else is an
    error naming the line and column of the first byte that is not UTF-8."""
    size = Path(path).stat().st_size
    if size > MAX_INPUT_BYTES:
        raise SsdemInputError(f"the file has {size} bytes, more than the {MAX_INPUT_BYTES} an input may have",
                              str(path), 1, "(file)")
    data = Path(path).read_bytes()
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        pos = exc.start
        line = data.count(b"\n", 0, pos) + 1
        col = pos - (data.rfind(b"\n", 0, pos) + 1) + 1
        raise SsdemInputError(f"the file is not UTF-8 text (byte 0x{data[pos]:02x} at line {line}, "
                              f"column {col})", str(path), line, "(file)", "", col,
                              "save the input as UTF-8 text") from None


def read(path: str | Path, fmt: str = "auto", **options):
    """Read an input file into a `Problem`; `fmt` is "toml", "appendix-a" or "auto" (by suffix).

    options: max_blocks (default DEFAULT_MAX_BLOCKS) and the reader's own options.
    """
    path = Path(path)
    if fmt == "auto":
        fmt = "toml" if path.suffix.lower() == ".toml" else "appendix-a"
    if fmt == "toml":
        from .toml_input import read_toml
        return read_toml(path, **options)
    from .appendix_a import read_appendix_a
    return read_appendix_a(path, **options)
