"""Passive elements: a joint's spring (:class:`Spring`, on a ball joint :class:`BallSpring`)
and fixed tendons (:class:`Tendon`),
the springs and dampers MuJoCo puts in ``qfrc_passive`` (docs/formats.md).

Sign conventions (MuJoCo's): a joint spring pushes its joint back to the reference,
``τ_i = −k (q_i − q_ref)``; a fixed tendon of length ``L = Σ c_i q_i`` (``c_i`` [1 or m/rad]
per joint) pulls with the force ``f = −k (L − clamp(L, L_lo, L_hi)) − b L̇`` (no spring force
inside the dead band ``[L_lo, L_hi]``; one rest length when both are equal), which reaches the
joints as ``τ_i = c_i f`` (``Jᵀ f`` with ``J = c``). These springs are distinct from a
flexible joint's series-elastic drive (:attr:`~eomgen.model.Actuator.stiffness`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import sympy as sp

from ..common import reprs
from .scalars import Scalar, scalar


@dataclass(frozen=True)
class Spring:
    """A linear spring on one joint: ``τ = −stiffness (q − reference)``.

    Attributes
    ----------
    stiffness:
        ``k`` [N m/rad or N/m], ``≥ 0``.
    reference:
        ``q_ref`` [rad or m], where the spring is at rest (MuJoCo's ``springref``).
    """

    __repr__ = reprs.field_repr

    stiffness: Scalar = sp.Integer(0)
    reference: Scalar = sp.Integer(0)

    def __post_init__(self):
        object.__setattr__(self, "stiffness", scalar(self.stiffness))
        object.__setattr__(self, "reference", scalar(self.reference))

    def substitute(self, subs: Mapping[sp.Symbol, sp.Expr]) -> "Spring":
        return Spring(self.stiffness.xreplace(subs), self.reference.xreplace(subs))


@dataclass(frozen=True)
class BallSpring:
    """A spring on a ball joint (MuJoCo's ``stiffness`` on a ball joint): the torque
    ``τ = −stiffness · log(q_ref⁻¹ ⊗ q)`` on its angular velocity coordinates, the rotation
    vector (axis times angle in ``(−π, π]``, in the child frame) that turns the reference
    quaternion into the joint's, MuJoCo's ``mju_subQuat(q, qpos_spring)``
    (:func:`ball_spring_torque`).

    Attributes
    ----------
    stiffness:
        ``k`` [N m/rad], ``≥ 0``.
    reference:
        ``q_ref = (x, y, z, w)``, the quaternion where the spring is at rest (MuJoCo's
        ``qpos_spring``, eomgen's order).
    """

    __repr__ = reprs.field_repr

    stiffness: Scalar = sp.Integer(0)
    reference: tuple[Scalar, Scalar, Scalar, Scalar] = (sp.Integer(0), sp.Integer(0),
                                                        sp.Integer(0), sp.Integer(1))

    def __post_init__(self):
        object.__setattr__(self, "stiffness", scalar(self.stiffness))
        object.__setattr__(self, "reference", tuple(scalar(v) for v in self.reference))

    def substitute(self, subs: Mapping[sp.Symbol, sp.Expr]) -> "BallSpring":
        return BallSpring(self.stiffness.xreplace(subs),
                          tuple(v.xreplace(subs) for v in self.reference))


#: Added under the square root of ``|v|²`` in :func:`ball_spring_torque` so that the torque and
#: its derivatives (up to the fifth power of ``1/|v|``, 1e-150, above the doubles' underflow)
#: are finite at the reference itself (``v = 0``). The factor ``atan(n / w) / n`` is even in
#: ``n`` with a zero slope at 0, so it moves the torque by a relative 1e-60 at most.
_TINY = sp.Float("1e-60")


def ball_spring_torque(spring: BallSpring, quaternion) -> list:
    """``τ = −k · 2 atan(|v| / w) / |v| · v`` (3 entries) of ``spring`` at the joint's
    ``quaternion`` ``(x, y, z, w)`` (SymPy expressions; any norm: the rotation vector does not
    depend on it), where ``(v, w) = q_ref⁻¹ ⊗ q``: ``2 atan(|v| / w)`` is MuJoCo's angle
    ``2 atan2(|v|, w)`` taken into ``(−π, π]`` as ``mju_quat2Vel`` does (the shorter way
    round), with a derivative everywhere (no sign function)."""
    rx, ry, rz, rw = spring.reference
    qx, qy, qz, qw = quaternion
    w = rw * qw + rx * qx + ry * qy + rz * qz
    v = (rw * qx - qw * rx - (ry * qz - rz * qy),
         rw * qy - qw * ry - (rz * qx - rx * qz),
         rw * qz - qw * rz - (rx * qy - ry * qx))
    norm = sp.sqrt(v[0] ** 2 + v[1] ** 2 + v[2] ** 2 + _TINY)
    scale = -spring.stiffness * 2 * sp.atan(norm / w) / norm
    return [scale * x for x in v]


@dataclass(frozen=True)
class Tendon:
    """A fixed tendon: the length ``L = Σ c_i q_i`` over ``coefficients`` ``((joint, c_i),
    …)``, a spring of ``stiffness`` [N/m] with the rest lengths ``lengths = (L_lo, L_hi)``
    (a dead band; equal for one rest length) and viscous ``damping`` [N s/m] (see the
    module docstring for the force and its sign)."""

    __repr__ = reprs.field_repr

    name: str
    coefficients: tuple[tuple[str, Scalar], ...]
    stiffness: Scalar = sp.Integer(0)
    lengths: tuple[Scalar, Scalar] = (sp.Integer(0), sp.Integer(0))
    damping: Scalar = sp.Integer(0)

    def __post_init__(self):
        object.__setattr__(self, "coefficients",
                           tuple((name, scalar(c)) for name, c in self.coefficients))
        object.__setattr__(self, "stiffness", scalar(self.stiffness))
        object.__setattr__(self, "lengths", tuple(scalar(v) for v in self.lengths))
        object.__setattr__(self, "damping", scalar(self.damping))

    def locked(self, positions: Mapping[str, object]) -> "Tendon":
        """The tendon with the joints of ``positions`` held there: their part of the length
        is constant, so it moves into the rest lengths."""
        held = sum((c * scalar(positions[name]) for name, c in self.coefficients
                    if name in positions), sp.Integer(0))
        return Tendon(self.name, tuple((n, c) for n, c in self.coefficients
                                       if n not in positions),
                      self.stiffness, tuple(v - held for v in self.lengths), self.damping)


def tendon_force(tendon: Tendon, length, rate):
    """``f = −k (L − clamp(L, L_lo, L_hi)) − b L̇`` of ``tendon`` at ``length`` and ``rate``
    (SymPy expressions): with a dead band, ``L − clamp(L, L_lo, L_hi)`` is
    ``min(L − L_lo, 0) + max(L − L_hi, 0)``, written with ``|x|`` (``max(x, 0) = (x + |x|) / 2``,
    exact in floating point) so that every backend prints it."""
    lo, hi = tendon.lengths
    if lo == hi:
        stretch = length - lo
    else:
        below, above = length - lo, length - hi
        stretch = (below - sp.Abs(below) + above + sp.Abs(above)) / 2
    return -tendon.stiffness * stretch - tendon.damping * rate
