"""Passive elements: a joint's spring (:class:`Spring`) and fixed tendons (:class:`Tendon`),
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
