"""The quaternion floating base (free flyer): Pinocchio's ``JointModelFreeFlyer`` as a joint of
eomgen's model.

:func:`add_free_flyer` lets the root link of a robot fly: the configuration and the velocity
then have different sizes, NQ = NV + 1, laid out as Pinocchio lays out a model built with
``pinocchio.buildModelFromUrdf(path, pinocchio.JointModelFreeFlyer())``:

==========  =====================================  =========  ===============================
 q index     configuration (NQ entries)             v index    velocity (NV entries)
==========  =====================================  =========  ===============================
 0, 1, 2     root origin ``p`` in the world [m]     0, 1, 2    root linear velocity, root
                                                               frame [m/s] (``Rᵀ ṗ``)
 3 … 6       quaternion (x, y, z, w) of ``R``       3, 4, 5    root angular velocity ω, root
                                                               frame [rad/s]
 7 …         the robot's joints                     6 …        the robot's joints
==========  =====================================  =========  ===============================

The robot's joints come in depth-first order from the root, the joints below one link sorted by
name: the order of Pinocchio's URDF reader (:func:`pinocchio_order`); a fixed-base model keeps the description's order instead. ``R`` rotates
root-frame vectors into the world frame. The dynamics are ``M(q) v̇ + C(q, v) v + g(q) = τ``
in these velocities, τ[0:6] being the wrench on the root (force then moment, root frame); C is
the matrix Pinocchio's ``computeCoriolisMatrix`` gives (Ṁ − 2C skew-symmetric).

**Non-unit quaternions.** Every generated function uses the *normalised* quaternion: R is
computed as ``(quadratic form of (x, y, z, w)) / (x² + y² + z² + w²)``, so any nonzero multiple
of a unit quaternion gives the same result (for a unit quaternion, Pinocchio's); a zero
quaternion has no orientation (the results are not finite). :func:`integrate` returns a unit
quaternion.

**How it is derived.** Within the model the free flyer is six virtual joints under the root
(translations along, then rotations about, the root frame's x, y, z axes), held at zero: at the
current configuration they are a chart whose velocities are the root twist. The derivation
(:mod:`eomgen.symbolic.free_flyer`) puts the root pose from ``q[0:7]`` above them and corrects
the chart's second-order terms, so that τ, M, C, g, h and q̈ are the free flyer's. Ball joints (:mod:`eomgen.model.quaternion`) are the same mechanism with
three rotations; :mod:`eomgen.model.configuration` integrates and differences any such model.

Examples
--------
>>> import numpy as np
>>> q = np.array([0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0])
>>> q1 = integrate(q, np.array([0.1, 0, 0, 0, 0, np.pi / 2]), 1.0)
>>> bool(np.allclose(difference(q, q1), [0.1, 0, 0, 0, 0, np.pi / 2]))
True
"""

from __future__ import annotations

from dataclasses import replace

from .floating import WORLD, virtual_chain
from .model.joints.lie import matrix_quaternion, quaternion_matrix
# integrate, difference, neutral and q̇ of any model with quaternion joints: without a model,
# the free flyer's layout (q[0:7], v[0:6]) and no ball joint.
from .model.configuration import configuration_rate, difference, integrate, neutral
from .model import (FREE_FLYER_CONFIGURATION, FREE_FLYER_VELOCITY, Joint, JointType, Link,
                    NoticeKind, RobotModel, Transform, vec3)

CONFIGURATION_NAMES = FREE_FLYER_CONFIGURATION
VELOCITY_NAMES = FREE_FLYER_VELOCITY

_AXES = ((1, 0, 0), (0, 1, 0), (0, 0, 1)) * 2
_TYPES = (JointType.PRISMATIC,) * 3 + (JointType.CONTINUOUS,) * 3


def add_free_flyer(model: RobotModel, origin: Transform | None = None) -> RobotModel:
    """``model`` with a quaternion free flyer between a fixed ``world`` link and its root link
    (module docstring): six virtual joints (massless links between them) come first, the
    robot's joints follow in depth-first order. The floating-base notice of the description is
    dropped (the root is now free). ``origin`` places the free flyer in the world (the origin
    of a URDF ``floating`` joint): the root's pose is then ``origin · (R(quaternion), p)``.

    Raises
    ------
    KinematicTreeError
        A root named ``world``, or a link or joint name the free flyer takes.
    InvalidInertiaError
        The robot's total spatial inertia is singular (see
        :func:`eomgen.floating.add_floating_base`).
    """
    chain = virtual_chain(model, VELOCITY_NAMES, "the free flyer's virtual joints")
    virtual = tuple(Joint(name, kind, chain[k], chain[k + 1],
                          (origin or Transform()) if k == 0 else Transform(), vec3(axis))
                    for k, (name, kind, axis) in enumerate(zip(VELOCITY_NAMES, _TYPES, _AXES)))
    return replace(
        model,
        links=(*(Link(name) for name in chain[:-1]), *model.links),
        joints=virtual + pinocchio_order(model),
        root=WORLD, free_flyer=True,
        notices=tuple(n for n in model.notices if n.kind is not NoticeKind.FLOATING_BASE))


def pinocchio_order(model: RobotModel) -> tuple[Joint, ...]:
    """The joints of ``model`` in the order Pinocchio's URDF reader gives them: depth-first from
    the root, the joints below one link in the byte order of their names (urdfdom keeps a
    link's children sorted by joint name)."""
    children: dict[str, list[Joint]] = {}
    for joint in model.joints:
        children.setdefault(joint.parent, []).append(joint)
    order: list[Joint] = []
    stack = sorted(children.get(model.root, []), key=lambda j: j.name.encode(), reverse=True)
    while stack:
        joint = stack.pop()
        order.append(joint)
        stack.extend(sorted(children.get(joint.child, []), key=lambda j: j.name.encode(),
                            reverse=True))
    return tuple(order)


__all__ = ["CONFIGURATION_NAMES", "VELOCITY_NAMES", "add_free_flyer", "configuration_rate",
           "difference",
           "integrate", "matrix_quaternion", "neutral", "pinocchio_order", "quaternion_matrix"]
