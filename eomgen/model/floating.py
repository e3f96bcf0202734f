"""Floating bases: a robot's root link let free, as six virtual joints from a fixed ``world`` link.

A legged robot or a humanoid is described (URDF) as a tree rooted at its trunk. To let that
trunk move, a floating base puts six virtual joints between a new fixed ``world`` link and the
root link (massless links between them), so that the Lagrangian derivation
(:func:`eomgen.derive`), the numeric Newton–Euler reference (:mod:`eomgen.numeric`) and code
generation work unchanged (the approach of FROST). There are two charts of the root's pose:

**Euler angles** (:func:`add_floating_base`): true generalised coordinates, ``q̇`` the time
derivative of ``q``:

=========  ============  =========================================================
 q index    joint         motion
=========  ============  =========================================================
 0, 1, 2    base_x/y/z    prismatic along the world x, y, z axes: the root link origin
                          ``p`` [m] in the world frame
 3          base_yaw      revolute about z: yaw ψ [rad]
 4          base_pitch    revolute about the new y: pitch θ [rad]
 5          base_roll     revolute about the new x: roll φ [rad]
 6 …        the robot's   in the description's order
=========  ============  =========================================================

so the root link's pose in the world is ``p`` and ``R = Rz(ψ) Ry(θ) Rx(φ)`` (ZYX Euler angles,
intrinsic yaw–pitch–roll; the same R as URDF's ``rpy="φ θ ψ"``). The world frame is the old
root frame at q = 0, and gravity keeps its components in it. The chart is singular at pitch
θ = ±π/2, and Pinocchio's free flyer maps to it (:mod:`eomgen.numeric.floating_base`: the
maps, the singularity, :class:`~eomgen.numeric.floating_base.PinocchioFreeFlyer`).

**The quaternion free flyer** (:func:`add_free_flyer`): Pinocchio's ``JointModelFreeFlyer`` as a
joint of eomgen's model. The configuration and the velocity then have different sizes,
NQ = NV + 1, laid out as Pinocchio lays out a model built with
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
name: the order of Pinocchio's URDF reader (:func:`pinocchio_order`); a fixed-base model keeps
the description's order instead. ``R`` rotates root-frame vectors into the world frame. The
dynamics are ``M(q) v̇ + C(q, v) v + g(q) = τ`` in these velocities, τ[0:6] being the wrench on
the root (force then moment, root frame); C is the matrix Pinocchio's
``computeCoriolisMatrix`` gives (Ṁ − 2C skew-symmetric).

*Non-unit quaternions.* Every generated function uses the *normalised* quaternion: R is
computed as ``(quadratic form of (x, y, z, w)) / (x² + y² + z² + w²)``, so any nonzero multiple
of a unit quaternion gives the same result (for a unit quaternion, Pinocchio's); a zero
quaternion has no orientation (the results are not finite). :func:`integrate` returns a unit
quaternion.

*How it is derived.* Within the model the free flyer is six virtual joints under the root
(translations along, then rotations about, the root frame's x, y, z axes), held at zero: at the
current configuration they are a chart whose velocities are the root twist. The derivation
(:mod:`eomgen.symbolic.charts`) puts the root pose from ``q[0:7]`` above them and
corrects the chart's second-order terms, so that τ, M, C, g, h and q̈ are the free flyer's.
Ball joints (:mod:`eomgen.model.quaternion`) are the same mechanism with three rotations;
:mod:`eomgen.model.configuration` integrates and differences any such model (its functions are
importable here: without a model, they take the free flyer's layout).

**What both refuse** (:func:`virtual_chain`): a root named ``world``, a name the virtual joints
take, and a robot whose total spatial inertia is singular (:func:`check_spatial_inertia`): its
six base equations would have a singular mass matrix.

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

import numpy as np

from ..errors import InvalidInertiaError, KinematicTreeError, ParameterError
from .bodies import InertialParameters
# integrate, difference, neutral and q̇ of any model with quaternion joints: without a model,
# the free flyer's layout (q[0:7], v[0:6]) and no ball joint; importable here, as the quaternion
# maps are.
from .configuration import configuration_rate, difference, integrate, neutral  # noqa: F401
from .joints.lie import matrix_quaternion, quaternion_matrix  # noqa: F401
from .notices import NoticeKind
from .parts import Joint, JointType, Link
from .joints import FREE_FLYER
from .joints.free_flyer import CONFIGURATION as FREE_FLYER_CONFIGURATION
from .joints.free_flyer import VELOCITY as FREE_FLYER_VELOCITY
from .quaternion import check_entry_names
from .robot import RobotModel, joint_motion
from .scalars import vec3
from .transforms import Transform

#: Name of the fixed link added below a floating robot.
WORLD = "world"

#: The six virtual joints of the Euler chart, in q order: position along world x, y, z, then
#: yaw, pitch, roll.
EULER_JOINTS = ("base_x", "base_y", "base_z", "base_yaw", "base_pitch", "base_roll")

#: The free flyer's configuration names (q[0:7]) and its virtual joints (v[0:6]).
CONFIGURATION_NAMES = FREE_FLYER_CONFIGURATION
VELOCITY_NAMES = FREE_FLYER_VELOCITY

_EULER_AXES = ((1, 0, 0), (0, 1, 0), (0, 0, 1), (0, 0, 1), (0, 1, 0), (1, 0, 0))
_FREE_FLYER_AXES = ((1, 0, 0), (0, 1, 0), (0, 0, 1)) * 2
_TYPES = (JointType.PRISMATIC,) * 3 + (JointType.CONTINUOUS,) * 3


def add_floating_base(model: RobotModel) -> RobotModel:
    """``model`` with a free-flying root in Euler coordinates: six virtual joints from a fixed
    ``world`` link.

    The virtual links between the joints are massless; the robot's root link becomes the
    child of ``base_roll``. The six virtual joints come first in the joint order (q[0:6], see
    the module docstring), the robot's joints after them in their own order. The floating-base
    notice of the description (a root that looks free, read as fixed) is dropped: the root is
    now free.

    Raises
    ------
    KinematicTreeError
        When the robot already has a link named ``world`` (a root so named is bolted to the
        world by convention) or a link or joint with a name the virtual joints take.
    InvalidInertiaError
        When the floating robot's total spatial inertia is singular (no mass, or mass on a
        line, e.g. a massless root with nothing below): its six base equations would have a
        singular mass matrix.
    """
    chain = virtual_chain(model, EULER_JOINTS, "the floating base's virtual joints")
    joints = tuple(
        Joint(name, kind, chain[k], chain[k + 1], Transform(), vec3(axis))
        for k, (name, kind, axis) in enumerate(zip(EULER_JOINTS, _TYPES, _EULER_AXES)))
    return replace(
        model,
        links=(*(Link(name) for name in chain[:-1]), *model.links),
        joints=joints + model.joints,
        root=WORLD,
        notices=tuple(n for n in model.notices if n.kind is not NoticeKind.FLOATING_BASE))


def add_free_flyer(model: RobotModel, origin: Transform | None = None) -> RobotModel:
    """``model`` with a quaternion free flyer between a fixed ``world`` link and its root link
    (module docstring): six virtual joints (massless links between them) come first, the
    robot's joints follow in depth-first order. The floating-base notice of the description is
    dropped (the root is now free). ``origin`` places the free flyer in the world (the origin
    of a URDF ``floating`` joint): the root's pose is then ``origin · (R(quaternion), p)``.

    Raises
    ------
    KinematicTreeError
        A root named ``world``, or a link or joint name the free flyer takes (its virtual
        joints ``base_vx … base_wz``, its configuration entries ``base_x … base_qw``).
    InvalidInertiaError
        The robot's total spatial inertia is singular (see :func:`add_floating_base`).
    """
    chain = virtual_chain(model, VELOCITY_NAMES, "the free flyer's virtual joints")
    virtual = tuple(Joint(name, kind, chain[k], chain[k + 1],
                          (origin or Transform()) if k == 0 else Transform(), vec3(axis))
                    for k, (name, kind, axis)
                    in enumerate(zip(VELOCITY_NAMES, _TYPES, _FREE_FLYER_AXES)))
    floating = replace(
        model,
        links=(*(Link(name) for name in chain[:-1]), *model.links),
        joints=virtual + pinocchio_order(model),
        root=WORLD, compound_joints=((FREE_FLYER.name, "base"), *model.compound_joints),
        notices=tuple(n for n in model.notices if n.kind is not NoticeKind.FLOATING_BASE))
    check_entry_names(floating)  # a joint named base_x: CONFIGURATION_NAMES would repeat it
    return floating


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


def virtual_chain(model: RobotModel, joints: tuple[str, ...], what: str) -> list[str]:
    """The links from a new fixed ``world`` link to ``model``'s root for six virtual joints
    named ``joints`` (massless links ``<root>_<joint>`` between them), after the checks every
    floating base needs: a root not named ``world``, no name taken, a total spatial inertia
    that is not singular (:func:`check_spatial_inertia`). ``what`` names the joints in errors."""
    names = {link.name for link in model.links} | {j.name for j in model.joints}
    if model.root == WORLD:
        raise KinematicTreeError(model.source, f"root link '{WORLD}'",
                                 "a root named 'world' is the fixed world by convention; it "
                                 "cannot float (give the robot's trunk as the root)")
    links = [f"{model.root}_{name}" for name in joints[:5]]
    for name in (WORLD, *joints, *links):
        if name in names:
            raise KinematicTreeError(model.source, f"link or joint '{name}'",
                                     f"the name is taken by {what}")
    check_spatial_inertia(model)
    return [WORLD, *links, model.root]


def total_inertial(model: RobotModel) -> InertialParameters:
    """The inertial parameters of the whole robot (every link, the root's included) about the
    root frame origin, in root-frame coordinates, with every joint at q = 0 (a coupled joint at
    its offset): mass, first moment ``h = m c`` and rotational inertia about the origin
    (:class:`~eomgen.model.bodies.InertialParameters`), in floats.

    Raises
    ------
    TypeError
        When a number of ``model`` is not a real number (a parameter symbol: substitute the
        values first, :meth:`~eomgen.model.RobotModel.with_numeric_parameters`).
    """
    offset = {c.follower: c.offset for c in model.couplings}
    pose = {model.root: (np.eye(3), np.zeros(3))}
    for joint in model.topological_joints:
        R, p = pose[joint.parent]
        T = joint.origin @ joint_motion(joint, offset.get(joint.name, 0))
        pose[joint.child] = (R @ np.array(T.rotation, dtype=float),
                             R @ np.array(T.translation, dtype=float) + p)
    total = _floats(InertialParameters())
    for link in model.links:
        if link.inertial is not None and link.name in pose:
            R, p = pose[link.name]
            total = total + _floats(InertialParameters.from_inertial(link.inertial)
                                    ).transformed(Transform(_rows(R), tuple(p.tolist())))
    return total


def _rows(R: np.ndarray):
    return tuple(tuple(row) for row in R.tolist())


def _floats(params: InertialParameters) -> InertialParameters:
    """``params`` in floats: the sums of :func:`total_inertial` are float arithmetic (in SymPy's
    numbers they took six times as long on a humanoid, Talos: 150 ms)."""
    return InertialParameters(float(params.mass), tuple(float(x) for x in params.first_moment),
                              _rows(np.array(params.inertia, dtype=float)))


def check_spatial_inertia(model: RobotModel) -> None:
    """Refuse a robot whose total spatial inertia (about the root, at q = 0) is singular: no
    mass, or a rotational inertia about the centre of mass that is singular (all mass on one
    line). A robot whose parameters have no values is not checked here (it is checked
    numerically when they get values)."""
    try:
        total = total_inertial(model.with_numeric_parameters())
    except (ParameterError, TypeError):  # parameters without values
        return
    mass, h, I_O = total.mass, np.array(total.first_moment), np.array(total.inertia)
    scale = max(mass, np.abs(I_O).max(), 1e-300)
    where = f"floating base '{model.root}'"
    if mass <= 1e-12 * scale or mass == 0:
        raise InvalidInertiaError(model.source, where, "the robot has no mass: a floating "
                                  "base needs a positive total mass")
    c = h / mass
    I_c = I_O - mass * (c @ c * np.eye(3) - np.outer(c, c))
    if np.linalg.eigvalsh(I_c).min() <= 1e-12 * max(np.abs(I_c).max(), 1e-300):
        raise InvalidInertiaError(model.source, where,
                                  "the robot's rotational inertia about its centre of mass is "
                                  "singular (a massless root with all mass on one line?): "
                                  "a floating base would have a singular mass matrix")


#: How a scene's ``floating_base:`` floats a robot, by its value (``true`` is
#: ``"quaternion"``): the free flyer, or the Euler chain.
FLOATING_BASES = {"quaternion": add_free_flyer, "euler": add_floating_base}


__all__ = [
    "FLOATING_BASES", "WORLD", "EULER_JOINTS", "CONFIGURATION_NAMES", "VELOCITY_NAMES",
    "add_floating_base", "add_free_flyer", "pinocchio_order", "virtual_chain",
    "total_inertial", "check_spatial_inertia",
]
