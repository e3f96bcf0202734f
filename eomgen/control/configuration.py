"""The configuration space a control law works on, read off a generated module: the
quaternion joints (a free flyer, ball joints: :mod:`eomgen.model.quaternion`) its
``CONFIGURATION_NAMES`` (NQ) and ``JOINT_NAMES`` (NV) show, and the position error and
configuration rate on it.

With quaternion joints ``q`` (NQ) and ``v`` (NV) have different sizes: a position error is
the velocity ``e = difference(q_d, q)`` that moves ``q_d`` to ``q`` in unit time (Pinocchio's
``difference``: ``q − q_d`` for the other joints, ``log(R_dᵀ R)`` for a ball joint, the SE(3)
logarithm in the desired root frame for the free flyer), and the configuration moves at
``q̇ = configuration_rate(q, v)`` (:mod:`eomgen.model.configuration`).
"""

from __future__ import annotations

import numpy as np

from ..model import QuaternionJoint, RobotModel
from ..model.joints import KINDS, ChartKind
from ..model.configuration import configuration_rate, difference, layout


def module_layout(module) -> tuple[QuaternionJoint, ...]:
    """The joints of a generated module whose configuration is not their coordinates (read
    off anything with ``JOINT_NAMES`` and, for such a model, ``CONFIGURATION_NAMES``), from the
    names each kind gives its entries (:mod:`eomgen.model.joints`): a free flyer's ``base_vx …
    base_wz`` over ``base_x … base_qw``, a ball joint's ``<name>_wx … _wz`` over ``<name>_qx …
    _qw``, a planar joint's ``<name>_vx, _vy, _wz`` over ``<name>_x, _y, _cos, _sin``; empty
    when the two lists are one. Of a :class:`~eomgen.model.RobotModel`, its own
    (:func:`eomgen.model.configuration.layout`)."""
    if isinstance(module, RobotModel):
        return layout(module)
    velocity = tuple(getattr(module, "JOINT_NAMES", ()))
    configuration = tuple(getattr(module, "CONFIGURATION_NAMES", velocity))
    if configuration == velocity:
        return ()
    kinds = [kind for kind in KINDS.values() if isinstance(kind, ChartKind)]
    found, k, iq = [], 0, 0
    while k < len(velocity):
        for kind in kinds:
            name = velocity[k][:-len(kind.velocity_suffixes[0]) - 1]
            if (velocity[k:k + kind.nv] == kind.velocity_names(name)
                    and configuration[iq:iq + kind.nq] == kind.configuration_names(name)):
                found.append(QuaternionJoint(kind, "base" if kind.base else name,
                                             k, iq))
                k, iq = k + kind.nv, iq + kind.nq
                break
        else:
            k, iq = k + 1, iq + 1
    if iq != len(configuration):
        raise ValueError(f"CONFIGURATION_NAMES ({len(configuration)}) and JOINT_NAMES "
                         f"({len(velocity)}) do not describe one configuration space")
    return tuple(found)


def position_error(joints, q, q_d) -> np.ndarray:
    """``e`` (NV) of ``q`` from ``q_d`` (NQ each): ``q − q_d`` without quaternion joints, else
    ``difference(q_d, q)`` (module docstring)."""
    q, q_d = np.asarray(q, dtype=float), np.asarray(q_d, dtype=float)
    return q - q_d if not joints else difference(q_d, q, joints)


def rate(joints, q, v) -> np.ndarray:
    """``q̇`` (NQ) at velocity ``v``: ``v`` without quaternion joints, else
    :func:`~eomgen.model.configuration.configuration_rate`."""
    return np.asarray(v, dtype=float) if not joints else configuration_rate(q, v, joints)


__all__ = ["module_layout", "position_error", "rate"]
