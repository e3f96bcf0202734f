"""Read a URDF robot description into a :class:`~eomgen.model.RobotModel`.

What is read
------------
* ``<robot name>``: the model name. The root link of the link tree is the fixed base (as
  Pinocchio's ``buildModelFromUrdf`` without a root joint); gravity is ``(0, 0, -9.81)`` m/s²
  in the root link frame (URDF convention: base z axis up).
* ``<link name>`` with an optional ``<inertial>``: ``<origin xyz rpy>`` (default zeros) is the
  centre-of-mass frame in the link frame, ``<mass value>`` [kg] and
  ``<inertia ixx ixy ixz iyy iyz izz>`` [kg m²] about the centre of mass in the axes of that
  frame. The model stores the inertia in the *link* frame axes, ``I_link = R · I · Rᵀ`` with
  ``R = Rz(yaw) · Ry(pitch) · Rx(roll)`` from the origin's ``rpy``. A link without
  ``<inertial>`` is massless (``Link.inertial is None``).
* ``<joint name type>`` of type ``revolute``, ``continuous``, ``prismatic`` or ``fixed``, with
  ``<parent link>``, ``<child link>``, ``<origin xyz rpy>`` (the joint frame in the parent link
  frame; metres and radians; default zeros) and ``<axis xyz>`` (in the joint frame; default
  ``1 0 0`` as the URDF specification says; not read for fixed joints). Joints keep document
  order, so the joint vector ``q`` lists the movable joints in the order the file does.

* ``<dynamics damping friction>`` of a movable joint (both default 0): viscous friction
  [N m s/rad] and Coulomb friction [N m] of the joint's :class:`~eomgen.model.Actuator` (see
  docs/actuators.md; MuJoCo reads the same attributes as ``damping`` and ``frictionloss``).
  They enter the equations of motion only through :mod:`eomgen.analysis.actuators` (the generated
  ``M``, ``C``, ``g`` stay those of the rigid bodies). A ``<dynamics>`` on a fixed joint is
  ignored.

Everything else (visual, collision, limit, transmission, gazebo, material, sensors) is ignored:
it does not enter the equations of motion. URDF has no rotor inertia, gear ratio or joint
stiffness (``<transmission>`` ``mechanicalReduction`` is not read); give them in a scene's
``actuators``.

Decisions
---------
* An ``<inertial>`` must hold ``<mass>`` and ``<inertia>`` with all six attributes, as urdfdom
  (ROS, Pinocchio) requires; a point mass is written with zero moments of inertia. A missing
  ``<inertia>`` is more often an authoring slip than a deliberate point mass.
* A ``floating`` joint from a massless root link with nothing else attached is read as the
  quaternion free flyer (:func:`eomgen.model.floating.add_free_flyer` with the joint's origin, as
  Pinocchio reads it); any other ``floating`` joint raises
  :class:`~eomgen.errors.UnsupportedError`.
* A ``planar`` joint is Pinocchio's ``JointModelPlanar`` (:mod:`eomgen.model.joints.planar`):
  the child moves in the joint frame's xy plane, its ``<axis>`` (the plane's normal, default
  ``0 0 1``) must be ``0 0 1``.
* A root link that looks like the floating base of a legged robot (quadrupeds and humanoids
  are written as trees rooted at the trunk, without a floating joint) is read as bolted to
  the world, with one :class:`~eomgen.errors.UnsupportedFeatureWarning` naming the file and
  the root link (:func:`eomgen.parsers.legged.floating_base_notice` states the rule);
  ``strict=True`` raises :class:`~eomgen.errors.UnsupportedError`. A ``world`` root link (the
  ROS convention for a model bolted to the world) or a scene with ``fixed_base: true`` says
  the fixed base is meant.
* A joint with ``<mimic joint="..." multiplier="k" offset="c">`` follows the joint it names:
  ``q = k · q_other + c`` (``k`` 1 and ``c`` 0 when left out), a coupling of the model
  (:mod:`eomgen.model.coupling`); the follower is no coordinate (it leaves ``joint_names``),
  and the dynamics are those of the independent joints, as Pinocchio's
  ``buildModelFromUrdf(path, mimic=True)`` builds them. ``eomgen.load(path, couplings=False)``
  reads followers as independent joints instead (eomgen before 0.x, Pinocchio's default),
  with one :class:`~eomgen.errors.UnsupportedFeatureWarning` per follower (an error under
  ``strict``). The ``joint`` attribute is required (as urdfdom requires it) and must name a
  movable joint of the file; a follower that another joint mimics, or a cycle of mimics, is
  refused (:class:`~eomgen.errors.KinematicTreeError`). A ``<mimic>`` on a *fixed* joint
  (Talos' reduced models) couples nothing and is ignored.
* Numbers are plain decimal numbers read with :func:`float` (URDF has no expressions); they
  must be finite and of magnitude at most 1e12 (:mod:`eomgen.model.numbers`), but for the
  ``<limit>`` read by :func:`joint_limits`, where ``inf`` or ``1e16`` is no limit. Exact
  integers stay exact (see :func:`eomgen.model.scalar`).
* A singleton element (``<inertial>``, ``<origin>``, ``<axis>``, ...) given twice is an error
  rather than a silent choice of one of them.
* ``<limit>`` is not required for revolute and prismatic joints (urdfdom requires it): limits
  do not enter the equations of motion. :func:`joint_limits` reads them for ``eomgen excite``
  (positions and velocities an excitation trajectory must respect).

Safety
------
XML is parsed with :mod:`defusedxml`: entity declarations (billion laughs) and external
entities or DTDs are refused before anything is expanded or fetched. Names are data: they are
never evaluated, and error messages escape line breaks in them.

Validation of the assembled tree and of masses and inertias (negative mass, indefinite inertia,
triangle inequality, zero axis, cycles, duplicate or missing links) is done once, for every
format, by :func:`eomgen.model.build_model`.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Iterable
from xml.parsers import expat

import defusedxml
import defusedxml.ElementTree as SafeET
import sympy as sp

from ..errors import (
    ForbiddenXMLError,
    InvalidActuatorError,
    InvalidNumberError,
    SchemaError,
    UnreadableFileError,
    UnsupportedError,
    XMLSyntaxError,
)
from ..model.numbers import check_number
from ..model import (
    Actuator,
    Inertial,
    Joint,
    JointType,
    Link,
    Mat3,
    RobotModel,
    Transform,
    build_model,
    check_size,
    Coupling,
    make_coupling,
    with_couplings,
    emit_notices,
    mat3,
    settled,
    rotation_from_rpy,
    scalar,
    vec3,
)
from ..model.floating import add_free_flyer
from .registry import register
from .legged import floating_base_notice

#: Gravitational acceleration [m/s²] in the root link frame (URDF: z up).
GRAVITY = (0, 0, -9.81)
#: The joint axis when ``<axis>`` is absent (URDF specification).
DEFAULT_AXIS = (1.0, 0.0, 0.0)
ZEROS = (0.0, 0.0, 0.0)

_JOINT_TYPES = {t.value: t for t in (JointType.REVOLUTE, JointType.CONTINUOUS,
                                      JointType.PRISMATIC, JointType.FIXED, JointType.PLANAR)}
_UNSUPPORTED_JOINT_TYPES = ("floating",)
#: A planar joint's plane normal when ``<axis>`` is absent: the joint frame's z (the plane of
#: Pinocchio's ``JointModelPlanar``).
PLANAR_AXIS = (0.0, 0.0, 1.0)
_INERTIA_ATTRIBUTES = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
_SHOWN_CHARACTERS = 40


@register("URDF", (".urdf",))
def load_urdf(path: Path, strict: bool = False, defer_notices: bool = False) -> RobotModel:
    """Read the URDF file ``path`` (see the module docstring for what is read and how).

    Parameters
    ----------
    path:
        The ``.urdf`` file.
    strict:
        Refuse (rather than warn about) inertias that break the triangle inequality and a
        root that looks like a floating base.
    defer_notices:
        Neither warn nor refuse: record these findings in ``RobotModel.notices`` (see
        :func:`eomgen.parsers.load`).

    Returns
    -------
    RobotModel
        Links and joints in document order, gravity ``(0, 0, -9.81)`` m/s².

    Raises
    ------
    DescriptionError
        One line naming the file, the element and the problem; the subclass tells the kind
        (:class:`~eomgen.errors.XMLSyntaxError`, :class:`~eomgen.errors.ForbiddenXMLError`,
        :class:`~eomgen.errors.SchemaError`, :class:`~eomgen.errors.InvalidNumberError`, and
        those of :func:`eomgen.model.build_model`).
    UnsupportedError
        For floating and planar joints, and under ``strict`` for a root that looks like a
        floating base.

    Warns
    -----
    UnsupportedFeatureWarning
        For a root link that looks like a floating base (:func:`floating_base_notice`; read as fixed), unless
        ``strict``.
    PhysicalConsistencyWarning
        For inertias that break the triangle inequality, unless ``strict``.
    """
    source = str(path)
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise UnreadableFileError(source, "", f"cannot read the file ({exc.strerror})") from None
    return _read_robot(data, source, strict, defer_notices)


def parse_urdf_string(text: str | bytes, source: str = "<string>", strict: bool = False,
                      defer_notices: bool = False) -> RobotModel:
    """Read URDF from a string; ``source`` names it in error messages. See :func:`load_urdf`.

    >>> model = parse_urdf_string('''<robot name="r">
    ...   <link name="base"/>
    ...   <link name="arm"><inertial><mass value="2"/>
    ...     <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
    ...   <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/>
    ...     <axis xyz="0 0 1"/></joint>
    ... </robot>''')
    >>> model.joint_names, model.link_by_name["arm"].inertial.mass
    (('j1',), 2)
    """
    return _read_robot(text, source, strict, defer_notices)


# ----------------------------------------------------------------------------------------------
# Document
# ----------------------------------------------------------------------------------------------

def _read_robot(data: str | bytes, source: str, strict: bool, defer_notices: bool = False
                ) -> RobotModel:
    root = _parse_xml(data, source)
    if root.tag != "robot":
        raise SchemaError(source, f"root element <{root.tag}>", "expected <robot>")
    name = _required_name(root, source, "<robot>")
    check_size(source, len(root.findall("link")), len(root.findall("joint")))
    links = [_read_link(element, index, source)
             for index, element in enumerate(root.findall("link"), start=1)]
    joints, mimics, free_flyer = [], [], None
    for index, element in enumerate(root.findall("joint"), start=1):
        if element.get("type") == "floating":
            free_flyer = _read_floating_joint(element, index, source, root, free_flyer)
            continue
        joint, mimic = _read_joint(element, index, source)
        joints.append(joint)
        if mimic is not None and joint.type.is_movable:  # a fixed joint has nothing to couple
            mimics.append(mimic)
    if free_flyer is not None:  # the massless root the floating joint hangs from goes
        links = [link for link in links if link.name != free_flyer.parent]
    model = build_model(source, name, links, joints, gravity=GRAVITY, defer_notices=True)
    if free_flyer is not None:
        model = add_free_flyer(model, free_flyer.origin)
    model = with_couplings(model, mimics)
    # only once the file is known to be valid: the whole model first, then links, then joints
    floating = floating_base_notice(model)
    notices = ([floating] if floating is not None else []) + list(model.notices)
    model = replace(model, notices=tuple(notices))
    if not defer_notices:
        model = settled(model)
        emit_notices(model.notices, strict)
    return model


@dataclass(frozen=True)
class JointLimit:
    """The ``<limit>`` of a URDF joint, SI units (rad or m, rad/s or m/s, N m or N); None
    where the attribute is absent (and ``lower``, ``upper`` always None for a continuous
    joint, which has no position limits)."""

    lower: float | None = None
    upper: float | None = None
    velocity: float | None = None
    effort: float | None = None


def joint_limits(path) -> dict[str, JointLimit]:
    """The ``<limit>`` element of each revolute, continuous and prismatic joint of the URDF file
    ``path``, by joint name (joints without one are left out).

    Not part of :class:`~eomgen.model.RobotModel` (limits do not enter the equations of
    motion); read for the excitation trajectories of ``eomgen excite``. Unlike urdfdom, an
    absent ``lower`` or ``upper`` is no limit on that side (urdfdom reads 0).

    Raises
    ------
    DescriptionError
        Unreadable file, malformed XML, two ``<limit>`` elements in a joint, an attribute that
        is not a number or is ``nan`` (``inf`` and large numbers are no limit).
    """
    source = str(path)
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise UnreadableFileError(source, "", f"cannot read the file ({exc.strerror})") from None
    limits = {}
    for joint in _parse_xml(data, source).findall("joint"):
        name, kind = joint.get("name", ""), joint.get("type", "")
        if kind not in ("revolute", "continuous", "prismatic"):
            continue
        where = f"joint '{name}' <limit>"
        element = _single_child(joint, "limit", source, f"joint '{name}'")
        if element is None:
            continue
        values = {a: (_limit(element.get(a), a, source, where)
                      if element.get(a) is not None else None)
                  for a in ("lower", "upper", "velocity", "effort")}
        if kind == "continuous":
            values["lower"] = values["upper"] = None
        limits[name] = JointLimit(**values)
    return limits


def _parse_xml(data: str | bytes, source: str) -> ET.Element:
    """The document's root element; no entity is expanded and nothing external is read."""
    try:
        return SafeET.fromstring(data, forbid_dtd=False, forbid_entities=True,
                                 forbid_external=True)
    except ET.ParseError as exc:
        line, column = getattr(exc, "position", (0, -1))
        where = f"line {line}, column {column + 1}" if line else ""
        raise XMLSyntaxError(source, where,
                             f"malformed XML ({expat.ErrorString(exc.code)})") from None
    except defusedxml.EntitiesForbidden as exc:
        raise ForbiddenXMLError(source, f"<!ENTITY {exc.name}>",
                                "entity declarations are not allowed in a URDF") from None
    except defusedxml.DefusedXmlException as exc:  # external references, DTD tricks
        raise ForbiddenXMLError(source, "XML", f"refused: {exc}") from None


# ----------------------------------------------------------------------------------------------
# Links
# ----------------------------------------------------------------------------------------------

def _read_link(element: ET.Element, index: int, source: str) -> Link:
    name = _required_name(element, source, f"<link> number {index}")
    where = f"link '{name}'"
    inertial = _single_child(element, "inertial", source, where)
    if inertial is None:
        return Link(name)
    return Link(name, _read_inertial(inertial, source, f"{where} <inertial>"))


def _read_inertial(element: ET.Element, source: str, where: str) -> Inertial:
    """Mass [kg], centre of mass [m] in the link frame and inertia [kg m²] about it in the
    link frame axes (the origin's rpy applied)."""
    xyz, rpy = _read_origin(_single_child(element, "origin", source, where), source,
                            f"{where}<origin>")
    mass_element = _single_child(element, "mass", source, where)
    if mass_element is None:
        raise SchemaError(source, where, "no <mass> element")
    mass = _number_attribute(mass_element, "value", source, f"{where}<mass>")
    inertia_element = _single_child(element, "inertia", source, where)
    if inertia_element is None:
        raise SchemaError(
            source, where,
            "no <inertia> element (a point mass has ixx=ixy=ixz=iyy=iyz=izz=\"0\")")
    inertia = _read_inertia(inertia_element, source, f"{where}<inertia>")
    return Inertial(scalar(mass), vec3(xyz), rotate_inertia(inertia, rpy))


def _read_inertia(element: ET.Element, source: str, where: str) -> list[list[float]]:
    """The symmetric 3×3 matrix of ``<inertia ixx ixy ixz iyy iyz izz>``."""
    xx, xy, xz, yy, yz, zz = (_number_attribute(element, attribute, source, where)
                              for attribute in _INERTIA_ATTRIBUTES)
    return [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]


def rotate_inertia(inertia: list[list[float]], rpy: Iterable[float]) -> Mat3:
    """Express an inertia given in a frame rotated by ``rpy`` in the outer frame's axes.

    ``I_outer = R · I · Rᵀ`` with ``R = Rz(yaw) · Ry(pitch) · Rx(roll)``. When ``rpy`` is zero
    the values are kept exactly (structural zeros stay exact zeros); otherwise the result is
    made exactly symmetric by computing the upper triangle only.

    >>> rotate_inertia([[1, 0, 0], [0, 2, 0], [0, 0, 3]], (0, 0, math.pi / 2))[0]
    (2, 0, 0)
    """
    rpy = tuple(rpy)
    if not any(rpy):
        return mat3(inertia)
    R = rotation_from_rpy(vec3(rpy))
    I = mat3(inertia)
    upper = {
        (i, j): scalar(sp.Add(*[R[i][k] * I[k][l] * R[j][l] for k in range(3) for l in range(3)]))
        for i in range(3) for j in range(i, 3)
    }
    return mat3([[upper[min(i, j), max(i, j)] for j in range(3)] for i in range(3)])


# ----------------------------------------------------------------------------------------------
# Joints
# ----------------------------------------------------------------------------------------------

def _read_joint(element: ET.Element, index: int, source: str) -> tuple[Joint, Coupling | None]:
    """The joint, and its coupling to the joint it mimics (None without ``<mimic>``)."""
    name = _required_name(element, source, f"<joint> number {index}")
    where = f"joint '{name}'"
    joint_type = _read_joint_type(element, source, where)
    element_mimic = _single_child(element, "mimic", source, where)
    mimic = None
    if element_mimic is not None:
        mimicked = element_mimic.get("joint")
        if not mimicked:
            raise SchemaError(source, f"{where} <mimic>", "no 'joint' attribute")
        ratio, offset = (_number_attribute(element_mimic, key, source, f"{where} <mimic>")
                         if element_mimic.get(key) is not None else default
                         for key, default in (("multiplier", 1), ("offset", 0)))
        mimic = make_coupling(name, {mimicked: ratio}, offset, f"{where} <mimic>")
    parent = _link_reference(element, "parent", source, where)
    child = _link_reference(element, "child", source, where)
    xyz, rpy = _read_origin(_single_child(element, "origin", source, where), source,
                            f"{where} <origin>")
    axis = PLANAR_AXIS if joint_type is JointType.PLANAR else DEFAULT_AXIS
    axis_element = _single_child(element, "axis", source, where)
    if joint_type.is_movable and axis_element is not None:
        axis = _vector_attribute(axis_element, "xyz", 3, source, f"{where} <axis>")
    actuator = None
    dynamics = _single_child(element, "dynamics", source, where)
    if joint_type.is_movable and dynamics is not None:
        actuator = _read_dynamics(dynamics, source, f"{where} <dynamics>")
    return (Joint(name, joint_type, parent, child, Transform.from_xyz_rpy(xyz, rpy), vec3(axis),
                  actuator), mimic)


def _read_floating_joint(element: ET.Element, index: int, source: str, document: ET.Element,
                         found: Joint | None) -> Joint:
    """A ``floating`` joint, read as the robot's quaternion free flyer
    (:mod:`eomgen.model.floating`, Pinocchio's reading) when it joins a massless root link with
    nothing else attached to the robot: returned as a fixed joint whose origin places the
    free flyer and whose parent is the root link to leave out. Anywhere else it is refused."""
    name = _required_name(element, source, f"<joint> number {index}")
    where = f"joint '{name}'"
    parent = _link_reference(element, "parent", source, where)
    child = _link_reference(element, "child", source, where)
    others = [j for j in document.findall("joint") if j is not element]
    massless = all(link.find("inertial") is None for link in document.findall("link")
                   if link.get("name") == parent)
    if found is not None or not massless or any(
            parent in (_link_attribute(j, "parent"), _link_attribute(j, "child"))
            for j in others):
        raise UnsupportedError(
            source, where,
            f"a floating joint is read as the robot's free flyer only from a massless root link "
            f"with nothing else attached (one per robot); here link '{parent}' "
            + ("has a second floating joint" if found is not None else
               "has mass" if not massless else "is not such a root")
            + f": to let link '{child}' fly, remove this joint and give a scene "
            f"'floating_base: quaternion' or 'floating_base: true' (docs/legged.md)")
    xyz, rpy = _read_origin(_single_child(element, "origin", source, where), source,
                            f"{where} <origin>")
    return Joint(name, JointType.FIXED, parent, child, Transform.from_xyz_rpy(xyz, rpy))


def _link_attribute(element: ET.Element, tag: str) -> str | None:
    found = element.find(tag)
    return None if found is None else found.get("link")


def _read_dynamics(element: ET.Element, source: str, where: str) -> Actuator | None:
    """``<dynamics damping friction>``: viscous [N m s/rad] and Coulomb [N m] friction (both
    default 0, as urdfdom); None when both are zero."""
    values = {}
    for attribute in ("damping", "friction"):
        if element.get(attribute) is not None:
            value = _number_attribute(element, attribute, source, where)
            if value < 0:
                raise InvalidActuatorError(source, where, f"{attribute} {value:g} is negative")
            values[attribute] = scalar(value)
    if not any(values.values()):
        return None
    return Actuator(**values)


def _read_joint_type(element: ET.Element, source: str, where: str) -> JointType:
    text = element.get("type")
    if text is None:
        raise SchemaError(source, where, "no 'type' attribute")
    try:
        return _JOINT_TYPES[text]
    except KeyError:
        known = ", ".join(sorted(_JOINT_TYPES) + list(_UNSUPPORTED_JOINT_TYPES))
        raise SchemaError(source, where,
                          f"unknown joint type {_show(text)} (URDF knows {known})") from None


def _link_reference(element: ET.Element, role: str, source: str, where: str) -> str:
    """The link named by the joint's ``<parent link>`` or ``<child link>``."""
    reference = _single_child(element, role, source, where)
    if reference is None:
        raise SchemaError(source, where, f"no <{role}> element")
    link = reference.get("link")
    if not link:
        raise SchemaError(source, f"{where} <{role}>", "no 'link' attribute")
    return link


# ----------------------------------------------------------------------------------------------
# Attributes
# ----------------------------------------------------------------------------------------------

def _required_name(element: ET.Element, source: str, where: str) -> str:
    name = element.get("name")
    if not name:
        raise SchemaError(source, where, "no 'name' attribute (or it is empty)")
    return name


def _single_child(element: ET.Element, tag: str, source: str, where: str) -> ET.Element | None:
    """The one ``<tag>`` child of ``element``, or None; two or more are an error."""
    found = element.findall(tag)
    if len(found) > 1:
        raise SchemaError(source, where, f"{len(found)} <{tag}> elements, expected one")
    return found[0] if found else None


def _read_origin(element: ET.Element | None, source: str, where: str
                 ) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """``(xyz [m], rpy [rad])`` of an ``<origin>``; zeros when absent."""
    if element is None:
        return ZEROS, ZEROS
    return (_vector_attribute(element, "xyz", 3, source, where, ZEROS),
            _vector_attribute(element, "rpy", 3, source, where, ZEROS))


def _vector_attribute(element: ET.Element, attribute: str, count: int, source: str, where: str,
                      default: tuple[float, ...] | None = None) -> tuple[float, ...]:
    """``count`` whitespace-separated finite numbers; ``default`` (if not None) when absent."""
    text = element.get(attribute)
    if text is None:
        if default is None:
            raise SchemaError(source, where, f"no '{attribute}' attribute")
        return default
    parts = text.split()
    if len(parts) != count:
        raise SchemaError(
            source, where,
            f"{attribute}={_show(text)} has {len(parts)} numbers, expected {count}")
    return tuple(_finite(part, f"{attribute} component", source, where) for part in parts)


def _number_attribute(element: ET.Element, attribute: str, source: str, where: str) -> float:
    text = element.get(attribute)
    if text is None:
        raise SchemaError(source, where, f"no '{attribute}' attribute")
    return _finite(text, attribute, source, where)


def _finite(text: str, label: str, source: str, where: str) -> float:
    """``float(text)``, refusing text that is not a number or breaks the rule for numbers in
    descriptions (:mod:`eomgen.model.numbers`: finite, magnitude at most 1e12)."""
    return check_number(_float(text, label, source, where), source, where, label, _show(text))


def _float(text: str, label: str, source: str, where: str) -> float:
    """``float(text)``, refusing text that is not a number."""
    try:
        return float(text)
    except ValueError:
        raise InvalidNumberError(source, where,
                                 f"{label} {_show(text)} is not a number") from None


def _limit(text: str, label: str, source: str, where: str) -> float:
    """A ``<limit>`` attribute: any number but ``nan`` (limits do not enter the equations of
    motion; ``inf`` or ``1e16`` is no limit)."""
    value = _float(text, label, source, where)
    if math.isnan(value):
        raise InvalidNumberError(source, where, f"{label} {_show(text)} is not a number")
    return value


def _show(text: str) -> str:
    """A short quoted rendering of file text for an error message."""
    if len(text) > _SHOWN_CHARACTERS:
        text = text[:_SHOWN_CHARACTERS] + "..."
    return repr(text)
