"""JAX backend: ``<robot>_jax.py``, pure functions for ``jax.jit``, ``jax.vmap`` and ``jax.grad``.

Printer: the NumPy backend's printer with ``jnp.`` (``jax.numpy``) as the module prefix, so the
arithmetic is printed exactly as in the NumPy module. Template: ``templates/jax/module.py.jinja``.
The generated module imports only ``jax``; generating it does not.

How a function assembles its output changes XLA's CPU speed several-fold
(benchmarks/backend_speed.py, Panda, jaxlib 0.10):

* a matrix (M, C) is one ``jnp.stack`` of all its entries, row by row. XLA builds one loop per
  distinct entry (28 for the Panda's M) and concatenates them; with one ``.at[i, j].set`` per
  entry it built 49 in-place updates, and M took 1.75 times as long. Either way each loop
  recomputes the intermediates its entry needs, which keeps M several times slower than NumPy;
* a vector (tau, g) is one ``.at[i].set`` per entry: stacked, XLA fused the whole program into
  one concatenation whose CPU code recomputed the shared intermediates for every entry, 40-90
  times slower than the updates;
* each named sine and cosine is ``_kept(jnp.sin(x), x)``, i.e. divided by ``1 + 0·x``: exactly
  1, so the value is the same bit for bit. XLA's instruction fusion counts ``sin`` and ``cos``
  as cheap and copies them into every loop that uses them (for the Panda's M, all 14 into most
  of its 28 output loops); it counts a division as costly and computes it once, so each sine
  and cosine is computed once. ``1 + 0·x`` is not folded to 1 (``0·x`` is NaN for x = ±inf).
  With it, ``jax.jit(jax.vmap(f))`` on 10,000 Panda states took 0.3-0.75 times NumPy's time
  per state for τ and M (benchmarks/backend_speed.py, six runs) and 0.4 and 0.7 times for C and
  g (one run), against 0.9-5 times without.
"""

from __future__ import annotations

import ast
from dataclasses import dataclass, replace

from ...common.output import GeneratedFile
from ..job import Job
from ..registry import register
from ...common.templating import render
from .common import PrintedFunction, python_loader, python_module_context
from .numpy_backend import ArrayModulePrinter


class JaxModulePrinter(ArrayModulePrinter):
    """``jax.numpy`` code, the module aliased as ``jnp``."""

    alias = "jnp"


@dataclass(frozen=True)
class JaxConfig:
    """Options of the JAX backend."""

    template: str = "jax/module.py.jinja"
    suffix: str = "_jax.py"


def _float64() -> None:
    """JAX in float64, as the tests compare the module with NumPy to 1e-12 (a process-wide
    setting of JAX's)."""
    import jax  # optional dependency (eomgen[jax]): only loading a generated module needs it

    jax.config.update("jax_enable_x64", True)


@register("jax", "JAX module: pure functions for jax.jit, jax.vmap and jax.grad (needs jax)",
          config=JaxConfig, order=60, reserved=("jnp", "jax"), printer=JaxModulePrinter,
          load=python_loader(JaxConfig.suffix, before=_float64), requires=("jax",))
def generate_jax(job: Job, config: JaxConfig = JaxConfig()) -> list[GeneratedFile]:
    printer = JaxModulePrinter({"fully_qualified_modules": True, "standard": "python3"})
    context = python_module_context(job, printer, config.template, backend="jax")
    context["functions"] = [replace(f, assignments=kept_trigonometry(f.assignments))
                            for f in context["functions"]]
    context["kept"] = any("_kept(" in rhs for f in context["functions"]
                          for _, rhs in f.assignments)
    context["stacked"] = {f.name: stacked_rows(f) for f in context["functions"]
                          if len(f.output_shape) == 2}
    text = render(config.template, xp=printer.alias, **context)
    return [GeneratedFile(job.stem + config.suffix, text)]


def stacked_rows(f: PrintedFunction) -> list[list[str]]:
    """The rows of the matrix output of ``f``, structural zeros as ``0.0``: the entries the
    generated ``_stack`` receives, in row-major order."""
    rows, cols = f.output_shape
    entries = dict(f.output_entries)
    return [[entries.get((r, c), "0.0") for c in range(cols)] for r in range(rows)]


def kept_trigonometry(assignments: list[tuple[str, str]]) -> list[tuple[str, str]]:
    """``(lhs, rhs)`` pairs with each ``rhs`` that is one ``jnp.sin(x)`` or ``jnp.cos(x)``
    written ``_kept(jnp.sin(x), x)`` (see the module docstring)."""
    out = []
    for lhs, rhs in assignments:
        call = ast.parse(rhs, mode="eval").body
        if (isinstance(call, ast.Call) and ast.unparse(call.func) in ("jnp.sin", "jnp.cos")
                and len(call.args) == 1 and not call.keywords):
            rhs = f"_kept({rhs}, {ast.unparse(call.args[0])})"
        out.append((lhs, rhs))
    return out
