"""Fixtures and options shared by every test folder (helpers to import: ``tests/support/``).

``erd_robots_dir`` is a fixture here (request it as an argument; it skips the test when
example-robot-data is not installed) and a plain function in :mod:`support` (returns None).
"""

from __future__ import annotations

import os
import sys

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


def _seed_pinocchio():
    pinocchio = sys.modules.get("pinocchio")
    if pinocchio is not None:
        pinocchio.seed(0)


@pytest.fixture(autouse=True, scope="module")
def _pinocchio_seeded_per_module():
    """Pinocchio's global generator (``randomConfiguration``, ``SE3.Random``) seeded before a
    module's fixtures and before every test, so that a test draws the same states whatever
    ran before it on its worker."""
    _seed_pinocchio()


@pytest.fixture(autouse=True)
def _pinocchio_seeded(_pinocchio_seeded_per_module):
    _seed_pinocchio()


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


# ----------------------------------------------------------------------------------------------
# One worker per module that derives something once for its tests. A module-scoped fixture
# (a robot derived, its modules generated and compiled) is computed once per worker process
# that runs one of its tests (and so is a function of the module cached with functools);
# `pytest -n auto` hands the tests out one by one (the first quarter of the collection
# round-robin), so both workers paid for most of them. With `--dist loadgroup` (chosen below
# when -n is given without a --dist of the caller's), the tests of a module that defines such a
# fixture go to one worker together, largest groups first; the other tests are still handed out
# one by one. Without xdist the mark is inert.
# ----------------------------------------------------------------------------------------------


def _module_fixture_here(item) -> bool:
    """Whether ``item`` uses a module- or session-scoped fixture its own module defines, or
    its module keeps results in a cached function (``functools.cache``, ``lru_cache``)."""
    module = item.nodeid.split("::")[0]
    namespace = getattr(getattr(item, "module", None), "__dict__", {})
    if any(hasattr(value, "cache_info") and value.__module__ == namespace["__name__"]
           for value in namespace.values()):
        return True
    info = getattr(item, "_fixtureinfo", None)
    if info is None:
        return False
    for definitions in info.name2fixturedefs.values():
        definition = definitions[-1]
        if definition.scope in ("module", "session") and definition.baseid == module:
            return True
    return False


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config, items):
    grouped = {item.nodeid.split("::")[0] for item in items if _module_fixture_here(item)}
    for item in items:
        module = item.nodeid.split("::")[0]
        if module in grouped:
            item.add_marker(pytest.mark.xdist_group(module))



def pytest_configure(config):
    """``-n`` without a ``--dist`` of the caller's: xdist's default ``load`` becomes
    ``loadgroup`` (above), and each worker is told so (a worker reads the command line again,
    where no ``--dist`` stands). Set here rather than in addopts, so that pytest without
    pytest-xdist still runs."""
    workerinput = getattr(config, "workerinput", None)
    if workerinput is not None:
        if workerinput.get("eomgen_loadgroup"):
            config.option.loadgroup = True
        return
    chosen = [*config.invocation_params.args, *os.environ.get("PYTEST_ADDOPTS", "").split()]
    if getattr(config.option, "dist", "no") == "load" and not any(
            str(a).startswith(("--dist", "-d")) for a in chosen):
        config.option.dist = "loadgroup"


@pytest.hookimpl(optionalhook=True)
def pytest_configure_node(node):
    node.workerinput["eomgen_loadgroup"] = node.config.getvalue("dist") == "loadgroup"


# ----------------------------------------------------------------------------------------------
# What skipped, for CI: `.ci/run` first runs the README's test command as a newcomer would (only
# the `test` extra), then installs the other extras and system packages and runs what skipped.
# With EOMGEN_SKIPPED_LOG set, every process (each xdist worker, and the controller) notes the
# node ids of the tests and modules that skipped in it, and the controller writes them all there
# at the end, one a line, sorted. (Each process keeps its own list: xdist forwards only one of the
# module skips whose reasons read alike.)
# ----------------------------------------------------------------------------------------------

_SKIPPED: set[str] = set()


def _note_skipped(report) -> None:
    if os.environ.get("EOMGEN_SKIPPED_LOG") and report.skipped and report.nodeid \
            and not hasattr(report, "wasxfail"):
        _SKIPPED.add(report.nodeid)


def pytest_collectreport(report):
    _note_skipped(report)


def pytest_runtest_logreport(report):
    _note_skipped(report)


def pytest_sessionfinish(session):
    path = os.environ.get("EOMGEN_SKIPPED_LOG")
    if not path:
        return
    workerinput = getattr(session.config, "workerinput", None)
    if workerinput is not None:   # a worker: its part, for the controller to gather
        part = Path(f"{path}.{workerinput['workerid']}")
        part.write_text("".join(f"{n}\n" for n in sorted(_SKIPPED)), encoding="utf-8")
        return
    for part in sorted(Path(path).parent.glob(Path(path).name + ".*")):
        _SKIPPED.update(part.read_text(encoding="utf-8").split("\n"))
        part.unlink()
    _SKIPPED.discard("")
    Path(path).write_text("".join(f"{n}\n" for n in sorted(_SKIPPED)), encoding="utf-8")
