"""Pieces shared by the Python-source backends (NumPy, CasADi): naming of inputs and printing of
a straight-line program into ``(lhs, rhs)`` pairs for the templates."""

from __future__ import annotations

import importlib.util
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import sympy as sp

from ..job import Job
from ..registry import Loaded
from ...outputs import (CONSTRAINED_DERIVATIVES, CONSTRAINED_FORWARD, CONSTRAINED_PARTIALS,
                       FORWARD, INPUT_SIZES, INPUTS, PARALLEL_INVERSE,
                       TASK_SPACE, composition_names, constrained_names, exported,
                       parallel_names, task_space_names)
from ..functions import FunctionSpec
from ...outputs.catalogue import (FORWARD_DERIVATIVES, FORWARD_HESSIAN, FORWARD_SECOND,
                                  SECOND_DERIVATIVES)
from ...symbolic.printing import renamed


@dataclass(frozen=True)
class PrintedFunction:
    """A function ready for a template: everything is a string or a list of strings."""

    name: str
    summary: str
    arguments: list[tuple[str, str]]      # (name, doc) of the vector inputs
    unpack: list[tuple[str, str, int]]     # (element name, vector name, index)
    assignments: list[tuple[str, str]]     # (lhs, rhs)
    output_name: str
    output_shape: tuple[int, ...]
    output_entries: list[tuple[tuple[int, ...], str]]  # (index, rhs) of non-zero entries
    operation_count: int
    units: str
    releases: list[list[str]]  # names no longer needed after each assignment
    sizes: dict[str, int | str] | None = None  # lengths of inputs not NV long (input_sizes)
    returns: tuple = ()  # (symbol, start, stop or None) of a several-result function


def last_uses(assignments, outputs) -> list[list[str]]:
    """For each assignment, the intermediates whose last use it is (never those the outputs
    use): a backend may free them there (NumPy batches hold one array per intermediate)."""
    kept = set()
    for e in outputs:
        kept |= e.free_symbols
    defined = {symbol for symbol, _ in assignments}
    seen: set = set()
    releases: list[list[str]] = []
    for symbol, expr in reversed(assignments):
        free = [x for x in expr.free_symbols if x in defined and x not in kept and x not in seen]
        seen.update(free)
        releases.append(sorted(x.name for x in free))
    releases.reverse()
    return releases


def input_sizes(arguments, model) -> dict:
    """The lengths of the inputs of :data:`~eomgen.outputs.INPUT_SIZES` among ``arguments``
    that are not NV: a number (e.g. the contact rows of ``F_c``), or ``"NQ"`` for ``q`` when
    the configuration is longer than the velocity (a free flyer)."""
    sizes = {}
    for a in arguments:
        if a.name == "q":
            if model.nq != model.dof:
                sizes["q"] = "NQ"
        elif a.name in INPUT_SIZES:
            sizes[a.name] = len(a.symbols)
    return sizes


class TermOrderShared:
    """A printer mixin (put it first): the order of a sum's terms, which the printer's classes
    after it choose (SymPy's canonical order, then :class:`~eomgen.symbolic.printing.
    FloatLiteralMixin`'s leading plus), remembered for each sum *object* and shared by every
    printer whose ordering is the same function: the NumPy, JAX, PyTorch and CasADi modules of
    one model print the same sums, and SymPy's ordering is a third of printing. The memory is
    emptied past :attr:`KEPT` sums (it keeps the sums it ordered alive)."""

    KEPT = 50_000
    _orders: dict[tuple, tuple[sp.Expr, tuple]] = {}

    def _as_ordered_terms(self, expr, order=None):
        ordering = super()._as_ordered_terms
        key = (id(expr), order or self.order, ordering.__func__)
        found = TermOrderShared._orders.get(key)
        if found is None or found[0] is not expr:
            if len(TermOrderShared._orders) >= self.KEPT:
                TermOrderShared._orders.clear()
            found = TermOrderShared._orders[key] = (expr, tuple(ordering(expr, order=order)))
        return list(found[1])


def printed_once(doprint: Callable[[sp.Expr], str]) -> Callable[[sp.Expr], str]:
    """``doprint`` remembering its text for each expression *object* it printed: the functions
    of a module share most of their intermediates (the pruned programs of M, C, g, ... hold the
    same assignment objects), each printed once. Keyed by identity, not equality, so that the
    text is exactly what ``doprint`` gives that object (the object is kept alive with it)."""
    texts: dict[int, tuple[sp.Expr, str]] = {}

    def once(expr: sp.Expr) -> str:
        found = texts.get(id(expr))
        if found is None:
            found = texts[id(expr)] = (expr, doprint(expr))
        return found[1]

    return once


def print_function(spec: FunctionSpec, job: Job, doprint, element_name) -> PrintedFunction:
    """Print ``spec`` with ``doprint(expr) -> str``; ``element_name(vector, index) -> str`` names
    the scalar unpacked from an input vector."""
    unpack = []
    for argument in spec.arguments:
        for k, symbol in enumerate(argument.symbols):
            unpack.append((symbol.name, argument.name, k))
    used = set()
    for _, expr in spec.program.assignments:
        used |= expr.free_symbols
    for e in spec.output:
        used |= e.free_symbols
    unpack = [u for u in unpack if sp.Symbol(u[0], real=True) in used]
    assignments = [(symbol.name, doprint(expr)) for symbol, expr in spec.program.assignments]
    rows, cols = spec.output.shape
    entries = []
    if spec.is_vector:
        shape: tuple[int, ...] = (rows,)
        for r in range(rows):
            if spec.output[r, 0] != 0:
                entries.append(((r,), doprint(spec.output[r, 0])))
    else:
        shape = (rows, cols)
        for r in range(rows):
            for c in range(cols):
                if spec.output[r, c] != 0:
                    entries.append(((r, c), doprint(spec.output[r, c])))
    return PrintedFunction(
        name=spec.name,
        summary=spec.summary,
        arguments=[(a.name, a.doc) for a in spec.arguments],
        unpack=unpack,
        assignments=assignments,
        output_name=spec.output_name,
        output_shape=shape,
        output_entries=entries,
        operation_count=spec.operation_count,
        units=spec.units,
        releases=last_uses(spec.program.assignments, list(spec.output)),
        sizes=input_sizes(spec.arguments, job.model),
        returns=spec.returns,
    )


def parameter_renames(job: Job) -> dict[sp.Symbol, sp.Symbol]:
    """Parameter symbols → symbols named by their safe Python identifiers."""
    return {p.symbol: sp.Symbol(p.identifier, real=True) for p in job.parameters
            if p.identifier != p.symbol.name}


def parameter_bindings(job: Job) -> list[tuple[str, str]]:
    """``(identifier, keyword)`` of the parameters whose identifier inside the bodies is not
    their keyword (``("g_", "g")``): a function's first lines bind them."""
    return [(p.identifier, p.keyword) for p in job.parameters if p.identifier != p.keyword]


def python_literal(text: str) -> str:
    """A Python string literal for ``text`` that cannot break out of its quotes."""
    return repr(str(text))


def docstring_literal(text: str) -> str:
    """``text`` quoted for the inside of a triple-double-quoted docstring, which then reads as
    :func:`python_literal` of ``text``.

    The literal's backslashes and double quotes are escaped once more, so that no three double
    quotes in a robot's name can end the docstring early (and let the rest of the name run as
    code when the module is imported), and no backslash can start an escape sequence.
    """
    return python_literal(text).replace("\\", "\\\\").replace('"', '\\"')


def dunder_all_lines(names, width: int = 79) -> list[str]:
    """The lines of ``__all__ = [...]`` listing ``names``, filled up to ``width`` characters.

    >>> dunder_all_lines(["NV", "M"])
    ['__all__ = ["NV", "M"]']
    """
    prefix = "__all__ = ["
    items = [f'"{name}"' for name in names]
    lines, current = [], prefix
    for k, item in enumerate(items):
        text = item + ("]" if k == len(items) - 1 else ",")
        if current not in (prefix, " " * len(prefix)) and len(current) + 1 + len(text) > width:
            lines.append(current)
            current = " " * len(prefix)
        current += ("" if current in (prefix, " " * len(prefix)) else " ") + text
    lines.append(current if items else prefix + "]")
    return lines


def parallel_indices(model) -> dict[str, list[int]]:
    """``actuated_indices`` and ``passive_indices``: the joints (``JOINT_NAMES`` positions)
    the scene's ``actuated:`` drives (all when it names none) and the others, for
    ``parallel_inverse_dynamics``."""
    names = model.joint_names
    actuated = [names.index(j) for j in (model.actuated or names)]
    return {"actuated_indices": actuated,
            "passive_indices": [k for k in range(len(names)) if k not in actuated]}


def warning_exports(job: Job) -> list[str]:
    """``["IllConditionedWarning"]`` when the module composes forward dynamics (whose Cholesky
    solve warns of an ill-conditioned M, in the NumPy, PyTorch and fast modules), else ``[]``."""
    return ["IllConditionedWarning"] if FORWARD.function in job.functions else []


def python_module_context(job: Job, printer, template: str, extra_exports=(),
                          backend: str | None = None) -> dict:
    """What the Python-source templates (NumPy, CasADi) receive: the printed functions and the
    escaped module metadata. ``printer`` prints one SymPy expression (``printer.doprint``);
    ``backend`` names the backend, whose module leaves out the composed functions it does not
    compose (:func:`eomgen.outputs.exported`)."""
    functions = exported(job.functions, backend) if backend else job.functions
    renames = parameter_renames(job)

    def text(expr: sp.Expr) -> str:
        return printer.doprint(renamed(expr, renames))

    doprint = printed_once(text)

    return dict(
        header=job.header_lines(template),
        robot=docstring_literal(job.model.name),
        joint_names=[python_literal(n) for n in job.dynamics.joint_names],
        nq=job.model.nq,
        nv=job.model.dof,
        configuration_names=[python_literal(n) for n in job.model.configuration_names],
        # (keyword, identifier inside the bodies, default, doc); the identifiers a function
        # binds from the keywords first; the description's names that are not the keywords
        parameters=[(p.keyword, p.identifier,
                     repr(float(p.default)) if p.default is not None else None,
                     python_literal(p.doc)) for p in job.parameters],
        bindings=parameter_bindings(job),
        renamed=[(python_literal(p.name), python_literal(p.keyword)) for p in job.parameters
                 if p.renamed],
        functions=[print_function(spec, job, doprint, None) for spec in job.specs],
        constants=[(name, [python_literal(v) for v in values]) for name, values in job.constants],
        # q, qd, qdd and tau (forward dynamics takes tau), then any other input a function takes
        vector_inputs=[name for name in INPUTS if name in ("q", "qd", "qdd", "tau") or any(
            name == a.name for spec in job.specs for a in spec.arguments)],
        input_sizes={name: "NQ" if name == "q" else len(job.dynamics.input_symbols[name])
                     for name in INPUT_SIZES if name in job.dynamics.input_symbols},
        dunder_all=dunder_all_lines(["JOINT_NAMES", "CONFIGURATION_NAMES", "NQ", "NV", "PARAMETERS",
                                     *(name for name, _ in job.constants), *functions,
                                     *extra_exports]),
        exports=list(functions),
        forward_dynamics=FORWARD.function in job.functions,
        fd=composition_names(FORWARD),
        constrained_forward_dynamics=CONSTRAINED_FORWARD.function in functions,
        cfd=constrained_names(),
        # issue 25: its derivatives, composed from it and the KKT partials
        constrained_derivatives=CONSTRAINED_DERIVATIVES.function in functions,
        cfdd={"name": CONSTRAINED_DERIVATIVES.function, "partials": CONSTRAINED_PARTIALS.function},
        parallel_inverse=PARALLEL_INVERSE.function in functions,
        # issue 42: the second derivatives of the forward dynamics, composed from those of tau
        forward_second=FORWARD_SECOND.function in functions,
        forward_hessian=FORWARD_HESSIAN.function in functions,
        fs={"second": FORWARD_SECOND.function, "hessian": FORWARD_HESSIAN.function,
            "derivatives": FORWARD_DERIVATIVES.function, "tensors": SECOND_DERIVATIVES.function},
        pid=parallel_names(),
        **parallel_indices(job.model),
        # the task-space functions (composed from M, J_f, J_f-dot qd and tau) it exports
        task_space=any(o.function in functions for o in TASK_SPACE),
        ts=task_space_names(),
    )


def import_file(path: Path, name: str) -> dict:
    """The namespace of the Python module or extension at ``path``, imported as ``name`` (not
    put in ``sys.modules``): what a backend's ``load`` gives."""
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return vars(module)


def positional(namespace: dict) -> Loaded:
    """``namespace`` as a :class:`~eomgen.codegen.Loaded` whose functions take the input
    vectors positionally and the parameters by keyword (NumPy, JAX, PyTorch, fast)."""
    return Loaded(namespace, lambda function, *inputs, **parameters:
                  namespace[function](*inputs, **parameters))


def python_loader(suffix: str, before: Callable[[], None] | None = None):
    """A backend's ``load`` for a generated Python module ``<stem><suffix>`` whose functions
    take the input vectors positionally (NumPy, JAX, PyTorch). ``before`` runs first (JAX:
    float64)."""

    def load(folder: Path, stem: str) -> Loaded:
        if before is not None:
            before()
        return positional(import_file(folder / (stem + suffix),
                                      f"{stem}{suffix[:-3]}_{abs(hash(str(folder)))}"))

    return load
