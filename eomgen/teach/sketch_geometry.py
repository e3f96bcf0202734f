"""What the kinematic sketch of a handout shows, as plain data: :func:`sketch_geometry`.

The numeric forward kinematics (:func:`eomgen.numeric.link_poses`) at one pose
(:func:`sketch_pose`, 30° at every revolute joint) gives a :class:`SketchGeometry`: joint
origins, centres of mass, the link segments and, when the robot moves in a plane, which plane.
:mod:`eomgen.teach.sketch` draws it.

Every point is in the *world* frame, which is the root link frame (as in :mod:`eomgen.numeric`),
in metres. Joint angles are in radians, prismatic joint positions in metres. ``q[k]`` belongs
to ``model.movable_joints[k]`` (description order). NumPy alone: no matplotlib.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model import RobotModel
from ..numeric import link_poses, numeric_model

Point = tuple[float, float, float]

#: Angle [rad] of every revolute or continuous joint in the default pose: 30°, so that the joint
#: angles are visible in the figure (at 0 the links would line up).
SKETCH_ANGLE = math.pi / 6

#: Value given to a parameter that has none, so that the robot can still be drawn.
PLACEHOLDER_VALUE = 1.0

#: A length [m] or a norm below this counts as zero (here and in the drawing).
TOL = 1e-9


@dataclass(frozen=True)
class SketchGeometry:
    """What the sketch shows: plain data, world (root link) frame, metres.

    Attributes
    ----------
    q : tuple of float, (n,)
        The pose drawn, in ``model.movable_joints`` order: radians for revolute and continuous
        joints, metres for prismatic ones.
    joints : tuple of (str, (x, y, z))
        Every joint, fixed ones included, in description order, with the world origin of its
        joint frame after the joint's motion, i.e. the origin of its child link frame (for a
        revolute joint a point of its axis; for a prismatic joint it slides with ``q``).
    coms : tuple of (str, (x, y, z))
        Every link with mass > 0, in description order, with its centre of mass in the world.
    segments : tuple of ((x, y, z), (x, y, z))
        The links as drawn: for every joint, the line from the origin of its parent link frame
        (the parent joint's origin, or the world origin for the root) to the joint's origin;
        for every link with mass but no child joint, the line from its origin to its centre of
        mass. Zero-length lines are left out.
    plane : (int, int) or None
        ``(i, j)``: the world axes spanning the motion plane when the robot is planar, drawn as
        the horizontal and vertical axes of a 2-D view: (0, 1) for x-y, (0, 2) for x-z, (1, 2)
        for y-z. Planar means every revolute joint turns about a world axis parallel to one
        root axis (the plane normal; at least one such joint), and every prismatic joint slides
        perpendicular to it: then every point moves in a plane parallel to ``(i, j)``. None
        otherwise (a 3-D view).
    placeholder_parameters : tuple of str
        Parameters without a value, drawn with :data:`PLACEHOLDER_VALUE` (1.0).
    """

    q: tuple[float, ...]
    joints: tuple[tuple[str, Point], ...]
    coms: tuple[tuple[str, Point], ...]
    segments: tuple[tuple[Point, Point], ...]
    plane: tuple[int, int] | None
    placeholder_parameters: tuple[str, ...]


def sketch_pose(model: RobotModel) -> tuple[float, ...]:
    """The default pose drawn: every revolute or continuous joint at π/6 rad (30°), so that
    the joint angles can be seen, and every prismatic joint at 0 m.

    Returns
    -------
    tuple of float, (n,)
        In ``model.movable_joints`` order.

    Examples
    --------
    >>> import eomgen
    >>> sketch_pose(eomgen.load(eomgen.example_path("planar_2link")))  # doctest: +ELLIPSIS
    (0.5235987755982..., 0.5235987755982...)
    """
    return tuple(SKETCH_ANGLE if j.rotates else 0.0 for j in model.movable_joints)


def _point(v) -> Point:
    return (float(v[0]), float(v[1]), float(v[2]))


def sketch_geometry(model: RobotModel, q=None) -> SketchGeometry:
    """Forward kinematics of ``model`` at ``q``, as the sketch draws it.

    Parameters
    ----------
    model : RobotModel
        The robot. Parameters without a value are set to :data:`PLACEHOLDER_VALUE` and
        listed in ``placeholder_parameters``.
    q : (n,) array_like, optional
        Joint positions in ``model.movable_joints`` order [rad or m]; :func:`sketch_pose`
        when omitted.

    Returns
    -------
    SketchGeometry
        Points in the world (root link) frame [m].

    Raises
    ------
    ValueError
        When ``q`` has the wrong length or a non-finite entry.
    """
    placeholders = tuple(p.name for p in model.parameters if p.value is None)
    nm = numeric_model(model, values={name: PLACEHOLDER_VALUE for name in placeholders})
    q = sketch_pose(model) if q is None else q
    poses = link_poses(nm, q)  # checks the shape of q
    q = tuple(float(x) for x in q)
    body = {name: i for i, name in enumerate(nm.body_names)}

    def origin(link: str) -> np.ndarray:
        return poses[link][1]

    def com(link: str) -> np.ndarray:
        return poses[link][1] + poses[link][0] @ nm.com[body[link]]

    joints = tuple((j.name, _point(origin(j.child))) for j in model.joints)
    coms = tuple((link.name, _point(com(link.name))) for link in model.links
                 if nm.mass[body[link.name]] > 0)
    lines = [(origin(j.parent), origin(j.child)) for j in model.joints]
    # A link ending the chain is drawn from its origin to its centre of mass.
    parents = {j.parent for j in model.joints}
    lines += [(origin(name), com(name)) for name, _ in coms if name not in parents]
    segments = tuple((_point(a), _point(b)) for a, b in lines if np.linalg.norm(b - a) > TOL)

    return SketchGeometry(
        q=q,
        joints=joints,
        coms=coms,
        segments=segments,
        plane=_motion_plane(model),
        placeholder_parameters=placeholders,
    )


def _motion_plane(model: RobotModel) -> tuple[int, int] | None:
    """The ``(i, j)`` root-frame plane of a planar robot: the plane of
    :func:`eomgen.reduction.planar_motion` when its normal is a root axis (the view is drawn in
    root coordinates), else None."""
    from ..reduction import planar_motion  # start-up time: it imports SymPy; this needs NumPy

    planar = planar_motion(model)
    if planar is None:
        return None
    k = int(np.argmax(np.abs(planar.normal)))
    if abs(abs(planar.normal[k]) - 1.0) > TOL:
        return None
    return {0: (1, 2), 1: (0, 2), 2: (0, 1)}[k]
