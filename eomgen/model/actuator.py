"""The drive of a joint (:class:`Actuator`): armature, friction, elasticity (docs/actuators.md)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import sympy as sp

from ..common import reprs
from .scalars import Scalar, scalar

#: Coulomb friction is smoothed as ``friction · tanh(q̇ / friction_width)`` for simulation; this
#: width [rad/s or m/s] is used when a description gives Coulomb friction without a width.
DEFAULT_FRICTION_WIDTH = 0.01


@dataclass(frozen=True)
class Actuator:
    """The drive of one movable joint: a motor behind a gear, with friction, and optionally
    an elastic transmission (a flexible joint, Spong's model). See docs/actuators.md.

    Conventions: the gear ratio ``r`` is motor turns per joint turn (``θ_rotor = r θ``), so a
    rotor of inertia ``I_rotor`` [kg m²] about its spin axis adds the *reflected inertia*
    (armature) ``r² I_rotor`` to the joint's diagonal entry of ``M`` (MuJoCo's ``armature``,
    Drake's rotor inertia and gear ratio). Motor angles of flexible joints are on the link side
    of the gear (``θ_m = θ_rotor / r`` [rad]), so the motor inertia of Spong's model is
    ``B = armature``. Torques are joint-side (N m; N for prismatic joints), positive along the
    joint axis; friction opposes the motion (``τ_friction = -damping q̇ - friction sign(q̇)``
    acts on the joint).

    Attributes
    ----------
    armature:
        Reflected rotor inertia [kg m²; kg for a prismatic joint], ``≥ 0``: given directly or
        computed as ``gear_ratio² · rotor_inertia``.
    damping:
        Viscous friction coefficient [N m s/rad], ``≥ 0``.
    friction:
        Coulomb friction torque [N m], ``≥ 0``.
    friction_width:
        Velocity [rad/s] of the ``tanh`` smoothing of Coulomb friction used for simulation
        (inverse dynamics uses the exact sign), ``> 0``.
    stiffness:
        Joint stiffness ``K`` [N m/rad] of a flexible joint, ``> 0``; None for a rigid joint.
    rotor_inertia, gear_ratio:
        The rotor inertia [kg m²] and gear ratio when the description gives them (None
        otherwise); ``armature`` holds their product ``r² I_rotor``.
    """

    __repr__ = reprs.field_repr  # its numbers as short as they read back

    armature: Scalar = sp.Integer(0)
    damping: Scalar = sp.Integer(0)
    friction: Scalar = sp.Integer(0)
    friction_width: Scalar = scalar(DEFAULT_FRICTION_WIDTH)
    stiffness: Scalar | None = None
    rotor_inertia: Scalar | None = None
    gear_ratio: Scalar | None = None

    def __post_init__(self):  # accept plain numbers from Python callers
        for name in ("armature", "damping", "friction", "friction_width", "stiffness",
                     "rotor_inertia", "gear_ratio"):
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, scalar(value))

    @staticmethod
    def from_rotor(rotor_inertia, gear_ratio, **others) -> "Actuator":
        """An actuator whose armature is ``gear_ratio² · rotor_inertia``."""
        I, r = scalar(rotor_inertia), scalar(gear_ratio)
        return Actuator(armature=r ** 2 * I, rotor_inertia=I, gear_ratio=r, **others)

    def updated(self, values: Mapping[str, object]) -> "Actuator":
        """A copy with the given fields replaced (a scene over a description). Giving
        ``rotor_inertia`` or ``gear_ratio`` recomputes ``armature`` from both (a missing gear
        ratio is 1); giving ``armature`` forgets them."""
        fields = {name: getattr(self, name) for name in self.__dataclass_fields__}
        values = {k: scalar(v) for k, v in values.items()}
        if "rotor_inertia" in values or "gear_ratio" in values:
            I = values.pop("rotor_inertia", self.rotor_inertia)
            r = values.pop("gear_ratio", self.gear_ratio)
            r = sp.Integer(1) if r is None else r
            I = sp.Integer(0) if I is None else I
            values.update(armature=r ** 2 * I, rotor_inertia=I, gear_ratio=r)
        elif "armature" in values:
            values.update(rotor_inertia=None, gear_ratio=None)
        fields.update(values)
        return Actuator(**fields)

    @property
    def flexible(self) -> bool:
        """Whether the joint is elastic (has a stiffness): Spong's model gives it a motor."""
        return self.stiffness is not None

    def scalars(self) -> tuple[sp.Expr, ...]:
        """Every value it holds (for symbol bookkeeping)."""
        return tuple(v for v in (self.armature, self.damping, self.friction,
                                 self.friction_width, self.stiffness, self.rotor_inertia,
                                 self.gear_ratio) if v is not None)

    def substitute(self, subs: Mapping[sp.Symbol, sp.Expr]) -> "Actuator":
        """A copy with ``subs`` applied to every value."""
        def s(x):
            return None if x is None else scalar(x.xreplace(subs))
        return Actuator(s(self.armature), s(self.damping), s(self.friction),
                        s(self.friction_width), s(self.stiffness), s(self.rotor_inertia),
                        s(self.gear_ratio))
