"""Symbolic equations of motion ``M(q) q̈ + C(q, q̇) q̇ + g(q) = τ``: :func:`derive` and its result.

Joint order is ``JOINT_NAMES``: the movable joints in the order the description lists them.
Symbols: ``q1 … qn`` [rad or m], ``qd1 … qdn`` [rad/s or m/s], ``qdd1 … qddn``; parameters keep
the names the description gave them. ``g`` is ∂P/∂q with ``P = −Σ m_l g_vecᵀ c_l`` (so a
gravity vector (0, 0, −9.81) makes height cost energy). ``C`` is the Coriolis matrix built from
the Christoffel symbols of the first kind, ``C_ij = Σ_k c_ijk q̇_k`` with
``c_ijk = ½(∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_jk/∂q_i)``, which makes ``Ṁ − 2C`` skew-symmetric.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from functools import cached_property
from typing import Iterable

import sympy as sp

from .common import reprs
from .errors import TooLargeError, UnsupportedError
from .model import Parameter, RobotModel
from .model.joints import KINDS
from .outputs import BY_SYMBOL, derived_symbols
# Derivation, joint_symbols and vector_symbols live in eomgen.symbolic.derivation; re-exported here
# because the docs and earlier code import them from eomgen.dynamics.
from .symbolic.derivation import Derivation, joint_symbols, new_derivation, vector_symbols  # noqa: F401
from .symbolic.couplings import refused
from .symbolic.program import Program
from .symbolic.named import AUTO_EXPAND_WORK, ExpansionTooLargeError, ProgramMatrix
from .symbolic.textbook import TEXTBOOK_MAX_DOF, TEXTBOOK_MAX_OPERATIONS, textbook_derivation
# Every module that registers the builder of an output (eomgen.symbolic.builders), imported for
# its registrations: a derivation finds each output's builder by symbol, so all must be known
# before derive() builds one (tests/architecture checks that every printed output has one).
from . import regressor  # noqa: F401  (the regressor outputs: eomgen.regressor.generated)
from .regressor import slotine_li  # noqa: F401
from .symbolic import (aba, centroidal, combined, contact_derivatives, controls,  # noqa: F401
                       derivatives, drives, flat, frames, loops, newton_euler, passive, routes,
                       second_derivatives)

#: What generated modules export by default: the mass matrix, Coriolis matrix, gravity vector
#: and the inverse dynamics τ(q, q̇, q̈) (by a symbolic Newton–Euler pass; cheaper to evaluate).
#: :func:`derive` builds these and every further output of :mod:`eomgen.outputs`.
ALL_OUTPUTS = derived_symbols(default_only=True)  # ("M", "C", "g", "tau")
DEFAULT_OUTPUTS = ("M", "C", "g")

#: ``derive(model, simplify=True)`` refuses models with more movable joints: trigonometric
#: simplification of the expanded expressions grows exponentially with the number of joints
#: (hours beyond this size), while the unsimplified program stays linear.
MAX_SIMPLIFY_JOINTS = 6


@dataclass(frozen=True)
class Step:
    """One step of a derivation: a title, a sentence on what it computes, and named results."""

    key: str
    title: str
    explanation: str
    results: tuple[tuple[str, sp.Expr], ...]


@dataclass(frozen=True)
class Dynamics:
    """The derived equations of motion of one model. Immutable.

    Attributes
    ----------
    model:
        The model they were derived from.
    q, qd, qdd:
        Joint position, velocity and acceleration symbols, in ``joint_names`` order.
    program:
        The straight-line program: intermediates and the outputs ``M``, ``C``, ``g``, ``P`` in
        terms of them (what printers turn into code).
    steps:
        The ordered derivation steps (for LaTeX and notebook export).
    timings:
        Seconds spent in each stage.
    vectors:
        ``(name, symbols)`` of every input vector of :data:`eomgen.outputs.INPUTS`.
    """

    model: RobotModel
    q: tuple[sp.Symbol, ...]
    qd: tuple[sp.Symbol, ...]
    qdd: tuple[sp.Symbol, ...]
    program: Program
    steps: tuple[Step, ...]
    timings: tuple[tuple[str, float], ...] = ()
    simplified: bool = False
    vectors: tuple[tuple[str, tuple[sp.Symbol, ...]], ...] = ()

    @property
    def input_symbols(self) -> dict[str, tuple[sp.Symbol, ...]]:
        """The symbols of each input vector of :data:`eomgen.outputs.INPUTS` by its name
        (``q`` → ``q1 … qn``, ``tau`` → ``tau1 … taun`` the joint efforts for outputs taking
        them, ...)."""
        return {"q": self.q, "qd": self.qd, "qdd": self.qdd, **dict(self.vectors)}

    @property
    def efforts(self) -> tuple[sp.Symbol, ...]:
        """The symbols ``tau1 … taun`` of the joint efforts (an input of some outputs)."""
        return self.input_symbols["tau"]

    @property
    def joint_names(self) -> tuple[str, ...]:
        return self.model.joint_names

    @property
    def parameters(self) -> tuple[Parameter, ...]:
        return self.model.parameters

    @property
    def outputs(self) -> tuple[str, ...]:
        return tuple(name for name, _ in self.program.outputs)

    @cached_property
    def _full(self) -> dict:
        return self.program.expanded()

    @cached_property
    def textbook(self):
        """The body-by-body textbook derivation of the model
        (:class:`eomgen.symbolic.textbook.TextbookDerivation`): M, C, g reduced with
        ``sin² + cos² = 1``, in angle sums ``cos(q2 + q3)`` along parallel joint axes, exact
        numbers. Computed in a polynomial ring (seconds for 3 joints), on first use. A façade
        for the README's API: the work is :func:`eomgen.symbolic.textbook.textbook_derivation`."""
        if self.model.couplings:
            raise UnsupportedError(self.model.source, "couplings", "no textbook derivation of "
                                   "a model with coupled joints")
        return textbook_derivation(self.model, max_dof=MAX_SIMPLIFY_JOINTS)

    @cached_property
    def regressor_form(self):
        """The regressor written out for teaching (:func:`eomgen.regressor.regressor_form`):
        the named columns of Y(q, q̇, q̈) in compact trigonometric notation and the base
        parameters as formulas of the standard ones, on first use. Meant for teaching-sized
        models (the LaTeX document and the notebook use it below the textbook bound). A façade
        for the README's API: the work is :func:`eomgen.regressor.regressor_form`."""
        return regressor.regressor_form(self.model)

    def named(self, name: str):
        """Output ``name`` (``"M"``, ``"C"``, ``"g"``, ``"P"``, ``"tau"``) in terms of the
        program's named intermediates, with their definitions: a
        :class:`~eomgen.symbolic.named.ProgramMatrix`, whatever the model's size (nothing is
        expanded; ``.expand()`` writes it out)."""
        if name not in self.outputs:
            raise KeyError(f"{name} was not derived (outputs: {', '.join(self.outputs)})")
        return ProgramMatrix(name, self.program.output(name), self.program.assignments)

    def _expanded(self, name: str):
        """Output ``name`` as :attr:`M` and the others give it: the textbook form when
        ``simplified``; else written out (:meth:`ProgramMatrix.expand
        <eomgen.symbolic.named.ProgramMatrix.expand>`) when that takes at most
        :data:`~eomgen.symbolic.named.AUTO_EXPAND_WORK` term operations (about a
        second at most), else the named form."""
        if name not in self.outputs:
            raise KeyError(f"{name} was not derived (outputs: {', '.join(self.outputs)})")
        if self.simplified:
            book = self.textbook
            if name == "P":
                return sp.Matrix([[book.P]])
            if name == "tau":
                tau = book.M * sp.Matrix(self.qdd) + book.C * sp.Matrix(self.qd) + book.g
                return tau.applyfunc(lambda e: sp.factor_terms(sp.expand(e)))
            return getattr(book, name)
        value = self.named(name)
        try:
            return value.expand(max_work=AUTO_EXPAND_WORK)
        except (ExpansionTooLargeError, NotImplementedError):
            return value

    @cached_property
    def M(self):
        """Mass matrix M(q), n×n, symmetric positive definite [kg m², kg m, kg].

        An ordinary SymPy Matrix when it is cheap to write out: the reduced textbook form for
        teaching-sized models (see :func:`derive`'s ``simplify``), else the entries multiplied
        out in ``sin q_i``, ``cos q_i`` with ``sin² + cos² = 1`` applied, when that takes about a
        second at most (the 6-joint PUMA 560: 262 terms). Otherwise (a general 5-joint
        arm, the Panda) a :class:`~eomgen.symbolic.named.ProgramMatrix`: the matrix in terms
        of named intermediates with their definitions (``.subexpressions``), which indexes,
        adds and multiplies like a matrix, substitutes (``.subs``; all inputs given: an
        ordinary matrix of numbers), evaluates (``.evalf``), lambdifies, displays, and
        ``.expand()`` writes out on request. SymPy's own functions (``sympify``, ``Matrix``,
        ``lambdify``, ``simplify``, ``latex``) take it as an ordinary matrix whose entries are
        written out where that is cheap, else functions of their inputs (``M_1_1(q1, …)``) that
        evaluate the program (:mod:`eomgen.symbolic.entries`). For numbers, :meth:`lambdify`
        is the fast route. The same holds for :attr:`C`, :attr:`g`, :attr:`P`, :attr:`K` and
        :attr:`tau`."""
        return self._expanded("M")

    @cached_property
    def C(self):
        """Coriolis matrix C(q, q̇), n×n, from Christoffel symbols of the first kind (a SymPy
        Matrix or a ProgramMatrix: see :attr:`M`)."""
        return self._expanded("C")

    @cached_property
    def g(self):
        """Gravity vector g(q) = ∂P/∂q, n×1 [N m or N] (see :attr:`M`)."""
        return self._expanded("g")

    @cached_property
    def P(self):
        """Potential energy P(q) = −Σ m_l g_vecᵀ c_l [J] (zero at the world origin; see
        :attr:`M`)."""
        return self._expanded("P")[0, 0]

    @cached_property
    def K(self):
        """Kinetic energy K = ½ q̇ᵀ M(q) q̇ [J] (see :attr:`M`)."""
        qd = sp.Matrix(self.qd)
        value = (qd.T * self.M * qd)[0, 0] / 2
        return sp.factor_terms(sp.expand(value)) if self.simplified else value

    @cached_property
    def tau(self):
        """Inverse dynamics τ = M q̈ + C q̇ + g, n×1: from the Newton–Euler program when it was
        derived (``outputs`` with ``"tau"``), else formed from M, C and g; in reduced textbook
        form (from :attr:`textbook`'s M, C, g) when ``simplified`` (see :attr:`M`)."""
        if "tau" in self.outputs:
            return self._expanded("tau")
        return self.M * sp.Matrix(self.qdd) + self.C * sp.Matrix(self.qd) + self.g

    def operation_count(self, names: Iterable[str] | None = None) -> int:
        """Arithmetic operations of the straight-line program for the given outputs."""
        return self.program.operation_count(names)

    def lambdify(self):
        """NumPy functions ``M(q, **p)``, ``C(q, qd, **p)``, ``g(q, **p)``,
        ``tau(q, qd, qdd, **p)`` compiled from the program (not from expanded matrices): the
        generated NumPy module's functions, with the parameters kept symbolic as keyword
        arguments. See :class:`eomgen.codegen.lambdify.NumericDynamics`. A façade for the README's
        API: the work is :func:`eomgen.codegen.lambdify.lambdify`."""
        # Imported on first use: lambdify prints through code generation (Jinja, the NumPy
        # backend), which derive never needs (start-up time).
        from .codegen.lambdify import lambdify

        return lambdify(self)

    def __repr__(self) -> str:
        """One line: the robot, the sizes, the outputs derived, the parameters (the matrices
        themselves: ``dyn.M``, ``dyn.C``, ...)."""
        model = self.model
        params = (f"{len(model.parameters)} parameters ({reprs.names(model.parameter_names)})"
                  if model.parameters else "no parameters")
        return (f"<Dynamics of {model.name!r}: nq={model.nq}, nv={model.dof}; outputs "
                f"{reprs.names(self.outputs, most=8)}; {params}"
                + ("; simplified" if self.simplified else "") + ">")

    def _repr_latex_(self) -> str | None:  # rich display in notebooks: registered by eomgen.present.display
        return reprs.render("dynamics", self, "text/latex")


def derive(model: RobotModel, outputs: Iterable[str] = DEFAULT_OUTPUTS, simplify: bool | None = None) -> Dynamics:
    """Derive the equations of motion of ``model`` symbolically (Lagrangian method).

    Parameters
    ----------
    model:
        A robot model (see :func:`eomgen.load`).
    outputs:
        Which of ``"M"``, ``"C"``, ``"g"``, ``"tau"`` to derive; what is not asked is not
        computed.
    simplify:
        Give ``dynamics.M``, ``.C``, ``.g``, ``.P``, ``.tau`` in reduced textbook form (those of
        :attr:`Dynamics.textbook`: ``sin² + cos² = 1`` applied, angle sums along parallel
        axes, exact numbers) instead of the program's expressions substituted into each other.
        ``None`` (default) does it for teaching-sized models only (at most
        :data:`~eomgen.symbolic.textbook.TEXTBOOK_MAX_DOF` joints and a program of at most
        :data:`~eomgen.symbolic.textbook.TEXTBOOK_MAX_OPERATIONS` operations, an estimate of
        the cost known before anything is expanded): the expanded form grows exponentially
        with the model size. ``True`` forces it (a 3-joint arm with general axes: tens of
        seconds). ``True`` is refused above
        :data:`MAX_SIMPLIFY_JOINTS` joints.

    Returns
    -------
    Dynamics
        Its ``program`` holds every output asked for; ``M``, ``C``, ``g``, ``tau`` read as
        SymPy matrices in ``q``, ``qd`` (``qdd``) and the parameters: reduced textbook forms for
        teaching-sized models, multiplied out where that is cheap, else
        :class:`~eomgen.symbolic.named.ProgramMatrix` (the matrix in named intermediates,
        ``.expand()`` on request).

    Raises
    ------
    TooLargeError
        For ``simplify=True`` on a model with more than :data:`MAX_SIMPLIFY_JOINTS` joints.

    Examples
    --------
    >>> import eomgen
    >>> arm = eomgen.load(eomgen.example_path("planar_2link"))
    >>> dyn = eomgen.derive(arm)
    >>> dyn.joint_names
    ('joint1', 'joint2')
    """
    outputs = set(outputs)
    known = derived_symbols()
    unknown = outputs - set(known)
    if unknown:
        raise ValueError(f"unknown outputs {sorted(unknown)}; choose from {known}")
    # With a joint whose configuration is not its coordinates (nq > nv: a quaternion free
    # flyer, ball joints, eomgen.model.quaternion), the outputs the catalogue marks, each
    # checked against Pinocchio's free flyer and spherical joints (Y against
    # computeJointTorqueRegressor: a virtual joint's massless body has columns of its own,
    # multiplied by zero parameters; Y_base by the numeric route,
    # without them; Y_SL against M, computeCoriolisMatrix and g; Y_K, Y_P against Pinocchio's
    # energies; the drive outputs against model.armature and the friction law; the flat outputs
    # against finite differences along a trajectory integrated on the configuration space; the
    # loop rows against Pinocchio's frames and constraintDynamics). An output the catalogue
    # does not mark would be refused in one line, in the words of the first such joint's kind;
    # the derivatives, the drives' too, are taken along the tangent (eomgen.symbolic.tangent).
    refused_here = sorted(s for s in outputs if not BY_SYMBOL[s].on_charts)
    if model.nq > model.dof and refused_here:
        kind, name = next((KINDS[k], n) for k, n in model.compound_joints
                          if KINDS[k].nq > KINDS[k].nv)
        what, where, hint = kind.refused_as(name)
        raise UnsupportedError(
            model.source, where, f"{', '.join(refused_here)} not derived for {what} yet; "
            f"leave {'it' if len(refused_here) == 1 else 'them'} out of the outputs (every "
            f"other output is derived for it){hint}")
    if model.couplings and refused(outputs):
        raise UnsupportedError(
            model.source, "couplings", f"{', '.join(refused(outputs))} not derived for a model "
            "with coupled joints (see eomgen.symbolic.couplings); read the followers as "
            "independent joints (eomgen.model.uncoupled) for them")
    if simplify and model.dof > MAX_SIMPLIFY_JOINTS:
        raise TooLargeError(
            model.source, "derive(simplify=True)",
            f"{model.dof} joints: simplify is limited to {MAX_SIMPLIFY_JOINTS} joints; use "
            "simplify=False (the default for large models)")
    timings = []
    start = time.perf_counter()
    derivation = new_derivation(model)
    inputs = derivation.inputs
    q, qd, qdd = inputs["q"], inputs["qd"], inputs["qdd"]
    timings.append(("bodies", time.perf_counter() - start))
    start = time.perf_counter()
    derivation.build(outputs)
    result = derivation.built
    timings.append(("program", time.perf_counter() - start))
    program = derivation.program(result.items())
    if model.couplings:  # the projected outputs (eomgen.symbolic.couplings)
        result = dict(program.outputs)
    steps = _steps(program, result)
    if model.nq > model.dof or model.couplings:  # the textbook forms take q as the coordinates
        simplify = False
    if simplify is None:  # teaching-sized: few joints and a small program (a cheap estimate)
        counted = [o for o in ("M", "C", "g") if o in outputs]
        simplify = model.dof <= TEXTBOOK_MAX_DOF and (
            not counted or program.operation_count(counted) <= TEXTBOOK_MAX_OPERATIONS)
    vectors = tuple((k, v) for k, v in inputs.items() if k not in ("q", "qd", "qdd"))
    return Dynamics(model, q, qd, qdd, program, steps, tuple(timings), bool(simplify), vectors)


#: The tag families (:class:`eomgen.symbolic.program.Tag`, set where the Lagrangian program
#: defines its intermediates) of each derivation step.
STEP_FAMILIES = {
    "kinematics": ("s", "c", "A", "R", "o", "z", "p", "v"),
    "inertia": ("Rh", "Iw", "hw", "mc", "hc", "Ic", "F"),
    "christoffel": ("X", "G", "Y", "dM", "Gamma"),
}


def _steps(program: Program, result: dict) -> tuple[Step, ...]:
    tags = program.tags()

    def named(step: str) -> tuple[tuple[str, sp.Expr], ...]:
        families = STEP_FAMILIES[step]
        return tuple((s.name, e) for s, e in program.assignments
                     if s in tags and tags[s].family in families)

    steps = [
        Step("kinematics", "Forward kinematics",
             "Sines and cosines, world rotation R_i, origin p_i and motion axis S_i of every "
             "body.", named("kinematics")),
        Step("inertia", "Composite inertias",
             "Each body's inertia in world axes, then mass m, first moment h and rotational "
             "inertia of each subtree about the first moving joint's origin, and F_j = I^c_j S_j.",
             named("inertia")),
    ]
    if "M" in result:
        steps.append(Step("M", "Mass matrix", "M_ij = S_iᵀ I^c_j S_j for i an ancestor of j.",
                          tuple((f"M[{i},{j}]", result["M"][i, j]) for i in range(result["M"].rows)
                                for j in range(i, result["M"].cols))))
    if "C" in result:
        steps.append(Step("christoffel", "Christoffel symbols",
                          "∂M/∂q in closed form, then c_ijk = ½(∂M_ij/∂q_k + ∂M_ik/∂q_j − "
                          "∂M_jk/∂q_i).", named("christoffel")))
        steps.append(Step("C", "Coriolis matrix", "C_ij = Σ_k c_ijk q̇_k.",
                          tuple((f"C[{i},{j}]", result["C"][i, j]) for i in range(result["C"].rows)
                                for j in range(result["C"].cols))))
    if "g" in result:
        steps.append(Step("g", "Gravity vector", "g_i = ∂P/∂q_i.",
                          tuple((f"g[{i}]", result["g"][i, 0]) for i in range(result["g"].rows))))
    return tuple(steps)
