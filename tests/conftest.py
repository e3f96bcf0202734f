"""Shared test helpers.

``erd_robots_dir()`` is both a plain function (import it: ``from conftest import
erd_robots_dir``; returns None when example-robot-data is not installed) and a fixture of the
same name (request it as an argument; skips the test when the data is not installed).
"""

from __future__ import annotations

import functools
import importlib.metadata
import os
import sysconfig
from pathlib import Path

import pytest

#: Where the example-robot-data wheel (a cmeel package) puts its robots, below a prefix.
_ERD_SUFFIX = Path("cmeel.prefix", "share", "example-robot-data", "robots")


@functools.cache
def erd_robots_dir() -> Path | None:
    """The ``robots/`` folder of the example-robot-data package, or None when absent.

    Looked up, in order: the ``EXAMPLE_ROBOT_DATA_ROBOTS`` environment variable, the files the
    installed ``example-robot-data`` distribution lists, and the site-packages folders.
    """
    override = os.environ.get("EXAMPLE_ROBOT_DATA_ROBOTS")
    candidates = [Path(override)] if override else []
    candidates += _from_distribution_files()
    candidates += [Path(sysconfig.get_paths()[key]) / _ERD_SUFFIX for key in ("purelib", "platlib")]
    for candidate in candidates:
        if candidate.is_dir():
            return candidate
    return None


def _from_distribution_files() -> list[Path]:
    try:
        distribution = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        return []
    marker = _ERD_SUFFIX.parts[-3:]  # share/example-robot-data/robots
    for file in distribution.files or ():
        parts = Path(file).parts
        for start in range(len(parts) - len(marker) + 1):
            if parts[start:start + len(marker)] == marker:
                return [Path(distribution.locate_file(Path(*parts[:start + len(marker)])))]
    return []


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
