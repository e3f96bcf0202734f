"""Fixtures and options shared by every test folder (helpers to import: ``tests/support/``).

``erd_robots_dir`` is a fixture here (request it as an argument; it skips the test when
example-robot-data is not installed) and a plain function in :mod:`support` (returns None).
"""

from __future__ import annotations

import os

# One BLAS thread per test process: `pytest -n auto` already runs a worker per core, and
# OpenBLAS's own threads on top of that oversubscribe the cores (a least-squares fit of the
# identification tests ran 6x slower under load with them). Set before NumPy loads OpenBLAS;
# processes the tests start inherit it. A variable the caller set is kept.
for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

from pathlib import Path  # noqa: E402

import pytest  # noqa: E402

from support import erd_robots_dir  # noqa: E402


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
