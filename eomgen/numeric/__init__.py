"""The numeric layer: NumPy evaluators of the dynamics, independent of the generated code.

* :mod:`eomgen.numeric.newton_euler`: rigid-body dynamics by Newton–Euler recursions on a
  :class:`NumericModel` (the independent reference for the symbolic engine); its names are
  importable from ``eomgen.numeric`` itself (``eomgen.numeric.rnea``, ``numeric_model``, ...).
* :mod:`eomgen.numeric.so3`: the skew matrix, exponential and logarithm of rotations, the
  one numeric copy every module uses.
* :mod:`eomgen.numeric.quaternion_chart`: quaternion joints (a free flyer, ball joints) in those
  recursions: ``q`` of NQ entries, ``qd``, ``qdd``, ``tau`` of NV (Pinocchio's layout).
* :mod:`eomgen.numeric.frames`: pose, Jacobians and J̇ q̇ of named links by recursion (the
  counterpart of the derived frame program).
* :mod:`eomgen.numeric.contacts`: rigid contacts (:class:`~eomgen.numeric.contacts.ContactDynamics`,
  KKT constrained dynamics).
* :mod:`eomgen.numeric.actuated`: armature, friction and Spong's flexible joints
  (:class:`~eomgen.numeric.actuated.ActuatedModel`).
* :mod:`eomgen.numeric.pinocchio`: the adapters to Pinocchio (optional dependency).

Importing ``eomgen.numeric`` loads only the Newton–Euler module (NumPy); the others are imported
by name.
"""

from __future__ import annotations

from .newton_euler import (
    FIXED,
    FLOAT64,
    HELICAL,
    PRISMATIC,
    REVOLUTE,
    M_crba,
    M_rnea,
    Numbers,
    NumericModel,
    coriolis_times_qd,
    forward_dynamics,
    gravity_torques,
    kinetic_energy,
    link_poses,
    numeric_model,
    potential_energy,
    rnea,
)

__all__ = [
    "Numbers", "FLOAT64", "NumericModel", "numeric_model", "rnea", "gravity_torques", "M_rnea",
    "M_crba",
    "coriolis_times_qd", "forward_dynamics", "kinetic_energy", "potential_energy", "link_poses",
    "FIXED", "REVOLUTE", "PRISMATIC", "HELICAL",
]
