"""Read a MuJoCo MJCF model (``.xml`` with a ``<mujoco>`` root) into a
:class:`~eomgen.model.RobotModel`.

MuJoCo's own compiler reads the file (the ``simulators`` extra: ``pip install
'eomgen[simulators]'``): default classes, ``childclass``, ``<include>``, angle units, Euler
sequences, ``inertiafromgeom`` and the other compiler options are MuJoCo's to resolve. eomgen's
model is built from the compiled ``mujoco.MjModel`` (:mod:`eomgen.parsers.mjcf.tree` for the
bodies and joints, :mod:`eomgen.parsers.mjcf.actuators` for the actuators,
:mod:`eomgen.parsers.mjcf.extras` for tendons, equalities and what is warned about or refused). A
file the compiler rejects is a :class:`MujocoCompileError` carrying the compiler's message on
one line.

What is read
------------
* Bodies, each a link named as in MuJoCo, with the compiled mass, centre of mass and inertia
  (``body_mass``, ``body_ipos``, ``body_iquat``, ``body_inertia``); the link frame *is* the
  MuJoCo body frame. The world body is the link ``world``.
* ``hinge`` and ``slide`` joints, in MuJoCo's joint order, so ``q`` is MuJoCo's ``qpos`` and
  ``JOINT_NAMES`` MuJoCo's joint names. The body frame as written is the pose at
  ``qpos = ref`` (MuJoCo's ``qpos0``); eomgen's ``q`` equals MuJoCo's ``qpos`` (not
  ``qpos − ref``): the joint origin carries the rotation (or translation) by ``−ref``. A
  joint whose ``pos`` is not the body origin rotates about its anchor: its eomgen joint frame
  sits at the anchor, and a fixed joint ``<body>_anchor`` leads back to the body frame.
* Several joints in one body (planar walkers: ``rootz``, ``rootx``, ``rooty``) are a chain of
  massless links ``<body>_<joint>`` (the frame of each joint but the last), applied in MuJoCo's
  order.
* A body without joints is welded to its parent by a fixed joint ``<body>_weld``.
* The ``free`` joint (a body of the world) is the quaternion free flyer of
  :mod:`eomgen.model.floating` (Pinocchio's layout): ``q[0:7] = (x, y, z, qx, qy, qz, qw)`` where
  MuJoCo's ``qpos`` has ``(x, y, z, qw, qx, qy, qz)``; ``v[0:6]`` is the body twist in the body
  frame (linear, then angular) where MuJoCo's ``qvel`` has the linear velocity in *world* axes
  (the angular one in the body frame, as eomgen's). The joint's MuJoCo name is in
  ``model.info`` (``"mujoco_free_joint"``); the six velocity coordinates keep the free
  flyer's names ``base_vx … base_wz``. With several free bodies (dm_control's quadruped and
  its ball), the one with the most joints below it flies and the others are dropped with
  their subtrees (warned by name: nothing but contacts and equalities joins them to it).
* Each hinge or slide joint's ``armature``, ``damping`` and ``frictionloss`` are its
  :class:`~eomgen.model.Actuator` (``armature``, viscous ``damping``, Coulomb ``friction``;
  docs/actuators.md); those of the free joint go to the six free-flyer coordinates (equal on
  all six, so they map exactly).
* Each hinge or slide joint's ``stiffness`` and ``springref``: its
  :class:`~eomgen.model.Spring` ``−k (q − qpos_spring)``; a ball joint's ``stiffness``: its
  :class:`~eomgen.model.BallSpring`, MuJoCo's ``−k · subQuat(q, qpos_spring)``; each fixed tendon with a stiffness
  or a damping: a :class:`~eomgen.model.Tendon` of ``model.tendons`` (``L = Σ cᵢ qᵢ``, the
  rest lengths ``springlength``, a dead band since MuJoCo 3). With the joints' damping they
  are the output ``tau_p`` (MuJoCo's ``qfrc_passive``, :mod:`eomgen.symbolic.passive`).
* Each body's ``gravcomp``: :attr:`~eomgen.model.RobotModel.gravcomp`, its weight times the
  factor pushed back up at its centre of mass, in ``tau_p`` (MuJoCo's ``qfrc_gravcomp``).
* ``<option gravity>`` (zero when the ``gravity`` flag is disabled).
* Actuators with a joint transmission on hinge and slide joints or a transmission on a fixed
  tendon (the moment ``gear`` times the tendon's coefficients), with no activation dynamics
  or an integrator or filter one (``dyntype``, :attr:`~eomgen.model.Control.dynamics`: the
  state ``act`` of ``forward_dynamics_act``; with ``actearly``, the force one step ahead), a
  fixed or affine gain and bias (``<motor>``, ``<position>``, ``<velocity>``,
  ``<intvelocity>``, ``<general>`` of those kinds), ``<dcmotor>`` on its voltage input
  (its current a state with ``inductance``; ``saturation``, ``cogging``) and ``<pid>`` on its
  position input (its integral a state with ``ki``): the model's :attr:`~eomgen.model.RobotModel.controls`
  (:class:`~eomgen.model.Control`), entries of the input ``ctrl`` in MuJoCo's actuator order
  (``ACTUATOR_NAMES``), with MuJoCo's ``gear`` (first component), ``gainprm``, ``biasprm``,
  ``ctrlrange`` (when ``ctrllimited``) and ``forcerange`` (when ``forcelimited``); the
  outputs ``actuator_forces`` and ``forward_dynamics_ctrl`` (docs/formats.md).
  ``model.info["mujoco_motors"]`` lists ``(actuator, joint, gear · gain)`` of the plain
  motors.
* First-order ``joint`` equalities (``polycoef`` ``c0 c1 0 0 0``): MuJoCo's ``q1 − ref1 = c0
  + c1 (q2 − ref2)`` is the coupling ``q1 = c1 q2 + (ref1 + c0 − c1 ref2)``
  (:mod:`eomgen.model.coupling`; ``q`` is ``qpos``, so the refs enter the offset): ``joint1``
  follows and leaves ``JOINT_NAMES``. A chain of them is written in the independent joints; a
  ``joint`` equality without ``joint2`` (or with ``c1 = 0``) locks ``joint1`` at ``ref1 + c0``
  (``model.info["mujoco_locks"]``). MuJoCo's equalities are soft (``solref``, ``solimp``);
  eomgen's hold exactly.
* ``connect`` and ``weld`` equalities: loops (:attr:`~eomgen.model.RobotModel.loops`,
  docs/loops.md), named after the equality (``eq<i>`` unnamed): a ``connect`` is a point loop
  whose frame b is the anchor on ``body1`` and frame a the same point on ``body2`` (where
  MuJoCo's compiler put it at ``qpos0``), so that ``Φ = p_1 − p_2`` and ``J_l`` are MuJoCo's
  rows and λ is the force on ``body1``; a ``weld`` is a weld loop, frame b on ``body1`` with
  the axes of ``relpose``, frame a on ``body2`` at the ``anchor`` (a point loop with
  ``torquescale="0"``); between sites, the two site frames. Every command applies them as if
  a scene declared them (a scene's own loops come after).

Unnamed bodies and joints are named ``body<i>`` and ``joint<i>`` with MuJoCo's id ``i``;
a name that is taken gets ``_2``, ``_3``, … appended.

Warned about (:class:`~eomgen.errors.UnsupportedFeatureWarning`, refused under ``strict``),
by name: free joints' springs, spatial tendons (and a fixed tendon's armature and
frictionloss), the actuators not read (one line per kind, with their count and first names:
activation dynamics ``dyntype`` user, a DC motor's thermal model, LuGre friction or
on-board controller, a PID's inputs other than ``pos``, ``slewmax`` or ``imax``; spatial tendon, site,
slider-crank or body transmissions; muscles; free and ball joints; user-defined gains),
equalities that are inactive (``active="false"``),
``tendon`` and flex equalities, an equality joining a dropped free body, fluid forces
(``density``, ``viscosity``), MuJoCo 4's polynomial springs and dampers (``stiffnesspoly``,
``dampingpoly``) and control ``delay``, a joint's ``actuatorgravcomp`` (its compensation stays in
``tau_p``). Refused
(:class:`~eomgen.errors.UnsupportedError`), by name: ``joint`` equalities of order above
one; two ``joint`` equalities on one joint or a cycle of them
(:class:`~eomgen.errors.KinematicTreeError`); a ``connect`` or ``weld`` that fails the checks
of a scene's loops (:mod:`eomgen.numeric.loop_checks`: between bodies welded together, loops
leaving no degree of freedom; :class:`~eomgen.errors.InvalidLoopError`). ``ball`` joints are ball joints
(:mod:`eomgen.model.quaternion`): MuJoCo's ``(qw, qx, qy, qz)`` is eomgen's ``(qx, qy, qz,
qw)``; the velocity is the same (the child's angular velocity in the child frame); their
armature, damping and frictionloss are each of their velocity coordinates' drive, as MuJoCo
applies them per dof.

Every number eomgen takes from the compiled model is held to the rule for numbers in
descriptions (finite, magnitude at most 1e12: :mod:`eomgen.model.numbers`) before anything is
built, an :class:`~eomgen.errors.InvalidNumberError` naming the element and the attribute
(:mod:`eomgen.parsers.mjcf.numbers`). A DTD with entity declarations or an external identifier
is refused (:class:`~eomgen.errors.ForbiddenXMLError`), as in URDF.

Contacts, joint limits, geoms, sites, sensors and the rendering options do not enter the
equations of motion and are ignored.
"""

from __future__ import annotations

import re
import warnings
from dataclasses import replace
from pathlib import Path

from ...errors import (DescriptionError, ForbiddenXMLError, InvalidLoopError,
                       UnknownFormatError, UnreadableFileError, UnsupportedError)
from ...model import RobotModel, emit_notices, settled
from ...numeric.loop_checks import LoopProblem, check_loops
from ..registry import register
from .actuators import controls, motors
from .extras import gravity_compensation, model_notices, with_equalities, with_tendons
from .numbers import check_compiled
from .tree import build_tree

#: The optional extra that installs MuJoCo.
EXTRA = "simulators"

_LEADING = re.compile(r"\s*(<\?.*?\?>|<!--.*?-->|<!DOCTYPE[^>]*>)", re.S)
#: A document type declaration with an internal subset (entity declarations) or an external
#: identifier, or an entity declaration: refused, as in URDF (a bare ``<!DOCTYPE mujoco>`` is
#: read).
_DTD = re.compile(r"<!DOCTYPE\b[^>\[]*(?:\[|\b(?:SYSTEM|PUBLIC)\b)|<!ENTITY\b")
_COMMENT = re.compile(r"<!--.*?-->", re.S)


class MujocoCompileError(DescriptionError):
    """MuJoCo's compiler rejected the MJCF file: its message, on one line."""


def is_mjcf(text: str) -> bool:
    """Whether XML ``text`` has a ``<mujoco>`` root element (after the declaration, comments
    and a doctype)."""
    position = 0
    while True:
        match = _LEADING.match(text, position)
        if not match:
            break
        position = match.end()
    return re.match(r"\s*<mujoco[\s/>]", text[position:]) is not None


@register("MJCF", (".xml",), sniff=is_mjcf)
def load_mjcf(path: Path, strict: bool = False, defer_notices: bool = False) -> RobotModel:
    """Read the MJCF file ``path`` with MuJoCo's compiler (see the module docstring).

    Raises
    ------
    UnsupportedError
        MuJoCo is not installed (naming the extra); higher-order joint equalities; under ``strict``, every warned feature.
    MujocoCompileError
        The compiler rejected the file (its message).
    ForbiddenXMLError
        A DTD with entity declarations or an external identifier.
    UnknownFormatError
        The root element is not ``<mujoco>``.
    """
    source = str(path)
    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise UnreadableFileError(source, "", f"cannot read the file ({exc})") from None
    if _DTD.search(_COMMENT.sub("", text)):
        raise ForbiddenXMLError(source, "<!DOCTYPE>", "XML with a DTD, entity declarations or "
                                "external references is not read (security)")
    if not is_mjcf(text):
        raise UnknownFormatError(source, "", "not an MJCF file: the root element is not "
                                 "<mujoco>")
    return model_from_mujoco(compile_mjcf(path), source, strict, defer_notices)


def compile_mjcf(path) -> "mujoco.MjModel":  # noqa: F821
    """MuJoCo's compiled model of the MJCF file ``path``.

    Raises
    ------
    UnsupportedError
        MuJoCo is not installed.
    MujocoCompileError
        The compiler's message, on one line.

    Warns
    -----
    UserWarning
        Each warning of the compiler (a deprecated attribute), on one line.
    """
    mujoco = import_mujoco(str(path))
    said: list[str] = []
    handler = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(said.append)  # the compiler's warnings, else on stderr
    try:
        m = mujoco.MjModel.from_xml_path(str(path))
    except ValueError as exc:
        raise MujocoCompileError(str(path), "", f"MuJoCo's compiler: {_one_line(exc)}") from None
    finally:
        mujoco.set_mju_user_warning(handler)
    for message in said:
        warnings.warn(f"{path}: MuJoCo's compiler: {_one_line(message)}", UserWarning,
                      stacklevel=2)
    return m


def _one_line(message) -> str:
    return "; ".join(line.strip() for line in str(message).splitlines() if line.strip())


def import_mujoco(source: str):
    """The ``mujoco`` module, or an :class:`UnsupportedError` naming the extra."""
    try:
        import mujoco  # here: an optional dependency, loaded only to read MJCF
    except ImportError:
        raise UnsupportedError(source, "", "reading MJCF needs MuJoCo: pip install "
                               f"'eomgen[{EXTRA}]'") from None
    return mujoco


def model_from_mujoco(m, source: str = "<mujoco>", strict: bool = False,
                      defer_notices: bool = False) -> RobotModel:
    """eomgen's model of the compiled MuJoCo model ``m`` (``mujoco.MjModel``); see the module
    docstring. ``source`` names it in messages.

    Raises
    ------
    InvalidNumberError
        A number eomgen reads that is not finite or of magnitude above 1e12
        (:mod:`eomgen.parsers.mjcf.numbers`), naming the element and the attribute.
    """
    check_compiled(m, source)
    model = with_equalities(with_tendons(build_tree(m, source), m, source), m, source)
    if model.loops:  # the same checks as a scene's loops (eomgen.numeric.loop_checks)
        try:
            check_loops(model)
        except LoopProblem as exc:
            raise InvalidLoopError(source, f"equality '{model.loops[exc.index].name}'",
                                   exc.problem) from None
    present = {joint.name for joint in model.joints}
    links = {link.name for link in model.links}
    model = replace(model, gravcomp=tuple((body, factor) for body, factor
                                          in gravity_compensation(m) if body in links))
    # what concerns only the joints of a dropped free body goes with it
    notices = tuple(n for n in model_notices(m, source)
                    if not n.joints or any(j in present for j in n.joints))
    model = replace(model, notices=tuple(model.notices) + notices,
                    controls=tuple(c for c in controls(m)
                                   if all(n in present for n, _ in c.transmission)),
                    info=model.info + (("mujoco_motors", tuple(
                        motor for motor in motors(m) if motor[1] in present)),))
    if not defer_notices:
        model = settled(model)
        emit_notices(model.notices, strict)
    return model


__all__ = ["EXTRA", "MujocoCompileError", "compile_mjcf", "import_mujoco", "is_mjcf",
           "load_mjcf", "model_from_mujoco"]
