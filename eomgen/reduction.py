"""Model reduction: the smallest :class:`~eomgen.model.RobotModel` a scene needs, and a report.

:func:`apply_scene` takes a robot and a :class:`~eomgen.scene.Scene` and returns a reduced
model whose M, C, g and τ equal those of the robot with the scene's joints locked, together
with a :class:`ReductionReport` of every step:

1. **Parameters**: those the scene does not keep symbolic take their values.
2. **Moving part**: the movable joints on the paths from ``base`` to each tip (every joint below
   ``base`` when no tips are given), less those the scene locks. Every *other* movable joint is
   locked too: at the scene's ``locked`` position or, when the scene does not list it, at 0
   (the report lists which).
3. **Locking**: a locked joint becomes a fixed joint at its position.
4. **Merging**: every link rigidly attached to a moving body (through fixed and locked joints,
   including whole subtrees outside the scene that hang from it, and the scene's payloads) is
   merged into it: the inertial parameters about the body origin (m, h = m c, I_O) are summed
   after moving each part into the body frame (parallel-axis theorem), then turned back into
   mass, centre of mass and inertia about it. A body with a single link keeps that link's data
   exactly.
5. **Dropping**: links rigidly attached to the world (the root and everything fixed to it,
   including the part above ``base`` once it is locked) cannot influence the moving joints and
   are dropped. The reduced model has one massless link for the world and one link per
   moving joint, whose joint is placed by the composed fixed transforms.
6. **Fixed frame**: when a single moving body hangs from the world, the fixed frame is moved to
   its joint frame at q = 0 (:func:`_reroot`): no constant rotation or offset multiplies every
   later quantity; gravity is re-expressed in that frame. Joint-space M, C, g and τ are the same
   in any fixed frame.
7. **Notices**: of the description's findings that warn (or refuse under ``--strict``,
   :class:`~eomgen.model.Notice`), the reduced model keeps those that still matter: not those
   about joints none of which moves (a ``<mimic>`` finger the scene locks) nor those about links
   the scene drops; the floating-base notice only when the scene does not say
   ``fixed_base: true``. The report's notes list the others. :func:`load_for_scene` loads a
   description and warns only about what a scene keeps.
8. **Planar motion** is recognised (every moving revolute axis parallel to one normal n,
   prismatic axes perpendicular to it, in the root frame at q = 0): the report says so, and
   the component of gravity along n, which does no work in such motion, is dropped, so gravity
   along n gives g ≡ 0 exactly. Out-of-plane inertia terms are not removed from the model
   (the model stores inertia about the centre of mass, where they cannot be zeroed exactly);
   the derivation prunes what no output uses.

Structural zeros stay exact: locks at 0 give exact identity rotations, entries that come out of
composing exact numbers stay exact, and roundoff below :data:`ROUNDOFF` of a value's inputs is
snapped to an exact zero (as :data:`eomgen.model.SNAP_TOLERANCE` does for parsed rotations).

Examples
--------
>>> import eomgen
>>> from eomgen.scene import load_scene
>>> arm = eomgen.load(eomgen.example_path("planar_2link"))
>>> scene = load_scene("s.yaml", text="version: 1\\nlocked: {joint2: 0}\\nsymbolic: none")
>>> reduced, report = apply_scene(arm, scene)
>>> reduced.joint_names, report.locked[0].name
(('joint1',), 'joint2')
"""

from __future__ import annotations

import json
import pickle
import subprocess
import sys
import time
from dataclasses import dataclass, replace
from typing import Iterable, NamedTuple, Sequence

import sympy as sp

from .bodies import InertialParameters, attach_fixed_links, merged_inertial
from .floating import EULER_JOINTS, add_floating_base
from .errors import DescriptionError
from .model import (
    ZERO3,
    Actuator,
    Inertial,
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
    scalar,
    vec3,
)
from .codegen.functions import select_functions
from .scene import Payload, Scene, did_you_mean, scene_error

#: Relative size below which a number computed while merging is roundoff of an exact zero.
ROUNDOFF = 1e-13

#: Default time limit [s] of :func:`measure_derivation`.
MEASURE_TIMEOUT = 300.0


# ----------------------------------------------------------------------------------------------
# The report
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ModelSize:
    """Counts of a model: links, links with mass (bodies), joints, movable joints."""

    links: int
    bodies: int
    joints: int
    dof: int

    @staticmethod
    def of(model: RobotModel) -> "ModelSize":
        bodies = sum(1 for link in model.links
                     if link.inertial is not None and not _is_zero_inertial(link.inertial))
        return ModelSize(len(model.links), bodies, len(model.joints), model.dof)


@dataclass(frozen=True)
class LockedJoint:
    """A movable joint of the description held still at ``position`` [rad or m]; ``listed`` when
    the scene gives the position, else it lies outside the moving part and is locked at 0."""

    name: str
    position: float
    listed: bool


@dataclass(frozen=True)
class MergedBody:
    """A moving body of the reduced model: the child link of ``joint`` with ``links`` (attached
    through fixed or locked joints) and ``payloads`` merged into it."""

    link: str
    joint: str
    links: tuple[str, ...]
    payloads: tuple[str, ...]


@dataclass(frozen=True)
class PlanarMotion:
    """Every moving revolute axis is parallel to ``normal`` (world frame, unit) and every
    prismatic axis perpendicular to it: the bodies move in parallel planes. ``gravity`` is how
    gravity relates to the plane: ``"in the plane"``, ``"along the normal"``, ``"tilted"``,
    ``"none"`` or ``"symbolic"``."""

    normal: tuple[float, float, float]
    gravity: str


@dataclass(frozen=True)
class DerivationCost:
    """What deriving a model cost: seconds (None when not measured or not finished) and the
    operation count of each derived output (``("M", 1878)``, …)."""

    seconds: float | None
    operations: tuple[tuple[str, int], ...] = ()
    timeout: float | None = None  # set when the derivation did not finish within it
    error: str = ""

    @property
    def total_operations(self) -> int | None:
        return sum(n for _, n in self.operations) if self.operations else None

    def describe_time(self) -> str:
        if self.timeout is not None:
            return f"> {self.timeout:g} s (timeout)"
        if self.error:
            return f"failed ({self.error})"
        return "not measured" if self.seconds is None else f"{self.seconds:.2f} s"


@dataclass(frozen=True)
class ReductionReport:
    """What :func:`apply_scene` did, step by step (see the module docstring)."""

    robot: str
    scene: str
    description: str
    before: ModelSize
    after: ModelSize
    base: str
    tips: tuple[str, ...]
    moving: tuple[str, ...]
    world: str
    locked: tuple[LockedJoint, ...]
    merged: tuple[MergedBody, ...]
    dropped: tuple[str, ...]
    dropped_payloads: tuple[str, ...]
    planar: PlanarMotion | None
    notes: tuple[str, ...]
    outputs: tuple[str, ...]
    #: The scene's contacts (:class:`eomgen.contacts.Contact`); each frame is a link of the
    #: reduced model (a massless frame fixed to its body when the merge absorbed it).
    contacts: tuple = ()

    @property
    def locked_by_default(self) -> tuple[str, ...]:
        return tuple(j.name for j in self.locked if not j.listed)

    def markdown(self, before: DerivationCost | None = None,
                 after: DerivationCost | None = None) -> str:
        """The report as a Markdown document; ``before`` and ``after`` are the derivation costs
        of the whole description and of the reduced model, when measured."""
        out = [f"# Scene report: {_md(self.robot)}", ""]
        out.append(f"Scene `{_md(self.scene)}` applied to robot `{_md(self.robot)}`."
                   + (f" {_md(self.description)}" if self.description else ""))
        out += ["", "## Effect", "",
                "| | whole description | with the scene | ratio |", "| --- | ---: | ---: | ---: |"]
        for label, a, b in (("links", self.before.links, self.after.links),
                            ("links with mass", self.before.bodies, self.after.bodies),
                            ("joints", self.before.joints, self.after.joints),
                            ("movable joints (dof)", self.before.dof, self.after.dof)):
            out.append(f"| {label} | {a} | {b} | {_ratio(a, b)} |")
        names = [n for n, _ in (after.operations if after else ())] or \
                [n for n, _ in (before.operations if before else ())]
        ops_before = dict(before.operations) if before else {}
        ops_after = dict(after.operations) if after else {}
        for name in names:
            a, b = ops_before.get(name), ops_after.get(name)
            out.append(f"| operations of {name} | {_or_dash(a)} | {_or_dash(b)} | {_ratio(a, b)} |")
        if before is not None or after is not None:
            b = after.seconds if after else None
            if before is not None and before.timeout is not None:
                speedup = "> " + _ratio(before.timeout, b)
            else:
                speedup = _ratio(before.seconds if before else None, b)
            out.append(f"| derivation time | "
                       f"{before.describe_time() if before else 'not measured'} | "
                       f"{after.describe_time() if after else 'not measured'} | {speedup} |")
        if before is None:
            out += ["", "The whole description was not derived for comparison "
                    "(`eomgen generate --explain` does it)."]
        out += ["", "Outputs: " + ", ".join(f"`{o}`" for o in self.outputs) + "."]
        out += ["", "## Moving part", "",
                f"Base `{_md(self.base)}`, "
                + ("tips " + ", ".join(f"`{_md(t)}`" for t in self.tips) if self.tips else
                   "no tips (every joint below the base)")
                + f"; moving: {len(self.moving)} joints, in this order: "
                + ", ".join(f"`{_md(j)}`" for j in self.moving) + ".",
                "", f"Fixed frame of the reduced model: {_md(self.world)}."]
        out += ["", "## Locked", ""]
        listed = [j for j in self.locked if j.listed]
        for j in listed:
            out.append(f"- `{_md(j.name)}` at {j.position:g} (from the scene)")
        if self.locked_by_default:
            out.append(f"- at 0, because they lie outside the moving part and the scene does not "
                       f"list them ({len(self.locked_by_default)}): "
                       + ", ".join(f"`{_md(n)}`" for n in self.locked_by_default))
        if not self.locked:
            out.append("Nothing: every movable joint moves.")
        out += ["", "## Merged", "",
                "Links attached through fixed or locked joints, and payloads, merged into the "
                "moving body they hang from (composite inertia, parallel-axis theorem):", ""]
        merged_any = False
        for body in self.merged:
            parts = [f"`{_md(n)}`" for n in body.links] + \
                    [f"payload `{_md(n)}`" for n in body.payloads]
            if parts:
                merged_any = True
                out.append(f"- `{_md(body.link)}` (joint `{_md(body.joint)}`) ← " + ", ".join(parts))
        if not merged_any:
            out.append("- nothing to merge")
        out += ["", "## Dropped", "",
                "Rigidly attached to the world, so without influence on the moving joints "
                f"(the root link first), {len(self.dropped)} links: "
                + ", ".join(f"`{_md(n)}`" for n in self.dropped) + "."]
        for name in self.dropped_payloads:
            out.append(f"Payload `{_md(name)}` sits on a link fixed to the world: dropped.")
        out += ["", "## Planar motion", ""]
        if self.planar is None:
            out.append("Not planar: the moving joints' axes are not all parallel (revolute) and "
                       "perpendicular (prismatic) to one direction.")
        else:
            n = ", ".join(f"{x:.6g}" for x in self.planar.normal)
            out.append(f"Planar: every body moves in a plane with normal ({n}) in the root frame; "
                       f"gravity {self.planar.gravity}.")
        if self.notes:
            out += ["", "## Notes", ""] + [f"- {_md(note)}" for note in self.notes]
        return "\n".join(out) + "\n"


def _md(text: str) -> str:
    """Text safe inside Markdown inline code and prose: one line, no backticks."""
    return " ".join(str(text).split()).replace("`", "'")


def _or_dash(value) -> str:
    return "–" if value is None else str(value)


def _ratio(a, b) -> str:
    if a is None or b is None or b == 0:
        return "–"
    return f"{a / b:.1f}×"


class Reduction(NamedTuple):
    """The result of :func:`apply_scene`: the reduced model and the report."""

    model: RobotModel
    report: ReductionReport


# ----------------------------------------------------------------------------------------------
# Applying a scene
# ----------------------------------------------------------------------------------------------


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
    if scene.robot is not None and scene.robot != model.name:
        raise scene.error("robot", f"the scene is for robot '{scene.robot}', not "
                          f"'{model.name}' ({model.source})")
    before = ModelSize.of(model)
    model = _with_actuators(model, scene)
    model, payloads, scene_gravity, notes = _parameters(model, scene)
    if scene.floating_base:
        model = _float(model, scene)
        notes.append(f"the root link '{model.joints[5].child}' floats: six virtual joints "
                     f"{', '.join(EULER_JOINTS)} (position, ZYX Euler angles) from the fixed "
                     f"link '{model.root}' (see eomgen.floating)")
    _check_names(model, scene, payloads)
    base = scene.base or model.root
    moving = _moving_joints(model, scene, base)
    listed = scene.locked_positions
    locks = [LockedJoint(j.name, float(listed.get(j.name, 0.0)), j.name in listed)
             for j in model.movable_joints if j.name not in moving]
    locked_model = lock_joints(model, {j.name: j.position for j in locks})
    reduced, merged, dropped, dropped_payloads = _merge(locked_model, payloads)
    gravity = model.gravity if scene_gravity is None else scene_gravity
    if scene_gravity is not None:
        notes.append("gravity set by the scene to (" + ", ".join(str(g) for g in gravity)
                     + ") m/s² in the root frame")
    reduced = replace(reduced, gravity=gravity)
    planar = planar_motion(reduced)
    if planar is not None and planar.gravity in ("along the normal", "tilted"):
        reduced = replace(reduced, gravity=_in_plane(reduced.gravity, planar.normal))
        notes.append("the component of gravity along the plane normal does no work in planar "
                     "motion and was dropped" + (": g(q) ≡ 0" if planar.gravity ==
                                                 "along the normal" else ""))
    reduced, world = _reroot(reduced)
    reduced = _keep_contact_frames(locked_model, reduced, scene, set(dropped))
    reduced = replace(reduced, contacts=scene.contacts, frames=scene.frames)
    if scene.contacts:
        notes.append("contacts (generated with --outputs contact_jacobian, contact_bias, constrained_forward_dynamics; numerically eomgen.contacts.ContactDynamics): "
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
        outputs=select_functions(scene.outputs), contacts=scene.contacts)
    return Reduction(reduced, report)


def _float(model: RobotModel, scene: Scene) -> RobotModel:
    """``model`` with a floating base (:func:`eomgen.floating.add_floating_base`); its
    errors name the scene's ``floating_base`` entry."""
    from .errors import DescriptionError
    from .scene import scene_error

    try:
        return add_floating_base(model)
    except DescriptionError as exc:
        raise scene_error(type(exc))(scene.source, "floating_base",
                                     f"{exc.element}: {exc.problem}") from None


def _keep_contact_frames(locked: RobotModel, reduced: RobotModel, scene: Scene,
                         dropped: set[str]) -> RobotModel:
    """Check the scene's contact frames and keep each one in the reduced model: a frame the
    merge absorbed into its body comes back as a massless link fixed to that body."""
    from .symbolic.frames import frame_site

    present = reduced.link_by_name
    links, joints = list(reduced.links), list(reduced.joints)
    names = {l.name for l in links} | {j.name for j in joints}
    wanted = [(f"contacts[{k}] '{c.name}' frame", c.frame, "a contact there holds nothing")
              for k, c in enumerate(scene.contacts)]
    wanted += [(f"frames[{k}]", name, "its pose is constant")
               for k, name in enumerate(scene.frames)]
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
        joints.append(Joint(joint, JointType.FIXED, body, frame, _clean(pose)))
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
    once the scene is applied, for what remains: a mimic finger the scene locks, a link it
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
    from .parsers import load

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
        inertial = _substituted(payload.inertial, fixed)
        for value in _inertial_scalars(inertial):
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
        notes.append("flexible joints (Spong's model, eomgen.actuators; the generated M, C, g "
                     "are the rigid links'): " + ", ".join(flexible))
    return notes


def _substituted(inertial: Inertial, values: dict) -> Inertial:
    if not values:
        return inertial

    def s(x):
        return scalar(x.xreplace({k: scalar(v) for k, v in values.items()}))

    return Inertial(s(inertial.mass), tuple(s(c) for c in inertial.com),
                    tuple(tuple(s(v) for v in row) for row in inertial.inertia))


def _inertial_scalars(inertial: Inertial) -> Iterable[sp.Expr]:
    yield inertial.mass
    yield from inertial.com
    for row in inertial.inertia:
        yield from row


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
    for name, _ in scene.locked:
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
    locked = scene.locked_positions
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
    rigid = attach_fixed_links(model, tidy=_clean)
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
        links.append(Link(joint.child, _combine(parts[k])))
        joints.append(replace(joint, parent=parent_link, origin=placement))
        merged.append(MergedBody(joint.child, joint.name, tuple(merged_links[k]),
                                 tuple(merged_payloads[k])))
    info = tuple((k, v) for k, v in model.info if not str(k).startswith("dh"))
    reduced = RobotModel(name=model.name, links=tuple(links), joints=tuple(joints),
                         root=model.root, gravity=model.gravity, parameters=model.parameters,
                         source=model.source, info=info)
    return reduced, tuple(merged), tuple(dropped), tuple(dropped_payloads)


def _number(x) -> float | None:
    if isinstance(x, sp.Basic) and x.is_number:
        return float(x)
    return None


def _clean(T: Transform) -> Transform:
    """``T`` with rotation entries within roundoff (:data:`ROUNDOFF`) of 0 or ±1 made exact."""
    def snap_rotation(x):
        v = _number(x)
        if v is None:
            return x
        for target in (0, 1, -1):
            if abs(v - target) <= ROUNDOFF:
                return sp.Integer(target)
        return x

    rotation = tuple(tuple(snap_rotation(x) for x in row) for row in T.rotation)
    return Transform(rotation, T.translation)  # type: ignore[arg-type]


def _combine(parts: list[tuple[Inertial, Transform]]) -> Inertial | None:
    """One body's inertial data from parts given in frames with the given poses."""
    if not parts:
        return None
    if len(parts) == 1 and parts[0][1] == Transform():
        return parts[0][0]
    return _inertial(merged_inertial(parts))


def _inertial(p: InertialParameters) -> Inertial | None:
    """Mass, centre of mass and inertia about it from inertial parameters about the origin."""
    m = p.mass
    if p.is_zero:
        return None
    if m == 0:
        return Inertial(0, ZERO3, p.inertia)
    com = tuple(_tidy(h / m, abs_terms=[h]) for h in p.first_moment)
    cc = sum((c * c for c in com), sp.Integer(0))
    inertia = [[sp.Integer(0)] * 3 for _ in range(3)]
    for a in range(3):
        for b in range(a, 3):  # the upper triangle, mirrored: exactly symmetric
            shift = m * ((cc if a == b else 0) - com[a] * com[b])
            inertia[a][b] = inertia[b][a] = _tidy(p.inertia[a][b] - shift,
                                                  abs_terms=[p.inertia[a][b], shift])
    return Inertial(scalar(m), com, tuple(tuple(row) for row in inertia))


def _tidy(x, abs_terms) -> sp.Expr:
    """``x`` as a model scalar; an exact zero when it is roundoff of the ``abs_terms``."""
    v = _number(x)
    if v is None:
        return x
    scale = sum(abs(_number(t) or 0.0) for t in abs_terms)
    if abs(v) <= ROUNDOFF * scale:
        return sp.Integer(0)
    return scalar(v)


def _is_zero_inertial(inertial: Inertial) -> bool:
    return all(x == 0 for x in _inertial_scalars(inertial))


def _world_axes(model: RobotModel) -> dict[str, tuple[float, ...]] | None:
    """Unit axis of every movable joint in the root frame at q = 0; None when symbolic."""
    import numpy as np

    rotation = {model.root: np.eye(3)}
    axes = {}
    for joint in model.topological_joints:
        try:
            R = rotation[joint.parent] @ np.array(joint.origin.rotation, dtype=float)
            axis = R @ np.array(joint.axis, dtype=float)
        except TypeError:
            return None
        rotation[joint.child] = R
        if joint.type.is_movable:
            axes[joint.name] = tuple(axis / np.linalg.norm(axis))
    return axes


def planar_motion(model: RobotModel, tolerance: float = 1e-9) -> PlanarMotion | None:
    """Whether ``model``'s bodies move in parallel planes (see :class:`PlanarMotion`).

    At q = 0, in the root frame: every revolute axis is parallel to the first one, n, and every
    prismatic axis is perpendicular to n (both stay so at every q, since rotations about n keep
    n and vectors perpendicular to it). Needs at least one revolute joint; None otherwise, or
    when the geometry is symbolic.
    """
    import numpy as np

    axes = _world_axes(model)
    if not axes:
        return None
    revolute = [np.array(axes[j.name]) for j in model.movable_joints if j.type.is_revolute]
    prismatic = [np.array(axes[j.name]) for j in model.movable_joints if not j.type.is_revolute]
    if not revolute:
        return None
    n = revolute[0]
    if any(np.linalg.norm(np.cross(n, a)) > tolerance for a in revolute):
        return None
    if any(abs(float(n @ a)) > tolerance for a in prismatic):
        return None
    k = int(np.argmax(np.abs(n)))  # normal pointing along the positive dominant axis
    n = n if n[k] > 0 else -n
    n = np.where(np.abs(n) < 1e-15, 0.0, n)
    normal = tuple(float(x) for x in n)
    try:
        g = np.array(model.gravity, dtype=float)
    except TypeError:  # symbolic: classify by which components are non-zero
        support = [k for k in range(3) if model.gravity[k] != 0]
        if all(n[k] == 0 for k in support):
            return PlanarMotion(normal, "in the plane")
        if len(support) == 1 and abs(n[support[0]]) == 1:
            return PlanarMotion(normal, "along the normal")
        return PlanarMotion(normal, "symbolic")
    size = float(np.linalg.norm(g))
    if size == 0:
        relation = "none"
    elif abs(float(g @ n)) <= tolerance * size:
        relation = "in the plane"
    elif float(np.linalg.norm(np.cross(g, n))) <= tolerance * size:
        relation = "along the normal"
    else:
        relation = "tilted"
    return PlanarMotion(normal, relation)


def _in_plane(gravity, normal) -> tuple:
    """``gravity`` less its component along ``normal`` (exact zeros where they come out so)."""
    if any(not (isinstance(x, sp.Basic) and x.is_number) for x in gravity):
        # symbolic gravity is only classified "along the normal" when n is a coordinate axis
        return vec3([0 if abs(n) == 1 else x for x, n in zip(gravity, normal)])
    g = [float(x) for x in gravity]
    along = sum(a * b for a, b in zip(g, normal))
    return vec3([_tidy(sp.Float(g[i] - along * normal[i], 17), [g[i], along * normal[i]])
                 for i in range(3)])


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
    gravity = vec3([_tidy(sp.Add(*[R[k][i] * g[k] for k in range(3)]),
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
    """A note for each moving body whose subtree carries no mass at all (M is then singular)."""
    children: dict[str, list[str]] = {}
    for j in model.joints:
        children.setdefault(j.parent, []).append(j.child)
    links = model.link_by_name

    def massless(name: str) -> bool:
        inertial = links[name].inertial
        if inertial is not None and not _is_zero_inertial(inertial):
            return False
        return all(massless(c) for c in children.get(name, []))

    return [f"joint '{j.name}' moves nothing with mass: the mass matrix is singular"
            for j in model.movable_joints if massless(j.child)]


# ----------------------------------------------------------------------------------------------
# What a derivation costs
# ----------------------------------------------------------------------------------------------


def derivation_cost(dynamics) -> DerivationCost:
    """The cost of a finished derivation (:class:`eomgen.Dynamics`): seconds and operations per
    output (M, C, g, tau as derived)."""
    from .outputs import derived_symbols

    names = [n for n in derived_symbols() if n in dynamics.outputs]
    return DerivationCost(sum(t for _, t in dynamics.timings),
                          tuple((n, dynamics.operation_count([n])) for n in names))


def measure_derivation(model: RobotModel, outputs: Sequence[str],
                       timeout: float = MEASURE_TIMEOUT) -> DerivationCost:
    """Derive ``model`` in a fresh Python process, after a warm-up derivation of the bundled
    two-link arm (so SymPy's start-up costs are not counted), and return its cost; a
    derivation that takes longer than ``timeout`` seconds is stopped and reported as such."""
    payload = pickle.dumps((model, tuple(outputs)))
    try:
        done = subprocess.run([sys.executable, "-m", "eomgen.reduction"], input=payload,
                              capture_output=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return DerivationCost(None, (), timeout=timeout)
    if done.returncode != 0:
        lines = done.stderr.decode("utf-8", "replace").strip().splitlines()
        return DerivationCost(None, (), error=lines[-1] if lines else f"exit {done.returncode}")
    result = json.loads(done.stdout.decode("utf-8"))
    return DerivationCost(result["seconds"], tuple((n, c) for n, c in result["operations"]))


def _measure_main() -> None:  # pragma: no cover - runs in the subprocess
    from . import derive, example_path, load

    model, outputs = pickle.loads(sys.stdin.buffer.read())  # noqa: S301 - our own parent
    derive(load(example_path("planar_2link")), simplify=False)
    start = time.perf_counter()
    dynamics = derive(model, outputs=outputs, simplify=False)
    seconds = time.perf_counter() - start
    cost = derivation_cost(dynamics)
    json.dump({"seconds": seconds, "operations": list(cost.operations)}, sys.stdout)


if __name__ == "__main__":  # pragma: no cover
    _measure_main()
