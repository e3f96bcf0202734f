"""Fixtures and options shared by every test folder (helpers to import: ``tests/support/``).

``erd_robots_dir`` is a fixture here (request it as an argument; it skips the test when
example-robot-data is not installed) and a plain function in :mod:`support` (returns None).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from support import erd_robots_dir


@pytest.fixture(name="erd_robots_dir")
def _erd_robots_dir_fixture() -> Path:
    """The example-robot-data ``robots/`` folder; skips the test when it is not installed."""
    found = erd_robots_dir()
    if found is None:
        pytest.skip("example-robot-data is not installed")
    return found


def pytest_addoption(parser):
    parser.addoption("--update-golden", action="store_true", default=False,
                     help="Rewrite generated/ from the current code instead of comparing.")


# ----------------------------------------------------------------------------------------------
# The derivation cache: never the user's. Every test module gets a fresh cache folder (set
# before the module's own fixtures run, so that `eomgen generate` processes they start inherit
# it), and the whole session one besides; nothing is ever written to ~/.cache/eomgen.
# ----------------------------------------------------------------------------------------------


@pytest.fixture(autouse=True, scope="session")
def _session_cache_dir(tmp_path_factory):
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("EOMGEN_CACHE_DIR", str(tmp_path_factory.mktemp("eomgen_cache")))
        yield


@pytest.fixture(autouse=True, scope="module")
def _module_cache_dir(_session_cache_dir, tmp_path_factory):
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("EOMGEN_CACHE_DIR", str(tmp_path_factory.mktemp("eomgen_cache")))
        yield
