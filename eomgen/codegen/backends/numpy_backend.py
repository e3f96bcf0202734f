"""NumPy backend: ``<robot>_numpy.py``, straight-line, vectorised over a batch of states.

Printer: SymPy's :class:`~sympy.printing.numpy.NumPyPrinter` with the module aliased as ``np``
and floats printed with all 17 significant digits. Template: ``templates/numpy/module.py.jinja``.
"""

from __future__ import annotations

from dataclasses import dataclass

from sympy.printing.numpy import NumPyPrinter

from ...common.output import GeneratedFile
from ..job import Job
from ..registry import register
from ...symbolic.printing import NumPyModulePrinter
from ...common.templating import render
from ...runtime.cholesky import included_source
from ...runtime import task_space
from .common import TermOrderShared, python_loader, python_module_context, warning_exports


@dataclass(frozen=True)
class NumPyConfig:
    """Options of the NumPy backend."""

    template: str = "numpy/module.py.jinja"
    suffix: str = "_numpy.py"


class ArrayModulePrinter(TermOrderShared, NumPyModulePrinter):
    """NumPy-style code whose ``numpy.<name>`` calls go to another array module, ``alias``
    (``jnp`` for ``jax.numpy``, ``torch``): the same expressions, the same float literals."""

    alias = "np"

    def _module_format(self, fqn, register=True):
        text = NumPyPrinter._module_format(self, fqn, register)
        return f"{self.alias}.{text[len('numpy.'):]}" if text.startswith("numpy.") else text


@register("numpy", "NumPy module: single states (n,) and batches (N, n), NumPy only",
          config=NumPyConfig, order=10, reserved=("np",), printer=NumPyModulePrinter,
          load=python_loader(NumPyConfig.suffix), requires=("numpy",))
def generate_numpy(job: Job, config: NumPyConfig = NumPyConfig()) -> list[GeneratedFile]:
    printer = ArrayModulePrinter({"fully_qualified_modules": True, "standard": "python3"})
    return [GeneratedFile(job.stem + config.suffix, numpy_source(job, printer, config))]


def numpy_source(job: Job, printer, config: NumPyConfig = NumPyConfig()) -> str:
    """The NumPy module's text for ``job`` printed with ``printer`` (also what
    :func:`eomgen.codegen.lambdify` executes): the template, with the Cholesky runtime
    (:mod:`eomgen.runtime.cholesky`) included where forward dynamics needs it; ``xp``, the
    array module's name that the composed functions call (common/composed.py.jinja)."""
    return render(config.template, xp=ArrayModulePrinter.alias,
                  cholesky_runtime=included_source(),
                  task_space_runtime=task_space.included_source(),
                  **python_module_context(job, printer, config.template, warning_exports(job),
                                          backend="numpy"))
