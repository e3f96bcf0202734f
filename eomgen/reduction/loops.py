"""A scene's loop closures and actuated joints carried into the reduced model, checked."""

from __future__ import annotations

from dataclasses import replace

from ..errors import InvalidLoopError
from ..model import RobotModel
from ..numeric.loop_checks import LoopMobility, LoopProblem, check_loops
from ..scene import Scene, did_you_mean, scene_error


def with_loops(reduced: RobotModel, scene: Scene, notes: list[str]
               ) -> tuple[RobotModel, LoopMobility | None]:
    """``(model, mobility)``: ``reduced`` carrying ``scene``'s loops and actuated joints (their
    links are already kept in the reduced model), checked against its joints
    (:func:`eomgen.numeric.loop_checks.check_loops`), and what the loops leave of the
    mechanism (None without loops); a note says what they are and the degrees of freedom
    they leave.

    Raises
    ------
    SceneError
        For an actuated joint that is not a moving joint of the reduced model. A ball joint named in
        ``actuated`` is its three velocity coordinates (``<joint>_wx``, ``_wy``, ``_wz``).
    InvalidLoopError
        A loop that fails :func:`~eomgen.numeric.loop_checks.check_loops`: a scene's (also a
        :class:`SceneError`, naming the scene and ``loops[k]``), or the description's own (an
        MJCF equality, naming the description file).
    """
    # a ball joint (or the free flyer, ``base``) named whole is its velocity coordinates
    compound = {p.name: reduced.joint_names[p.v_slice] for p in reduced.joint_places
                if p.nq != p.nv}
    for k, joint in enumerate(scene.actuated):
        if joint not in reduced.joint_names and joint not in compound:
            raise scene.error(f"actuated[{k}]", f"'{joint}' is not a moving joint of the "
                              "model" + did_you_mean(joint, reduced.joint_names
                                                     + tuple(compound)))
    actuated = tuple(dict.fromkeys(name for joint in scene.actuated
                                   for name in compound.get(joint, (joint,))))
    own = {loop.name for loop in reduced.loops}  # the description's (MJCF equalities)
    model = replace(reduced, loops=scene.loops, actuated=actuated)
    if not scene.loops:
        return model, None
    try:
        mobility = check_loops(model)
    except LoopProblem as exc:
        raise loop_error(model, scene, exc.index, exc.problem, own) from None
    notes.append("loops (generated with --outputs loop_constraint, loop_jacobian, "
                     "loop_bias, and in contact_jacobian and constrained_forward_dynamics; "
                     "numerically eomgen.numeric.loops.LoopDynamics): "
                     + ", ".join(f"{loop.name} ({loop.kind}"
                                 + (", planar" if loop.plane is not None else "")
                                 + f", {loop.size} rows)" for loop in scene.loops)
                 + "; " + mobility.describe())
    return model, mobility


def loop_error(model: RobotModel, scene: Scene, k: int, problem: str,
               own: set[str] = frozenset()) -> InvalidLoopError:
    """The error of loop ``k`` of ``scene.loops``: naming the scene file and ``loops[k]`` (its
    index in the file), or, for a loop of the description itself (``own``: an MJCF equality,
    which come first), the description file and the equality."""
    loop = scene.loops[k]
    if loop.name in own:
        return InvalidLoopError(model.source, f"equality '{loop.name}'", problem)
    first = sum(1 for other in scene.loops if other.name in own)
    return scene_error(InvalidLoopError)(scene.source, f"loops[{k - first}] '{loop.name}'",
                                         problem)
