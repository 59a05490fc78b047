import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))          # arch.py, the drivers' model text


@pytest.fixture(autouse=True)
def fresh_it(tmp_path, monkeypatch):
    """Every test starts with no model bound and the working folder a fresh temporary one."""
    import dec3d.itasca as it

    monkeypatch.chdir(tmp_path)
    it.bind(None)
    yield
    it.bind(None)
