"""JAX backend: ``<robot>_jax.py``, pure functions for ``jax.jit``, ``jax.vmap`` and ``jax.grad``.

Printer: the NumPy backend's printer with ``jnp.`` (``jax.numpy``) as the module prefix, so the
arithmetic is printed exactly as in the NumPy module. Template: ``templates/jax/module.py.jinja``.
The generated module imports only ``jax``; generating it does not.
"""

from __future__ import annotations

from dataclasses import dataclass

from sympy.printing.numpy import NumPyPrinter

from .. import GeneratedFile, Job, register
from ..render import render
from .common import python_module_context
from .numpy_backend import NumPyModulePrinter


class ArrayModulePrinter(NumPyModulePrinter):
    """NumPy-style code whose ``numpy.<name>`` calls go to another array module, ``alias``
    (``jnp`` for ``jax.numpy``, ``torch``): the same expressions, the same float literals."""

    alias = "np"

    def _module_format(self, fqn, register=True):
        text = NumPyPrinter._module_format(self, fqn, register)
        return f"{self.alias}.{text[len('numpy.'):]}" if text.startswith("numpy.") else text


class JaxModulePrinter(ArrayModulePrinter):
    """``jax.numpy`` code, the module aliased as ``jnp``."""

    alias = "jnp"


@dataclass(frozen=True)
class JaxConfig:
    """Options of the JAX backend."""

    template: str = "jax/module.py.jinja"
    suffix: str = "_jax.py"


@register("jax", "JAX module: pure functions for jax.jit, jax.vmap and jax.grad (needs jax)",
          config=JaxConfig, order=60, reserved=("jnp", "jax"))
def generate_jax(job: Job, config: JaxConfig = JaxConfig()) -> list[GeneratedFile]:
    printer = JaxModulePrinter({"fully_qualified_modules": True, "standard": "python3"})
    text = render(config.template, **python_module_context(job, printer, config.template, backend="jax"))
    return [GeneratedFile(job.stem + config.suffix, text)]
