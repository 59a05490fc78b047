"""Input errors that name the file, the line and the field."""
from __future__ import annotations

from dec3d.errors import Dec3dError, SourceLocation


class SsdemInputError(Dec3dError):
    """Bad SSDEM input.  `field` is the dotted name of the offending entry."""

    def __init__(self, message: str, file: str, line: int, field: str, text: str = "",
                 column: int = 1, hint: str | None = None):
        self.file, self.line, self.field = str(file), int(line), field
        loc = SourceLocation(file=str(file), line=int(line), column=max(1, column), text=text,
                             length=max(1, len(field.split(".")[-1].split("[")[0])) if text else 1)
        super().__init__(f"field '{field}': {message}", loc, hint)
