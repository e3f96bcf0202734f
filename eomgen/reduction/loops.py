"""A scene's loop closures and actuated joints carried into the reduced model, checked."""

from __future__ import annotations

from dataclasses import replace

from ..model import RobotModel
from ..scene import Scene, did_you_mean
from ..model.bodies import frame_site


def with_loops(reduced: RobotModel, scene: Scene, notes: list[str]) -> RobotModel:
    """``reduced`` carrying ``scene``'s loops and actuated joints (their links are already
    kept in the reduced model); a note says what they are.

    Raises
    ------
    SceneError
        For a loop whose two frames are on the same rigid body (it constrains nothing), or an
        actuated joint that is not a moving joint of the reduced model. A ball joint named in
        ``actuated`` is its three velocity coordinates (``<joint>_wx``, ``_wy``, ``_wz``).
    """
    for k, loop in enumerate(scene.loops):
        body_a, body_b = (frame_site(reduced, f.link)[0] for f in (loop.a, loop.b))
        if body_a == body_b:
            body = f"'{body_a}'" if body_a is not None else "the world (fixed base)"
            raise scene.error(f"loops[{k}] '{loop.name}'",
                              f"frames a (link '{loop.a.link}') and b (link '{loop.b.link}') are "
                              f"on the same rigid body {body}: the loop constrains nothing")
    # a ball joint (or the free flyer, ``base``) named whole is its velocity coordinates
    compound = {j.name: reduced.joint_names[j.v_slice] for j in reduced.quaternion_joints}
    for k, joint in enumerate(scene.actuated):
        if joint not in reduced.joint_names and joint not in compound:
            raise scene.error(f"actuated[{k}]", f"'{joint}' is not a moving joint of the "
                              "model" + did_you_mean(joint, reduced.joint_names
                                                     + tuple(compound)))
    actuated = tuple(dict.fromkeys(name for joint in scene.actuated
                                   for name in compound.get(joint, (joint,))))
    if scene.loops:
        notes.append("loops (generated with --outputs loop_constraint, loop_jacobian, "
                     "loop_bias, and in contact_jacobian and constrained_forward_dynamics; "
                     "numerically eomgen.numeric.loops.LoopDynamics): "
                     + ", ".join(f"{loop.name} ({loop.kind}"
                                 + (", planar" if loop.plane is not None else "")
                                 + f", {loop.size} rows)" for loop in scene.loops))
    return replace(reduced, loops=scene.loops, actuated=actuated)
