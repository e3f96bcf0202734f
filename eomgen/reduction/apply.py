"""Applying a scene to a model (:func:`apply_scene`, :func:`load_for_scene`): the steps 1–8 of
:mod:`eomgen.reduction`, from the whole robot to the reduced model and its report."""

from __future__ import annotations

from dataclasses import replace
from typing import Sequence

import sympy as sp

from ..model.bodies import attach_fixed_links
from ..errors import DescriptionError
from ..model.floating import EULER_JOINTS, FLOATING_BASES, VELOCITY_NAMES
from ..model import (
    Actuator,
    Joint,
    JointType,
    Link,
    Notice,
    NoticeKind,
    RobotModel,
    Transform,
    check_actuator,
    emit_notices,
    lock_joints,
    massless_joints,
    scalar,
    vec3,
    with_couplings,
)
from ..model.coupling import locked_couplings
from ..model.joints import KINDS
from ..model.robot import compound_names, compound_of
from ..model.moving_mass import massless_problem
from ..outputs import select
from ..parsers import load
from ..scene import Payload, Scene, did_you_mean, scene_error
from ..model.bodies import frame_site
from .inertia import (clean_transform, combined_inertial, inertial_scalars, merged_gravcomp,
                      substituted_inertial, tidy)
from .passive import with_springs_and_controls
from .planar import in_plane, planar_motion
from .loops import with_loops
from .report import LockedJoint, MergedBody, ModelSize, Reduction, ReductionReport


def apply_scene(model: RobotModel, scene: Scene | None = None) -> Reduction:
    """The model ``scene`` needs of ``model``, and a report of the reduction.

    Parameters
    ----------
    model:
        The whole robot (see :func:`eomgen.load`).
    scene:
        What to model (see :mod:`eomgen.scene`); None for the empty scene, which only merges
        fixed joints and drops what is fixed to the world.

    Returns
    -------
    Reduction
        ``(model, report)``: the reduced model, whose joint order is the description's order of
        the moving joints, and a :class:`ReductionReport`.

    Raises
    ------
    SceneError
        Naming the scene file and the entry: an unknown link or joint (with the closest name),
        a lock on a joint that is not movable, a tip not below the base, nothing left moving,
        a payload on an unknown link, unknown parameters.
    """
    scene = scene or Scene()
    own = tuple(loop for loop in model.loops if loop not in scene.loops)
    if own:  # the description's own loops (MJCF connect, weld): as if the scene said them
        taken = {loop.name for loop in own} & {loop.name for loop in scene.loops}
        if taken:
            raise scene.error("loops", f"the description ({model.source}) has a loop named "
                              f"'{sorted(taken)[0]}' already (an MJCF equality)")
        scene = replace(scene, loops=own + scene.loops)
    if scene.robot is not None and scene.robot != model.name:
        raise scene.error("robot", f"the scene is for robot '{scene.robot}', not "
                          f"'{model.name}' ({model.source})")
    before = ModelSize.of(model)
    model = with_springs_and_controls(_with_actuators(model, scene), scene)
    model, payloads, scene_gravity, notes = _parameters(model, scene)
    if scene.floating_base == "quaternion":
        model = _float(model, scene, FLOATING_BASES["quaternion"])
        notes.append(f"the root link '{model.joints[5].child}' floats: a free flyer (q: "
                     "position and quaternion x, y, z, w; v: the root twist "
                     f"{', '.join(VELOCITY_NAMES)}) from the fixed link '{model.root}' (see "
                     "eomgen.model.floating)")
    elif scene.floating_base:
        model = _float(model, scene, FLOATING_BASES["euler"])
        notes.append(f"the root link '{model.joints[5].child}' floats: six virtual joints "
                     f"{', '.join(EULER_JOINTS)} (position, ZYX Euler angles) from the fixed "
                     f"link '{model.root}' (see eomgen.model.floating)")
    _check_names(model, scene, payloads)
    model = _with_scene_couplings(model, scene)
    base = scene.base or model.root
    moving = _moving_joints(model, scene, base)
    listed = scene.locked_positions
    compound = compound_names(model)
    inside = compound_of(model)
    locks = [LockedJoint(j.name, float(listed.get(j.name, 0.0)), j.name in listed)
             for j in model.movable_joints if j.name not in moving and j.name not in inside]
    locks = _coupled_locks(model, locks)
    for name, (kind, virtual) in compound.items():  # ball and planar joints: whole or not
        if virtual[0] not in moving:
            position = listed.get(name, tuple(float(x) for x in KINDS[kind].neutral()))
            locks.append(LockedJoint(name, tuple(position), name in listed))
    locked_model = lock_joints(model, {j.name: j.position for j in locks})
    reduced, merged, dropped, dropped_payloads = _merge(locked_model, payloads)
    gravity = model.gravity if scene_gravity is None else scene_gravity
    if scene_gravity is not None:
        notes.append("gravity set by the scene to (" + ", ".join(str(g) for g in gravity)
                     + ") m/s² in the root frame")
    reduced = replace(reduced, gravity=gravity)
    planar = planar_motion(reduced)
    if planar is not None and planar.gravity in ("along the normal", "tilted"):
        reduced = replace(reduced, gravity=in_plane(reduced.gravity, planar.normal))
        notes.append("the component of gravity along the plane normal does no work in planar "
                     "motion and was dropped" + (": g(q) ≡ 0" if planar.gravity ==
                                                 "along the normal" else ""))
    reduced, world = _reroot(reduced)
    reduced = _keep_contact_frames(locked_model, reduced, scene, set(dropped))
    reduced = replace(reduced, contacts=scene.contacts, frames=scene.frames)
    reduced, mobility = with_loops(reduced, scene, notes)
    if scene.contacts:
        notes.append("contacts (generated with --outputs contact_jacobian, contact_bias, constrained_forward_dynamics; numerically eomgen.numeric.contacts.ContactDynamics): "
                     + ", ".join(f"{c.name} on '{c.frame}' ({c.kind}"
                                 + (f", μ = {c.mu:g}" if c.mu is not None else "") + ")"
                                 for c in scene.contacts))
    used = reduced.free_symbols
    unused = [p.name for p in reduced.parameters if p.symbol not in used]
    if unused:
        reduced = replace(reduced, parameters=tuple(p for p in reduced.parameters
                                                    if p.symbol in used))
        notes.append("parameters that no longer appear in the reduced model (dropped): "
                     + ", ".join(unused))
    notes += _massless_notes(reduced)
    notes += _actuator_notes(reduced, scene)
    kept, moot = _split_notices(model.notices, scene, set(reduced.joint_names), set(dropped))
    reduced = replace(reduced, notices=kept)
    notes += _moot_notes(moot, scene.floating_base)
    report = ReductionReport(
        robot=model.name, scene=scene.source, description=scene.description, before=before,
        after=ModelSize.of(reduced), base=base, tips=scene.tips,
        moving=reduced.joint_names, world=world, locked=tuple(locks), merged=merged,
        dropped=dropped,
        dropped_payloads=dropped_payloads, planar=planar, notes=tuple(notes),
        outputs=select(scene.outputs), contacts=scene.contacts, mobility=mobility,
        virtual_joints=(VELOCITY_NAMES if scene.floating_base == "quaternion" else
                        EULER_JOINTS if scene.floating_base else ()))
    return Reduction(reduced, report)


def _coupled_locks(model: RobotModel, locks: list[LockedJoint]) -> list[LockedJoint]:
    """``locks`` with each follower the scene does not list (:attr:`RobotModel.couplings`) at
    the position its locked leaders give it, or left moving with a leader that moves."""
    if not model.couplings:
        return locks
    followers = {c.follower for c in model.couplings}
    given = {j.name: j.position for j in locks if j.listed or j.name not in followers}
    positions, _ = locked_couplings(model, given)
    return [replace(j, position=float(positions[j.name])) for j in locks
            if j.name in positions]


def _with_scene_couplings(model: RobotModel, scene: Scene) -> RobotModel:
    """``model`` with the scene's ``couplings`` added (:mod:`eomgen.model.coupling`); errors
    name the scene file and the entry, and a coupling of a joint the scene locks is refused."""
    if not scene.couplings:
        return model
    locked = scene.locked_positions
    for coupling in scene.couplings:
        for name in [coupling.follower] + [n for n, _ in coupling.leaders]:
            if name in locked:
                raise scene.error(coupling.where, f"joint '{name}' is locked by the scene: "
                                  "a locked joint cannot be coupled")
    try:
        return with_couplings(model, model.couplings + scene.couplings)
    except DescriptionError as exc:
        raise scene_error(type(exc))(scene.source, exc.element, exc.problem) from None


def _float(model: RobotModel, scene: Scene, add) -> RobotModel:
    """``model`` with a floating base (``add``: one of
    :data:`eomgen.model.floating.FLOATING_BASES`); its errors name the scene's
    ``floating_base`` entry."""
    try:
        return add(model)
    except DescriptionError as exc:
        raise scene_error(type(exc))(scene.source, "floating_base",
                                     f"{exc.element}: {exc.problem}") from None


def _keep_contact_frames(locked: RobotModel, reduced: RobotModel, scene: Scene,
                         dropped: set[str]) -> RobotModel:
    """Check the scene's contact frames and keep each one in the reduced model: a frame the
    merge absorbed into its body comes back as a massless link fixed to that body."""
    present = reduced.link_by_name
    links, joints = list(reduced.links), list(reduced.joints)
    names = {l.name for l in links} | {j.name for j in joints}
    wanted = [(f"contacts[{k}] '{c.name}' frame", c.frame, "a contact there holds nothing")
              for k, c in enumerate(scene.contacts)]
    wanted += [(f"frames[{k}]", name, "its pose is constant")
               for k, name in enumerate(scene.frames)]
    # a loop may end on the world: its root link (still present), not a link dropped with it
    loop_ends = [(f"loops[{k}] '{loop.name}' {end} link", getattr(loop, end).link,
                  f"give the pose on the root link '{reduced.root}' instead")
                 for k, loop in enumerate(scene.loops) for end in ("a", "b")]
    wanted += [w for w in loop_ends if w[1] not in present]
    for where, frame, moot in wanted:
        if frame not in locked.link_by_name:
            raise scene.error(where, f"no link '{frame}' in robot '{locked.name}'"
                              + did_you_mean(frame, locked.link_by_name))
        if frame in dropped:
            raise scene.error(where, f"link '{frame}' is fixed to the world once the "
                              f"scene locks its joints (dropped): {moot}")
        if frame in present or frame in names:
            continue
        body, pose = frame_site(locked, frame)
        joint = f"{frame}_contact_frame"
        while joint in names:
            joint += "_"
        links.append(Link(frame, None))
        joints.append(Joint(joint, JointType.FIXED, body, frame, clean_transform(pose)))
        names |= {frame, joint}
    if len(links) == len(reduced.links):
        return reduced
    return replace(reduced, links=tuple(links), joints=tuple(joints))


def _split_notices(notices: Sequence[Notice], scene: Scene, moving: set[str],
                   dropped: set[str]) -> tuple[tuple[Notice, ...], tuple[Notice, ...]]:
    """``(kept, moot)``: the notices that still concern the reduced model, and the others."""
    kept, moot = [], []
    for notice in notices:
        if notice.kind is NoticeKind.FLOATING_BASE:
            matters = not (scene.fixed_base or scene.floating_base)
        else:
            matters = ((not notice.joints or any(j in moving for j in notice.joints))
                       and (not notice.links or any(l not in dropped for l in notice.links)))
        (kept if matters else moot).append(notice)
    return tuple(kept), tuple(moot)


def _moot_notes(moot: Sequence[Notice], scene_floating: bool = False) -> list[str]:
    """Report notes naming the notices the scene made moot."""
    said = "floating_base: true" if scene_floating else "fixed_base: true"
    notes = [f"{n.element}: the scene says {said}, so the floating-base warning is left out"
             for n in moot if n.kind is NoticeKind.FLOATING_BASE]
    others = [n.element for n in moot if n.kind is not NoticeKind.FLOATING_BASE]
    if others:
        notes.append(f"warnings left out, about what the scene locks or drops ({len(others)}): "
                     + ", ".join(others))
    return notes


def load_for_scene(path, scene: Scene | None = None, strict: bool = False,
                   snap: bool = True) -> RobotModel:
    """Read a description and warn (or, under ``strict``, refuse) only about what ``scene``
    keeps; without a scene, about everything, as :func:`eomgen.load` does.

    The findings that warn (:class:`~eomgen.model.Notice`: a ``<mimic>`` joint, an inertia
    that breaks the triangle inequality, a root that looks like a floating base) are emitted
    once the scene is applied, for what remains: a follower the scene locks, a link it
    drops, a floating base it declares fixed (``fixed_base: true``) say nothing.

    Parameters
    ----------
    path:
        The description file (see :func:`eomgen.load`).
    scene:
        The scene the caller will apply (:func:`eomgen.scene.load_scene`), or None.
    strict:
        Raise the first remaining finding's error (``--strict``) instead of warning.
    snap:
        As :func:`eomgen.load` (``False``: keep the description's floats exactly).

    Returns
    -------
    RobotModel
        The *whole* model, the scene not applied (apply it with :func:`apply_scene`).

    Raises
    ------
    DescriptionError
        As :func:`eomgen.load`; :class:`~eomgen.errors.SceneError` when the scene does not
        fit the robot; under ``strict``, the error of the first finding that remains.
    """
    if scene is None:
        return load(path, strict=strict, snap=snap)
    model = load(path, strict=strict, snap=snap, defer_notices=True)
    emit_notices(apply_scene(model, scene).model.notices, strict)
    return model


def _parameters(model: RobotModel, scene: Scene):
    """Fix the parameters the scene does not keep symbolic; add the scene's own.

    Returns the model, the payloads and the scene's gravity (None: the description's) with the
    fixed parameters replaced by their values, and notes for the report.
    """
    declared = {p.name: p for p in model.parameters}
    for p in scene.parameters:
        if p.name in declared:
            raise scene.error(f"parameters '{p.name}'",
                              f"robot '{model.name}' already declares a parameter of this name")
    everything = list(model.parameters) + list(scene.parameters)
    notes: list[str] = []
    if scene.symbolic is None:
        kept = {p.name for p in everything}
    else:
        known = [p.name for p in everything]
        for name in scene.symbolic:
            if name not in known:
                raise scene.error(
                    f"symbolic '{name}'", "unknown parameter"
                    + (f" (known: {', '.join(sorted(known))})" + did_you_mean(name, known)
                       if known else " (neither the robot nor the scene declares parameters)"))
        kept = set(scene.symbolic)
    fixed = {p.symbol: p.value for p in everything if p.name not in kept}
    missing = [p.name for p in everything if p.name not in kept and p.value is None]
    if missing:
        raise scene.error("symbolic", f"parameter {', '.join(missing)} has no value: keep it "
                          "symbolic or give it a value")
    if fixed:
        notes.append("parameters fixed at their values: "
                     + ", ".join(sorted(s.name for s in fixed)))
    if kept:
        notes.append("parameters kept symbolic: " + ", ".join(sorted(kept)))
    reduced = model.substitute(fixed) if fixed else model
    used = set()
    payloads = []
    for payload in scene.payloads:
        inertial = substituted_inertial(payload.inertial, fixed)
        for value in inertial_scalars(inertial):
            used |= {s.name for s in value.free_symbols}
        payloads.append(replace(payload, inertial=inertial))
    for joint in reduced.joints:  # scene parameters set in the scene's actuators
        if joint.actuator is not None:
            used |= {s.name for v in joint.actuator.scalars() for s in v.free_symbols}
    gravity = None
    if scene.gravity is not None:
        gravity = vec3([g.xreplace({k: scalar(v) for k, v in fixed.items()})
                        for g in scene.gravity])
        used |= {s.name for g in gravity for s in g.free_symbols}
    extra = tuple(p for p in scene.parameters if p.name in kept and p.name in used)
    return replace(reduced, parameters=reduced.parameters + extra), payloads, gravity, notes


def _with_actuators(model: RobotModel, scene: Scene) -> RobotModel:
    """``model`` with the scene's actuator values set over the description's (see
    :class:`eomgen.model.Actuator`), checked at the parameters' values."""
    if not scene.actuators:
        return model
    joints = {j.name: j for j in model.joints}
    changed = {}
    for name, values in scene.actuators:
        where = f"actuators '{name}'"
        if name not in joints:
            raise scene.error(where, f"no joint '{name}' in robot '{model.name}'"
                              + did_you_mean(name, joints))
        joint = joints[name]
        if not joint.type.is_movable:
            raise scene.error(where, "a fixed joint cannot have an actuator")
        base = joint.actuator or Actuator()
        values = dict(values)
        if "gear_ratio" in values and "rotor_inertia" not in values \
                and base.rotor_inertia is None:
            raise scene.error(where, "'gear_ratio' given without 'rotor_inertia' (the "
                              "description gives none)")
        joint = replace(joint, actuator=base.updated(values))
        defaults = {p.symbol: p.value for p in (*model.parameters, *scene.parameters)
                    if p.value is not None}
        try:
            check_actuator(scene.source, joint, defaults, where=where)
        except DescriptionError as exc:
            raise scene_error(type(exc))(scene.source, where, exc.problem) from None
        changed[name] = joint
    return replace(model, joints=tuple(changed.get(j.name, j) for j in model.joints))


def _actuator_notes(model: RobotModel, scene: Scene) -> list[str]:
    """What the scene set of the moving joints' actuators, and which joints are flexible."""
    moving = set(model.joint_names)
    notes = []
    set_here = [f"{name} ({', '.join(key for key, _ in values)})"
                for name, values in scene.actuators if name in moving]
    if set_here:
        notes.append("actuators set by the scene: " + ", ".join(set_here))
    ignored = [name for name, _ in scene.actuators if name not in moving]
    if ignored:
        notes.append("actuators of joints that do not move (no effect): " + ", ".join(ignored))
    flexible = [j.name for j in model.movable_joints if j.actuator and j.actuator.flexible]
    if flexible:
        notes.append("flexible joints (Spong's model, eomgen.analysis.actuators; the generated M, C, g "
                     "are the rigid links'): " + ", ".join(flexible))
    return notes


def _check_names(model: RobotModel, scene: Scene, payloads: Sequence[Payload]) -> None:
    links = model.link_by_name
    joints = {j.name: j for j in model.joints}

    def link(name: str, element: str) -> None:
        if name not in links:
            raise scene.error(element, f"no link '{name}' in robot '{model.name}'"
                              + did_you_mean(name, links))

    if scene.base is not None:
        link(scene.base, f"base '{scene.base}'")
    for k, tip in enumerate(scene.tips):
        link(tip, f"tips[{k}] '{tip}'")
    compound = compound_names(model)
    inside = compound_of(model)
    for name, value in scene.locked:
        if name in compound:
            kind = KINDS[compound[name][0]]
            if not isinstance(value, tuple) or len(value) != kind.nq:
                raise scene.error(f"locked '{name}'", f"a {kind.describe()[0]} joint is locked "
                                  f"at its {kind.nq} configuration entries: "
                                  f"[{', '.join(kind.configuration_names(name))}]")
            continue
        if name in inside:
            kind = KINDS[compound[inside[name]][0]]
            raise scene.error(f"locked '{name}'", f"a virtual joint of {kind.describe()[0]} "
                              f"joint '{inside[name]}': lock '{inside[name]}' at its "
                              f"configuration [{', '.join(kind.configuration_names(inside[name]))}]")
        if isinstance(value, tuple):
            raise scene.error(f"locked '{name}'", "expected a number [rad or m]")
        if name not in joints:
            raise scene.error(f"locked '{name}'", f"no joint '{name}' in robot '{model.name}'"
                              + did_you_mean(name, joints))
        if not joints[name].type.is_movable:
            raise scene.error(f"locked '{name}'", "cannot lock a fixed joint (only movable "
                              "joints can be locked)")
    for k, payload in enumerate(payloads):
        link(payload.link, f"payloads[{k}] '{payload.name}' link")


def _moving_joints(model: RobotModel, scene: Scene, base: str) -> set[str]:
    """Names of the movable joints that move under ``scene`` (see the module docstring)."""
    parent = model.parent_joint
    if scene.tips:
        on_paths: set[str] = set()
        for k, tip in enumerate(scene.tips):
            if tip == base:
                raise scene.error(f"tips[{k}] '{tip}'", "the tip is the base itself")
            path, link = [], tip
            while link != base:
                if link not in parent:
                    raise scene.error(f"tips[{k}] '{tip}'",
                                      f"not below the base '{base}' (no path from the base to it)")
                joint = parent[link]
                path.append(joint.name)
                link = joint.parent
            on_paths.update(path)
    else:
        below = {base}
        on_paths = set()
        for joint in model.topological_joints:
            if joint.parent in below:
                below.add(joint.child)
                on_paths.add(joint.name)
    locked = set(scene.locked_positions)
    for name, (_, virtual) in compound_names(model).items():
        if name in locked:
            locked.update(virtual)
    moving = {j.name for j in model.movable_joints if j.name in on_paths and j.name not in locked}
    if not moving:
        what = (f"between base '{base}' and the tips" if scene.tips else f"below '{base}'")
        raise scene.error("tips" if scene.tips else ("base" if scene.base else "locked"),
                          f"nothing moves: no movable joint {what} is left unlocked")
    return moving


def _merge(model: RobotModel, payloads: Sequence[Payload]):
    """Merge every link into the moving body it is rigidly attached to (see module docstring).

    Returns the reduced model (gravity still the description's), the merged bodies, the dropped
    link names and the names of payloads dropped with them.
    """
    rigid = attach_fixed_links(model, tidy=clean_transform)
    movers, site = rigid.movers, rigid.site
    parts = rigid.inertial_parts(model)
    merged_links: list[list[str]] = [[] for _ in movers]
    merged_payloads: list[list[str]] = [[] for _ in movers]
    dropped: list[str] = [model.root]
    for link in model.links:
        body = site[link.name][0]
        if body < 0:
            if link.name != model.root:
                dropped.append(link.name)
        elif link.name != movers[body][0].child:
            merged_links[body].append(link.name)
    dropped_payloads = []
    for payload in payloads:
        body, pose = site[payload.link]
        if body < 0:
            dropped_payloads.append(payload.name)
            continue
        parts[body].append((payload.inertial, pose))
        merged_payloads[body].append(payload.name)
    order = {j.name: k for k, j in enumerate(model.joints)}
    by_description = sorted(range(len(movers)), key=lambda k: order[movers[k][0].name])
    links = [Link(model.root, None)]
    joints = []
    merged = []
    for k in by_description:
        joint, parent, placement = movers[k]
        parent_link = model.root if parent < 0 else movers[parent][0].child
        links.append(Link(joint.child, combined_inertial(parts[k])))
        joints.append(replace(joint, parent=parent_link, origin=placement))
        merged.append(MergedBody(joint.child, joint.name, tuple(merged_links[k]),
                                 tuple(merged_payloads[k])))
    info = tuple((k, v) for k, v in model.info if not str(k).startswith("dh"))
    # the tendons and controls name moving joints only (the locked ones were taken out of
    # them by lock_joints), which keep their names; gravity compensation moves to the bodies
    gravcomp = merged_gravcomp(model, site, parts,
                               [(k, movers[k][0].child) for k in by_description])
    reduced = RobotModel(name=model.name, links=tuple(links), joints=tuple(joints),
                         root=model.root, gravity=model.gravity, parameters=model.parameters,
                         source=model.source, info=info,
                         compound_joints=model.compound_joints, couplings=model.couplings,
                         tendons=model.tendons, controls=model.controls, gravcomp=gravcomp)
    return reduced, tuple(merged), tuple(dropped), tuple(dropped_payloads)


#: Name of the root link of a reduced model whose fixed frame was moved (see :func:`_reroot`).
SCENE_WORLD = "scene_world"


def _reroot(model: RobotModel) -> tuple[RobotModel, str]:
    """Move the fixed frame to the frame of the first moving joint at q = 0, when one moving
    body hangs from the world: its placement becomes the identity (no constant rotation or
    offset multiplies every later quantity) and gravity is re-expressed in the new frame.

    Joint-space M, C, g and τ do not depend on which fixed frame the bodies are described in
    (the potential energy changes by a constant only), so the dynamics are unchanged. With
    several bodies on the world, the root frame is kept. Returns the model and a sentence saying
    which frame is fixed.
    """
    first = [j for j in model.joints if j.parent == model.root]
    kept = f"the root link '{model.root}' frame"
    if len(first) != 1 or first[0].origin == Transform():
        return model, kept
    joint = first[0]
    R = joint.origin.rotation
    g = model.gravity
    gravity = vec3([tidy(sp.Add(*[R[k][i] * g[k] for k in range(3)]),
                          [R[k][i] * g[k] for k in range(3)]) for i in range(3)])
    names = {l.name for l in model.links}
    root = SCENE_WORLD
    while root in names:
        root += "_"
    links = (Link(root, None),) + tuple(l for l in model.links if l.name != model.root)
    joints = tuple(replace(j, parent=root, origin=Transform()) if j is joint else j
                   for j in model.joints)
    pose = joint.origin if model.root_pose is None else model.root_pose @ joint.origin
    return (replace(model, links=links, joints=joints, root=root, gravity=gravity,
                    root_pose=pose),
            f"the frame of joint '{joint.name}' at q = 0 (link '{root}'), where gravity is "
            "(" + ", ".join(f"{float(x):.6g}" if x.is_number else str(x) for x in gravity)
            + ") m/s²; joint-space M, C, g and τ do not depend on the fixed frame")


def _massless_notes(model: RobotModel) -> list[str]:
    """A note for each joint that moves no mass (M is then singular,
    :func:`eomgen.model.massless_joints`)."""
    return [f"joint '{joint}' {massless_problem(links)}"
            for joint, links in massless_joints(model)]