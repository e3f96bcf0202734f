"""Old module paths, kept for one more release: importing one warns and gives the module at its
new place (docs/architecture.md lays the layers out).

========================================  =====================================
 old path                                 new path
========================================  =====================================
 ``eomgen.actuators``                     :mod:`eomgen.analysis.actuators`
 ``eomgen.batch``                         :mod:`eomgen.analysis.batch`
 ``eomgen.bodies``                        :mod:`eomgen.model.bodies`
 ``eomgen.catalogue``                     :mod:`eomgen.outputs.catalogue`
 ``eomgen.compiler``                      :mod:`eomgen.common.compiler`
 ``eomgen.contacts``                      :mod:`eomgen.numeric.contacts`
 ``eomgen.display``                       :mod:`eomgen.present.display`
 ``eomgen.expressions``                   :mod:`eomgen.model.expressions`
 ``eomgen.floating``                      :mod:`eomgen.numeric.floating_base`
 ``eomgen.free_flyer``                    :mod:`eomgen.model.floating`
 ``eomgen.lambdify``                      :mod:`eomgen.codegen.lambdify`
 ``eomgen.loops``                         :mod:`eomgen.numeric.loops`
 ``eomgen.notebook``                      :mod:`eomgen.teach.notebook`
 ``eomgen.output``                        :mod:`eomgen.common.output`
 ``eomgen.progress``                      :mod:`eomgen.common.progress`
 ``eomgen.quaternion_joints``             :mod:`eomgen.model.configuration`
 ``eomgen.reduction.cost``                :mod:`eomgen.codegen.derivation_cost`
 ``eomgen.reprs``                         :mod:`eomgen.common.reprs`
 ``eomgen.symbolic.quaternion_joints``    :mod:`eomgen.symbolic.charts`
 ``eomgen.symbolic.free_flyer``           :mod:`eomgen.symbolic.charts` (see below)
 ``eomgen.templating``                    :mod:`eomgen.common.templating`
========================================  =====================================

``import eomgen.quaternion_joints`` (or ``from eomgen.quaternion_joints import integrate``)
emits one :class:`DeprecationWarning` naming the new path and :data:`REMOVED_IN`, and binds the
new module under the old name: its functions and classes are the same objects. The new module
offers every public name of the old one (``eomgen.numeric.floating_base`` offers
``add_floating_base``, ``EULER_JOINTS`` and ``WORLD`` of the model layer with its own maps).
The one exception is ``eomgen.symbolic.free_flyer``, whose functions had the free flyer at the
start of ``v`` bound in: :mod:`eomgen.symbolic.charts` takes the joints (or the model) first, so
``chart_offset(v)`` is ``charts.chart_offset(base, v)`` with ``base =
eomgen.model.configuration.layout(None)`` (the free flyer at ``v[0:6]``), and
``root_placement(q, b)`` is ``charts.placement(base[0], q, b)``; a call in the old form fails
loudly (a missing argument or name), never silently.

Names that left a module which stays (:data:`MOVED_NAMES`) are looked up by that module's
``__getattr__`` through :func:`moved_name`, with the same warning:

================================================  =====================================
 old name                                           new place
================================================  =====================================
 ``eomgen.model.FREE_FLYER_CONFIGURATION``          :mod:`eomgen.model.floating`
 ``eomgen.model.FREE_FLYER_VELOCITY``               :mod:`eomgen.model.floating`
 ``eomgen.reduction.derivation_cost``               :mod:`eomgen.codegen.derivation_cost`
 ``eomgen.reduction.measure_derivation``            :mod:`eomgen.codegen.derivation_cost`
 ``eomgen.reduction.MEASURE_TIMEOUT``               :mod:`eomgen.codegen.derivation_cost`
================================================  =====================================
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import warnings

#: The release that drops the old paths.
REMOVED_IN = "0.3.0"

#: Old module → its new place.
MOVED: dict[str, str] = {
    "eomgen.actuators": "eomgen.analysis.actuators",
    "eomgen.batch": "eomgen.analysis.batch",
    "eomgen.bodies": "eomgen.model.bodies",
    "eomgen.catalogue": "eomgen.outputs.catalogue",
    "eomgen.compiler": "eomgen.common.compiler",
    "eomgen.contacts": "eomgen.numeric.contacts",
    "eomgen.display": "eomgen.present.display",
    "eomgen.expressions": "eomgen.model.expressions",
    "eomgen.floating": "eomgen.numeric.floating_base",
    "eomgen.free_flyer": "eomgen.model.floating",
    "eomgen.lambdify": "eomgen.codegen.lambdify",
    "eomgen.loops": "eomgen.numeric.loops",
    "eomgen.notebook": "eomgen.teach.notebook",
    "eomgen.output": "eomgen.common.output",
    "eomgen.progress": "eomgen.common.progress",
    "eomgen.quaternion_joints": "eomgen.model.configuration",
    "eomgen.reduction.cost": "eomgen.codegen.derivation_cost",
    "eomgen.reprs": "eomgen.common.reprs",
    "eomgen.symbolic.quaternion_joints": "eomgen.symbolic.charts",
    "eomgen.symbolic.free_flyer": "eomgen.symbolic.charts",
    "eomgen.templating": "eomgen.common.templating",
}

#: Module that stays → {name that left it: the module it went to}.
MOVED_NAMES: dict[str, dict[str, str]] = {
    "eomgen.model": {
        "FREE_FLYER_CONFIGURATION": "eomgen.model.floating",
        "FREE_FLYER_VELOCITY": "eomgen.model.floating",
    },
    "eomgen.reduction": {
        "derivation_cost": "eomgen.codegen.derivation_cost",
        "measure_derivation": "eomgen.codegen.derivation_cost",
        "MEASURE_TIMEOUT": "eomgen.codegen.derivation_cost",
    },
}


def moved_name(module: str, name: str):
    """``module``'s ``__getattr__``: a name of :data:`MOVED_NAMES` warns and is taken from its
    new module, then bound in ``module`` (so it warns once, as an old module path does); any
    other name is missing (:class:`AttributeError`)."""
    new = MOVED_NAMES.get(module, {}).get(name)
    if new is None:
        raise AttributeError(f"module {module!r} has no attribute {name!r}")
    warnings.warn(f"{module}.{name} moved to {new}; the old path goes in eomgen {REMOVED_IN}",
                  DeprecationWarning, stacklevel=3)
    value = getattr(importlib.import_module(new), name)
    setattr(sys.modules[module], name, value)
    return value


class MovedModules(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """The import hook of :data:`MOVED` (installed by ``import eomgen``)."""

    def find_spec(self, fullname, path=None, target=None):
        if fullname in MOVED:
            return importlib.util.spec_from_loader(fullname, self)
        return None

    def create_module(self, spec):
        return None  # a placeholder, replaced in sys.modules by exec_module

    def exec_module(self, module) -> None:
        """Import the new module and put it in the old name's place (the import system then
        hands out what ``sys.modules`` holds under that name)."""
        new = MOVED[module.__name__]
        warnings.warn(f"{module.__name__} moved to {new}; the old path goes in eomgen "
                      f"{REMOVED_IN}", DeprecationWarning, stacklevel=2)
        sys.modules[module.__name__] = importlib.import_module(new)


def install() -> None:
    """Put the hook on ``sys.meta_path`` once."""
    if not any(isinstance(finder, MovedModules) for finder in sys.meta_path):
        sys.meta_path.append(MovedModules())


__all__ = ["MOVED", "MOVED_NAMES", "MovedModules", "REMOVED_IN", "install", "moved_name"]
