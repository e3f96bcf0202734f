"""The symbolic regressor: :class:`Regressor` (Y, its energy rows and parameters π of one model)
and :func:`derive_regressor`, which builds it as a straight-line program on a derivation
(:func:`eomgen.symbolic.derivation.new_derivation`; the algorithm is
:mod:`eomgen.symbolic.regressor`)."""

from __future__ import annotations

import time
from dataclasses import dataclass
from functools import cached_property
from typing import Iterable, Mapping, Sequence

import numpy as np
import sympy as sp

from ..model.bodies import BodyTree
from ..errors import ParameterError
from ..model import RobotModel, parameter_symbol
from ..symbolic.derivation import new_derivation
from ..symbolic.evaluate import compile_program
from ..symbolic.program import Program
from ..symbolic.regressor import (ACTUATOR_NAMES, ACTUATOR_TERMS, INERTIAL_NAMES,
                                  regressor_program)


def by_symbol(values: Mapping | None) -> dict:
    """``values`` (parameter symbol or name → value) keyed by symbols (:func:`~eomgen.model.
    parameter_symbol` of a name)."""
    return {(parameter_symbol(k) if isinstance(k, str) else k): v
            for k, v in (values or {}).items()}


@dataclass(frozen=True)
class Regressor:
    """The regressor of one model. Immutable.

    Attributes
    ----------
    model:
        The model it was derived from.
    tree:
        Its moving bodies (one 10-column block per body, in JOINT_NAMES order).
    q, qd, qdd:
        Joint symbols in JOINT_NAMES order: the inputs of :meth:`compiled` (with quaternion
        joints ``q`` has NQ entries, ``CONFIGURATION_NAMES``, and ``qdd`` the true
        accelerations the program's chart accelerations are expressions of).
    program:
        Straight-line program with outputs ``"Y"`` (n × p), ``"K"`` and ``"P"`` (1 × p):
        ``τ = Y π``, kinetic energy ``K = Y_K π``, potential energy ``P = Y_P π``.
    actuators:
        The actuator terms with columns (subset of ``ACTUATOR_TERMS``, in column order).
    seconds:
        Time spent building the program.
    """

    model: RobotModel
    tree: BodyTree
    q: tuple
    qd: tuple
    qdd: tuple
    program: Program
    actuators: tuple[str, ...] = ()
    seconds: float = 0.0

    @property
    def n(self) -> int:
        """The number of joints (NV): one 10-column block per body."""
        return len(self.qd)

    @cached_property
    def PARAMETER_NAMES(self) -> tuple[str, ...]:
        """Name of each column of Y: ``M1, MX1, …, ZZ1, M2, …`` then ``IA1…``, ``FV1…`` etc."""
        names = [f"{name}{k + 1}" for k in range(self.n) for name in INERTIAL_NAMES]
        for term in self.actuators:
            names += [f"{ACTUATOR_NAMES[term]}{k + 1}" for k in range(self.n)]
        return tuple(names)

    @property
    def p(self) -> int:
        """Number of standard parameters (columns of Y)."""
        return len(self.PARAMETER_NAMES)

    @cached_property
    def parameter_symbols(self) -> tuple[sp.Symbol, ...]:
        """π as symbols named after :attr:`PARAMETER_NAMES` (for β(π) expressions)."""
        return tuple(parameter_symbol(name) for name in self.PARAMETER_NAMES)

    def inertial_parameters(self, values: Mapping | None = None, actuator: Mapping | None = None
                            ) -> sp.Matrix:
        """π of the description, p × 1: each body's (m, h, I about its origin), symbolic in the
        model's parameters unless ``values`` (symbol or name → number) are given.

        Actuator entries (``IA``, ``FV``, ``FC``, ``FO``) are 0 here unless ``actuator`` maps
        their names (``"FV2"``) to values; the values a description declares (its
        ``<dynamics>`` or actuators) come from
        :func:`eomgen.regressor.generated.description_values`.
        """
        pi = []
        bodies = sorted(self.tree.bodies, key=lambda body: body.q_index)
        for body in bodies:
            par = body.inertial
            I = par.inertia
            pi += [par.mass, *par.first_moment, I[0][0], I[0][1], I[1][1], I[0][2], I[1][2],
                   I[2][2]]
        pi += [sp.sympify((actuator or {}).get(name, 0)) for name in self.PARAMETER_NAMES[10 * self.n:]]
        out = sp.Matrix(pi)
        if values is not None:
            out = out.xreplace({k: sp.sympify(v) for k, v in by_symbol(values).items()})
        return out

    def parameter_values(self, values: Mapping | None = None) -> dict:
        """The model's default parameter values by symbol, ``values`` (symbol or name → value)
        overriding."""
        return {**self.model.parameter_values, **by_symbol(values)}

    def numeric_parameters(self, values: Mapping | None = None) -> np.ndarray:
        """π as floats at the model's default parameter values (``values`` overriding)."""
        merged = self.parameter_values(values)
        return np.array([float(x) for x in self.inertial_parameters(merged)], dtype=float)

    @cached_property
    def Y(self) -> sp.Matrix:
        """Y(q, q̇, q̈), n × p, expanded to full expressions (small models only)."""
        return self.program.expand(self.program.output("Y"))

    @cached_property
    def Y_K(self) -> sp.Matrix:
        """Kinetic energy row, 1 × p: ``K = Y_K(q, q̇) π`` [J]."""
        return self.program.expand(self.program.output("K"))

    @cached_property
    def Y_P(self) -> sp.Matrix:
        """Potential energy row, 1 × p: ``P = Y_P(q) π`` [J], P = −Σ m g_vec · c."""
        return self.program.expand(self.program.output("P"))

    def base_program(self, columns: Sequence[int]) -> Program:
        """The program computing only ``Y_base = Y[:, columns]`` (n × b), output ``"Y_base"``;
        unused intermediates pruned (what generated ``base_regressor(q, qd, qdd)`` prints)."""
        Y = self.program.output("Y")
        out = Y.extract(list(range(Y.rows)), list(columns))
        return Program(self.program.assignments, (("Y_base", out),)).pruned(["Y_base"])

    def operation_count(self, columns: Sequence[int] | None = None) -> int:
        """Operations (SymPy ``count_ops``) of the program computing Y, or only the given
        columns of Y (the base regressor)."""
        if columns is None:
            return self.program.operation_count(["Y"])
        return self.base_program(columns).operation_count()

    def compiled(self, values: Mapping | None = None, program: Program | None = None):
        """A numeric function ``f(q, qd, qdd) -> {"Y": (n, p), "K": (1, p), "P": (1, p)}``
        (or the outputs of ``program``, e.g. :meth:`base_program`).

        Geometry parameters take their default values (``values`` overriding, symbol or name).
        """
        program = self.program if program is None else program
        merged = self.parameter_values(values)
        signs = tuple(sp.Symbol(f"sign_{s.name}", real=True) for s in self.qd)
        swap = {sp.sign(s): t for s, t in zip(self.qd, signs)}
        subs = {k: sp.Float(v) for k, v in merged.items()}
        free = {s for s in self.model.free_symbols if s not in subs}
        used = set().union(*(e.free_symbols for _, e in program.assignments),
                           *(m.free_symbols for _, m in program.outputs))
        if free & used:
            raise ParameterError(self.model.source, "parameters", "no numeric value for "
                                 + ", ".join(sorted(s.name for s in free & used)))
        assignments = tuple((s, e.xreplace(subs)) for s, e in program.assignments)
        outputs = tuple((name, m.xreplace(swap).xreplace(subs)) for name, m in program.outputs)
        raw = compile_program(Program(assignments, outputs), self.q + self.qd + self.qdd + signs)

        def evaluate(q, qd, qdd) -> dict:
            q, qd, qdd = (np.asarray(x, dtype=float) for x in (q, qd, qdd))
            return raw(*q, *qd, *qdd, *np.sign(qd))

        return evaluate


def derive_regressor(model: RobotModel, actuators: Iterable[str] = ()) -> Regressor:
    """Derive the joint torque regressor of ``model`` (see the module docstring).

    Parameters
    ----------
    model:
        A robot model; geometry may stay symbolic (DH lengths as parameters).
    actuators:
        Actuator terms to add columns for, from ``("armature", "viscous", "coulomb",
        "offset")``; their groups follow the inertial columns in the order given.

    Raises
    ------
    ValueError
        For an unknown or repeated actuator term.
    """
    actuators = tuple(actuators)
    bad = [t for t in actuators if t not in ACTUATOR_TERMS]
    if bad or len(set(actuators)) != len(actuators):
        raise ValueError(f"actuator terms must be distinct ones of {ACTUATOR_TERMS}, got {actuators}")
    start = time.perf_counter()
    d = new_derivation(model, ("q", "qd", "qdd"))
    out = regressor_program(d.tree, d.q, d.qd, d.qdd, model.gravity, d.builder, actuators)
    program = d.program((k, out[k]) for k in ("Y", "K", "P"))
    return Regressor(model, d.tree, d.inputs["q"], d.qd, d.inputs["qdd"], program, actuators,
                     time.perf_counter() - start)
