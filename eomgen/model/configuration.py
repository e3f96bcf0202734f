"""The configuration space of a model with quaternion joints (a free flyer, ball joints):
Pinocchio's ``integrate``, ``difference`` and ``neutral`` and the configuration rate ``q̇(q, v)``,
NumPy, one state.

``q`` has NQ entries and ``v`` NV, laid out as :mod:`eomgen.model.quaternion` says (Pinocchio's
layout): a free flyer moves along the SE(3) exponential of its twist (root frame), a ball joint
along the SO(3) exponential of its angular velocity (child frame), ``R(t) = R exp([ω t]×)``, the
other joints by ``q + v t``. Every function takes the model (or the joints of :func:`layout`)
as ``model``; without it ``q`` is taken to start with the virtual base joint (the free flyer)
and to hold no other joint whose configuration is not its coordinates
(:mod:`eomgen.model.floating`).

**Non-unit quaternions** on input: every generated function and these ones use the normalised
quaternion (any nonzero multiple of a unit quaternion gives the same result; a zero quaternion
has no orientation and gives results that are not finite); :func:`integrate` returns unit
quaternions, with ``w ≥ 0`` when it rebuilds them from a rotation.

Examples
--------
>>> import numpy as np
>>> import eomgen
>>> from eomgen.model import Joint, JointType, Link, build_model
>>> ball = build_model("<memory>", "pendulum",
...     [Link("base"), Link("bob", eomgen.model.Inertial(1.0, (0, 0, -1), [[0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.1]]))],
...     [Joint("hip", JointType.SPHERICAL, "base", "bob")])
>>> ball.configuration_names, ball.joint_names
(('hip_qx', 'hip_qy', 'hip_qz', 'hip_qw'), ('hip_wx', 'hip_wy', 'hip_wz'))
>>> q1 = integrate(neutral(ball), np.array([0.0, 0.0, np.pi / 2]), 1.0, model=ball)
>>> bool(np.allclose(q1, [0, 0, np.sin(np.pi / 4), np.cos(np.pi / 4)]))
True
>>> bool(np.allclose(difference(neutral(ball), q1, model=ball), [0, 0, np.pi / 2]))
True
"""

from __future__ import annotations

import numpy as np

from .joints import KINDS
from .quaternion import QuaternionJoint
from .robot import RobotModel
# kept importable here: the rotations every kind uses (eomgen.model.joints.lie)
from .joints.lie import left_jacobian, skew, so3_exp, so3_log


#: The kind of the virtual base joint (:attr:`~eomgen.model.joints.JointKind.base`).
BASE_KIND = next(kind for kind in KINDS.values() if kind.base)


def layout(model, nv: int | None = None) -> tuple[QuaternionJoint, ...]:
    """The joints of ``model`` whose configuration is not their coordinates (NQ ≠ NV), from
    its :attr:`~eomgen.model.RobotModel.joint_places` (or ``model`` itself when it is such
    joints); None: the virtual base joint (the free flyer) at the start."""
    if model is None:
        return (QuaternionJoint(BASE_KIND, "base", 0, 0),)
    if isinstance(model, RobotModel):
        return tuple(place for place in model.joint_places if place.nq != place.nv)
    return tuple(model)


def _pieces(joints, nv: int):
    """``(joint or None, v slice, q slice)`` for every joint of the layout, in order."""
    starts = {j.v_index: j for j in joints}
    k = iq = 0
    while k < nv:
        joint = starts.get(k)
        width, length = (1, 1) if joint is None else (joint.nv, joint.nq)
        yield joint, slice(k, k + width), slice(iq, iq + length)
        k, iq = k + width, iq + length


#: A unit part (quaternion, (cos, sin) pair) shorter than this stands for no configuration.
DEGENERATE_LENGTH = 1e-9


def degenerate(q, model=None) -> str | None:
    """None when every joint's configuration in ``q`` (NQ) stands for one (each quaternion and
    planar ``(cos, sin)`` pair longer than :data:`DEGENERATE_LENGTH`: it stands for its
    normalised value); otherwise what is wrong, in words naming the first joint and its
    entries, e.g. ``"joint 'hip': its quaternion (hip_qx, hip_qy, hip_qz, hip_qw) has zero
    length"``."""
    q = np.asarray(q, dtype=float)
    for joint in layout(model):
        unit = joint.kind.unit_entries
        if unit is not None and not np.linalg.norm(q[joint.q_slice][unit]) > DEGENERATE_LENGTH:
            names = ", ".join(joint.kind.configuration_names(joint.name)[unit])
            return (f"joint '{joint.name}': its {joint.kind.unit_name} ({names}) has zero "
                    "length; give a unit one")
    return None


def norm_error(q, model=None) -> float:
    """How far ``q`` (NQ) is off the configuration manifold: the largest ``|‖u‖ − 1|`` over
    the unit parts of its joints (each kind's
    :meth:`~eomgen.model.joints.ChartKind.norm_error`: a quaternion, a planar joint's
    ``(cos θ, sin θ)``); 0 without them."""
    q = np.asarray(q, dtype=float)
    return max((j.kind.norm_error(q[j.q_slice]) for j in layout(model)), default=0.0)


def configuration_rate(q, v, model=None) -> np.ndarray:
    """``q̇`` (NQ) at velocity ``v`` (NV): each joint's kind's rate
    (:meth:`~eomgen.model.joints.JointKind.configuration_rate`): a free flyer's origin moves at
    ``R v_lin``, a quaternion at ``½ (x, y, z, w) ⊗ (ω, 0)``, the other joints at ``v``."""
    q, v = np.asarray(q, dtype=float), np.asarray(v, dtype=float)
    out = np.empty(len(q))
    for joint, sv, sq in _pieces(layout(model), len(v)):
        out[sq] = v[sv] if joint is None else joint.kind.configuration_rate(q[sq], v[sv])
    return out


def integrate(q, v, dt: float = 1.0, model=None) -> np.ndarray:
    """The configuration reached from ``q`` (NQ) moving with the constant velocity ``v`` (NV)
    for ``dt`` seconds (Pinocchio's ``integrate(model, q, v dt)``), each joint by its kind's
    exponential: a free flyer along the SE(3) exponential of its twist (root frame), a ball
    joint ``R exp([ω dt]×)``, a planar joint along SE(2)'s, the other joints by ``q + v dt``.
    The quaternions of the result are unit."""
    q, v = np.asarray(q, dtype=float), np.asarray(v, dtype=float) * dt
    out = np.empty(len(q))
    for joint, sv, sq in _pieces(layout(model), len(v)):
        out[sq] = q[sq] + v[sv] if joint is None else joint.kind.integrate(q[sq], v[sv])
    return out


def difference(q0, q1, model=None) -> np.ndarray:
    """The velocity ``v`` (NV) with ``integrate(q0, v, 1) = q1`` (Pinocchio's
    ``difference``), each joint by its kind's logarithm: a free flyer's SE(3) logarithm of
    ``(R0, p0)⁻¹ (R1, p1)`` (root frame of ``q0``), a ball joint's ``log(R0ᵀ R1)``, ``q1 − q0``
    for the one-axis joints."""
    q0, q1 = np.asarray(q0, dtype=float), np.asarray(q1, dtype=float)
    joints = layout(model)
    out = np.empty(len(q0) - sum(j.nq - j.nv for j in joints))
    for joint, sv, sq in _pieces(joints, len(out)):
        out[sv] = q1[sq] - q0[sq] if joint is None else joint.kind.difference(q0[sq], q1[sq])
    return out


def neutral(model) -> np.ndarray:
    """The neutral configuration (Pinocchio's ``neutral``): each joint's kind's (identity
    quaternions (0, 0, 0, 1), a planar joint's (0, 0, 1, 0)), everything else zero. ``model``:
    a :class:`~eomgen.model.RobotModel`, or the NQ of a model whose only such joint is a free
    flyer at the start."""
    if isinstance(model, RobotModel):
        q, joints = np.zeros(model.nq), layout(model)
    else:
        q, joints = np.zeros(int(model)), layout(None)
    for joint in joints:
        q[joint.q_slice] = joint.kind.neutral()
    return q


def random_configuration(model, coordinates: np.ndarray, rng: np.random.Generator
                         ) -> np.ndarray:
    """The configuration (``model.nq``) for tests and verification whose joints with a chart
    take their kind's :meth:`~eomgen.model.joints.JointKind.random_configuration` of their
    ``coordinates`` (a free flyer's origin; quaternions uniform on the unit sphere, from
    ``rng``) and the others ``coordinates`` (``model.dof`` values, by velocity index):
    ``coordinates`` itself when ``q`` is the coordinates."""
    joints = layout(model)
    if not joints:
        return coordinates
    q = np.empty(model.nq)
    for joint, sv, sq in _pieces(joints, model.dof):
        q[sq] = (coordinates[sv] if joint is None
                 else joint.kind.random_configuration(coordinates[sv], rng))
    return q


def chart_indices(model) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """``(massless, charted)``: the velocity indices of ``model`` whose bodies are the massless
    links inside the chain of a joint with a chart (all its virtual joints but the last:
    their inertial parameters are zero by construction), and the velocity indices of those
    joints (which take no drive); both empty when ``q`` is the coordinates."""
    joints = layout(model)
    return (tuple(k for joint in joints for k in joint.virtual),
            tuple(k for joint in joints for k in range(joint.v_index, joint.v_index + joint.nv)))


def chart_states(model, xi, xid, xidd) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(q, v, v̇)`` of the chart states ``(ξ, ξ̇, ξ̈)`` (each (N, NV)) of ``model`` (a
    :class:`~eomgen.model.RobotModel`, or the joints of :func:`layout`): ``q`` (N, NQ), ``v``
    and ``v̇`` (N, NV), each joint with a chart by its kind's
    :meth:`~eomgen.model.joints.ChartKind.chart_states`
    (:mod:`eomgen.identification.charts`); the inputs when ``q`` is the coordinates."""
    xi, xid, xidd = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (xi, xid, xidd))
    joints = layout(model)
    if not joints:
        return xi, xid, xidd
    N, nv = xi.shape
    q = np.empty((N, nv + sum(j.nq - j.nv for j in joints)))
    v, vd = xid.copy(), xidd.copy()
    for joint, sv, sq in _pieces(joints, nv):
        if joint is None:
            q[:, sq] = xi[:, sv]
        else:
            q[:, sq], v[:, sv], vd[:, sv] = joint.kind.chart_states(xi[:, sv], xid[:, sv],
                                                                    xidd[:, sv])
    return q, v, vd


def quaternion_indices(model) -> tuple[int, ...]:
    """The index in ``q`` of the x of each quaternion of ``model`` (then y, z, w), in order:
    the joints whose kind holds one (its ``quaternion_offset``); empty without them."""
    return tuple(j.quaternion for j in layout(model) if j.quaternion is not None)


__all__ = ["BASE_KIND", "DEGENERATE_LENGTH", "chart_indices", "chart_states",
           "configuration_rate", "degenerate", "difference", "integrate", "layout",
           "left_jacobian", "neutral", "norm_error", "quaternion_indices",
           "random_configuration", "skew", "so3_exp", "so3_log"]
