"""NumPy backend: ``<robot>_numpy.py``, straight-line, vectorised over a batch of states.

Printer: SymPy's :class:`~sympy.printing.numpy.NumPyPrinter` with the module aliased as ``np``
and floats printed with all 17 significant digits. Template: ``templates/numpy/module.py.jinja``.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp
from sympy.printing.numpy import NumPyPrinter

from .. import GeneratedFile, Job, register
from ..render import render
from .common import (docstring_literal, dunder_all_lines, parameter_renames, print_function,
                     python_literal)


class NumPyModulePrinter(NumPyPrinter):
    """NumPy code with ``np.`` as the module prefix and exact float literals."""

    def _module_format(self, fqn, register=True):
        text = super()._module_format(fqn, register)
        return "np." + text[len("numpy."):] if text.startswith("numpy.") else text

    def _print_Float(self, expr):
        return repr(float(expr))

    def _print_Rational(self, expr):
        return f"({int(expr.p)}/{int(expr.q)})"


@dataclass(frozen=True)
class NumPyConfig:
    """Options of the NumPy backend."""

    template: str = "numpy/module.py.jinja"
    suffix: str = "_numpy.py"


@register("numpy", "NumPy module: single states (n,) and batches (N, n), NumPy only")
def generate_numpy(job: Job, config: NumPyConfig = NumPyConfig()) -> list[GeneratedFile]:
    printer = NumPyModulePrinter({"fully_qualified_modules": True, "standard": "python3"})
    renames = parameter_renames(job)

    def doprint(expr: sp.Expr) -> str:
        return printer.doprint(expr.xreplace(renames) if renames else expr)

    functions = [print_function(spec, job, doprint, None) for spec in job.specs]
    text = render(
        config.template,
        header=job.header_lines(config.template),
        robot=docstring_literal(job.model.name),
        joint_names=[python_literal(n) for n in job.dynamics.joint_names],
        nq=job.model.dof,
        parameters=[(p.identifier, repr(float(p.default)) if p.default is not None else None,
                     python_literal(p.doc)) for p in job.parameters],
        functions=functions,
        dunder_all=dunder_all_lines(["JOINT_NAMES", "NQ", "PARAMETERS", *job.functions]
                                    + (["IllConditionedWarning"]
                                       if "forward_dynamics" in job.functions else [])),
        exports=list(job.functions),
        forward_dynamics="forward_dynamics" in job.functions,
    )
    return [GeneratedFile(job.stem + config.suffix, text)]
