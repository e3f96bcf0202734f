"""What the generated modules compute: function specifications built from derived dynamics.

A :class:`FunctionSpec` names a function, its inputs (joint vectors and the parameters kept
symbolic) and its single output, with the straight-line program that computes it. Every
backend prints the same specs, so every backend exports the same functions: those declared in
:data:`eomgen.outputs.OUTPUTS` (names, inputs, shapes, units, docstring lines). The composed
forward-dynamics function has no spec: each backend builds it from the mass-matrix and
inverse-dynamics functions.

A module may export a subset of these functions (:func:`select_functions`, e.g. from a scene's
``outputs``); only the outputs they need are derived (:func:`derived_outputs`).
"""

from __future__ import annotations

import builtins
import keyword
import re
from dataclasses import dataclass

import sympy as sp

from ..common.output import module_name  # noqa: F401  (re-exported: its earlier home)
from ..outputs import BY_SYMBOL, INPUTS, OUTPUTS, select, splits
from ..symbolic.builders import constants_provider
from ..symbolic.program import Program, count_ops as count_ops_of

# ``dynamics`` arguments are eomgen.dynamics.Dynamics, named in strings only: eomgen.dynamics
# imports eomgen.codegen.lambdify, which prints through this module (no import back up).


@dataclass(frozen=True)
class Argument:
    """An input vector of a generated function: ``name`` and its symbols in order."""

    name: str
    symbols: tuple[sp.Symbol, ...]
    doc: str


@dataclass(frozen=True)
class ParameterArgument:
    """A parameter kept symbolic: a keyword argument with the description's value as default.

    ``keyword`` is what a caller passes: the description's ``name`` itself, unless no keyword
    can be that (see :func:`parameter_arguments`). ``identifier`` names the parameter inside
    the generated bodies, apart from the names they use themselves (``g_`` for ``g``, the
    gravity vector's name); where it differs from the keyword, a function binds it first.
    """

    keyword: str
    identifier: str
    symbol: sp.Symbol
    default: float | None
    doc: str
    name: str = ""

    @property
    def renamed(self) -> bool:
        """Whether the keyword is not the description's name (a Python keyword, ...)."""
        return self.keyword != self.name


@dataclass(frozen=True)
class FunctionSpec:
    name: str
    summary: str
    arguments: tuple[Argument, ...]
    output_name: str
    output: sp.Matrix
    is_vector: bool
    program: Program
    operation_count: int
    units: str
    #: a several-result function (:attr:`eomgen.outputs.Output.returns`): ``(symbol, first
    #: column, end column or None)`` of each result in ``output``; empty otherwise
    returns: tuple[tuple[str, int, int | None], ...] = ()


#: Names no parameter's keyword can take, whatever the backend: the other arguments of the
#: generated functions (their inputs, ``return_condition``, ``damping``, ...), the names their
#: bodies read from the module (its functions, constants and runtime helpers; Python's
#: keywords and builtins), which a keyword argument of that name would hide. With the names
#: each backend's modules import (``register(..., reserved=("np",))``), see
#: :func:`reserved_keywords`.
RESERVED_KEYWORDS = frozenset(
    {"math", *INPUTS, "return_condition", "damping", "linear", "frames", "who",
     "JOINT_NAMES", "CONFIGURATION_NAMES", "NQ", "NV", "PARAMETERS", *OUTPUTS,
     "IllConditionedWarning",
     # the Cholesky runtime NumPy modules include (eomgen.runtime.cholesky)
     "_CONDITION_LIMIT", "_EXACT_FROM", "_condition_estimate", "_condition_number",
     "_ill_conditioned_message", "_cholesky_solve", "_at", "_not_positive_definite"}
) | frozenset(keyword.kwlist) | frozenset(dir(builtins))

#: Identifiers every generated module uses itself, whatever its backend: the reserved keywords
#: and the local names of the functions' bodies (``out``, ``M``, ``g``, ...). A parameter's
#: identifier inside a body avoids them (its keyword need not), and the names each backend's
#: modules import, see :func:`reserved_identifiers`.
RESERVED_IDENTIFIERS = RESERVED_KEYWORDS | frozenset(
    {"out", "single", "batch", "n", *BY_SYMBOL,
     "self", "cls", "L", "x", "y", "d",
     "rhs", "bias", "args", "names", "vectors", "functions", "parameters", "q_columns",
     "qd_columns", "qdd_columns", "k", "finite", "condition",
     "close", "eigenvalues"}) | frozenset(keyword.softkwlist)


def _backends_reserved() -> tuple[tuple[str, ...], ...]:
    # The package's registry: complete only once eomgen.codegen has imported every backend,
    # which happens after this module (imported by eomgen.codegen) is loaded.
    from .registry import available_backends

    return tuple(b.reserved for b in available_backends().values())


def reserved_identifiers() -> frozenset[str]:
    """:data:`RESERVED_IDENTIFIERS` and the names every registered backend reserves: the same
    parameter identifiers in every backend's module."""
    return RESERVED_IDENTIFIERS.union(OUTPUTS, BY_SYMBOL, *_backends_reserved())


def reserved_keywords() -> frozenset[str]:
    """:data:`RESERVED_KEYWORDS` and the names every registered backend's modules import: the
    same parameter keywords in every backend's module."""
    return RESERVED_KEYWORDS.union(OUTPUTS, *_backends_reserved())


_IDENTIFIER = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


def safe_identifier(name: str, taken: set[str], reserved: frozenset[str] | None = None) -> str:
    """A valid, unused Python/C identifier derived from ``name`` (ASCII letters, digits, _),
    none of ``reserved`` (default: :func:`reserved_identifiers`)."""
    if reserved is None:
        reserved = reserved_identifiers()
    candidate = re.sub(r"[^A-Za-z0-9_]", "_", name.encode("ascii", "replace").decode("ascii"))
    if not candidate or not _IDENTIFIER.match(candidate) or candidate.startswith("_"):
        candidate = "p" + candidate if candidate.startswith("_") else "p_" + candidate
    while candidate in taken or candidate in reserved:
        candidate += "_"
    taken.add(candidate)
    return candidate


def parameter_arguments(dynamics: "Dynamics") -> tuple[ParameterArgument, ...]:
    """Keyword arguments for the parameters the model keeps symbolic, sorted by name.

    A parameter's keyword is its name in the description (``g``), unless no keyword can be:
    a name that is not an ASCII identifier, a Python keyword or builtin, or a name the module
    needs (:func:`reserved_keywords`: ``q``, ``np``, ``mass_matrix``, ...) gets a keyword of
    :func:`safe_identifier` (``lambda_``). Its identifier inside the bodies avoids their own
    names as well (:func:`reserved_identifiers`: ``g_`` for ``g``) and every keyword.

    >>> import eomgen
    >>> dynamics = eomgen.derive(eomgen.load(eomgen.example_path("planar_2link")), outputs=["g"])
    >>> [(p.keyword, p.identifier) for p in parameter_arguments(dynamics)][2:4]
    [('g', 'g_'), ('l1', 'l1')]
    """
    declared = sorted(dynamics.parameters, key=lambda p: p.name)
    keywords_taken: set[str] = set()
    reserved = reserved_keywords()
    keywords = [safe_identifier(p.name, keywords_taken, reserved) for p in declared]
    taken = set(keywords)
    reserved = reserved_identifiers()
    out = []
    for p, keyword_ in zip(declared, keywords):
        doc = p.description or "model parameter"
        taken.discard(keyword_)  # its own keyword may be its identifier
        identifier = safe_identifier(p.name, taken, reserved)
        taken.add(keyword_)
        out.append(ParameterArgument(keyword_, identifier, p.symbol, p.value, doc, p.name))
    return tuple(out)



def select_functions(names=None) -> tuple[str, ...]:
    """The functions to generate for the requested ``names``, in module order: see
    :func:`eomgen.outputs.select`.

    >>> from eomgen.outputs import FORWARD
    >>> [OUTPUTS[f].symbol for f in select_functions(["g", FORWARD.function])]
    ['M', 'g', 'tau', None]
    """
    return select(names)


def derived_outputs(functions=None) -> tuple[str, ...]:
    """The outputs :func:`eomgen.derive` must build for ``functions`` (default: those exported
    by default, :func:`eomgen.outputs.function_names`), in registry order.

    >>> derived_outputs(["g"])
    ('g',)
    """
    needed = {o for f in select_functions(functions) for o in OUTPUTS[f].needs}
    return tuple(o for o in BY_SYMBOL if o in needed)


def function_specs(dynamics: "Dynamics", functions=None,
                   count_operations: bool = True) -> tuple[FunctionSpec, ...]:
    """The specs of the printed functions among ``functions`` (default: all; see
    :func:`select_functions`), from dynamics derived with the outputs they need.
    A composed function (forward dynamics) has no spec: backends compose it. Without ``count_operations`` the
    specs' ``operation_count`` is 0 (counting costs as much as printing; files need it for their
    header, in-memory modules do not)."""
    vectors = dynamics.input_symbols
    chosen = select_functions(functions)
    count = shared_operation_count() if count_operations else None
    specs = []
    for name in chosen:
        declared = OUTPUTS[name]
        if declared.composed:
            continue
        output, summary, args = declared.symbol, declared.summary, declared.inputs
        is_vector, units = declared.is_vector, declared.units
        if output not in dynamics.outputs:
            raise ValueError(f"code generation needs '{output}' among the derived outputs")
        program = dynamics.program.pruned([output])
        specs.append(FunctionSpec(
            name=name,
            summary=summary,
            arguments=tuple(Argument(a, vectors[a], INPUTS[a]) for a in args),
            output_name=output,
            output=program.output(output),
            is_vector=is_vector,
            program=program,
            operation_count=count(program) if count_operations else 0,
            units=units,
            returns=splits(declared, dynamics.model.dof),
        ))
    return tuple(specs)


def shared_operation_count():
    """``count(program)``: :meth:`~eomgen.symbolic.program.Program.operation_count` of
    ``program`` (SymPy's ``count_ops`` of its assignments and output entries, summed, as
    :func:`eomgen.symbolic.program.count_ops` counts it), each
    expression *object* counted once over the calls: the pruned programs of one module share
    most of their assignments, and counting costs as much as printing."""
    counted: dict[int, tuple[sp.Expr, int]] = {}

    def count_ops(expr) -> int:
        found = counted.get(id(expr))
        if found is None:
            found = counted[id(expr)] = (expr, count_ops_of(expr))
        return found[1]

    def count(program) -> int:
        total = sum(count_ops(expr) for _, expr in program.assignments)
        for _, matrix in program.outputs:
            total += sum(count_ops(e) for e in matrix)
        return int(total)

    return count


def module_constants(dynamics: "Dynamics", functions) -> tuple[tuple[str, tuple[str, ...]], ...]:
    """The name tuples a module exporting ``functions`` exports besides ``JOINT_NAMES`` (e.g.
    ``PARAMETER_NAMES``, the columns of the regressor): ``((NAME, (str, ...)), ...)`` from the
    outputs' :attr:`~eomgen.outputs.Output.constants`, in module order."""
    found: dict[str, tuple[str, ...]] = {}
    for name in functions:
        declared = OUTPUTS[name]
        if declared.constants:
            for key, values in constants_provider(declared.constants)(dynamics).items():
                found.setdefault(key, tuple(str(v) for v in values))
    return tuple(found.items())
