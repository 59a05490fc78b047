"""The fixture of the tests of dec3d.itasca (imported by each module: a conftest.py here would shadow the
top-level `conftest` other test folders import)."""
import pytest


@pytest.fixture(autouse=True)
def fresh_it(tmp_path, monkeypatch):
    """Every test starts with no model bound and the working folder a fresh temporary one."""
    import dec3d.itasca as it

    monkeypatch.chdir(tmp_path)
    it.bind(None)
    yield
    it.bind(None)
