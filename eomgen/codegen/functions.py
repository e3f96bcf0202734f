"""What the generated modules compute: function specifications built from derived dynamics.

A :class:`FunctionSpec` names a function, its inputs (joint vectors and the parameters kept
symbolic) and its single output, with the straight-line program that computes it. Every
backend prints the same specs, so every backend exports the same functions:

==================  ===================  ============================================
function            output               inputs
==================  ===================  ============================================
mass_matrix         M (n×n)              q
coriolis_matrix     C (n×n)              q, qd
gravity_vector      g (n,)               q
inverse_dynamics    tau (n,)             q, qd, qdd
==================  ===================  ============================================

``forward_dynamics(q, qd, tau)`` is composed by each backend from ``mass_matrix`` and
``inverse_dynamics`` (a Cholesky solve of M q̈ = τ − (C q̇ + g)).

A module may export a subset of these functions (:func:`select_functions`, e.g. from a scene's
``outputs``); only the outputs they need are derived (:func:`derived_outputs`).
"""

from __future__ import annotations

import builtins
import difflib
import keyword
import re
from dataclasses import dataclass

import sympy as sp

from ..dynamics import Dynamics
from ..symbolic.program import Program


@dataclass(frozen=True)
class Argument:
    """An input vector of a generated function: ``name`` and its symbols in order."""

    name: str
    symbols: tuple[sp.Symbol, ...]
    doc: str


@dataclass(frozen=True)
class ParameterArgument:
    """A parameter kept symbolic: a keyword argument with the description's value as default."""

    identifier: str
    symbol: sp.Symbol
    default: float | None
    doc: str


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


#: Identifiers every generated module uses itself; parameters and intermediates avoid them.
RESERVED_IDENTIFIERS = frozenset(
    {"np", "ca", "casadi", "math", "jnp", "jax", "torch", "q", "qd", "qdd", "tau", "out",
     "single", "batch", "n",
     "JOINT_NAMES", "NQ", "PARAMETERS", "mass_matrix", "coriolis_matrix", "gravity_vector",
     "inverse_dynamics", "forward_dynamics", "self", "cls", "M", "C", "g", "L", "x", "y", "d",
     "rhs", "bias", "args", "names", "vectors", "functions", "parameters", "q_columns",
     "qd_columns", "qdd_columns", "k", "finite", "condition", "return_condition",
     "close", "eigenvalues", "IllConditionedWarning"}
) | frozenset(keyword.kwlist) | frozenset(keyword.softkwlist) | frozenset(dir(builtins))

_IDENTIFIER = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


def safe_identifier(name: str, taken: set[str]) -> str:
    """A valid, unused Python/C identifier derived from ``name`` (ASCII letters, digits, _)."""
    candidate = re.sub(r"[^A-Za-z0-9_]", "_", name.encode("ascii", "replace").decode("ascii"))
    if not candidate or not _IDENTIFIER.match(candidate) or candidate.startswith("_"):
        candidate = "p" + candidate if candidate.startswith("_") else "p_" + candidate
    while candidate in taken or candidate in RESERVED_IDENTIFIERS:
        candidate += "_"
    taken.add(candidate)
    return candidate


def module_name(robot_name: str) -> str:
    """The file-name stem for a robot: a lower-case identifier."""
    stem = re.sub(r"[^a-z0-9_]", "_", robot_name.lower().encode("ascii", "replace").decode("ascii"))
    stem = stem.strip("_") or "robot"
    return stem if stem[0].isalpha() else "robot_" + stem


def parameter_arguments(dynamics: Dynamics) -> tuple[ParameterArgument, ...]:
    """Keyword arguments for the parameters the model keeps symbolic, sorted by name."""
    taken: set[str] = set()
    out = []
    for p in sorted(dynamics.parameters, key=lambda p: p.name):
        doc = p.description or "model parameter"
        out.append(ParameterArgument(safe_identifier(p.name, taken), p.symbol, p.value, doc))
    return tuple(out)


_SPECS = (
    ("mass_matrix", "M", "Mass matrix M(q), symmetric positive definite.", ("q",), False,
     "kg m^2 (revolute rows/columns), kg (prismatic)"),
    ("coriolis_matrix", "C", "Coriolis matrix C(q, qd) from the Christoffel symbols of the first "
     "kind, so that Mdot - 2 C is skew-symmetric.", ("q", "qd"), False, "kg m^2/s (revolute)"),
    ("gravity_vector", "g", "Gravity vector g(q) = dP/dq.", ("q",), True,
     "N m (revolute), N (prismatic)"),
    ("inverse_dynamics", "tau", "Joint efforts tau = M(q) qdd + C(q, qd) qd + g(q) "
     "(recursive Newton-Euler, straight-line).", ("q", "qd", "qdd"), True,
     "N m (revolute), N (prismatic)"),
)

_ARG_DOCS = {
    "q": "joint positions [rad or m]",
    "qd": "joint velocities [rad/s or m/s]",
    "qdd": "joint accelerations [rad/s^2 or m/s^2]",
}


#: Every function a generated module can export, in module order, with the derived outputs
#: (see :data:`eomgen.dynamics.ALL_OUTPUTS`) it needs.
FUNCTION_OUTPUTS: dict[str, tuple[str, ...]] = {
    "mass_matrix": ("M",),
    "coriolis_matrix": ("C",),
    "gravity_vector": ("g",),
    "inverse_dynamics": ("tau",),
    "forward_dynamics": ("M", "tau"),
}
FUNCTION_NAMES: tuple[str, ...] = tuple(FUNCTION_OUTPUTS)

#: Functions a function is composed from, and so generated with it.
FUNCTION_REQUIRES: dict[str, tuple[str, ...]] = {
    "forward_dynamics": ("mass_matrix", "inverse_dynamics"),
}

#: Short names accepted for functions: the symbol of what they return.
FUNCTION_ALIASES: dict[str, str] = {
    "M": "mass_matrix", "C": "coriolis_matrix", "g": "gravity_vector", "tau": "inverse_dynamics",
}


def select_functions(names=None) -> tuple[str, ...]:
    """The functions to generate for the requested ``names``, in module order.

    Parameters
    ----------
    names:
        Function names (``mass_matrix`` …) or their short names (``M``, ``C``, ``g``, ``tau``);
        ``None`` for all of :data:`FUNCTION_NAMES`. A function composed from others brings them
        along (``forward_dynamics`` needs ``mass_matrix`` and ``inverse_dynamics``).

    Raises
    ------
    ValueError
        For an unknown name, or no name at all.

    Examples
    --------
    >>> select_functions(["g", "forward_dynamics"])
    ('mass_matrix', 'gravity_vector', 'inverse_dynamics', 'forward_dynamics')
    """
    if names is None:
        return FUNCTION_NAMES
    wanted: set[str] = set()
    for name in names:
        function = FUNCTION_ALIASES.get(name, name)
        if function not in FUNCTION_OUTPUTS:
            known = list(FUNCTION_ALIASES) + list(FUNCTION_NAMES)
            hint = difflib.get_close_matches(str(name), known, n=1)
            raise ValueError(f"unknown output {name!r} (known: {', '.join(known)})"
                             + (f"; did you mean '{hint[0]}'?" if hint else ""))
        wanted.add(function)
        wanted.update(FUNCTION_REQUIRES.get(function, ()))
    if not wanted:
        raise ValueError("no output asked for")
    return tuple(f for f in FUNCTION_NAMES if f in wanted)


def derived_outputs(functions=None) -> tuple[str, ...]:
    """The outputs :func:`eomgen.derive` must build for ``functions`` (default: all), in
    ``ALL_OUTPUTS`` order.

    >>> derived_outputs(["gravity_vector"])
    ('g',)
    """
    from ..dynamics import ALL_OUTPUTS

    needed = {o for f in select_functions(functions) for o in FUNCTION_OUTPUTS[f]}
    return tuple(o for o in ALL_OUTPUTS if o in needed)


def function_specs(dynamics: Dynamics, functions=None,
                   count_operations: bool = True) -> tuple[FunctionSpec, ...]:
    """The specs of the printed functions among ``functions`` (default: all; see
    :func:`select_functions`), from dynamics derived with the outputs they need.
    ``forward_dynamics`` has no spec: backends compose it. Without ``count_operations`` the
    specs' ``operation_count`` is 0 (counting costs as much as printing; files need it for their
    header, in-memory modules do not)."""
    vectors = {"q": dynamics.q, "qd": dynamics.qd, "qdd": dynamics.qdd}
    chosen = select_functions(functions)
    specs = []
    for name, output, summary, args, is_vector, units in _SPECS:
        if name not in chosen:
            continue
        if output not in dynamics.outputs:
            raise ValueError(f"code generation needs '{output}' among the derived outputs")
        program = dynamics.program.pruned([output])
        specs.append(FunctionSpec(
            name=name,
            summary=summary,
            arguments=tuple(Argument(a, vectors[a], _ARG_DOCS[a]) for a in args),
            output_name=output,
            output=program.output(output),
            is_vector=is_vector,
            program=program,
            operation_count=program.operation_count() if count_operations else 0,
            units=units,
        ))
    return tuple(specs)
