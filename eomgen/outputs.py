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

Adding an output is one :func:`register_output` call here (plus the program that builds its
symbol in :func:`eomgen.derive`).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Output:
    """One function of a generated module.

    Attributes
    ----------
    function:
        Its name in the generated module (a Python and C identifier).
    symbol:
        The derived quantity it returns (``"M"``), the key of :attr:`Dynamics.outputs
        <eomgen.dynamics.Dynamics.outputs>` and a short name callers may use; ``None`` for a
        composed function.
    summary:
        The first line of its docstring.
    inputs:
        Names of its vector inputs, in call order (``"q"``, ``"qd"``, ``"qdd"``, ``"tau"``).
    is_vector:
        Whether it returns an (n,) vector rather than an (n, n) matrix.
    units:
        Units of the result's entries.
    needs:
        Symbols of the derived outputs it needs (its own symbol for a printed output).
    composed_from:
        Functions a composed output is built from (generated along with it); empty otherwise.
    """

    function: str
    symbol: str | None
    summary: str
    inputs: tuple[str, ...]
    is_vector: bool
    units: str
    needs: tuple[str, ...]
    composed_from: tuple[str, ...] = ()

    @property
    def composed(self) -> bool:
        """Whether backends compose it from other functions instead of printing a program."""
        return bool(self.composed_from)

    def shape(self, n: int) -> tuple[int, ...]:
        """Its result's shape for ``n`` joints."""
        return (n,) if self.is_vector else (n, n)


#: Every output, by function name, in module order.
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
    if missing:
        raise ValueError(f"{output.function!r} is composed from unregistered {missing}")
    OUTPUTS[output.function] = output
    if output.symbol is not None:
        BY_SYMBOL[output.symbol] = output
    return output


#: Printed outputs by symbol (``BY_SYMBOL["M"].function``).
BY_SYMBOL: dict[str, Output] = {}

_REVOLUTE_EFFORT = "N m (revolute), N (prismatic)"

MASS = register_output(Output(
    "mass_matrix", "M", "Mass matrix M(q), symmetric positive definite.", ("q",), False,
    "kg m^2 (revolute rows/columns), kg (prismatic)", ("M",)))
CORIOLIS = register_output(Output(
    "coriolis_matrix", "C", "Coriolis matrix C(q, qd) from the Christoffel symbols of the first "
    "kind, so that Mdot - 2 C is skew-symmetric.", ("q", "qd"), False, "kg m^2/s (revolute)",
    ("C",)))
GRAVITY = register_output(Output(
    "gravity_vector", "g", "Gravity vector g(q) = dP/dq.", ("q",), True, _REVOLUTE_EFFORT,
    ("g",)))
INVERSE = register_output(Output(
    "inverse_dynamics", "tau", "Joint efforts tau = M(q) qdd + C(q, qd) qd + g(q) "
    "(recursive Newton-Euler, straight-line).", ("q", "qd", "qdd"), True, _REVOLUTE_EFFORT,
    ("tau",)))
FORWARD = register_output(Output(
    "forward_dynamics", None, "Joint accelerations qdd solving M(q) qdd = tau - (C(q, qd) qd "
    "+ g(q)) by Cholesky.", ("q", "qd", "tau"), True, "rad/s^2 (revolute), m/s^2 (prismatic)",
    ("M", "tau"), composed_from=(MASS.function, INVERSE.function)))


def derived_symbols() -> tuple[str, ...]:
    """The symbols :func:`eomgen.derive` can build, in registry order: ``("M", "C", "g",
    "tau")``."""
    return tuple(BY_SYMBOL)


def function_names() -> tuple[str, ...]:
    """Every function a generated module can export, in module order."""
    return tuple(OUTPUTS)


def composition_names(output: Output = FORWARD) -> dict[str, str]:
    """The names a template needs to compose ``output``: ``name`` (its own), and ``mass`` and
    ``bias`` (the functions giving M(q) and τ(q, q̇, 0) = C q̇ + g)."""
    mass, bias = output.composed_from
    return {"name": output.function, "mass": mass, "bias": bias}


__all__ = ["Output", "OUTPUTS", "BY_SYMBOL", "register_output", "derived_symbols",
           "function_names", "composition_names", "MASS", "CORIOLIS", "GRAVITY", "INVERSE",
           "FORWARD"]
