import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
SHARED = Path(os.environ.get("DEC3D_SHARED", ROOT.parent / "shared"))
DECKS = SHARED / "decks"


@pytest.fixture
def session(tmp_path):
    import io

    from dec3d.session import Session

    out = io.StringIO()
    s = Session(out_dir=tmp_path, stdout=out)
    s.output = out
    return s
