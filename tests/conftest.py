import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
# The public 3DEC decks are not part of the repository: DEC3D_SHARED names a folder holding `decks/`
# (default: `shared/` beside the repository). Tests that read them skip, with NO_DECKS as the reason,
# when the folder is absent.
SHARED = Path(os.environ.get("DEC3D_SHARED", ROOT.parent / "shared"))
DECKS = SHARED / "decks"
NO_DECKS = (f"public 3DEC decks not found at {DECKS}: set DEC3D_SHARED=<folder holding decks/> "
            "or place shared/ beside the repository (README, 'Set up')")
# a module that reads the decks starts with:
#     if not DECKS.is_dir():
#         pytest.skip(NO_DECKS, allow_module_level=True)


@pytest.fixture
def session(tmp_path):
    import io

    from dec3d.session import Session

    out = io.StringIO()
    s = Session(out_dir=tmp_path, stdout=out)
    s.output = out
    return s
