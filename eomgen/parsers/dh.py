"""Denavit-Hartenberg tables in YAML, standard (distal) or modified (Craig, proximal).

.. code-block:: yaml

    name: two_link
    convention: standard        # standard | modified (required)
    gravity: [0, 0, -9.81]      # optional, this is the default
    parameters: {a1: 1.0, a2: 1.0}
    dh:
      - {type: revolute, a: a1, alpha: 0, d: 0, theta: 0, mass: 1, com: [-a1/2, 0, 0]}
      - {a: a2, alpha: 0, d: 0, theta: 0}

Row ``i`` (``i = 1..n``) describes joint ``i`` and link ``i``; ``a alpha d theta`` default to 0,
``type`` to revolute. ``theta`` (revolute) or ``d`` (prismatic) is an offset to which the joint
variable ``q_i`` is added.

* ``standard``: ``T_{i-1,i} = Rz(theta_i + q_i) Tz(d_i) Tx(a_i) Rx(alpha_i)``; ``com`` and
  ``inertia`` of row ``i`` are given in DH frame ``i`` (at the distal end of link ``i``,
  Corke's Robotics Toolbox convention).
* ``modified``: ``T_{i-1,i} = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i + q_i) Tz(d_i)``; row ``i``
  holds ``alpha_{i-1}, a_{i-1}, d_i, theta_i`` as in Craig's table, in keys ``alpha, a, d,
  theta``. ``com`` and ``inertia`` are given in frame ``i`` (on joint axis ``i``).

(For a prismatic joint read ``Rz(theta_i) Tz(d_i + q_i)`` instead.)

Conversion to the URDF-like model (:mod:`eomgen.model`): links ``link0`` (the fixed base, DH
frame 0) to ``link{n}``, joints named by ``name`` (default ``joint{i}``), each moving about or
along its local z axis. ``Rz`` and ``Tz`` commute, so with ``P_i = Tz(d_i) Rz(theta_i)`` and
``motion_i = Rz(q_i)`` (or ``Tz(q_i)``):

* modified: the model's link frame ``i`` *is* DH frame ``i``; joint ``i``'s origin is
  ``Rx(alpha_{i-1}) Tx(a_{i-1}) P_i``.
* standard: ``T_{i-1,i} = P_i · motion_i · D_i`` with ``D_i = Tx(a_i) Rx(alpha_i)`` after the
  motion, so the model's link frame ``i`` is DH frame ``i`` moved back by ``D_i``: it lies on
  joint axis ``i`` (z_{i-1}). Joint ``i``'s origin is ``D_{i-1} P_i`` (``D_0`` = identity);
  the link's ``com`` and ``inertia`` are re-expressed from DH frame ``i`` into the link frame
  (``c = D_i c_DH``, ``I = R_x(alpha_i) I_DH R_x(alpha_i)^T``). DH frame ``n`` (the end frame)
  is kept as a massless link ``frame{n}`` fixed to ``link{n}`` by the joint ``frame{n}_fixed``
  with origin ``D_n``.

The table is kept in ``model.info``: ``convention``, ``dh_columns`` and ``dh`` (one tuple
``(joint, type, a, alpha, d, theta)`` per row, SymPy scalars, as written in the file).
"""

from __future__ import annotations

from pathlib import Path

import sympy as sp

from ..model import (
    IDENTITY3, Inertial, Joint, JointType, Link, Mat3, RobotModel, Transform, build_model,
    check_size, mat3, rotation_about_axis, vec3,
)
from .registry import register
from ._yaml import Reader, read_document, top_level_key

TOP_KEYS = ("name", "description", "convention", "gravity", "parameters", "dh")
ROW_KEYS = ("name", "type", "a", "alpha", "d", "theta", "mass", "com", "inertia")
CONVENTIONS = ("standard", "modified")
ROW_TYPES = {"revolute": JointType.REVOLUTE, "prismatic": JointType.PRISMATIC}
DH_COLUMNS = ("joint", "type", "a", "alpha", "d", "theta")

ZERO_INERTIA = mat3([[0, 0, 0], [0, 0, 0], [0, 0, 0]])
_X = vec3([1, 0, 0])
_Z = vec3([0, 0, 1])


def sniff(text: str) -> bool:
    """A DH table has a top-level ``dh:`` key."""
    return top_level_key(text, "dh")


@register("DH table", (".yaml", ".yml"), sniff)
def load(path, strict: bool = False, defer_notices: bool = False) -> RobotModel:
    """Read a DH table (see the module docstring for the conventions).

    Parameters
    ----------
    path:
        The ``.yaml`` file with a top-level ``dh`` list.
    strict:
        Refuse (rather than warn about) inertias that break the triangle inequality.
    defer_notices:
        Record such findings in ``RobotModel.notices`` without warning or refusing yet
        (see :func:`eomgen.parsers.load`).

    Raises
    ------
    DescriptionError
        One line naming the file and the element, e.g. ``dh[2] 'joint3' alpha``; the subclass
        tells the kind of problem (see :mod:`eomgen.errors`).
    """
    path = Path(path)
    return parse(read_document(path), str(path), strict, default_name=path.stem,
                 defer_notices=defer_notices)


def x_transform(a, alpha) -> Transform:
    """``Tx(a) Rx(alpha)``."""
    return Transform(rotation_about_axis(_X, alpha), vec3([a, 0, 0]))


def z_transform(d, theta) -> Transform:
    """``Rz(theta) Tz(d)`` (= ``Tz(d) Rz(theta)``)."""
    return Transform(rotation_about_axis(_Z, theta), vec3([0, 0, d]))


def rotate_inertia(rotation: Mat3, inertia: Mat3) -> Mat3:
    """``R I Rᵀ``: an inertia given in frame B re-expressed in frame A, ``R = R_AB``."""
    R, I = sp.Matrix(rotation), sp.Matrix(inertia)
    out = R * I * R.T
    rows = [[out[min(i, j), max(i, j)] for j in range(3)] for i in range(3)]  # exactly symmetric
    return tuple(tuple(sp.expand(v) if v.free_symbols else v for v in row)
                 for row in rows)  # type: ignore[return-value]


def parse(data: dict, source: str, strict: bool = False, default_name: str = "robot",
          defer_notices: bool = False) -> RobotModel:
    """Build the model from an already loaded document (see :func:`load`)."""
    r = Reader(source)
    r.mapping(data, "robot", required=("convention", "dh"), optional=TOP_KEYS)
    name = r.text(data["name"], "name") if "name" in data else default_name
    convention = r.choice(data["convention"], "convention", CONVENTIONS)
    r.read_parameters(data.get("parameters"))
    gravity = r.vector(data["gravity"], "gravity") if "gravity" in data else vec3([0, 0, -9.81])

    entries = r.sequence(data["dh"], "dh")
    check_size(source, len(entries) + 1, len(entries))  # one link more: the base
    rows = []
    for i, entry in enumerate(entries, start=1):
        where = f"dh[{i - 1}]"
        label = where
        if isinstance(entry, dict):
            label = r.named(entry, where) if "name" in entry else f"{where} 'joint{i}'"
        r.mapping(entry, label, optional=ROW_KEYS)
        joint_name = r.name(entry["name"], f"{where} name") if "name" in entry else f"joint{i}"
        where = f"{where} '{joint_name}'"
        kind = r.choice(entry.get("type", "revolute"), f"{where} type", ROW_TYPES)
        a, alpha, d, theta = (r.scalar(entry.get(k, 0), f"{where} {k}")
                              for k in ("a", "alpha", "d", "theta"))
        inertial = None
        if "mass" in entry:
            com = r.vector(entry["com"], f"{where} com") if "com" in entry else vec3([0, 0, 0])
            inertia = r.inertia(entry["inertia"], f"{where} inertia") if "inertia" in entry \
                else ZERO_INERTIA
            inertial = Inertial(r.scalar(entry["mass"], f"{where} mass"), com, inertia)
        else:
            for key in ("com", "inertia"):
                if key in entry:
                    raise r.error(where, f"'{key}' given without 'mass'")
        rows.append((joint_name, kind, a, alpha, d, theta, inertial))

    n = len(rows)
    links = [Link("link0")]
    joints = []
    before = Transform()  # the constant part between the previous link frame and this row
    for i, (joint_name, kind, a, alpha, d, theta, inertial) in enumerate(rows, start=1):
        if convention == "modified":
            origin = x_transform(a, alpha) @ z_transform(d, theta)
        else:
            origin = before @ z_transform(d, theta)
            after = x_transform(a, alpha)
            before = after
            if inertial is not None:
                inertial = Inertial(inertial.mass, after.apply(inertial.com),
                                    rotate_inertia(after.rotation, inertial.inertia))
        links.append(Link(f"link{i}", inertial))
        joints.append(Joint(joint_name, ROW_TYPES[kind], f"link{i - 1}", f"link{i}", origin, _Z))
    if convention == "standard" and (before.rotation != IDENTITY3
                                     or any(v != 0 for v in before.translation)):
        links.append(Link(f"frame{n}"))
        joints.append(Joint(f"frame{n}_fixed", JointType.FIXED, f"link{n}", f"frame{n}", before))

    info = {
        "convention": convention,
        "dh_columns": DH_COLUMNS,
        "dh": tuple((row[0], row[1]) + tuple(row[2:6]) for row in rows),
    }
    if "description" in data:
        info["description"] = r.text(data["description"], "description")
    return build_model(source, name, links, joints, gravity, r.used_parameters(), strict, info,
                       defer_notices=defer_notices)
