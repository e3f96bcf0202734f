"""The control inputs of a model (:class:`Control`): MuJoCo's actuators with a joint or a
fixed-tendon transmission, each a scalar ``ctrl`` turned into joint forces (docs/formats.md,
``controls:``).

Not the drive of a joint (:class:`~eomgen.model.Actuator`: armature, friction, a flexible
transmission): a control is what a controller commands. Its transmission is a linear length
``L = Σ c_i q_i + L_0`` over joints (:attr:`Control.transmission`: the joint itself with
``c = 1`` for a joint transmission; a fixed tendon's coefficients, as MuJoCo's ``fixed``
tendon, for a tendon transmission). Its force, MuJoCo's ``force = gain · ctrl + bias`` on the
actuator's length ``l = gear · L`` and velocity ``v = gear · L̇``::

    c      = clamp(ctrl, ctrlrange)                (when ctrlrange is given)
    gain   = gain[0] + gain[1] l + gain[2] v        (fixed: gain[1] = gain[2] = 0)
    bias   = bias[0] + bias[1] l + bias[2] v        (none: all zero)
    force  = clamp(gain · c + bias, forcerange)     (when forcerange is given)
    τ_i   += gear · c_i · force                      (MuJoCo's moment gear · ∂L/∂q_i)

An actuator with activation dynamics (MuJoCo's ``dyntype``, :attr:`Control.dynamics`) has a
state ``act`` of its own that replaces ``c`` in the force (``gain · act + bias``), with the
rate (``c`` the clamped control, ``T`` the :attr:`~Control.timeconst`)::

    integrator               act_dot = c
    filter, filterexact      act_dot = (c − act) / T

(``filterexact`` differs from ``filter`` only in how MuJoCo integrates ``act`` over a step;
``actrange`` clamps ``act`` there too, not in the force or the rate.)

A DC motor (MuJoCo's ``dcmotor``, :attr:`Control.motor` ``= (R, K)``, the control its terminal
voltage ``V = c``) without electrical dynamics is affine: ``gain = K / R``, ``bias = −K² v / R``
(the back-EMF). With them (``inductance``: :attr:`~Control.timeconst` ``T = L / R``) its state
is the armature current ``act = i``, the force ``K · i`` (``gain = (K, 0, 0)``), and::

    dcmotor                  act_dot = clamp(((c − K v) / R − act) / T, ±di_max)

(``di_max`` the :attr:`~Control.rate_limit`, MuJoCo's ``saturation`` current rate; none: not
clamped). A DC motor's cogging torque ``A sin(N l + φ)`` (:attr:`~Control.cogging`) is added to
its force after the ``forcerange`` clamp.

A PID (MuJoCo's ``<pid>`` on its position input, ``c`` the setpoint) is a position servo,
``gain = (kp, 0, 0)``, ``bias = (0, −kp, −kv)``; with an integral gain ``ki``
(:attr:`~Control.integral`) its state is the integral of the position error, ``act = z``::

    pid                      act_dot = c − l,    force = kp c + ki z + bias

``actearly`` (MuJoCo's; always on for a DC motor): the force takes the activation one time step
``h`` ahead, ``act + α act_dot`` (:attr:`~Control.early` ``= α``: ``h`` for an integrator or a
filter, ``T (1 − exp(−h / T))`` for ``filterexact`` and a DC motor's current, as MuJoCo
integrates them), clamped to ``actrange`` when given (not for a DC motor).

so a motor is ``gain = (1, 0, 0)``, a position servo ``gain = (kp, 0, 0), bias = (0, −kp,
−kv)``, a velocity servo ``gain = (kv, 0, 0), bias = (0, 0, −kv)``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from ..common import reprs
from .scalars import Scalar, scalar


@dataclass(frozen=True)
class Control:
    """One control input on a one-coordinate joint or a fixed tendon (see the module
    docstring).

    Attributes
    ----------
    name:
        Its name (MuJoCo's actuator name), an entry of ``ACTUATOR_NAMES``.
    joint:
        The joint it drives (a revolute, prismatic or helical joint of the model); None for a
        tendon transmission.
    gear:
        The transmission ratio: length ``gear · L``, joint forces ``gear · c_i · force``.
    gain, bias:
        The affine coefficients ``(c0, c_length, c_velocity)`` of the gain and the bias.
    ctrlrange, forcerange:
        ``(low, high)`` the control and the force are clamped to; None: not clamped.
    tendon:
        For a tendon transmission, the tendon's name (None for a joint transmission).
    coefficients:
        For a tendon transmission, ``((joint, c_i), …)``: the tendon's length ``Σ c_i q_i``.
    offset:
        ``L_0``, the length of the tendon's joints a scene holds still (:meth:`locked`).
    dynamics:
        None (the force follows ``ctrl``), or ``"integrator"``, ``"filter"``,
        ``"filterexact"``, ``"dcmotor"`` or ``"pid"``: the activation dynamics of the module
        docstring.
    timeconst:
        ``T`` [s] of a filter or of a DC motor's current (MuJoCo's ``dynprm[0]``).
    motor:
        ``(R, K)`` of a DC motor with a current state: resistance [Ω], motor constant
        [N m/A]; None otherwise.
    rate_limit:
        ``di_max`` [A/s] of a DC motor's current; None: not limited.
    cogging:
        ``(A, N, φ)`` of a DC motor's cogging torque ``A sin(N l + φ)``; None: none.
    integral:
        ``ki`` of a PID with an integral state (``dynamics="pid"``); None otherwise.
    early:
        ``α`` of ``actearly`` (the force at ``act + α act_dot``); None: the force at ``act``.
    actrange:
        ``(low, high)`` the early activation is clamped to; None: not clamped.
    """

    __repr__ = reprs.field_repr

    name: str
    joint: str | None
    gear: Scalar = scalar(1)
    gain: tuple[Scalar, Scalar, Scalar] = (scalar(1), scalar(0), scalar(0))
    bias: tuple[Scalar, Scalar, Scalar] = (scalar(0), scalar(0), scalar(0))
    ctrlrange: tuple[Scalar, Scalar] | None = None
    forcerange: tuple[Scalar, Scalar] | None = None
    tendon: str | None = None
    coefficients: tuple[tuple[str, Scalar], ...] = ()
    offset: Scalar = scalar(0)
    dynamics: str | None = None
    timeconst: Scalar = scalar(1)
    motor: tuple[Scalar, Scalar] | None = None
    rate_limit: Scalar | None = None
    cogging: tuple[Scalar, Scalar, Scalar] | None = None
    early: Scalar | None = None
    actrange: tuple[Scalar, Scalar] | None = None
    integral: Scalar | None = None

    @property
    def transmission(self) -> tuple[tuple[str, Scalar], ...]:
        """``((joint, c_i), …)`` of the length ``L = Σ c_i q_i + offset``: ``((joint, 1),)``
        for a joint transmission, the tendon's coefficients otherwise."""
        return self.coefficients if self.tendon is not None else ((self.joint, scalar(1)),)

    def locked(self, positions) -> "Control":
        """The control with the joints of ``positions`` (``{joint: value}``) held there: a
        tendon's terms on them move into :attr:`offset` (a joint transmission is unchanged:
        on a held joint it gives no force)."""
        if self.tendon is None or not any(n in positions for n, _ in self.coefficients):
            return self
        held = sum((c * scalar(positions[n]) for n, c in self.coefficients if n in positions),
                   self.offset)
        return replace(self, coefficients=tuple((n, c) for n, c in self.coefficients
                                                if n not in positions), offset=held)


def make_control(name: str, joint: str | None, gear=1, gain=(1, 0, 0), bias=(0, 0, 0),
                 ctrlrange=None, forcerange=None, tendon=None, coefficients=(), dynamics=None,
                 timeconst=1, motor=None, rate_limit=None, cogging=None, early=None,
                 actrange=None, integral=None) -> Control:
    """A :class:`Control` from plain numbers (each made a model scalar); a tendon
    transmission when ``tendon`` (its name) and ``coefficients`` ``((joint, c_i), …)`` are
    given, ``joint`` then None; activation ``dynamics`` with its ``timeconst``; a DC motor's
    ``motor``, ``rate_limit`` and ``cogging``; ``actearly``'s ``early`` and ``actrange``; a
    PID's ``integral`` gain."""
    def several(values):
        return None if values is None else tuple(scalar(v) for v in values)

    return Control(name, joint, scalar(gear), tuple(scalar(v) for v in gain),
                   tuple(scalar(v) for v in bias), several(ctrlrange), several(forcerange),
                   tendon, tuple((n, scalar(c)) for n, c in coefficients), scalar(0), dynamics,
                   scalar(timeconst), several(motor),
                   None if rate_limit is None else scalar(rate_limit), several(cogging),
                   None if early is None else scalar(early), several(actrange),
                   None if integral is None else scalar(integral))


__all__ = ["Control", "make_control"]
