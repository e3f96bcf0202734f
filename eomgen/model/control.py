"""The control inputs of a model (:class:`Control`): MuJoCo's actuators with a joint
transmission, each a scalar ``ctrl`` turned into a joint force (docs/formats.md, ``controls:``).

Not the drive of a joint (:class:`~eomgen.model.Actuator`: armature, friction, a flexible
transmission): a control is what a controller commands. Its force, MuJoCo's ``force = gain ·
ctrl + bias`` on the joint's length ``l = gear · q`` and velocity ``v = gear · q̇``::

    c      = clamp(ctrl, ctrlrange)                (when ctrlrange is given)
    gain   = gain[0] + gain[1] l + gain[2] v        (fixed: gain[1] = gain[2] = 0)
    bias   = bias[0] + bias[1] l + bias[2] v        (none: all zero)
    force  = clamp(gain · c + bias, forcerange)     (when forcerange is given)
    τ_joint += gear · force

so a motor is ``gain = (1, 0, 0)``, a position servo ``gain = (kp, 0, 0), bias = (0, −kp,
−kv)``, a velocity servo ``gain = (kv, 0, 0), bias = (0, 0, −kv)``.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..common import reprs
from .scalars import Scalar, scalar


@dataclass(frozen=True)
class Control:
    """One control input on a one-coordinate joint (see the module docstring).

    Attributes
    ----------
    name:
        Its name (MuJoCo's actuator name), an entry of ``ACTUATOR_NAMES``.
    joint:
        The joint it drives (a revolute, prismatic or helical joint of the model).
    gear:
        The transmission ratio: length ``gear · q``, joint force ``gear · force``.
    gain, bias:
        The affine coefficients ``(c0, c_length, c_velocity)`` of the gain and the bias.
    ctrlrange, forcerange:
        ``(low, high)`` the control and the force are clamped to; None: not clamped.
    """

    __repr__ = reprs.field_repr

    name: str
    joint: str
    gear: Scalar = scalar(1)
    gain: tuple[Scalar, Scalar, Scalar] = (scalar(1), scalar(0), scalar(0))
    bias: tuple[Scalar, Scalar, Scalar] = (scalar(0), scalar(0), scalar(0))
    ctrlrange: tuple[Scalar, Scalar] | None = None
    forcerange: tuple[Scalar, Scalar] | None = None


def make_control(name: str, joint: str, gear=1, gain=(1, 0, 0), bias=(0, 0, 0),
                 ctrlrange=None, forcerange=None) -> Control:
    """A :class:`Control` from plain numbers (each made a model scalar)."""
    def pair(values):
        return None if values is None else tuple(scalar(v) for v in values)

    return Control(name, joint, scalar(gear), tuple(scalar(v) for v in gain),
                   tuple(scalar(v) for v in bias), pair(ctrlrange), pair(forcerange))


__all__ = ["Control", "make_control"]
