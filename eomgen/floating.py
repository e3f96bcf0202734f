"""Floating bases: a free-flying root as six virtual joints, and the map to Pinocchio's free flyer.

A legged robot or a humanoid is described (URDF) as a tree rooted at its trunk. To let that
trunk move, :func:`add_floating_base` puts six virtual joints between a fixed ``world`` link
and the root link, so that the Lagrangian derivation (:func:`eomgen.derive`), the numeric
Newton–Euler reference (:mod:`eomgen.numeric`) and code generation work unchanged on true
generalised coordinates (the approach of FROST):

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
root frame at q = 0, and gravity keeps its components in it.

**The singularity.** The map from Euler rates to the body angular velocity,
``ω_b = E(θ, φ) [ψ̇, θ̇, φ̇]`` (:func:`euler_rate_matrix`), has ``det E = −cos θ``: at pitch
θ = ±π/2 the yaw and roll axes line up (gimbal lock), a rotation about the lost axis has no
Euler rates, and the mass matrix in these coordinates is singular. :func:`euler_singularity`
measures ``|cos θ|`` and :func:`check_euler` refuses states closer than a tolerance; keep the
trunk's pitch well inside (−π/2, π/2) (a walking or standing robot does).

**Pinocchio's free flyer** (``JointModelFreeFlyer``) uses ``q = [p, quaternion (x, y, z, w)]``
(nq = 7) and ``v = [Rᵀ ṗ, ω_b]`` (nv = 6): the linear velocity of the root origin and the
angular velocity, both in the *root link* frame. With ``T(q)`` the block-diagonal
``diag(Rᵀ, E(θ, φ), 1)`` (:func:`velocity_map`), ``v = T q̇`` and, because generalised
forces map by the transpose (virtual work),

    M = Tᵀ M_pin T,    C q̇ = Tᵀ (h_pin(q, v) + M_pin Ṫ q̇),    g = Tᵀ g_pin,

where ``h_pin = C_pin v`` (:func:`dynamics_from_free_flyer`). :func:`to_free_flyer` and
:func:`from_free_flyer` convert states both ways.

Examples
--------
>>> import numpy as np
>>> q = np.array([0.1, 0.2, 0.3, 0.4, -0.5, 0.6])
>>> qp, v = to_free_flyer(q, np.arange(6.0))
>>> q2, qd2 = from_free_flyer(qp, v)
>>> bool(np.allclose(q2, q) and np.allclose(qd2, np.arange(6.0)))
True
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .errors import InvalidInertiaError, KinematicTreeError
from .model import Joint, JointType, Link, NoticeKind, RobotModel, Transform, vec3
from .numeric.newton_euler import link_poses, numeric_model

# Deprecated path of the numeric maps (they moved to eomgen.numeric.floating_base) and of the
# Pinocchio adapter (eomgen.numeric.pinocchio); the docs and tests name them here.
from .numeric.floating_base import (
    SINGULARITY_TOLERANCE,
    EulerSingularityError,
    base_rotation,
    check_euler,
    dynamics_from_free_flyer,
    euler_angles,
    euler_rate_matrix,
    euler_singularity,
    from_free_flyer,
    to_free_flyer,
    velocity_map,
    velocity_map_dot_qd,
)
from .numeric.pinocchio import PinocchioFreeFlyer

#: Name of the fixed link added below a floating robot.
WORLD = "world"

#: The six virtual joints, in q order: position along world x, y, z, then yaw, pitch, roll.
EULER_JOINTS = ("base_x", "base_y", "base_z", "base_yaw", "base_pitch", "base_roll")

_AXES = ((1, 0, 0), (0, 1, 0), (0, 0, 1), (0, 0, 1), (0, 1, 0), (1, 0, 0))
_TYPES = (JointType.PRISMATIC,) * 3 + (JointType.CONTINUOUS,) * 3


def add_floating_base(model: RobotModel) -> RobotModel:
    """``model`` with a free-flying root: six virtual joints from a fixed ``world`` link.

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
        for k, (name, kind, axis) in enumerate(zip(EULER_JOINTS, _TYPES, _AXES)))
    return replace(
        model,
        links=(*(Link(name) for name in chain[:-1]), *model.links),
        joints=joints + model.joints,
        root=WORLD,
        notices=tuple(n for n in model.notices if n.kind is not NoticeKind.FLOATING_BASE))


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


def check_spatial_inertia(model: RobotModel) -> None:
    """Refuse a robot whose total spatial inertia (about the root, at q = 0) is singular."""
    try:
        nm = numeric_model(model)
    except Exception:  # noqa: BLE001 - parameters without values: checked numerically later
        return
    poses = link_poses(nm, np.zeros(nm.n))
    mass, h, I_O = 0.0, np.zeros(3), np.zeros((3, 3))
    for i, name in enumerate(nm.body_names):
        R, p = poses[name]
        m = nm.mass[i]
        c = p + R @ nm.com[i]
        mass += m
        h += m * c
        I_O += R @ nm.inertia[i] @ R.T + m * (c @ c * np.eye(3) - np.outer(c, c))
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


__all__ = [
    "WORLD", "EULER_JOINTS", "SINGULARITY_TOLERANCE", "EulerSingularityError",
    "add_floating_base", "base_rotation", "euler_angles", "euler_rate_matrix",
    "euler_singularity", "check_euler", "velocity_map", "velocity_map_dot_qd",
    "to_free_flyer", "from_free_flyer", "dynamics_from_free_flyer", "PinocchioFreeFlyer",
]
