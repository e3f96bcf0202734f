"""Scenes: what of a robot to model, read from a small YAML file.

A robot description says what the robot *is*; a scene says what a task *uses* of it: the part
that moves (a ``base`` link and ``tips``), joints held still (``locked``), loads carried
(``payloads``), the ``gravity`` it works in, the parameters kept ``symbolic`` and the
``outputs`` wanted. :func:`eomgen.reduction.apply_scene` turns a robot and a scene into the
smaller model the scene needs, and a report of what it did.

Version 1 of the format (every key but ``version`` is optional)::

    version: 1                    # required: the scene format version
    robot: talos                  # the robot's name; another robot is an error
    description: Left arm, the rest of the robot held still.
    fixed_base: true              # the root link is bolted to the world, on purpose
    floating_base: false          # or: the root link flies free: true or 'quaternion'
                                  #   (Pinocchio's free flyer, NQ = NV + 1), 'euler' (six
                                  #   virtual joints, ZYX Euler angles);
                                  #   'base: floating' says the same as true
    base: torso_2_link            # the link the moving part hangs from (default: the root)
    tips: [arm_left_7_link]       # its ends (default: everything below base)
    locked:                       # joint: position [rad or m]; other joints outside the
      torso_2_joint: 0.1          #   moving part are locked at 0
    payloads:                     # rigid loads fixed to links
      - link: arm_left_7_link
        name: tool
        mass: 1.5                 # kg
        com: [0, 0, -0.1]         # m, in the link frame
        inertia: {ixx: 0.01, iyy: 0.01, izz: 0.002}   # kg m², about com, link axes
    actuators:                    # joint: drive values over the description's
      arm_left_4_joint: {rotor_inertia: 1.0e-4, gear_ratio: 100, damping: 0.5,
                         friction: 0.2, stiffness: 1.0e4}   # see docs/actuators.md
    gravity: [0, 0, -9.81]        # m/s² in the root link frame; none for no gravity
    parameters: {m_load: 1.5}     # new symbols for payload values (name: default value)
    symbolic: [m_load]            # parameters kept symbolic (default: all; none for none)
    outputs: [M, C, g]            # symbols or function names of eomgen.outputs.OUTPUTS
    contacts:                     # frames held still (see eomgen.numeric.contacts, docs/contact.md)
      - frame: FL_FOOT            # a link of the robot
        type: point               # point (3D, default) or surface (6D)
        mu: 0.7                   # friction coefficient, >= 0 (optional)
        baumgarte: {kp: 0, kd: 0} # optional stabilisation gains [1/s², 1/s]
    frames: [FL_FOOT, base_link] # links whose pose, Jacobians and J̇ q̇ frame_* outputs give
                                 #   (default: the contact frames, else the leaf links)
    couplings:                    # coupled joints: q_joint = ratio q_to + offset, or the
      - {joint: finger2, to: finger1, ratio: 1, offset: 0}   # linear form below; the
      - {joint: diff_out, to: {wheel_l: 0.5, wheel_r: 0.5}}  # follower is no coordinate
                                  #   (eomgen.model.coupling; ratio 1, offset 0 by default)
    loops:                        # loop closures: frame b held on frame a (docs/loops.md)
      - name: closure             # names its rows (closure.x, ...) and forces
        type: point               # point (3 rows), hinge (5) or weld (6)
        a: {link: rocker, xyz: [0.5, 0, 0], rpy: [0, 0, 0]}   # a link, a pose in it
        b: {link: coupler, xyz: [1, 0, 0]}
        axis: [0, 0, 1]           # a hinge's axis, in frame a's (and b's) axes
        plane: [0, 0, 1]          # planar loop: the plane's normal (world axes); keeps the
                                  #   2 in-plane translations (+ the rotation of a weld)
    actuated: [crank_joint]       # the driven joints of a parallel robot (the others are
                                  #   passive), for the parallel inverse dynamics
    springs:                      # joint: its spring, as in eomgen's YAML (docs/formats.md):
      knee: {stiffness: 2.0, reference: 0.1}   # -k (q - q_ref); a spherical joint's
      hip: {stiffness: 1.5, reference: [0, 0, 0, 1]}   # reference is a quaternion x, y, z, w
    controls:                     # MuJoCo-style actuators, entries of ctrl, as YAML's
      - {name: knee_servo, joint: knee, gain: [10, 0, 0], bias: [0, -10, -1]}

The file is read like eomgen's robot YAML (:mod:`eomgen.parsers._yaml`): safe loading, no
aliases, size and depth limits, and an unknown key is an error that lists the known ones. Keys
planned for later versions (:data:`PLANNED_KEYS`) are refused by name until they exist.

Examples
--------
>>> scene = load_scene("s.yaml", text="version: 1\\nlocked: {joint2: 0.5}\\noutputs: [g]")
>>> from eomgen.outputs import OUTPUTS
>>> scene.locked_positions, [OUTPUTS[f].symbol for f in scene.outputs]
({'joint2': 0.5}, ['g'])
"""

from __future__ import annotations

import functools
import warnings
from dataclasses import dataclass, fields, replace
from pathlib import Path

from .model import HINGE, LOOP_KINDS, POINT, SURFACE, Contact, Loop, LoopFrame, Transform
from .errors import DescriptionError, SceneError, did_you_mean  # noqa: F401  (re-export)
from .model import Coupling, Inertial, Parameter, Vec3, check_inertial, make_coupling, mat3, vec3
from .model import BallSpring, Control, Link, Spring, check_model_numbers
from .outputs import select
from .parsers._yaml import Reader, read_document
from .parsers.yaml_format import read_controls, read_spring

#: The scene format version this eomgen reads.
SCENE_VERSION = 1

#: Top-level keys of a version-1 scene, in documentation order.
SCENE_KEYS = ("version", "robot", "description", "fixed_base", "floating_base", "base", "tips",
              "locked", "payloads", "actuators", "gravity", "parameters", "symbolic", "outputs",
              "contacts", "frames", "couplings", "loops", "actuated", "springs", "controls")

#: Keys reserved for later versions of the format; refused with a message saying so (those of
#: :data:`ACTUATOR_ALIASES` with a pointer to ``actuators``, which holds them per joint now).
PLANNED_KEYS = ("friction", "armature", "flexible_joints", "joint_limits")

#: Planned whole-scene keys that ``actuators`` now covers per joint.
ACTUATOR_ALIASES = ("friction", "armature", "flexible_joints")

PAYLOAD_KEYS = ("link", "name", "mass", "com", "inertia")

#: The values of ``floating_base`` and what they mean: no floating base, or its chart.
FLOATING_CHARTS = {False: False, True: "quaternion", "euler": "euler", "quaternion": "quaternion"}

#: ``base: floating`` is short for ``floating_base: true`` (a link of this name cannot be a
#: scene's base).
FLOATING = "floating"

CONTACT_KEYS = ("frame", "type", "mu", "baumgarte", "normal", "name")
LOOP_KEYS = ("name", "type", "a", "b", "axis", "plane")
LOOP_FRAME_KEYS = ("link", "xyz", "rpy")

COUPLING_KEYS = ("joint", "to", "ratio", "offset")


@dataclass(frozen=True)
class Payload:
    """A rigid load fixed to ``link``: mass [kg], centre of mass [m] in the link frame and
    inertia [kg m²] about the centre of mass in the link frame axes (``inertial``)."""

    link: str
    inertial: Inertial
    name: str


@dataclass(frozen=True)
class Scene:
    """What of a robot to model (see the module docstring for the file format).

    Attributes
    ----------
    source:
        The scene file (or a label), named by every error about the scene.
    fixed_base:
        The robot's root link is meant to be bolted to the world: silences the warning about a
        root that looks like a floating base (:mod:`eomgen.parsers.urdf`), as the task holds
        the robot still (an arm of a humanoid on a fixed torso, a legged robot on a stand).
    floating_base:
        The root link flies free (:data:`eomgen.model.floating.FLOATING_BASES`):
        ``"quaternion"`` (what ``true`` means): Pinocchio's free flyer (a unit quaternion in
        q, the root twist in v); ``"euler"``: :func:`eomgen.model.floating.add_floating_base` puts
        six virtual joints (x, y, z, yaw, pitch, roll) between a fixed ``world`` link and it
        (what ``true`` meant before the quaternion became the default). False for a root that
        does not fly.
    base, tips:
        The moving part is every movable joint on a path from ``base`` (default: the root) to
        one of ``tips`` (default: every joint below ``base``).
    locked:
        ``(joint, position)`` pairs [rad or m], in file order; a ball or planar joint's
        position is its configuration entries (a ball joint's quaternion x, y, z, w).
    payloads:
        Loads fixed to links.
    actuators:
        ``(joint, ((key, value), ...))`` pairs, in file order: actuator values (see
        :class:`~eomgen.model.Actuator`) set over the description's, key by key.
    gravity:
        Gravitational acceleration [m/s²] in the root link frame; None keeps the description's.
    parameters:
        Parameters the scene declares (for payload values).
    symbolic:
        Names of the parameters kept symbolic; None keeps every parameter symbolic.
    outputs:
        The functions wanted (:func:`eomgen.outputs.select` names); None
        for all.
    contacts:
        Frames held still (:class:`eomgen.model.Contact`), in file order.
    frames:
        Links whose kinematics the ``frame_*`` outputs give (``FRAME_NAMES``), in file order;
        empty for the default (the contact frames, else the leaf links).
    couplings:
        Coupled joints (:class:`eomgen.model.Coupling`), in file order: each ``joint``
        follows ``ratio · to + offset`` (or ``Σ gain · leader + offset`` for ``to`` a mapping).
    loops:
        Loop closures (:class:`eomgen.model.Loop`), in file order.
    actuated:
        The driven joints (``actuated:``), in file order; empty: every joint.
    springs:
        ``(joint, spring)`` pairs, in file order: a :class:`~eomgen.model.Spring`, or a
        :class:`~eomgen.model.BallSpring` when the reference is a quaternion; set over the
        description's when the scene is applied (numbers only, no parameters).
    controls:
        Controls (:class:`~eomgen.model.Control`) added to the description's, in file order
        (numbers only, no parameters); their joints are checked when the scene is applied.
    """

    source: str = "<scene>"
    version: int = SCENE_VERSION
    robot: str | None = None
    description: str = ""
    fixed_base: bool = False
    base: str | None = None
    tips: tuple[str, ...] = ()
    locked: tuple[tuple[str, float], ...] = ()
    payloads: tuple[Payload, ...] = ()
    actuators: tuple[tuple[str, tuple[tuple[str, object], ...]], ...] = ()
    gravity: Vec3 | None = None
    parameters: tuple[Parameter, ...] = ()
    symbolic: tuple[str, ...] | None = None
    outputs: tuple[str, ...] | None = None
    floating_base: bool | str = False
    contacts: tuple[Contact, ...] = ()
    frames: tuple[str, ...] = ()
    couplings: tuple[Coupling, ...] = ()
    loops: tuple[Loop, ...] = ()
    actuated: tuple[str, ...] = ()
    springs: tuple[tuple[str, Spring | BallSpring], ...] = ()
    controls: tuple[Control, ...] = ()

    @property
    def locked_positions(self) -> dict[str, float]:
        return dict(self.locked)

    def error(self, element: str, problem: str) -> SceneError:
        """A :class:`SceneError` naming this scene's file and ``element``."""
        return SceneError(self.source, element, problem)


@functools.cache
def scene_error(kind: type[DescriptionError] = DescriptionError) -> type[SceneError]:
    """The class of a scene problem of ``kind``: :class:`SceneError` and ``kind`` both, so that
    a payload mass of ``nan`` in a scene is caught as a ``SceneError`` and as an
    ``InvalidNumberError`` alike."""
    if issubclass(kind, SceneError):
        return kind
    if kind is DescriptionError:
        return SceneError
    return type(f"Scene{kind.__name__}", (SceneError, kind),
                {"__module__": __name__, "__doc__": f"{kind.__name__} in a scene file."})


def _as_scene_error(exc: DescriptionError) -> SceneError:
    return scene_error(type(exc))(exc.source, exc.element, exc.problem)


class _SceneReader(Reader):
    """The robot-YAML reader, raising :class:`SceneError` (of the reader's kind)."""

    def error(self, where: str, problem: str, *args, **kwargs) -> SceneError:
        return _as_scene_error(super().error(where, problem, *args, **kwargs))


def load_scene(path, text: str | None = None, strict: bool = False) -> Scene:
    """Read a scene file (see the module docstring).

    Parameters
    ----------
    path:
        The scene file; with ``text``, only the label errors name.
    text:
        The document itself, instead of reading ``path``.
    strict:
        Refuse payload inertias that break the triangle inequality instead of warning.

    Returns
    -------
    Scene
        Checked on its own; whether its links and joints exist is checked when it is applied to
        a robot (:func:`eomgen.reduction.apply_scene`).

    Raises
    ------
    SceneError
        One line naming the file, the entry and the problem.
    """
    source = str(path)
    try:
        data = read_document(Path(path) if text is None else source, text)
        return _read(data, source, strict)
    except SceneError:
        raise
    except DescriptionError as exc:  # from the shared YAML reader: the same fields
        raise _as_scene_error(exc) from None


def _read(data: dict, source: str, strict: bool) -> Scene:
    r = _SceneReader(source)
    for key in data:
        if key in PLANNED_KEYS:
            hint = (" (write it per joint under 'actuators', e.g. actuators: {joint1: "
                    "{armature: 0.1, damping: 0.5, stiffness: 1e4}})"
                    if key in ACTUATOR_ALIASES else "")
            raise r.error(str(key), f"'{key}' is planned for a later scene version; version "
                          f"{SCENE_VERSION} knows: {', '.join(SCENE_KEYS)}{hint}")
    r.mapping(data, "scene", required=("version",), optional=SCENE_KEYS)
    version = data["version"]
    if isinstance(version, bool) or not isinstance(version, int):
        raise r.error("version", f"expected the integer {SCENE_VERSION}, got {version!r}")
    if version != SCENE_VERSION:
        raise r.error("version", f"scene version {version} is not supported (this eomgen reads "
                      f"version {SCENE_VERSION})")
    r.read_parameters(data.get("parameters"), "parameters")
    robot = r.text(data["robot"], "robot") if "robot" in data else None
    description = r.text(data["description"], "description") if "description" in data else ""
    fixed_base = data.get("fixed_base", False)
    if not isinstance(fixed_base, bool):
        raise r.error("fixed_base", f"expected true or false, got {fixed_base!r}")
    floating_base = data.get("floating_base", False)
    if not (isinstance(floating_base, bool) or floating_base in ("euler", "quaternion")):
        raise r.error("floating_base", "expected true, false, 'euler' or 'quaternion', got "
                      f"{floating_base!r}")
    if data.get("base") == FLOATING:  # the spelling: base: floating
        if "floating_base" in data and not floating_base:
            raise r.error("base", "'base: floating' contradicts 'floating_base: false'")
        floating_base = floating_base or True
        data = {k: v for k, v in data.items() if k != "base"}
    floating_base = FLOATING_CHARTS[floating_base]
    if floating_base and fixed_base:
        raise r.error("floating_base", "the base cannot be both fixed (fixed_base: true) and "
                      "floating")
    if floating_base and data.get("base") is not None:
        raise r.error("base", "a floating robot moves as a whole from its root; 'base' "
                      "(the link a moving part hangs from) cannot be used with floating_base")
    base = r.name(data["base"], "base") if data.get("base") is not None else None
    tips: list[str] = []
    if data.get("tips") is not None:
        for k, tip in enumerate(r.sequence(data["tips"], "tips")):
            name = r.name(tip, f"tips[{k}]")
            if name in tips:
                raise r.error(f"tips[{k}] '{name}'", "listed twice")
            tips.append(name)
    locked: list[tuple[str, float | tuple[float, ...]]] = []
    if data.get("locked") is not None:
        if not isinstance(data["locked"], dict):
            raise r.error("locked", "expected a mapping of joint: position [rad or m]")
        for joint, value in data["locked"].items():
            name = r.name(joint, "locked")
            where = f"locked '{name}'"
            locked.append((name, tuple(r.number(x, where) for x in r.sequence(value, where))
                           if isinstance(value, list) else r.number(value, where)))
    payloads = []
    if data.get("payloads") is not None:
        for k, entry in enumerate(r.sequence(data["payloads"], "payloads")):
            payloads.append(_payload(r, entry, k, source, strict))
        names = [p.name for p in payloads]
        for p in payloads:
            if names.count(p.name) > 1:
                raise r.error(f"payloads '{p.name}'", "two payloads have this name")
    actuators: list[tuple[str, tuple[tuple[str, object], ...]]] = []
    if data.get("actuators") is not None:
        if not isinstance(data["actuators"], dict):
            raise r.error("actuators", "expected a mapping of joint: {armature, rotor_inertia, "
                          "gear_ratio, damping, friction, friction_width, stiffness}")
        for joint, entry in data["actuators"].items():
            name = r.name(joint, "actuators")
            values = r.actuator_values(entry, f"actuators '{name}'")
            actuators.append((name, tuple(values.items())))
    gravity = _gravity(r, data["gravity"]) if "gravity" in data else None
    symbolic = _symbolic(r, data["symbolic"]) if "symbolic" in data else None
    outputs = _outputs(r, data["outputs"]) if data.get("outputs") is not None else None
    contacts: list[Contact] = []
    if data.get("contacts") is not None:
        for k, entry in enumerate(r.sequence(data["contacts"], "contacts")):
            contacts.append(_contact(r, entry, k))
        names = [c.name for c in contacts]
        for c in contacts:
            if names.count(c.name) > 1:
                raise r.error(f"contacts '{c.name}'", "two contacts have this name")
    frames = _frames(r, data["frames"]) if data.get("frames") is not None else ()
    couplings = tuple(_coupling(r, entry, k) for k, entry in
                      enumerate(r.sequence(data["couplings"], "couplings"))
                      ) if data.get("couplings") is not None else ()
    loops = _loops(r, data["loops"]) if data.get("loops") is not None else ()
    actuated = (_names(r, data["actuated"], "actuated", "a joint name")
                if data.get("actuated") is not None else ())
    springs, controls = _springs_and_controls(r, data, source)
    declared = tuple(r.declared.values())
    return Scene(springs=springs, controls=controls,
                 frames=frames, loops=loops, actuated=actuated, source=source, version=version, robot=robot, description=description,
                 floating_base=floating_base, contacts=tuple(contacts),
                 fixed_base=fixed_base, base=base, tips=tuple(tips), locked=tuple(locked),
                 payloads=tuple(payloads), actuators=tuple(actuators),
                 gravity=gravity, parameters=declared, symbolic=symbolic, outputs=outputs,
                 couplings=couplings)


def _springs_and_controls(r: _SceneReader, data: dict, source: str) -> tuple[tuple, tuple]:
    """``springs:`` and ``controls:``, read as eomgen's YAML reads a joint's ``spring`` and
    ``controls`` (:mod:`eomgen.parsers.yaml_format`): a spring whose ``reference`` is a list
    is a ball joint's; numbers only (a scene's parameters do not reach them yet)."""
    springs = []
    try:
        if data.get("springs") is not None:
            if not isinstance(data["springs"], dict):
                raise r.error("springs", "expected a mapping of joint: {stiffness, reference}")
            for joint, entry in data["springs"].items():
                name = r.name(joint, "springs")
                ball = isinstance(entry, dict) and isinstance(entry.get("reference"), list)
                springs.append((name, read_spring(r, entry, f"springs '{name}'", source, ball)))
        controls = (read_controls(r, data["controls"], None)
                    if data.get("controls") is not None else ())
    except SceneError:
        raise
    except DescriptionError as exc:
        raise _as_scene_error(exc) from None
    for where, values in [*((f"springs '{name}'", (spring.stiffness, *(
            spring.reference if isinstance(spring, BallSpring) else (spring.reference,))))
            for name, spring in springs),
            *((f"controls '{c.name}'", _values(c)) for c in controls)]:
        if any(getattr(v, "free_symbols", ()) for v in values):
            raise r.error(where, "a scene's springs and controls take numbers, not parameters "
                          "(write the symbolic ones in the robot's description)")
    return tuple(springs), controls


def _values(item) -> list:
    """Every value held in ``item``'s fields (a dataclass), tuples opened."""
    out, todo = [], [getattr(item, f.name) for f in fields(item)]
    while todo:
        value = todo.pop()
        if isinstance(value, tuple):
            todo.extend(value)
        else:
            out.append(value)
    return out


def _payload(r: _SceneReader, entry, k: int, source: str, strict: bool) -> Payload:
    where = f"payloads[{k}]"
    r.mapping(entry, where, required=("link", "mass"), optional=PAYLOAD_KEYS)
    link = r.name(entry["link"], f"{where} link")
    name = r.name(entry["name"], f"{where} name") if "name" in entry else f"payload{k}"
    where = f"{where} '{name}'"
    mass = r.scalar(entry["mass"], f"{where} mass")
    com = r.vector(entry["com"], f"{where} com") if "com" in entry else vec3([0, 0, 0])
    inertia = (r.inertia(entry["inertia"], f"{where} inertia") if "inertia" in entry
               else mat3([[0, 0, 0]] * 3))
    inertial = Inertial(mass, com, inertia)
    values = {p.symbol: p.value for p in r.declared.values() if p.value is not None}
    numeric = Inertial(*(_at(x, values) for x in (inertial.mass, inertial.com, inertial.inertia)))
    try:  # expressions at their defaults: finite and of magnitude at most 1e12 too
        check_model_numbers(source, [Link(name, numeric)], [], [])
        found = check_inertial(source, name, numeric)
    except DescriptionError as exc:
        raise scene_error(type(exc))(source, where, exc.problem) from None
    for notice in found:  # named after the payload rather than a link
        if strict:
            raise scene_error(notice.error)(source, where,
                                            notice.problem + " (refused under --strict)")
        warnings.warn(replace(notice, element=where).message, notice.category, stacklevel=4)
    return Payload(link, inertial, name)


def _contact(r: _SceneReader, entry, k: int) -> Contact:
    where = f"contacts[{k}]"
    r.mapping(entry, where, required=("frame",), optional=CONTACT_KEYS)
    frame = r.name(entry["frame"], f"{where} frame")
    name = r.name(entry["name"], f"{where} name") if "name" in entry else frame
    where = f"{where} '{name}'"
    kind = r.choice(entry.get("type", POINT), f"{where} type", (POINT, SURFACE))
    mu = None
    if entry.get("mu") is not None:
        mu = r.number(entry["mu"], f"{where} mu")
        if mu < 0:
            raise r.error(f"{where} mu", f"friction coefficient {mu:g} is negative (μ ≥ 0)")
    gains = {"kp": 0.0, "kd": 0.0}
    if entry.get("baumgarte") is not None:
        value = entry["baumgarte"]
        r.mapping(value, f"{where} baumgarte", optional=("kp", "kd"))
        for key in value:
            gains[key] = r.number(value[key], f"{where} baumgarte {key}")
            if gains[key] < 0:
                raise r.error(f"{where} baumgarte {key}", f"gain {gains[key]:g} is negative")
    normal = (0.0, 0.0, 1.0)
    if entry.get("normal") is not None:
        if kind != POINT:
            raise r.error(f"{where} normal", "a surface contact's normal is its frame's z axis")
        normal = _unit(r, entry, "normal", where, "the normal is zero")
    return Contact(frame, kind, mu, gains["kp"], gains["kd"], normal, name)


def _coupling(r: _SceneReader, entry, k: int) -> Coupling:
    where = f"couplings[{k}]"
    r.mapping(entry, where, required=("joint", "to"), optional=COUPLING_KEYS)
    follower = r.name(entry["joint"], f"{where} joint")
    where = f"{where} '{follower}'"
    target = entry["to"]
    if isinstance(target, dict):
        if "ratio" in entry:
            raise r.error(f"{where} ratio", "give the gains in 'to' ({leader: gain, ...})")
        leaders = {r.name(name, f"{where} to"): r.number(gain, f"{where} to '{name}'")
                   for name, gain in target.items()}
    else:
        leaders = {r.name(target, f"{where} to"):
                   r.number(entry.get("ratio", 1), f"{where} ratio")}
    offset = r.number(entry.get("offset", 0), f"{where} offset")
    return make_coupling(follower, leaders, offset, where)
def _loops(r: _SceneReader, value) -> tuple[Loop, ...]:
    loops: list[Loop] = []
    for k, entry in enumerate(r.sequence(value, "loops")):
        where = f"loops[{k}]"
        r.mapping(entry, where, required=("a", "b"), optional=LOOP_KEYS)
        name = r.name(entry["name"], f"{where} name") if "name" in entry else f"loop{k + 1}"
        where = f"{where} '{name}'"
        if any(loop.name == name for loop in loops):
            raise r.error(where, "two loops have this name")
        kind = r.choice(entry.get("type", "point"), f"{where} type", LOOP_KINDS)
        ends = []
        for end in ("a", "b"):
            frame = entry[end]
            r.mapping(frame, f"{where} {end}", required=("link",), optional=LOOP_FRAME_KEYS)
            link = r.name(frame["link"], f"{where} {end} link")
            xyz = r.vector(frame["xyz"], f"{where} {end} xyz") if "xyz" in frame else (0, 0, 0)
            rpy = r.vector(frame["rpy"], f"{where} {end} rpy") if "rpy" in frame else (0, 0, 0)
            ends.append(LoopFrame(link, Transform.from_xyz_rpy(xyz, rpy)))
        axis = _unit(r, entry, "axis", where) if entry.get("axis") is not None else (0., 0., 1.)
        if "axis" in entry and kind != HINGE:
            raise r.error(f"{where} axis", f"only a hinge loop has an axis (this one is a {kind})")
        plane = _unit(r, entry, "plane", where) if entry.get("plane") is not None else None
        loops.append(Loop(name, kind, ends[0], ends[1], axis, plane))
    return tuple(loops)


def _unit(r: _SceneReader, entry: dict, key: str, where: str,
          zero: str = "the vector is zero") -> tuple[float, float, float]:
    """``entry[key]``, a list of 3 numbers, made a unit vector (``zero``: the error when it is
    zero)."""
    value = entry[key]
    if not isinstance(value, list) or len(value) != 3:
        raise r.error(f"{where} {key}", "expected a list of 3 numbers [x, y, z]")
    vector = [r.number(x, f"{where} {key}[{i}]") for i, x in enumerate(value)]
    norm = sum(x * x for x in vector) ** 0.5
    if not norm > 0:
        raise r.error(f"{where} {key}", zero)
    return tuple(x / norm for x in vector)


def _names(r: _SceneReader, value, key: str, what: str) -> tuple[str, ...]:
    names: list[str] = []
    for k, entry in enumerate(r.sequence(value, key)):
        if not isinstance(entry, str) or not entry:
            raise r.error(f"{key}[{k}]", f"expected {what}")
        if entry in names:
            raise r.error(f"{key}[{k}]", f"'{entry}' is listed twice")
        names.append(entry)
    return tuple(names)


def _at(value, values: dict):
    """``value`` (a scalar, vector or matrix of SymPy scalars) at the parameter values."""
    if isinstance(value, tuple):
        return tuple(_at(v, values) for v in value)
    return value.xreplace(values) if values else value


def _gravity(r: _SceneReader, value) -> Vec3:
    if value is None or (isinstance(value, str) and value.strip().lower() == "none"):
        return vec3([0, 0, 0])
    return r.vector(value, "gravity")


def _symbolic(r: _SceneReader, value) -> tuple[str, ...]:
    if value is None or (isinstance(value, str) and value.strip().lower() == "none"):
        return ()
    names = []
    for k, entry in enumerate(r.sequence(value, "symbolic", allow_empty=True)):
        if not isinstance(entry, str):
            raise r.error(f"symbolic[{k}]", "expected a parameter name")
        names.append(entry)
    return tuple(names)


def _frames(r: _SceneReader, value) -> tuple[str, ...]:
    names: list[str] = []
    for k, entry in enumerate(r.sequence(value, "frames")):
        if not isinstance(entry, str) or not entry:
            raise r.error(f"frames[{k}]", "expected a link name")
        if entry in names:
            raise r.error(f"frames[{k}]", f"frame '{entry}' is listed twice")
        names.append(entry)
    return tuple(names)


def _outputs(r: _SceneReader, value) -> tuple[str, ...]:
    names = []
    for k, entry in enumerate(r.sequence(value, "outputs")):
        if not isinstance(entry, str):
            raise r.error(f"outputs[{k}]", "expected an output name (M, C, g, tau, ...)")
        names.append(entry)
    try:
        return select(names)
    except ValueError as exc:
        raise r.error("outputs", str(exc)) from None
