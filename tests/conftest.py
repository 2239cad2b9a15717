"""The test suite keeps its caches to itself: every cupcheck cache (`validation.bridge.cache.user_cache_dir`)
goes to one temporary directory per session, never the user's."""

import pytest


@pytest.fixture(autouse=True, scope="session")
def _session_cache(tmp_path_factory):
    mp = pytest.MonkeyPatch()
    mp.setenv("CUPCHECK_CACHE_DIR", str(tmp_path_factory.mktemp("cupcheck-cache")))
    yield
    mp.undo()
