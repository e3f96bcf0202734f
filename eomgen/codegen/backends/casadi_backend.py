"""CasADi backend: ``<robot>_casadi.py`` building ``casadi.Function`` objects (SX), and the C
backend: C source from CasADi's code generator plus, where a C compiler is found, a shared library
that ``casadi.external`` loads.

Printer: SymPy's Python printer with CasADi's math functions (``ca.sin`` …). Templates:
``templates/casadi/module.py.jinja``.
"""

from __future__ import annotations

import os
import re
import tempfile
import warnings
from dataclasses import dataclass
from pathlib import Path

from sympy.printing.pycode import PythonCodePrinter

from ...outputs import exported, function_names
from ...outputs.catalogue import (FORWARD, FORWARD_DERIVATIVES, FORWARD_SECOND, INVERSE,
                                  INVERSE_DERIVATIVES, MASS)
from ...common.compiler import c_compiler, shared_library
from ...common.output import GeneratedFile
from ..job import Job
from ..registry import Loaded, register
from ...symbolic.printing import FloatLiteralMixin, exec_source
from ...common.templating import render
from .common import TermOrderShared, python_module_context

_FUNCTIONS = ("sin", "cos", "tan", "sqrt", "exp", "log", "asin", "acos", "atan", "atan2",
              "tanh", "sign")


class CasADiPrinter(TermOrderShared, FloatLiteralMixin, PythonCodePrinter):
    """Python code over CasADi SX symbols: ``ca.sin(x)``, exact float literals."""

    def _print_Function(self, expr):
        name = expr.func.__name__
        if name in _FUNCTIONS:
            return f"ca.{name}(" + ", ".join(self._print(a) for a in expr.args) + ")"
        raise ValueError(f"the CasADi backend cannot print function {name}")

    # sign: Coulomb friction (regressor columns, drive friction); PythonCodePrinter would print
    # math.copysign, which fails on CasADi symbols (and math.atan etc.: a ball joint's spring)
    _print_sin = _print_cos = _print_tan = _print_tanh = _print_sign = _print_Function
    _print_atan = _print_atan2 = _print_asin = _print_acos = _print_Function
    _print_exp = _print_log = _print_Function

    def _print_Pow(self, expr, rational=False):
        # x**(1/2) and x**(-1/2) through ca.sqrt (PythonCodePrinter's math.sqrt fails on
        # CasADi symbols, and the module imports no math)
        return self._hprint_Pow(expr, rational=rational, sqrt="ca.sqrt")

    def _print_Pi(self, expr):
        return "ca.pi"


@dataclass(frozen=True)
class CasADiConfig:
    template: str = "casadi/module.py.jinja"
    suffix: str = "_casadi.py"


#: The functions whose Jacobian (in CasADi's MX graphs, and ``jac_<name>`` of the C library)
#: is eomgen's derivative programs: {function: the functions whose results are its Jacobian's
#: blocks for its vector inputs, in input order}. tau(q, qd, qdd) has dtau/dqdd = M.
JACOBIAN_SOURCES: dict[str, tuple[str, ...]] = {
    FORWARD.function: (FORWARD_DERIVATIVES.function,),
    INVERSE.function: (INVERSE_DERIVATIVES.function, MASS.function),
}


#: The functions whose Jacobian's Jacobian (second order: IPOPT's exact Hessian through
#: ``casadi.Opti``) is eomgen's too: {function: the function giving the tensor of its second
#: derivatives over its vector inputs stacked, (n, (sum of their sizes)^2)}.
SECOND_SOURCES: dict[str, str] = {FORWARD.function: FORWARD_SECOND.function}


def jacobians(job: Job) -> list[tuple[str, tuple[str, ...], str | None]]:
    """The (function, sources, second) of :data:`JACOBIAN_SOURCES` a job's CasADi module
    builds: the function and all its sources exported, and no quaternion joint (whose
    derivatives are along the tangent, nv columns, not the NQ entries of q); ``second``, the
    function of :data:`SECOND_SOURCES` giving its second derivatives where it is exported,
    else None."""
    if job.model.nq != job.model.dof:
        return []
    functions = exported(job.functions, "casadi")
    return [(name, sources, SECOND_SOURCES.get(name) if SECOND_SOURCES.get(name) in functions
             else None)
            for name, sources in JACOBIAN_SOURCES.items()
            if name in functions and all(s in functions for s in sources)]


def _render_module(job: Job, config: CasADiConfig) -> str:
    printer = CasADiPrinter({"standard": "python3"})
    # Parameters without a value have no default: the module refuses calls that leave them out.
    required = [p.keyword for p in job.parameters if p.default is None]
    return render(config.template, required=required, jacobians=jacobians(job),
                  **python_module_context(job, printer, config.template, backend="casadi"))


def load_casadi(folder: Path, stem: str) -> Loaded:
    """The CasADi module written into ``folder``; a function is called by name (a parameter
    left out takes the description's value) and gives its output as a NumPy array (a vector
    output flattened, as the other backends give it)."""
    # start-up time: only loading a generated CasADi module needs NumPy and the registry
    import numpy as np

    from ...outputs import OUTPUTS

    path = folder / (stem + CasADiConfig.suffix)
    namespace = load_module_source(path.read_text(encoding="utf-8"),
                                   f"{stem}_ca_{abs(hash(str(folder)))}")

    def call(function, *inputs, **parameters):
        declared = OUTPUTS[function]
        result = namespace[function].call({**dict(zip(declared.inputs, inputs)), **parameters})
        out = np.array(result[declared.symbol] if declared.symbol in result
                       else next(iter(result.values())), dtype=float)
        return out.ravel() if declared.is_vector else out

    return Loaded(namespace, call)


@register("casadi", "CasADi module: casadi.Function objects (SX) with named inputs and outputs",
          config=CasADiConfig, order=20, reserved=("ca", "casadi"), printer=CasADiPrinter,
          load=load_casadi, requires=("casadi",))
def generate_casadi(job: Job, config: CasADiConfig = CasADiConfig()) -> list[GeneratedFile]:
    return [GeneratedFile(job.stem + config.suffix, _render_module(job, config))]


def load_module_source(source: str, name: str) -> dict:
    """Execute a generated CasADi module's source in a fresh namespace (our own printed code)."""
    return exec_source(source, f"<{name}>", {"__name__": name})


FUNCTION_NAMES = function_names(default_only=True)  # exported unless a job asks for others


class NoCompilerWarning(UserWarning):
    """The C backend found no C compiler: it wrote the C source and header, not the ``.so``."""


#: What the C files say, below their header, about the parameter inputs.
_C_PARAMETER_NOTE = [
    "Inputs: the vectors (q, qd, qdd or tau), then the parameters kept symbolic, sorted by name.",
    "casadi.external gives a parameter left out of a call by name <function>_default_in(i), the",
    "description's value (NaN where it has none); a direct C call reads a NULL input as zeros.",
]


def emit_c(job: Job, config: CasADiConfig = CasADiConfig()) -> list[GeneratedFile]:
    """The C source and header CasADi's code generator writes for the CasADi module's
    functions, each opening with the eomgen header (nothing compiled)."""
    import casadi as ca  # start-up time: CasADi takes a while to import; only loading needs it

    namespace = load_module_source(_render_module(job, config), job.stem + "_casadi")
    stem = job.stem + "_casadi"
    # The generator's name prefixes every C symbol; CasADi refuses names holding "__" (a robot
    # named "arm  2" has the stem "arm__2"), so the prefix has runs of "_" merged. File names
    # keep the stem.
    prefix = re.sub(r"__+", "_", stem)
    generator = ca.CodeGenerator(prefix + ".c", {"with_header": True, "with_mem": False})
    jacobians_of = namespace.get("_JACOBIANS", {})
    for name in exported(job.functions, "c"):
        generator.add(namespace[name])
        if name in jacobians_of:  # casadi.external(name, library) finds jac_<name>
            generator.add(jacobians_of[name])
            if "jac_" + name in jacobians_of:  # and, for the exact Hessian, jac_jac_<name>
                generator.add(jacobians_of["jac_" + name])
    with tempfile.TemporaryDirectory() as tmp:
        generator.generate(tmp + os.sep)
        c_source = Path(tmp, prefix + ".c").read_text()
        h_source = Path(tmp, prefix + ".h").read_text()
    lines = job.header_lines("CasADi CodeGenerator via casadi/module.py.jinja")
    if job.parameters:
        lines += _C_PARAMETER_NOTE
    header = "".join(f"/* {line.replace('*/', '* /')} */\n" for line in lines)
    return [GeneratedFile(stem + ".c", header + c_source),
            GeneratedFile(stem + ".h", header + h_source)]


def library_name(stem: str) -> str:
    """The file name of the C backend's shared library for modules named ``stem``:
    ``lib<stem>_casadi.so``, which ``casadi.external(function, path)`` loads. Not
    ``<stem>_casadi.so``: Python's import system finds a ``.so`` before a ``.py`` file of the
    same name, so that name would hide the CasADi module ``<stem>_casadi.py`` from ``import``.

    >>> library_name("planar_2link")
    'libplanar_2link_casadi.so'
    """
    return f"lib{stem}_casadi.so"


def build_c(job: Job, emitted: list[GeneratedFile], config: CasADiConfig = CasADiConfig()
            ) -> list[GeneratedFile]:
    """The shared library :func:`library_name` compiled from the emitted C source
    (``casadi.external`` loads it), or nothing, with a :class:`NoCompilerWarning`, when no C
    compiler is found."""
    stem = job.stem + "_casadi"
    (source,) = [f.content for f in emitted if f.name == stem + ".c"]
    compiler = c_compiler()
    if compiler is None:
        warnings.warn(f"no C compiler found ($CC, cc, gcc, clang): wrote {stem}.c/.h "
                      f"without {library_name(job.stem)}", NoCompilerWarning,
                      stacklevel=3)
        return []
    return [GeneratedFile(library_name(job.stem),
                          shared_library(compiler, source, stem, ("-O3", "-fPIC", "-shared"),
                                         message_limit=500), golden=False)]


@register("c", "C source through CasADi's code generator, and a shared library when a C compiler is found",
          config=CasADiConfig, order=30, emit=emit_c, build=build_c)
def generate_c(job: Job, config: CasADiConfig = CasADiConfig()) -> list[GeneratedFile]:
    emitted = emit_c(job, config)
    return emitted + build_c(job, emitted, config)
