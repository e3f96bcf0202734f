"""The configuration space a control law works on, read off a generated module: the
quaternion joints (a free flyer, ball joints: :mod:`eomgen.model.quaternion`) its
``CONFIGURATION_NAMES`` (NQ) and ``JOINT_NAMES`` (NV) show, and the position error and
configuration rate on it.

With quaternion joints ``q`` (NQ) and ``v`` (NV) have different sizes: a position error is
the velocity ``e = difference(q_d, q)`` that moves ``q_d`` to ``q`` in unit time (Pinocchio's
``difference``: ``q − q_d`` for the other joints, ``log(R_dᵀ R)`` for a ball joint, the SE(3)
logarithm in the desired root frame for the free flyer), and the configuration moves at
``q̇ = configuration_rate(q, v)`` (:mod:`eomgen.quaternion_joints`).
"""

from __future__ import annotations

import numpy as np

from ..model import QuaternionJoint
from ..model.quaternion import (BALL_CONFIGURATION, BALL_VELOCITY, FREE_FLYER,
                                FREE_FLYER_CONFIGURATION, FREE_FLYER_VELOCITY, SPHERICAL)
from ..quaternion_joints import configuration_rate, difference


def module_layout(module) -> tuple[QuaternionJoint, ...]:
    """The quaternion joints of a generated module (or anything with ``JOINT_NAMES`` and,
    for a model with quaternion joints, ``CONFIGURATION_NAMES``), from the names: a free
    flyer's ``base_vx … base_wz`` over ``base_x … base_qw``, a ball joint's ``<name>_wx …
    _wz`` over ``<name>_qx … _qw``; empty when the two lists are one."""
    velocity = tuple(getattr(module, "JOINT_NAMES", ()))
    configuration = tuple(getattr(module, "CONFIGURATION_NAMES", velocity))
    if configuration == velocity:
        return ()
    found, k, iq = [], 0, 0
    while k < len(velocity):
        name = velocity[k]
        if velocity[k:k + 6] == FREE_FLYER_VELOCITY \
                and configuration[iq:iq + 7] == FREE_FLYER_CONFIGURATION:
            found.append(QuaternionJoint(FREE_FLYER, "base", k, iq))
        else:
            ball = name[:-len(BALL_VELOCITY[0]) - 1]
            if (velocity[k:k + 3] == tuple(f"{ball}_{s}" for s in BALL_VELOCITY)
                    and configuration[iq:iq + 4] == tuple(f"{ball}_{s}"
                                                          for s in BALL_CONFIGURATION)):
                found.append(QuaternionJoint(SPHERICAL, ball, k, iq))
        width = found[-1].nv if found and found[-1].v_index == k else 1
        k, iq = k + width, iq + width + (width > 1)
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
    :func:`~eomgen.quaternion_joints.configuration_rate`."""
    return np.asarray(v, dtype=float) if not joints else configuration_rate(q, v, joints)


__all__ = ["module_layout", "position_error", "rate"]
