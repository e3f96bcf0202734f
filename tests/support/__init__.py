"""What the tests share: paths, the example-robot-data lookup, comparisons, random states,
module loaders and the two ways of running ``eomgen`` (in process and in a real process).

Import from a test module as ``from support import ...`` (pytest puts ``tests/`` on
``sys.path`` because ``tests/conftest.py`` is not inside a package; ``tests/`` and its feature
folders are deliberately not packages, so every test file's name is unique). The submodules
hold the bigger shared pieces:

* :mod:`support.reference`: independent references (Pinocchio models, a URDF writer, random
  robots);
* :mod:`support.robots`: robots several feature folders use (Panda, PUMA 560, UR5, solo12,
  legged trunks, the hostile-names star, the flexible drive arm);
* :mod:`support.generated`: every code backend's module of a model, loaded and callable alike;
* :mod:`support.array_backends`: the JAX and PyTorch modules next to the NumPy one;
* :mod:`support.browser`: headless Chromium judging typeset math.

Fixtures (``erd_robots_dir``, the cache folders, ``--update-golden``) live in
``tests/conftest.py``.
"""

from __future__ import annotations

import functools
import importlib.metadata
import importlib.util
import os
import subprocess
import sys
import sysconfig
import warnings
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest

#: The project's root folder (``examples/``, ``docs/``, ``generated/`` live there).
ROOT = Path(__file__).resolve().parents[2]
#: The ``tests/`` folder.
TESTS = ROOT / "tests"
#: The corpus of bad and hostile inputs (``tests/corpus/``).
CORPUS = TESTS / "corpus"
#: The ``docs/`` folder.
DOCS = ROOT / "docs"
#: The example scenes and contact scenes.
SCENES = ROOT / "examples" / "scenes"
CONTACTS = ROOT / "examples" / "contacts"

#: The prefixes of eomgen's error and warning lines on stderr.
ERROR = "eomgen: error: "
WARNING = "eomgen: warning: "

#: Relative tolerance of the numeric comparisons.
RTOL = 1e-10

# ----------------------------------------------------------------------------------------------
# example-robot-data
# ----------------------------------------------------------------------------------------------

#: Where the example-robot-data wheel (a cmeel package) puts its robots, below a prefix.
_ERD_SUFFIX = Path("cmeel.prefix", "share", "example-robot-data", "robots")


@functools.cache
def erd_robots_dir() -> Path | None:
    """The ``robots/`` folder of the example-robot-data package, or None when absent.

    Looked up, in order: the ``EXAMPLE_ROBOT_DATA_ROBOTS`` environment variable, the files the
    installed ``example-robot-data`` distribution lists, and the site-packages folders. (The
    fixture of the same name in ``conftest.py`` skips the test instead of returning None.)
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


def erd_robots_or_skip() -> Path:
    """:func:`erd_robots_dir`, skipping the calling test when the data is not installed."""
    robots = erd_robots_dir()
    if robots is None:
        pytest.skip("example-robot-data is not installed")
    return robots


# ----------------------------------------------------------------------------------------------
# Comparisons and random states
# ----------------------------------------------------------------------------------------------


def assert_close(a, b, what="", rtol=RTOL, same_shape=True):
    """``max|a - b| <= rtol * max(1, max|b|)``, and (``same_shape``) equal shapes."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if same_shape:
        assert a.shape == b.shape, f"{what}: shape {a.shape} != {b.shape}"
    err = float(np.max(np.abs(a - b))) if a.size else 0.0
    scale = max(1.0, float(np.max(np.abs(b))) if b.size else 1.0)
    assert err <= rtol * scale, f"{what}: max|a-b| = {err:.3g} (scale {scale:.3g})\na={a}\nb={b}"


def relative(a, b) -> float:
    """``max|a - b| / max|b|``."""
    return float(np.abs(np.asarray(a) - b).max() / np.abs(b).max())


def rng_of(seed_or_rng) -> np.random.Generator:
    """A generator: ``seed_or_rng`` itself, or a new one seeded with it."""
    if isinstance(seed_or_rng, np.random.Generator):
        return seed_or_rng
    return np.random.default_rng(seed_or_rng)


def random_states(seed_or_rng, n: int, count: int = 4, parts: int = 3) -> list[tuple]:
    """``count`` tuples ``(q, qd[, qdd])`` of ``parts`` vectors of size ``n``: q uniform in
    [−π, π], the others standard normal (drawn in that order, state after state)."""
    rng = rng_of(seed_or_rng)
    return [(rng.uniform(-np.pi, np.pi, n), *(rng.normal(size=n) for _ in range(parts - 1)))
            for _ in range(count)]


def uniform_states(seed_or_rng, n: int, count: int = 3, parts: int = 3,
                   scale: float = 2.0) -> list[tuple]:
    """``count`` tuples of ``parts`` vectors of size ``n``, uniform in [−scale, scale]."""
    rng = rng_of(seed_or_rng)
    return [tuple(rng.uniform(-scale, scale, n) for _ in range(parts)) for _ in range(count)]


def floating_states(n: int, count: int, seed: int = 0, accelerations: bool = False):
    """States of a floating-base robot (Euler coordinates): q and q̇ uniform in [−1, 1], the
    pitch q[4] in [−1.2, 1.2] (away from the singularity at ±π/2); with ``accelerations`` also
    q̈ uniform in [−2, 2]."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        q = rng.uniform(-1, 1, n)
        q[4] = rng.uniform(-1.2, 1.2)
        if accelerations:
            yield q, rng.uniform(-1, 1, n), rng.uniform(-2, 2, n)
        else:
            yield q, rng.uniform(-1, 1, n)


# ----------------------------------------------------------------------------------------------
# Loading
# ----------------------------------------------------------------------------------------------


def load_module(path: Path, name: str) -> ModuleType:
    """Import a (generated) file as a module, not registered in ``sys.modules``."""
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def load_quietly(path):
    """``eomgen.load(path)`` with its warnings silenced (PUMA 560's published inertias and the
    Panda's mimic fingers warn by design)."""
    import eomgen

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return eomgen.load(path)


def model_states(model, count: int = 3, seed: int = 0):
    """``count`` random states ``(q, v)`` of ``model``: ``q`` uniform in [−1, 1] with each
    quaternion joint's quaternion made unit (MuJoCo takes them as given), ``v`` normal."""
    import numpy as np

    rng = np.random.default_rng(seed)
    for _ in range(count):
        q = rng.uniform(-1, 1, model.nq)
        for joint in model.quaternion_joints:
            k = joint.quaternion
            q[k:k + 4] /= np.linalg.norm(q[k:k + 4])
        yield q, rng.normal(size=model.dof)


def write(path: Path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` and return the path."""
    path.write_text(text, encoding="utf-8")
    return path


# ----------------------------------------------------------------------------------------------
# Running eomgen
# ----------------------------------------------------------------------------------------------


def run_cli(*args, **invoke):
    """``eomgen ARGS`` in this process (click's runner); returns click's Result
    (``exit_code``, ``stdout``, ``stderr``, ``output``)."""
    from click.testing import CliRunner

    from eomgen.cli import main

    return CliRunner().invoke(main, [str(a) for a in args], prog_name="eomgen", **invoke)


def run_in_process(*args) -> subprocess.CompletedProcess:
    """``eomgen ARGS`` in this process, its result shaped as :func:`run_process`'s
    (``returncode``, ``stdout``, ``stderr``), for tests of what the command does rather than of
    the process it runs in. An exception that escaped the command is appended to ``stderr`` as
    its traceback (a real process would print it and exit with 1)."""
    import traceback

    result = run_cli(*args)
    stderr = result.stderr
    if result.exception is not None and not isinstance(result.exception, SystemExit):
        stderr += "".join(traceback.format_exception(result.exception))
    return subprocess.CompletedProcess(["eomgen", *map(str, args)], result.exit_code,
                                       result.stdout, stderr)


def run_process(*args, env=None, cwd=None, timeout=300, check=False
                ) -> subprocess.CompletedProcess:
    """``python -m eomgen.cli ARGS`` in a real process: for what only a process shows (exit
    codes of the interpreter, signals, terminals, hash seeds, the cache shared between
    processes, start-up imports)."""
    return subprocess.run([sys.executable, "-m", "eomgen.cli", *map(str, args)],
                          capture_output=True, text=True, timeout=timeout, env=env, cwd=cwd,
                          check=check)


# ----------------------------------------------------------------------------------------------
# Rendering without compiling
# ----------------------------------------------------------------------------------------------


def render_text_files(model, backends, **options):
    """``eomgen.codegen.generate.render_files(model, backends, **options)`` without compiling
    (``build=False``): the text files, byte for byte those a build writes, for renders whose
    binaries a test would throw away; the tests that load compiled code compile as before."""
    from eomgen.codegen.generate import render_files

    return render_files(model, backends, build=False, **options)
