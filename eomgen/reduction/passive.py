"""A scene's springs and controls (:mod:`eomgen.scene`'s ``springs:`` and ``controls:``) put on
the robot before it is reduced, as eomgen's YAML would have described them: a spring on a joint
of one coordinate (:class:`~eomgen.model.Spring`) or on a ball joint
(:class:`~eomgen.model.BallSpring`, on the first joint of its chain, as the description's
own), set over the description's; controls (:class:`~eomgen.model.Control`) after the
description's, each on a joint of one coordinate or a fixed tendon of such joints. What the
reduction then does with them (locked joints, merged bodies) is what it does with the
description's own (:mod:`eomgen.reduction.apply`)."""

from __future__ import annotations

from dataclasses import replace

from ..model import BallSpring, RobotModel, Spring
from ..model.joints import KINDS, SPHERICAL
from ..parsers.yaml_format import ONE_AXIS
from ..scene import Scene, did_you_mean


def with_springs_and_controls(model: RobotModel, scene: Scene) -> RobotModel:
    """``model`` with the scene's springs and controls.

    Raises
    ------
    SceneError
        Naming the scene entry: an unknown joint (with the closest name), a spring on a joint
        that has none (fixed, planar, a free flyer), a quaternion reference on a joint of one
        coordinate or a number on a ball joint, a control of a name the description has, or
        on a joint that is not revolute, prismatic or helical.
    """
    if not scene.springs and not scene.controls:
        return model
    joints = {j.name: j for j in model.joints}
    balls = {name: KINDS[kind].velocity_names(name)[0]
             for kind, name in model.compound_joints if kind == SPHERICAL.name}
    virtual = {entry: name for kind, name in model.compound_joints
               for entry in KINDS[kind].velocity_names(name)}  # a compound joint's chain

    def one_axis(joint: str, where: str, what: str) -> None:
        if joint not in joints:
            raise scene.error(where, f"no joint '{joint}' in robot '{model.name}'"
                              + did_you_mean(joint, [*joints, *balls]))
        if joint in virtual or joints[joint].type not in ONE_AXIS:
            kind = (f"a coordinate of joint '{virtual[joint]}'" if joint in virtual
                    else f"a {joints[joint].type.value} joint")
            raise scene.error(where, f"'{joint}' is {kind}: {what}")
    springs = {}
    for name, spring in scene.springs:
        where = f"springs '{name}'"
        if name in balls:
            if isinstance(spring, Spring):
                if spring.reference != 0:
                    raise scene.error(where, f"'{name}' is a ball joint: its reference is a "
                                      "quaternion [x, y, z, w]")
                spring = BallSpring(spring.stiffness)
            springs[balls[name]] = spring
        else:
            one_axis(name, where, "only joints of one coordinate and ball joints have a "
                     "spring")
            if isinstance(spring, BallSpring):
                raise scene.error(where, f"'{name}' has one coordinate: its reference is a "
                                  "number [rad or m], not a quaternion")
            springs[name] = spring
    taken = {c.name for c in model.controls}
    for control in scene.controls:
        where = f"controls '{control.name}'"
        if control.name in taken:
            raise scene.error(where, f"the description ({model.source}) has a control of this "
                              "name")
        for joint in (control.joint,) if control.joint else (j for j, _ in control.coefficients):
            one_axis(joint, where, "a control acts on a revolute, prismatic or helical joint")
    return replace(model, joints=tuple(replace(j, spring=springs[j.name]) if j.name in springs
                                       else j for j in model.joints),
                   controls=model.controls + scene.controls)


__all__ = ["with_springs_and_controls"]
