"""The builders of the generated regressor functions (registered in :mod:`eomgen.outputs`):
``regressor``, ``inertial_parameters``, ``base_regressor``, ``base_parameters``, the
kinetic and potential energy regressors and the module constants ``PARAMETER_NAMES``,
``BASE_PARAMETER_NAMES``, with the actuator columns a model declares."""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Mapping

import numpy as np
import sympy as sp

from ..errors import ParameterError, UnsupportedError
from ..model import RobotModel
from ..symbolic.builders import builds, provides
from ..symbolic.program import Program
from ..symbolic.regressor import ACTUATOR_NAMES, INERTIAL_NAMES, regressor_program
from .derive import Regressor, derive_regressor
from .numeric_base import base_parameters
from .symbolic_base import symbolic_base_parameters


#: Actuator terms a generated regressor gets columns for when a joint's actuator declares them,
#: with the :class:`~eomgen.model.Actuator` field holding each one's value. Descriptions and
#: scenes have no offset, so generated regressors have no ``FO`` columns.
DECLARED_TERMS = {"armature": "armature", "viscous": "damping", "coulomb": "friction"}


def declared_actuator_terms(model: RobotModel) -> tuple[str, ...]:
    """The actuator terms (:data:`DECLARED_TERMS` order) for which some movable joint of
    ``model`` has an actuator with a value that is not identically zero: the actuator column
    groups of the generated regressor.

    Raises
    ------
    UnsupportedError
        For a flexible joint (an actuator with a stiffness): its motor has an equation of its
        own, which τ = Y π does not describe.
    """
    actuators = [(j.name, j.actuator) for j in model.movable_joints if j.actuator is not None]
    for name, a in actuators:
        if a.flexible:
            raise UnsupportedError(model.source, f"joint '{name}' actuator",
                                   "a flexible joint has no rigid-body regressor (remove its "
                                   "stiffness to identify it as a rigid joint)")
    return tuple(term for term, field in DECLARED_TERMS.items()
                 if any(getattr(a, field) != 0 for _, a in actuators))


#: The friction terms among :data:`DECLARED_TERMS`: what ``--friction`` / ``--no-friction`` of
#: ``eomgen excite`` and ``eomgen identify`` add or leave out (:func:`identification_terms`).
FRICTION_TERMS = ("viscous", "coulomb")


def identification_terms(model: RobotModel, friction: bool | None = None) -> tuple[str, ...]:
    """The actuator terms of the regressor that ``eomgen excite`` and ``eomgen identify`` use
    for ``model`` (:data:`DECLARED_TERMS` order).

    ``friction=None`` (the default): those the description declares
    (:func:`declared_actuator_terms`), as the generated regressor has them. ``True``: viscous
    and Coulomb friction columns for every joint even where none is declared (the declared
    values are then 0). ``False``: no friction columns (a declared armature is kept: it is part
    of the inertia the joint sees).

    Raises
    ------
    UnsupportedError
        For a flexible joint, as :func:`declared_actuator_terms`.
    """
    declared = declared_actuator_terms(model)
    if friction is None:
        return declared
    wanted = (set(declared) | set(FRICTION_TERMS)) if friction \
        else (set(declared) - set(FRICTION_TERMS))
    return tuple(term for term in DECLARED_TERMS if term in wanted)


def description_parameters(reg: Regressor) -> sp.Matrix:
    """π of the description (p × 1): :meth:`Regressor.inertial_parameters` with the actuator
    columns taken from the joints' actuators (armature, damping, friction; 0 for a joint
    without one), in the model's parameters."""
    values = {}
    for term in reg.actuators:
        for k, joint in enumerate(reg.model.movable_joints):
            actuator = joint.actuator
            values[f"{ACTUATOR_NAMES[term]}{k + 1}"] = (
                0 if actuator is None else getattr(actuator, DECLARED_TERMS[term]))
    return reg.inertial_parameters(actuator=values)


def description_values(reg: Regressor, values: Mapping | None = None) -> np.ndarray:
    """:func:`description_parameters` as floats (p,), the model's parameters at their default
    values (``values``, symbol or name → value, overriding): the π whose β the identification
    report compares its estimate with, declared friction and armature included.

    Raises
    ------
    ParameterError
        When a parameter has no value.
    """
    merged = reg.parameter_values(values)
    pi = description_parameters(reg).xreplace({k: sp.sympify(v) for k, v in merged.items()})
    free = sorted({s.name for x in pi for s in x.free_symbols})
    if free:
        raise ParameterError(reg.model.source, "parameters", "no numeric value for "
                             + ", ".join(free))
    return np.array([float(x) for x in pi], dtype=float)


@dataclass(frozen=True)
class GeneratedBase:
    """The base parameters a generated module exports.

    Attributes
    ----------
    names:
        ``BASE_PARAMETER_NAMES``: each base column's name, ``R`` appended when others were
        grouped into it.
    columns:
        Their columns of Y, increasing (``Y_base = Y[:, columns]``).
    beta:
        β as expressions of the model's parameters (the description's π substituted into the
        grouping's β(π)).
    route:
        ``"symbolic"`` (closed-form grouping, checked numerically) or ``"numeric"`` (QR over
        random states, for revolute axes the grouping rules do not cover).
    """

    names: tuple[str, ...]
    columns: tuple[int, ...]
    beta: tuple[sp.Expr, ...]
    route: str


@functools.lru_cache(maxsize=8)
def generated_base(model: RobotModel) -> GeneratedBase:
    """The base parameters of ``model`` as generated modules export them (cached per model:
    the output builder and the module constants ask for the same).

    The closed-form grouping (:func:`symbolic_base_parameters`, exact in geometry symbols when
    it leaves no residual column) is used where its rules apply; otherwise, and for a model
    with quaternion joints (its rules read the virtual joints as joints that turn), the numeric
    route (:func:`base_parameters`, needs SciPy). Both sample the regressor at the parameters' values.

    Raises
    ------
    ParameterError
        When a parameter the regressor uses has no value (the base is found numerically).
    UnsupportedError
        For a tilted revolute axis without SciPy installed.
    """
    reg = derive_regressor(model, declared_actuator_terms(model))
    pi = description_parameters(reg)
    subs = dict(zip(reg.parameter_symbols, pi))
    try:
        if model.nq > model.dof:  # q is not the coordinates: no trigonometric base
            raise UnsupportedError(model.source, "base parameters", "quaternion joints")
        base = symbolic_base_parameters(reg)
        names, columns, route = base.names, base.base, "symbolic"
        exprs = base.expressions
    except UnsupportedError:
        try:
            numeric = base_parameters(reg)
        except ImportError:
            raise UnsupportedError(model.source, "base parameters", "a revolute axis not along "
                                   "x, y or z of its joint frame needs SciPy for the numeric "
                                   "route (pip install scipy)") from None
        named = numeric.expressions(digits=17)
        names, columns, route = tuple(n for n, _ in named), numeric.base, "numeric"
        exprs = tuple(e for _, e in named)
    beta = tuple(sp.expand(e.xreplace(subs)) for e in exprs)
    return GeneratedBase(tuple(names), tuple(columns), beta, route)


@builds("Y", "pi", "Y_base", "beta", "Y_K", "Y_P")
def build_outputs(derivation, wanted) -> dict:
    """The builder of the regressor outputs (:mod:`eomgen.outputs`): ``Y`` (n × p),
    ``Y_K`` and ``Y_P`` (p × 1, the energy regressors), ``pi`` (p × 1), ``Y_base`` (n × b) and
    ``beta`` (b × 1), those in ``wanted``.

    Y is built by :func:`eomgen.symbolic.regressor.regressor_program` into the derivation's
    program, with the actuator columns the model declares (:func:`declared_actuator_terms`);
    Y_base is its base columns (:func:`generated_base`); π and β are expressions of the model's
    parameters (functions of the parameters only in the generated modules).
    """
    model = derivation.model
    terms = declared_actuator_terms(model)
    out: dict[str, sp.Matrix] = {}
    if wanted & {"Y", "Y_K", "Y_P", "Y_base"}:
        built = regressor_program(derivation.tree, derivation.q, derivation.qd, derivation.qdd,
                                  model.gravity, derivation.builder, terms)
        Y = built["Y"]
        if "Y" in wanted:
            out["Y"] = Y
        if "Y_K" in wanted:
            out["Y_K"] = built["K"].T
        if "Y_P" in wanted:
            out["Y_P"] = built["P"].T
        if "Y_base" in wanted:
            out["Y_base"] = Y.extract(list(range(Y.rows)), list(generated_base(model).columns))
    if "pi" in wanted:
        tree = derivation.tree
        q, qd, qdd = derivation.q, derivation.qd, derivation.qdd
        out["pi"] = description_parameters(
            Regressor(model, tree, q, qd, qdd, Program((), ()), terms))
    if "beta" in wanted:
        out["beta"] = sp.Matrix(generated_base(model).beta)
    return out


@provides("PARAMETER_NAMES")
def parameter_names(dynamics) -> dict[str, tuple[str, ...]]:
    """``PARAMETER_NAMES``: the columns of the generated regressor (module constant)."""
    model = dynamics.model
    terms = declared_actuator_terms(model)
    bodies = len(model.movable_joints)  # one per movable joint, coupled followers included
    names = [f"{name}{k + 1}" for k in range(bodies) for name in INERTIAL_NAMES]
    for term in terms:
        names += [f"{ACTUATOR_NAMES[term]}{k + 1}" for k in range(bodies)]
    return {"PARAMETER_NAMES": tuple(names)}


@provides("PARAMETER_NAMES", "BASE_PARAMETER_NAMES")
def base_parameter_names(dynamics) -> dict[str, tuple[str, ...]]:
    """``BASE_PARAMETER_NAMES`` (and ``PARAMETER_NAMES``): the columns of the generated base
    regressor (module constants)."""
    return {**parameter_names(dynamics),
            "BASE_PARAMETER_NAMES": generated_base(dynamics.model).names}
