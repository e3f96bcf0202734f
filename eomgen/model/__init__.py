"""The robot model: plain, frozen data shared by every stage of eomgen.

Conventions (URDF's, whatever the input format):

* Every link has a frame. A joint connects a parent link to a child link; its ``origin`` is the
  pose of the joint frame in the parent link frame, and the child link frame *is* the joint
  frame moved by the joint variable: ``T_parent_child(q) = origin · motion(axis, q)``.
* ``axis`` is a unit vector in the joint (= child link) frame. A revolute joint rotates by ``q``
  radians about it (right hand rule); a prismatic joint translates by ``q`` metres along it.
* A link's inertial data: mass [kg], centre of mass [m] in the link frame, and the 3×3
  rotational inertia [kg m²] about the centre of mass, expressed in the link frame axes (a
  URDF ``<inertial><origin rpy>`` is already applied by the parser).
* ``gravity`` is the gravitational acceleration [m/s²] in the root link frame, e.g.
  ``(0, 0, -9.81)`` for URDF input.
* A movable joint may carry an :class:`Actuator` (armature, friction, stiffness): the rigid
  bodies' ``M``, ``C``, ``g`` do not use it; :mod:`eomgen.analysis.actuators` does (docs/actuators.md).

Every geometric and inertial quantity is a SymPy expression: a number (exact integers are kept
exact so that structural zeros stay zeros) or an expression in the model's parameter symbols.
``RobotModel.parameters`` lists those symbols with their default numeric values.

The package holds one concept per module, bottom up: :mod:`~eomgen.model.scalars` (numbers,
3-vectors, 3×3 matrices), :mod:`~eomgen.model.snapping`, :mod:`~eomgen.model.transforms`
(rotations, rigid transforms), :mod:`~eomgen.model.actuator`, :mod:`~eomgen.model.contact`,
:mod:`~eomgen.model.parts` (joint types, links, joints, parameters),
:mod:`~eomgen.model.notices`, :mod:`~eomgen.model.coupling` (coupled joints),
:mod:`~eomgen.model.quaternion` (free flyer and ball joints: the layout of q and v),
:mod:`~eomgen.model.robot` (:class:`RobotModel`),
:mod:`~eomgen.model.numbers` (the rule for every number read from a file: finite, magnitude
at most 1e12), :mod:`~eomgen.model.checks` (validation, :func:`build_model`) and
:mod:`~eomgen.model.moving_mass` (what the dynamics see of the masses: joints that move no
mass, inertias whose findings do not matter). Import every name from
``eomgen.model``.
"""

from __future__ import annotations

from ..moved import moved_name
from .actuator import DEFAULT_FRICTION_WIDTH, Actuator
from .checks import (
    MAX_JOINTS,
    build_model,
    check_actuator,
    check_axis,
    check_inertial,
    check_size,
    check_tree,
)
from .contact import POINT, SURFACE, Contact
from .control import Control, make_control
from .coupling import Coupling, couple, coupling_map, make_coupling, uncoupled, with_couplings
from .loop import HINGE, LOOP_KINDS, POINT_LOOP, WELD, Loop, LoopFrame
from .notices import Notice, NoticeKind, emit_notices
from .numbers import MAX_MAGNITUDE, check_model_numbers, check_number
from .moving_mass import massless_joints, massless_notices, settled
from .passive import BallSpring, Spring, Tendon, ball_spring_torque, tendon_force
from .parts import Inertial, Joint, JointType, Link, Parameter
from .quaternion import (
    QuaternionJoint,
    expand_ball_joints,
    expand_joints,
    quaternion_layout,
)
from .robot import (
    RobotModel,
    configuration_size,
    all_scalars,
    float_constants,
    flexible_indices,
    joint_actuators,
    joint_motion,
    lock_joints,
)
from .scalars import IDENTITY3, ZERO3, Mat3, Scalar, Vec3, mat3, parameter_symbol, scalar, vec3
from .snapping import ANGLE_SNAP_TOLERANCE, SNAP_TOLERANCE, Snap, snap, snap_summary, snapping
from .transforms import Transform, rotation_about_axis, rotation_from_rpy



def __getattr__(name: str):
    """The names that left this package for the module of their kind (the free flyer's entry
    names): a warning, then the object at its new place (:data:`eomgen.moved.MOVED_NAMES`)."""
    return moved_name(__name__, name)


__all__ = [
    "BallSpring", "Spring", "Tendon", "ball_spring_torque", "tendon_force",
    "HINGE", "LOOP_KINDS", "POINT_LOOP", "WELD", "Loop", "LoopFrame",
    "MAX_MAGNITUDE", "check_model_numbers", "check_number",
    "ANGLE_SNAP_TOLERANCE", "DEFAULT_FRICTION_WIDTH", "IDENTITY3", "MAX_JOINTS", "POINT",
    "SNAP_TOLERANCE", "SURFACE",
    "ZERO3", "Actuator", "Contact", "Control", "make_control", "Coupling", "couple", "coupling_map", "uncoupled",
    "make_coupling", "with_couplings", "Inertial", "Joint", "JointType", "Link", "Mat3", "Notice",
    "NoticeKind", "Parameter", "QuaternionJoint", "RobotModel", "Scalar", "Snap", "Transform", "Vec3",
    "all_scalars", "build_model", "check_actuator", "float_constants", "check_axis", "check_inertial",
    "check_size", "check_tree", "configuration_size", "emit_notices", "expand_ball_joints", "expand_joints", "flexible_indices", "joint_actuators",
    "joint_motion", "lock_joints", "massless_joints", "massless_notices", "settled", "mat3", "parameter_symbol", "quaternion_layout", "rotation_about_axis",
    "rotation_from_rpy", "scalar", "snap", "snap_summary", "snapping", "vec3",
]
