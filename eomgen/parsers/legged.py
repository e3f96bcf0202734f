"""Whether a description's root link looks like the floating base of a legged robot:
:func:`floating_base_notice`.

URDF has no way to say that a robot's base is free, so a quadruped or a humanoid, written as a
tree rooted at its trunk or pelvis, reads like an arm bolted to the world there. The URDF
reader (:mod:`eomgen.parsers.urdf`) asks this rule of every model it reads and warns when the
root stands on legs (docs/formats.md surveys the rule over example-robot-data).
"""

from __future__ import annotations

import math

from ..model import Joint, Notice, NoticeKind, RobotModel

#: The root link name by which ROS and Gazebo bolt a model to the world (a massless ``world``
#: link and a fixed joint to the robot's base): such a root is never taken for a floating base.
WORLD_LINK = "world"

#: A branch leaving the root body counts as a leg when, at q = 0, one of its link frames lies
#: below the root link origin (along gravity) by at least this fraction of the model's extent.
LEG_REACH = 0.5

#: At most this many legs are named in the warning.
_SHOWN_LEGS = 6


def floating_base_notice(model: RobotModel) -> Notice | None:
    """A :class:`~eomgen.model.Notice` when the root link looks like the floating base of a
    legged robot, None otherwise.

    URDF has no way to say that a robot's base is free (the ``floating`` joint is not part of
    the specification that robot descriptions follow), so a quadruped or a humanoid reads like
    an arm bolted to the world at its trunk or pelvis. The rule (see docs/formats.md for its
    survey over example-robot-data and its limits):

    * the root link is not named ``world`` (:data:`WORLD_LINK`), and
    * at q = 0, at least two movable joints leaving the *root body* (the root link and the
      links fixed to it) start branches that reach below the root link origin, along gravity,
      by at least :data:`LEG_REACH` times the model's extent (the largest distance of a link
      frame from the root link origin): legs standing on the ground.

    Arms reach up or sideways from their base and hang one chain from it; a hand's fingers and
    a dual-arm torso's arms do not reach far down; legged robots are described with their legs
    straight down at q = 0.

    Parameters
    ----------
    model:
        A model with numeric geometry (as URDF gives).

    Returns
    -------
    Notice or None
        Kind :attr:`~eomgen.model.NoticeKind.FLOATING_BASE`, naming the root link and the legs.
    """
    if model.root == WORLD_LINK:
        return None
    legs = _legs(model, exact=False)
    if legs is _UNDECIDED:
        legs = _legs(model, exact=True)
    if len(legs) < 2:
        return None
    shown = ", ".join(f"'{name}'" for name in legs[:_SHOWN_LEGS]) + \
        (", ..." if len(legs) > _SHOWN_LEGS else "")
    return Notice(
        NoticeKind.FLOATING_BASE, model.source, f"root link '{model.root}'",
        f"looks like a floating base ({len(legs)} branches reach down from it like legs at "
        f"q = 0: {shown}), but is read as bolted to the world",
        f"M, C and g are those of a robot held at '{model.root}' (a scene with "
        "'floating_base: true' gives it a free base, one with 'fixed_base: true' says bolted is "
        "meant; either silences this warning)")


_UNDECIDED = object()


def _link_origins(model: RobotModel, exact: bool):
    """``(origins, extent, height)`` for the rule of :func:`floating_base_notice`: every link
    frame's origin at q = 0 from the root link origin, the largest distance of one, and
    ``height(origin)``, its distance along gravity; None for symbolic geometry, a zero gravity
    or a zero extent. In plain floats, or with ``exact`` in NumPy as the rule was first
    written (for a robot at the rule's threshold only: loading does not import NumPy)."""
    if exact:
        import numpy as np

        try:
            down = np.array([float(g) for g in model.gravity])
            frames = {model.root: (np.eye(3), np.zeros(3))}
            for joint in model.topological_joints:
                R, p = frames[joint.parent]
                R_j = np.array([[float(v) for v in row] for row in joint.origin.rotation])
                p_j = np.array([float(v) for v in joint.origin.translation])
                frames[joint.child] = (R @ R_j, p + R @ p_j)
        except TypeError:  # symbolic geometry: not from a URDF
            return None
        norm = float(np.linalg.norm(down))
        origins = {link: p for link, (_, p) in frames.items()}
        extent = max(float(np.linalg.norm(p)) for p in origins.values())
        if norm == 0 or extent == 0:
            return None
        down /= norm
        return origins, extent, lambda p: float(p @ down)
    try:
        down = [float(g) for g in model.gravity]
        frames = {model.root: (((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)),
                               (0.0, 0.0, 0.0))}
        for joint in model.topological_joints:
            R, p = frames[joint.parent]
            R_j = [[float(v) for v in row] for row in joint.origin.rotation]
            p_j = [float(v) for v in joint.origin.translation]
            frames[joint.child] = (
                tuple(tuple(sum(R[r][k] * R_j[k][c] for k in range(3)) for c in range(3))
                      for r in range(3)),
                tuple(p[r] + sum(R[r][k] * p_j[k] for k in range(3)) for r in range(3)))
    except TypeError:  # symbolic geometry: not from a URDF
        return None
    norm = math.sqrt(sum(g * g for g in down))
    origins = {link: p for link, (_, p) in frames.items()}
    extent = max(math.sqrt(sum(x * x for x in p)) for p in origins.values())
    if norm == 0 or extent == 0:
        return None
    down = [g / norm for g in down]
    return origins, extent, lambda p: sum(p[r] * down[r] for r in range(3))


def _legs(model: RobotModel, exact: bool):
    """The movable joints leaving the root body whose branches reach down like legs (the rule
    of :func:`floating_base_notice`), with the link origins of :func:`_link_origins`. In plain
    floats, a branch whose reach is within 1e-9 of the extent from the threshold (the floats
    and NumPy round far less differently), or a non-finite number, leaves the answer to NumPy:
    ``_UNDECIDED``."""
    found = _link_origins(model, exact)
    if found is None:
        return []
    origins, extent, height = found
    if not exact and not math.isfinite(extent):
        return _UNDECIDED
    children: dict[str, list[Joint]] = {}
    for joint in model.joints:
        children.setdefault(joint.parent, []).append(joint)
    body = {model.root}
    legs = []
    for joint in model.topological_joints:
        if joint.parent not in body:
            continue
        if not joint.type.is_movable:
            body.add(joint.child)
            continue
        stack, depth = [joint.child], -math.inf
        while stack:
            link = stack.pop()
            depth = max(depth, height(origins[link]))
            stack.extend(j.child for j in children.get(link, ()))
        if not exact and not abs(depth - LEG_REACH * extent) > 1e-9 * extent:
            return _UNDECIDED
        if depth >= LEG_REACH * extent:
            legs.append(joint.name)
    return legs
