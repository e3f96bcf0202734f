"""Linear parameterization τ = Y(q, q̇, q̈) π: the regressor, its parameters and base parameters.

:func:`derive_regressor` builds Y as a straight-line program (see
:mod:`eomgen.symbolic.regressor` for the derivation, frames and parameter order);
:func:`base_parameters` finds the identifiable combinations numerically (QR over random
states), :func:`symbolic_base_parameters` by the closed-form grouping rules
(:mod:`eomgen.symbolic.grouping`), checked numerically; :func:`identify` estimates them from
measured efforts by least squares. See docs/regressor.md.

One module a concept, all importable from here: :mod:`~eomgen.regressor.derive` (Y as a
program), :mod:`~eomgen.regressor.numeric_base` and :mod:`~eomgen.regressor.symbolic_base`
(base parameters, two routes), :mod:`~eomgen.regressor.notation` (LaTeX names, grouped linear
forms), :mod:`~eomgen.regressor.form` (written out for teaching),
:mod:`~eomgen.regressor.least_squares` (the observation matrix and ordinary least squares) and
:mod:`~eomgen.regressor.generated` (the builders :mod:`eomgen.outputs` names as
``eomgen.regressor:build_outputs`` etc.).

Parameters π, per moving body in JOINT_NAMES order (body k is the child of joint k, fixed links
merged, frame = joint k's frame after it has moved), Pinocchio's order::

    M, MX, MY, MZ, XX, XY, YY, XZ, YZ, ZZ       (m, m c, inertia about the body origin)

then, if asked, one group of n actuator columns per term: ``IA`` (armature, τ_k += I_a q̈_k),
``FV`` (viscous, f_v q̇_k), ``FC`` (Coulomb, f_c sign q̇_k), ``FO`` (offset, f_o).

>>> import eomgen
>>> from eomgen.regressor import derive_regressor
>>> reg = derive_regressor(eomgen.load(eomgen.example_path("planar_2link")))
>>> reg.PARAMETER_NAMES[:4]
('M1', 'MX1', 'MY1', 'MZ1')
"""

from __future__ import annotations

from ..symbolic.regressor import ACTUATOR_NAMES, ACTUATOR_TERMS, INERTIAL_NAMES  # noqa: F401
from .derive import Regressor, by_symbol, derive_regressor
from .form import PARAMETER_MEANINGS, RegressorForm, regressor_form
from .generated import (DECLARED_TERMS, FRICTION_TERMS, GeneratedBase, base_parameter_names,
                        build_outputs, declared_actuator_terms, description_parameters,
                        description_values, generated_base, identification_terms,
                        parameter_names)
from .least_squares import Identification, identify, normalised_condition, observation_matrix
from .notation import by_coefficient, parameter_latex
from .numeric_base import (RANK_TOLERANCE, ZERO_COLUMN, BaseParameters, base_parameters,
                           sample_regressor)
from .symbolic_base import SymbolicBase, symbolic_base_parameters

__all__ = [
    "ACTUATOR_NAMES", "ACTUATOR_TERMS", "INERTIAL_NAMES",
    "Regressor", "derive_regressor", "by_symbol",
    "RANK_TOLERANCE", "ZERO_COLUMN", "BaseParameters", "base_parameters", "sample_regressor",
    "SymbolicBase", "symbolic_base_parameters",
    "parameter_latex", "by_coefficient",
    "PARAMETER_MEANINGS", "RegressorForm", "regressor_form",
    "Identification", "identify", "observation_matrix", "normalised_condition",
    "DECLARED_TERMS", "FRICTION_TERMS", "GeneratedBase", "declared_actuator_terms",
    "description_parameters", "description_values", "identification_terms",
    "generated_base", "build_outputs", "parameter_names", "base_parameter_names",
]
