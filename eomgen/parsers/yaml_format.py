"""eomgen's own YAML robot format: URDF's model, written to be read on a slide.

.. code-block:: yaml

    name: planar_2link
    gravity: [0, -g, 0]
    parameters:
      m1: {value: 1.0, description: "mass of link 1 [kg]"}
      lc1: 0.5                     # shorthand for {value: 0.5}
      I1: {value: 1/12}
      g: 9.81
    links:
      - name: base                 # no mass: a massless link
      - name: link1
        mass: m1
        com: [lc1, 0, 0]           # [m], in the link frame
        inertia: {izz: I1}         # about the COM, link-frame axes; missing entries are 0
    joints:
      - name: joint1
        type: revolute             # a joint kind (docs/formats.md lists them; helical
                                   # with pitch: [m/rad])
        parent: base
        child: link1
        origin: {xyz: [0, 0, 0], rpy: [0, 0, 0]}   # optional, default identity
        axis: [0, 0, 1]                            # optional, default [0, 0, 1]
        actuator:                                  # optional: the drive (docs/actuators.md)
          rotor_inertia: 1.0e-4    # [kg m²], with gear_ratio (or armature: r² I directly)
          gear_ratio: 100          # motor turns per joint turn
          damping: 0.1             # viscous [N m s/rad]
          friction: 0.5            # Coulomb [N m], smoothed over friction_width [rad/s]
          stiffness: K1            # [N m/rad]: a flexible joint (Spong's model)
        spring: {stiffness: 2.0, reference: 0.1}   # optional: -k (q - q_ref) on the joint
                                                   # (passive_forces; one-axis joints, and
                                                   # spherical ones: reference [x, y, z, w])
    controls:                      # optional: MuJoCo's actuators, entries of ctrl
      - name: shoulder_servo
        joint: joint1              # a revolute, prismatic or helical joint, or instead
                                   # tendon: {joint1: 1, joint2: -0.5}: a fixed tendon's
                                   # length sum c_i q_i (MuJoCo's tendon transmission)
        gear: 1                    # optional, default 1: force on the joint gear * force
        gain: [kp, 0, 0]           # force = gain * ctrl + bias, each c0 + c1 gear q + c2 gear qd
        bias: [0, -kp, -kv]        # optional, default 0; gain optional, default 1
        ctrlrange: [-1, 1]         # optional: ctrl clamped to it
        forcerange: [-10, 10]      # optional: force clamped to it
        dynamics: filter           # optional: integrator, filter or filterexact: the force
        timeconst: 0.05            # follows the state act (forward_dynamics_act) [s]
      - name: wheel                # a DC motor (MuJoCo's dcmotor; ctrl its voltage [V]),
        joint: joint2              # instead of gain, bias and dynamics:
        dcmotor: {resistance: 2, motorconst: 0.05, timeconst: 0.01, rate_limit: 30,
                  cogging: [0.02, 4, 0.3]}   # the last three optional

Frames and units follow :mod:`eomgen.model` (URDF's conventions). Values are numbers or
expressions read by :func:`eomgen.model.expressions.parse_scalar`; every symbol must be declared under
``parameters``. ``controls:`` is not the joint's ``actuator:`` (the drive: armature,
friction): each entry is one control input (:class:`~eomgen.model.Control`) of
``actuator_forces`` and ``forward_dynamics_ctrl``. A ``spherical`` joint (a ball joint, no ``axis``) is Pinocchio's
``JointModelSpherical``: its configuration is a unit quaternion, its velocity the angular
velocity of the child in the child frame (:mod:`eomgen.model.quaternion`). A ``planar`` joint
(its axis, the plane's normal, 0 0 1) is ``JointModelPlanar``, a ``helical`` joint with
``pitch`` (metres per radian) is ``JointModelHelicalUnaligned``
(:mod:`eomgen.model.joints`). Unknown keys are errors. The full reference is ``docs/formats.md``.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from ..errors import UnsupportedError
from ..model import (
    BallSpring, Control, Inertial, Joint, JointType, Link, RobotModel, Spring, Transform,
    build_model, check_size, scalar, vec3,
)
from .registry import register
from ._yaml import Reader, read_document, top_level_key

TOP_KEYS = ("name", "description", "gravity", "parameters", "links", "joints", "controls")
CONTROL_KEYS = ("name", "joint", "tendon", "gear", "gain", "bias", "ctrlrange", "forcerange",
                "dynamics", "timeconst", "dcmotor")
#: A DC motor's keys (MuJoCo's ``<dcmotor>``, ctrl its voltage): ``timeconst`` gives it a
#: current state, ``rate_limit`` clamps the current's rate, ``cogging`` is ``[A, N, phase]``.
DCMOTOR_KEYS = ("resistance", "motorconst", "timeconst", "rate_limit", "cogging")
#: The activation dynamics a control may have (:attr:`eomgen.model.Control.dynamics`).
CONTROL_DYNAMICS = ("integrator", "filter", "filterexact")
LINK_KEYS = ("name", "mass", "com", "inertia")
JOINT_KEYS = ("name", "type", "parent", "child", "origin", "axis", "pitch", "actuator", "spring")
SPRING_KEYS = ("stiffness", "reference")
ORIGIN_KEYS = ("xyz", "rpy")
JOINT_TYPES = {t.value: t for t in JointType}
UNSUPPORTED_TYPES = ("floating", "mimic")


def sniff(text: str) -> bool:
    """An eomgen robot has top-level ``links:`` and ``joints:`` keys."""
    return top_level_key(text, "links") and top_level_key(text, "joints")


@register("eomgen YAML", (".yaml", ".yml"), sniff)
def load(path, strict: bool = False, defer_notices: bool = False) -> RobotModel:
    """Read an eomgen YAML robot file.

    Parameters
    ----------
    path:
        The ``.yaml`` file.
    strict:
        Refuse (rather than warn about) inertias that break the triangle inequality.
    defer_notices:
        Record such findings in ``RobotModel.notices`` without warning or refusing yet
        (see :func:`eomgen.parsers.load`).

    Raises
    ------
    DescriptionError
        One line naming the file and the element, e.g. ``links[2] 'link2' inertia``; the
        subclass tells the kind of problem (see :mod:`eomgen.errors`).
    """
    path = Path(path)
    return parse(read_document(path), str(path), strict, default_name=path.stem,
                 defer_notices=defer_notices)


def parse(data: dict, source: str, strict: bool = False, default_name: str = "robot",
          defer_notices: bool = False) -> RobotModel:
    """Build the model from an already loaded document (see :func:`load`)."""
    r = Reader(source)
    r.mapping(data, "robot", required=("links", "joints"), optional=TOP_KEYS)
    name = r.text(data["name"], "name") if "name" in data else default_name
    r.read_parameters(data.get("parameters"))
    gravity = r.vector(data["gravity"], "gravity") if "gravity" in data else vec3([0, 0, -9.81])

    link_entries = r.sequence(data["links"], "links")
    joint_entries = r.sequence(data["joints"], "joints", allow_empty=True)
    check_size(source, len(link_entries), len(joint_entries))
    links = []
    for i, entry in enumerate(link_entries):
        r.mapping(entry, r.named(entry, f"links[{i}]"), required=("name",), optional=LINK_KEYS)
        link_name = r.name(entry["name"], f"links[{i}] name")
        where = f"links[{i}] '{link_name}'"
        links.append(Link(link_name, _inertial(r, entry, where)))

    joints = []
    for i, entry in enumerate(joint_entries):
        r.mapping(entry, r.named(entry, f"joints[{i}]"),
                  required=("name", "type", "parent", "child"), optional=JOINT_KEYS)
        joint_name = r.name(entry["name"], f"joints[{i}] name")
        where = f"joints[{i}] '{joint_name}'"
        kind = entry["type"]
        if kind in UNSUPPORTED_TYPES:
            raise UnsupportedError(source, f"{where} type", f"{kind} joints are not supported")
        kind = JOINT_TYPES[r.choice(kind, f"{where} type", JOINT_TYPES)]
        origin = Transform()
        if "origin" in entry:
            o = r.mapping(entry["origin"], f"{where} origin", optional=ORIGIN_KEYS)
            xyz = r.vector(o["xyz"], f"{where} origin xyz") if "xyz" in o else (0, 0, 0)
            rpy = r.vector(o["rpy"], f"{where} origin rpy") if "rpy" in o else (0, 0, 0)
            origin = Transform.from_xyz_rpy(xyz, rpy)
        if kind is JointType.SPHERICAL and "axis" in entry:
            raise UnsupportedError(source, f"{where} axis", "a spherical joint has no axis "
                                   "(it turns about all three)")
        axis = r.vector(entry["axis"], f"{where} axis") if "axis" in entry else vec3([0, 0, 1])
        if ("pitch" in entry) != (kind is JointType.HELICAL):
            raise UnsupportedError(source, f"{where} pitch", "a helical joint needs a pitch "
                                   "[m/rad], and only a helical joint has one")
        pitch = r.scalar(entry["pitch"], f"{where} pitch") if "pitch" in entry else 0
        actuator = r.actuator(entry["actuator"], f"{where} actuator") \
            if "actuator" in entry else None
        spring = _spring(r, entry["spring"], f"{where} spring", kind, source) \
            if "spring" in entry else None
        joints.append(Joint(
            joint_name, kind,
            r.name(entry["parent"], f"{where} parent"),
            r.name(entry["child"], f"{where} child"),
            origin, axis, actuator, pitch, spring))

    info = {"description": r.text(data["description"], "description")} \
        if "description" in data else {}
    controls = read_controls(r, data["controls"], joints) if "controls" in data else ()
    model = build_model(source, name, links, joints, gravity, r.used_parameters(), strict, info,
                        defer_notices=defer_notices)
    return replace(model, controls=controls) if controls else model


#: The joint types a control or a fixed tendon acts on (one coordinate).
ONE_AXIS = (JointType.REVOLUTE, JointType.CONTINUOUS, JointType.PRISMATIC, JointType.HELICAL)


def read_controls(r: Reader, value, joints: list[Joint] | None) -> tuple[Control, ...]:
    """The ``controls:`` entries (module docstring), each on a one-coordinate joint or on a
    fixed tendon of such joints (``tendon: {joint: coefficient, …}``, named after the
    control). ``joints`` None (a scene, read before its robot): the joints are checked when
    the scene is applied."""
    kinds = None if joints is None else {joint.name: joint.type for joint in joints}
    out, seen = [], set()

    def one_axis(joint: str, where: str) -> str:
        joint = r.name(joint, where)
        if kinds is not None and kinds.get(joint) not in ONE_AXIS:
            raise r.error(where, f"'{joint}' is not a revolute, prismatic or helical joint of "
                          "the robot")
        return joint

    for i, entry in enumerate(r.sequence(value, "controls")):
        r.mapping(entry, r.named(entry, f"controls[{i}]"), required=("name",),
                  optional=CONTROL_KEYS)
        name = r.name(entry["name"], f"controls[{i}] name")
        where = f"controls[{i}] '{name}'"
        if name in seen:
            raise r.error(f"{where} name", "a second control of this name")
        seen.add(name)
        if ("joint" in entry) == ("tendon" in entry):
            raise r.error(where, "expected either 'joint' (a joint transmission) or 'tendon' "
                          "(a fixed tendon: {joint: coefficient, ...})")
        joint, tendon, coefficients = None, None, ()
        if "joint" in entry:
            joint = one_axis(entry["joint"], f"{where} joint")
        else:
            if not isinstance(entry["tendon"], dict) or not entry["tendon"]:
                raise r.error(f"{where} tendon", "expected a mapping {joint: coefficient, ...} "
                              "of one joint or more")
            tendon = name
            coefficients = tuple((one_axis(j, f"{where} tendon"),
                                  r.scalar(c, f"{where} tendon {j}"))
                                 for j, c in entry["tendon"].items())
        dynamics = entry.get("dynamics")
        if dynamics is not None and dynamics not in CONTROL_DYNAMICS:
            raise r.error(f"{where} dynamics", f"expected one of {', '.join(CONTROL_DYNAMICS)}")
        if "timeconst" in entry and dynamics not in ("filter", "filterexact"):
            raise r.error(f"{where} timeconst", "a time constant needs dynamics: filter or "
                          "filterexact")
        timeconst = r.scalar(entry.get("timeconst", 1), f"{where} timeconst")
        gain = entry.get("gain", 1)
        gain = [gain, 0, 0] if not isinstance(gain, list) else gain
        control = Control(
            name, joint, r.scalar(entry.get("gear", 1), f"{where} gear"),
            _triple(r, gain, f"{where} gain"), _triple(r, entry.get("bias", [0, 0, 0]),
                                                       f"{where} bias"),
            _range(r, entry.get("ctrlrange"), f"{where} ctrlrange"),
            _range(r, entry.get("forcerange"), f"{where} forcerange"), tendon, coefficients,
            scalar(0), dynamics, timeconst)
        if "dcmotor" in entry:
            control = _dcmotor(r, entry, control, f"{where} dcmotor")
        out.append(control)
    return tuple(out)


def _dcmotor(r: Reader, entry: dict, control: Control, where: str) -> Control:
    """``control`` as the DC motor of ``entry["dcmotor"]`` (:mod:`eomgen.model.control`):
    without ``timeconst`` the affine ``K/R (V − K v)``, with it the current state."""
    clash = [key for key in ("gain", "bias", "dynamics", "timeconst") if key in entry]
    if clash:
        raise r.error(where, f"a DC motor's force is its own: drop {', '.join(clash)}")
    motor = entry["dcmotor"]
    r.mapping(motor, where, required=("resistance", "motorconst"), optional=DCMOTOR_KEYS)
    R, K = (r.scalar(motor[key], f"{where} {key}") for key in ("resistance", "motorconst"))
    cogging = motor.get("cogging")
    if cogging is not None:
        if not isinstance(cogging, list) or len(cogging) != 3:
            raise r.error(f"{where} cogging", "expected [amplitude, poles, phase]")
        cogging = tuple(r.scalar(v, f"{where} cogging[{k}]") for k, v in enumerate(cogging))
    if "timeconst" not in motor:
        if "rate_limit" in motor:
            raise r.error(f"{where} rate_limit", "a current rate limit needs the current "
                          "state: give timeconst")
        return replace(control, gain=(K / R, scalar(0), scalar(0)),
                       bias=(scalar(0), scalar(0), -K * K / R), cogging=cogging)
    limit = motor.get("rate_limit")
    return replace(control, gain=(K, scalar(0), scalar(0)), dynamics="dcmotor",
                   timeconst=r.scalar(motor["timeconst"], f"{where} timeconst"), motor=(R, K),
                   rate_limit=None if limit is None else r.scalar(limit, f"{where} rate_limit"),
                   cogging=cogging)


def _triple(r: Reader, value, where: str) -> tuple:
    if not isinstance(value, list) or len(value) != 3:
        raise r.error(where, "expected a number or a list of 3 values [c0, c_length, "
                      "c_velocity]")
    return tuple(r.scalar(v, f"{where}[{k}]") for k, v in enumerate(value))


def _range(r: Reader, value, where: str):
    if value is None:
        return None
    if not isinstance(value, list) or len(value) != 2:
        raise r.error(where, "expected a list of 2 numbers [low, high]")
    low, high = (r.number(v, f"{where}[{k}]") for k, v in enumerate(value))
    if not low < high:
        raise r.error(where, f"low {low:g} is not below high {high:g}")
    return scalar(low), scalar(high)


def _inertial(r: Reader, entry: dict, where: str) -> Inertial | None:
    if "mass" not in entry:
        for key in ("com", "inertia"):
            if key in entry:
                raise r.error(where, f"'{key}' given without 'mass'")
        return None
    mass = r.scalar(entry["mass"], f"{where} mass")
    com = r.vector(entry["com"], f"{where} com") if "com" in entry else vec3([0, 0, 0])
    if "inertia" in entry:
        return Inertial(mass, com, r.inertia(entry["inertia"], f"{where} inertia"))
    return Inertial(mass, com)


def _spring(r: Reader, value, where: str, kind: JointType, source: str) -> Spring | BallSpring:
    """A joint's ``spring: {stiffness, reference}`` (:func:`read_spring`), on a joint of one
    coordinate or a spherical one."""
    ball = kind is JointType.SPHERICAL
    if not ball and (kind.kind.nv != 1 or not kind.is_movable):
        raise UnsupportedError(source, where, f"a {kind.value} joint has no spring: only "
                               "joints of one coordinate (revolute, prismatic, ...) and "
                               "spherical joints have one")
    return read_spring(r, value, where, source, ball)


def read_spring(r: Reader, value, where: str, source: str, ball: bool) -> Spring | BallSpring:
    """``{stiffness, reference}``: ``stiffness`` ``k ≥ 0``, and for a joint of one coordinate
    (:class:`~eomgen.model.Spring`, ``−k (q − q_ref)``) ``reference`` [rad or m] (default 0)
    with ``k`` in [N m/rad or N/m]; for a spherical joint (``ball``;
    :class:`~eomgen.model.BallSpring`, MuJoCo's ``−k · subQuat(q, q_ref)``) ``reference`` the
    quaternion ``[x, y, z, w]`` where it rests (default the identity; normalised) with ``k`` in
    [N m/rad]."""
    r.mapping(value, where, required=("stiffness",), optional=SPRING_KEYS)
    stiffness = r.scalar(value["stiffness"], f"{where} stiffness")
    if stiffness.is_number and stiffness < 0:
        raise UnsupportedError(source, f"{where} stiffness", f"a negative stiffness "
                               f"({stiffness}): a spring pulls back, k >= 0")
    if ball:
        return BallSpring(stiffness, _rest_quaternion(r, value.get("reference"),
                                                      f"{where} reference", source))
    return Spring(stiffness, r.scalar(value["reference"], f"{where} reference")
                  if "reference" in value else 0)


def _rest_quaternion(r: Reader, value, where: str, source: str) -> tuple[float, ...]:
    """A ball spring's ``reference``: four numbers ``[x, y, z, w]``, not all zero, normalised
    (the identity when absent)."""
    if value is None:
        return (0.0, 0.0, 0.0, 1.0)
    if not isinstance(value, list) or len(value) != 4:
        shown = f"{len(value)} entries" if isinstance(value, list) else repr(value)
        raise UnsupportedError(source, where, "a spherical joint's spring reference is a "
                               f"quaternion [x, y, z, w], got {shown}")
    numbers = [r.number(v, f"{where}[{i}]") for i, v in enumerate(value)]
    norm = sum(v * v for v in numbers) ** 0.5
    if norm == 0.0:
        raise UnsupportedError(source, where, "a quaternion of norm 0 is no rotation")
    return tuple(v / norm for v in numbers)
