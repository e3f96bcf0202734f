"""eomgen: symbolic equations of motion M(q) q̈ + C(q, q̇) q̇ + g(q) = τ for robots.

The pipeline, one module per stage::

    eomgen.load(path) -> RobotModel -> eomgen.derive(model) -> Dynamics -> eomgen.verify(dynamics)

and, between loading and deriving, optionally a scene: only what a task needs is modelled
(:mod:`eomgen.scene`, :mod:`eomgen.reduction`)::

    eomgen.apply_scene(model, eomgen.load_scene(path)) -> (RobotModel, ReductionReport)

>>> import eomgen
>>> arm = eomgen.load(eomgen.example_path("planar_2link"))
>>> dyn = eomgen.derive(arm)
>>> dyn.joint_names
('joint1', 'joint2')

The public names are imported on first use, so that ``import eomgen`` does not import SymPy:
``eomgen generate`` answers from the derivation cache (:mod:`eomgen.cache`) without it. The
exceptions, one class per kind of problem, are in :mod:`eomgen.errors`.
"""

from __future__ import annotations

from .common.version import __version__  # noqa: E402

import importlib  # noqa: E402
import sys  # noqa: E402
import types  # noqa: E402
from typing import TYPE_CHECKING  # noqa: E402

from .errors import DescriptionError, EomgenError, SceneError, UnsupportedError  # noqa: E402
from .moved import install as _install_moved  # noqa: E402

_install_moved()  # the old module paths, each warning once (eomgen.moved)

if TYPE_CHECKING:  # what the lazy names are, for readers and type checkers
    from .dynamics import Dynamics, derive
    from .model import RobotModel
    from .parsers import load
    from .reduction import Reduction, ReductionReport, apply_scene
    from .robots import example_path
    from .scene import Scene, load_scene
    from .verify import verify

#: Public name → the submodule defining it, imported when the name is first used.
_LAZY = {
    "load": "parsers",
    "derive": "dynamics",
    "Dynamics": "dynamics",
    "verify": "verify",
    "example_path": "robots",
    "RobotModel": "model",
    "load_scene": "scene",
    "Scene": "scene",
    "apply_scene": "reduction",
    "Reduction": "reduction",
    "ReductionReport": "reduction",
}

__all__ = [
    "load", "derive", "verify", "example_path", "RobotModel", "Dynamics",
    "load_scene", "apply_scene", "Scene", "Reduction", "ReductionReport",
    "EomgenError", "DescriptionError", "UnsupportedError", "SceneError", "__version__",
]


def __getattr__(name: str):
    if name in _LAZY:
        value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))


class _Package(types.ModuleType):
    """The package's module type. Importing a submodule binds it as an attribute of its
    package; for ``eomgen.verify`` that would replace the function :func:`verify` (the public
    API) by the module of the same name. Such bindings are skipped: the module stays reachable
    as ``sys.modules["eomgen.verify"]`` and through ``from eomgen.verify import ...``."""

    def __setattr__(self, name: str, value) -> None:
        if name in _LAZY and isinstance(value, types.ModuleType):
            return
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package

from .present import display  # noqa: E402,F401  (registers the notebook display of models and dynamics)
