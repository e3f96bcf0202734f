"""The outputs eomgen derives and every generated module exports, declared once.

Each :class:`Output` says what a function of a generated module computes: its name in the
module (``function``), the symbol of the derived quantity it returns (``symbol``, also accepted
as a short name), its inputs, shape, units and docstring line, and what it needs derived.
:func:`eomgen.derive`, the code generation backends, the templates (through the context the
backends give them), verification, LaTeX and bench read this registry; no other module spells a
function name. The printed outputs, in module order:

==================  ======  ===================  ============================================
function            symbol  inputs               shape
==================  ======  ===================  ============================================
mass_matrix         M       q                    (n, n)
coriolis_matrix     C       q, qd                (n, n)
gravity_vector      g       q                    (n,)
inverse_dynamics    tau     q, qd, qdd           (n,)
==================  ======  ===================  ============================================

``forward_dynamics(q, qd, tau)`` is *composed*: it has no symbol of its own and no printed
body; each backend's template builds it from the mass-matrix and inverse-dynamics functions (a
Cholesky solve of ``M q̈ = τ − (C q̇ + g)``), whose names it receives from :data:`FORWARD`.

Further outputs are derived and exported only when asked for (``default=False``: ``eomgen
generate --outputs Y`` or a scene's ``outputs``), so that existing modules stay as they were.

The outputs are declared as data in :mod:`eomgen.outputs.catalogue` (re-exported here, the public
name); this module indexes them (:data:`OUTPUTS`, :data:`BY_SYMBOL`) and answers what is asked
of them. It names no function that builds an output and imports nothing of eomgen but the
catalogue, so every layer may read it (docs/architecture.md: layer 0). Adding an output is one
entry in the catalogue and, in the module that builds its symbol, a builder registered with
:func:`@builds(symbol) <eomgen.symbolic.builders.builds>`: :func:`eomgen.derive` finds it by
symbol, the backends print what it returns.
"""

from __future__ import annotations

import difflib

# The catalogue's data, re-exported under the public name (docs, backends, tests use it).
from . import catalogue
from .catalogue import (CATALOGUE, CONSTRAINED_DERIVATIVES, CONSTRAINED_FORWARD,  # noqa: F401
                        CONSTRAINED_PARTIALS, CORIOLIS, DYNAMICALLY_CONSISTENT_INVERSE, DYNAMICS,
                        FORWARD, FRAME_JACOBIANS, FRAME_JACOBIANS_DOT_QD, GRAVITY, INVERSE, MASS,
                        MASS_AND_BIAS, OPERATIONAL_SPACE_BIAS, OPERATIONAL_SPACE_INERTIA,
                        PARALLEL_INVERSE, TASK_SPACE, Output)

#: The vector inputs a generated function may take, by name, with their docstring line
#: (:data:`eomgen.outputs.catalogue.INPUTS`).
INPUTS = catalogue.INPUTS
#: The inputs whose length is not the number of joints, with what their length is
#: (:data:`eomgen.outputs.catalogue.INPUT_SIZES`; the function giving it is registered with
#: :func:`eomgen.symbolic.builders.sizes`).
INPUT_SIZES = catalogue.INPUT_SIZES


def __getattr__(name: str):
    """The catalogue's other entries under the public name (``eomgen.outputs.FRAME_POSITIONS``)."""
    if name.isupper() and isinstance(getattr(catalogue, name, None), Output):
        return getattr(catalogue, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


#: Every output, by function name, in module order (:data:`~eomgen.outputs.catalogue.CATALOGUE`, then
#: any registered later).
OUTPUTS: dict[str, Output] = {}


def register_output(output: Output) -> Output:
    """Add ``output`` to :data:`OUTPUTS` (after those registered before it) and return it.

    Raises
    ------
    ValueError
        For a function name or symbol already taken, or a composed output built from functions
        not registered yet.
    """
    if output.function in OUTPUTS:
        raise ValueError(f"output function {output.function!r} is already registered")
    if output.symbol is not None and output.symbol in BY_SYMBOL:
        raise ValueError(f"output symbol {output.symbol!r} is already registered")
    missing = [f for f in output.composed_from if f not in OUTPUTS]
    if isinstance(output.constants, str):
        raise ValueError(f"{output.function!r}: constants are a tuple of names, not "
                         f"{output.constants!r}")
    strangers = [s for s in output.returns if s not in BY_SYMBOL]
    if strangers:
        raise ValueError(f"{output.function!r} returns unregistered outputs {strangers}")
    unknown = [name for name in output.inputs if name not in INPUTS]
    if unknown:
        raise ValueError(f"{output.function!r} takes unknown inputs {unknown}; known: "
                         f"{', '.join(INPUTS)}")
    if missing:
        raise ValueError(f"{output.function!r} is composed from unregistered {missing}")
    OUTPUTS[output.function] = output
    if output.symbol is not None:
        BY_SYMBOL[output.symbol] = output
    return output


#: Printed outputs by symbol (``BY_SYMBOL["M"].function``).
BY_SYMBOL: dict[str, Output] = {}

for _output in CATALOGUE:
    register_output(_output)
del _output


def splits(output: Output, n: int) -> tuple[tuple[str, int, int | None], ...]:
    """How the module splits a several-result function's matrix (:attr:`Output.returns`):
    ``(symbol, first column, end column or None for a vector's single column)`` per result."""
    out, column = [], 0
    for symbol in output.returns:
        if BY_SYMBOL[symbol].is_vector:
            out.append((symbol, column, None))
            column += 1
        else:
            declared = BY_SYMBOL[symbol]
            width = n * (n if declared.tensor else declared.width)
            out.append((symbol, column, column + width))
            column += width
    return tuple(out)


def task_space_names() -> dict[str, str]:
    """The names a template needs to compose the task-space functions: theirs (``inertia``,
    ``bias``, ``inverse``), and ``mass`` (M), ``jacobian`` (J_f), ``drift`` (J_f-dot qd) and
    ``tau`` (inverse dynamics: C qd + g = tau(q, qd, 0), g = tau(q, 0, 0))."""
    return {"inertia": OPERATIONAL_SPACE_INERTIA.function,
            "bias": OPERATIONAL_SPACE_BIAS.function,
            "inverse": DYNAMICALLY_CONSISTENT_INVERSE.function, "mass": MASS.function,
            "jacobian": FRAME_JACOBIANS.function, "drift": FRAME_JACOBIANS_DOT_QD.function,
            "tau": INVERSE.function}


def exported(functions, backend: str) -> tuple[str, ...]:
    """``functions`` less the composed ones ``backend`` does not compose
    (:attr:`Output.backends`)."""
    return tuple(f for f in functions
                 if OUTPUTS[f].backends is None or backend in OUTPUTS[f].backends)


def constrained_names() -> dict[str, str]:
    """The names a template needs to compose ``constrained_forward_dynamics``: ``name``,
    ``mass``, ``bias`` (τ(q, q̇, 0) = C q̇ + g), ``jacobian`` (J_c) and ``drift`` (J̇_c q̇)."""
    mass, bias, jacobian, drift = CONSTRAINED_FORWARD.composed_from
    return {"name": CONSTRAINED_FORWARD.function, "mass": mass, "bias": bias,
            "jacobian": jacobian, "drift": drift}


def parallel_names() -> dict[str, str]:
    """The names a template needs to compose ``parallel_inverse_dynamics``: ``name``,
    ``inverse`` (tau) and ``jacobian`` (J_l)."""
    inverse, jacobian = PARALLEL_INVERSE.composed_from
    return {"name": PARALLEL_INVERSE.function, "inverse": inverse, "jacobian": jacobian}


def derived_symbols(default_only: bool = False) -> tuple[str, ...]:
    """The symbols :func:`eomgen.derive` can build, in registry order (with ``default_only``,
    those of the outputs exported by default: ``("M", "C", "g", "tau")``)."""
    return tuple(s for s, o in BY_SYMBOL.items() if o.default or not default_only)


def function_names(default_only: bool = False) -> tuple[str, ...]:
    """Every function a generated module can export, in module order (with ``default_only``,
    those it exports when the caller names none)."""
    return tuple(f for f, o in OUTPUTS.items() if o.default or not default_only)


#: Where an unknown output's error sends the reader for the list of names.
UNKNOWN_OUTPUT_HELP = "docs/outputs.md lists them all; in Python, eomgen.outputs.OUTPUTS"


def select(names=None) -> tuple[str, ...]:
    """The functions to generate for the requested ``names``, in module order.

    Parameters
    ----------
    names:
        Function names (:data:`eomgen.outputs.OUTPUTS`) or their short names, the symbols of
        what they return (``M``, ``C``, ``g``, ``tau``, ...); ``None`` for
        those exported by default (:attr:`Output.default`). A function composed from others brings them along (forward
        dynamics needs the mass-matrix and inverse-dynamics functions).

    Raises
    ------
    ValueError
        For an unknown name, or no name at all.

    Examples
    --------
    >>> [OUTPUTS[f].symbol for f in select(["g", FORWARD.function])]
    ['M', 'g', 'tau', None]
    """
    if names is None:
        return function_names(default_only=True)
    aliases = {s: o.function for s, o in BY_SYMBOL.items()}
    wanted: set[str] = set()
    for name in names:
        function = aliases.get(name, name)
        if function not in OUTPUTS:
            hints = difflib.get_close_matches(str(name), list(aliases) + list(OUTPUTS), n=3)
            said = " or ".join(f"'{h}'" for h in hints)
            raise ValueError(f"unknown output {name!r}" + (f"; did you mean {said}?" if hints
                                                           else "")
                             + f" ({UNKNOWN_OUTPUT_HELP})")
        wanted.add(function)
        wanted.update(OUTPUTS[function].composed_from)
    if not wanted:
        raise ValueError("no output asked for")
    return tuple(f for f in OUTPUTS if f in wanted)


def composition_names(output: Output = FORWARD) -> dict[str, str]:
    """The names a template needs to compose ``output``: ``name`` (its own), and ``mass`` and
    ``bias`` (the functions giving M(q) and τ(q, q̇, 0) = C q̇ + g)."""
    mass, bias = output.composed_from
    return {"name": output.function, "mass": mass, "bias": bias}


__all__ = ["INPUTS", "splits", "DYNAMICS", "MASS_AND_BIAS", "INPUT_SIZES", "Output", "OUTPUTS",
           "BY_SYMBOL", "register_output", "derived_symbols", "function_names", "select",
           "composition_names", "MASS", "CORIOLIS", "GRAVITY", "INVERSE", "FORWARD", "exported",
           "constrained_names", "CONSTRAINED_FORWARD", "PARALLEL_INVERSE", "parallel_names",
           "TASK_SPACE", "task_space_names"]
