"""Actuators: armature, friction and flexible joints (Spong's model).

A robot joint is driven by a motor through a gear. With the drive data of each joint
(:class:`eomgen.model.Actuator`, read from eomgen YAML, scenes and URDF ``<dynamics>``) this
module forms, from the rigid-body equations of a :class:`~eomgen.dynamics.Dynamics`:

**Rigid joints with actuators** (every joint stiff)::

    (M(q) + diag(a)) q̈ + C(q, q̇) q̇ + g(q) + τ_f(q̇) = τ
    τ_f,i(q̇) = d_i q̇_i + f_i sign(q̇_i)            exact (inverse dynamics)
    τ_f,i(q̇) = d_i q̇_i + f_i tanh(q̇_i / w_i)      smoothed (simulation)

with ``a = r² I_rotor`` the armature (reflected rotor inertia), ``d`` the viscous and ``f`` the
Coulomb friction, ``w`` the smoothing width (:attr:`~eomgen.model.Actuator.friction_width`).
``τ`` is the joint torque the drives apply; ``τ_f`` is the torque friction takes from them.

**Flexible joints** (Spong 1987, the *reduced model*): every joint with a stiffness ``K_j``
gets a motor angle ``θ_j`` (link side of the gear, ``θ_j = θ_rotor,j / r_j``)::

    M_a(q) q̈ + C(q, q̇) q̇ + g(q) + τ_f,R(q̇) = S_R τ_R + E K (θ − Eᵀ q)      (link equations)
    B θ̈ + K (θ − Eᵀ q) + τ_f,F(θ̇) = τ_m                                 (motor equations)

``E`` (n×m) selects the m flexible joints, ``S_R`` the rigid ones, ``M_a = M + diag(a)`` with
the armature of *rigid* joints only, ``B = diag(a_F)`` the motor inertias (armature of the
flexible joints) and the friction of a flexible joint acts on its motor. The reduced model
assumes each rotor's kinetic energy comes only from its own spin (Spong's assumption): the
rotor's angular velocity due to the links that carry it is neglected (rotor mass and
transverse inertia belong in the carrying link). The full model adds the coupling
``q̇ᵀ S(q) θ̇`` to the kinetic energy (:func:`spong_dynamics` with ``coupling=True``, symbolic
only, small models).

The inputs are one vector ``tau`` (n,) in joint order: the joint torque for a rigid joint,
the motor torque ``τ_m`` for a flexible one.

**Flatness.** The link angles ``q`` are a flat output of the reduced model: from ``q`` and its
time derivatives up to order 4 (``q⁽³⁾ = qddd``, ``q⁽⁴⁾ = qdddd``)::

    τ_L = M q̈ + C q̇ + g                           (rigid-body inverse dynamics)
    θ   = q_F + K⁻¹ τ_L,F,   θ̇ = q̇_F + K⁻¹ τ̇_L,F,   θ̈ = q̈_F + K⁻¹ τ̈_L,F
    τ_m = B θ̈ + K (θ − q_F) + τ_f,F(θ̇),    τ_R = τ_L,R + a_R q̈_R + τ_f,R(q̇)

The time derivatives ``τ̇_L`` and ``τ̈_L`` are computed without numeric differentiation: the
straight-line program of ``τ_L`` is differentiated in forward mode along the trajectory
(:func:`time_derivative_program`: each intermediate ``x = f(…)`` gets ``ẋ = Σ ∂f/∂s ṡ``), which
keeps the program's size linear in the model (the 7-DOF Panda included).

Where each piece lives: the drive data in the model (:class:`eomgen.model.Actuator`,
:func:`eomgen.model.joint_actuators`, :func:`eomgen.model.flexible_indices`); the friction law
(:func:`eomgen.symbolic.drives.friction_torque_expr`) and the program transform
(:func:`eomgen.symbolic.transforms.time_derivative_program`) in the symbolic engine; this
module the symbolic equations over a :class:`~eomgen.dynamics.Dynamics`
(:class:`RigidActuatorDynamics`, :class:`SpongDynamics`); the NumPy evaluators in
:mod:`eomgen.numeric.actuated` (re-exported here, the path the docs name).

The generated modules export these on request (:mod:`eomgen.symbolic.drives`,
``eomgen generate --outputs M_a,tau_f,...``; the flat inverse dynamics, :mod:`eomgen.symbolic.flat`,
``--outputs motor_angles,motor_velocities,flat_motor_torque``); see docs/actuators.md.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Callable, Mapping, Sequence

import numpy as np
import sympy as sp

from ..dynamics import Dynamics
from ..errors import ParameterError
from ..model import Actuator, RobotModel, flexible_indices, joint_actuators, joint_motion
from ..symbolic.drives import friction_torque_expr
from ..symbolic.program import Program
from ..symbolic.transforms import time_derivative_program

# Deprecated path of the numeric evaluators: they moved to eomgen.numeric.actuated (docs and
# tests name them here, as eomgen.analysis.actuators.flexible_forward_dynamics and so on).
from ..numeric.actuated import (
    ActuatedModel,
    actuated_model,
    flexible_energy,
    flexible_forward_dynamics,
    flexible_inverse_dynamics,
    flexible_rest_state,
    friction_torque,
    rigid_forward_dynamics,
    rigid_inverse_dynamics,
    rigid_M,
)

__all__ = [
    "joint_actuators", "flexible_indices", "friction_torque_expr", "RigidActuatorDynamics",
    "rigid_with_actuators", "SpongDynamics", "spong_dynamics", "time_derivative_program",
    "ActuatedModel", "actuated_model", "rigid_M", "friction_torque",
    "rigid_inverse_dynamics", "rigid_forward_dynamics", "flexible_forward_dynamics",
    "flexible_energy", "flexible_inverse_dynamics", "flexible_rest_state",
]


# ----------------------------------------------------------------------------------------------
# Symbolic: rigid joints with actuators
# ----------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class RigidActuatorDynamics:
    """Rigid equations of motion with actuators: ``(M + diag(a)) q̈ + C q̇ + g + τ_f(q̇) = τ``.

    Attributes
    ----------
    dynamics:
        The rigid-body equations (``M``, ``C``, ``g`` of the links only).
    actuators:
        One per joint, in ``dynamics.joint_names`` order.
    """

    dynamics: Dynamics
    actuators: tuple[Actuator, ...]

    @property
    def armature(self) -> sp.Matrix:
        """Armature ``a`` (n×1) [kg m² or kg]: ``r² I_rotor`` per joint."""
        return sp.Matrix([a.armature for a in self.actuators])

    @cached_property
    def M(self) -> sp.Matrix:
        """``M(q) + diag(a)`` (n×n)."""
        return self.dynamics.M + sp.diag(*self.armature)

    def tau_friction(self, smooth: bool = False) -> sp.Matrix:
        """Friction torques ``τ_f(q̇)`` (n×1): exact sign, or ``tanh`` when ``smooth``."""
        return friction_torque_expr(self.actuators, self.dynamics.qd, smooth)

    def tau(self, smooth: bool = False) -> sp.Matrix:
        """Inverse dynamics ``(M + diag(a)) q̈ + C q̇ + g + τ_f(q̇)`` (n×1)."""
        d = self.dynamics
        return self.M * sp.Matrix(d.qdd) + d.C * sp.Matrix(d.qd) + d.g + self.tau_friction(smooth)

    def program(self) -> Program:
        """The rigid-body program with ``M`` replaced by ``M + diag(a)`` and an output
        ``tau_f`` (smoothed friction): what a code generator would print."""
        p = self.dynamics.program
        outputs = []
        for name, matrix in p.outputs:
            if name == "M":
                matrix = matrix + sp.diag(*self.armature)
            outputs.append((name, matrix))
        outputs.append(("tau_f", self.tau_friction(smooth=True)))
        return Program(p.assignments, tuple(outputs))


def rigid_with_actuators(dynamics: Dynamics) -> RigidActuatorDynamics:
    """The rigid equations of ``dynamics`` with its model's actuators (every joint stiff; a
    flexible joint's motor inertia is its armature: the limit ``K → ∞``).

    >>> import eomgen
    >>> from eomgen.model import Actuator
    >>> from dataclasses import replace
    >>> arm = eomgen.load(eomgen.example_path("planar_2link"))
    >>> joints = tuple(replace(j, actuator=Actuator(armature=0.5)) for j in arm.joints)
    >>> rigid = rigid_with_actuators(eomgen.derive(replace(arm, joints=joints)))
    >>> sp.simplify(rigid.M - rigid.dynamics.M)
    Matrix([
    [0.5,   0],
    [  0, 0.5]])
    """
    return RigidActuatorDynamics(dynamics, joint_actuators(dynamics.model))


# ----------------------------------------------------------------------------------------------
# Symbolic: Spong's flexible-joint model
# ----------------------------------------------------------------------------------------------

def _symbols(prefix: str, indices: Sequence[int]) -> tuple[sp.Symbol, ...]:
    return tuple(sp.Symbol(f"{prefix}{k + 1}", real=True) for k in indices)


@dataclass(frozen=True)
class SpongDynamics:
    """Spong's flexible-joint model of a :class:`~eomgen.dynamics.Dynamics` (see the module
    docstring for the equations and conventions).

    Attributes
    ----------
    dynamics:
        The rigid-body equations of the links.
    actuators:
        One per joint, in joint order.
    flexible:
        Indices of the flexible joints (m of them).
    theta, thetad, thetadd:
        Motor angle [rad], rate and acceleration symbols ``thm<k>``, ``thmd<k>``, ``thmdd<k>``
        (k the joint's 1-based index), one per flexible joint.
    tau:
        Input symbols ``tau1…taun``: joint torque (rigid joint) or motor torque (flexible).
    qddd, qdddd:
        Symbols of the third and fourth derivatives of ``q`` (for the flat inverse dynamics).
    coupling:
        Whether the full model's rotor–link coupling ``q̇ᵀ S(q) θ̇`` is included.
    S:
        The coupling matrix ``S(q)`` (n×m), zero without ``coupling``.
    """

    dynamics: Dynamics
    actuators: tuple[Actuator, ...]
    flexible: tuple[int, ...]
    theta: tuple[sp.Symbol, ...]
    thetad: tuple[sp.Symbol, ...]
    thetadd: tuple[sp.Symbol, ...]
    tau: tuple[sp.Symbol, ...]
    qddd: tuple[sp.Symbol, ...]
    qdddd: tuple[sp.Symbol, ...]
    coupling: bool = False
    S: sp.Matrix | None = None

    @property
    def rigid(self) -> tuple[int, ...]:
        return tuple(k for k in range(len(self.actuators)) if k not in self.flexible)

    @property
    def K(self) -> sp.Matrix:
        """Joint stiffnesses, diag (m×m) [N m/rad]."""
        return sp.diag(*[self.actuators[k].stiffness for k in self.flexible])

    @property
    def B(self) -> sp.Matrix:
        """Motor inertias (link side of the gear), diag (m×m) [kg m²]: the armature."""
        return sp.diag(*[self.actuators[k].armature for k in self.flexible])

    @property
    def E(self) -> sp.Matrix:
        """Selection of the flexible joints (n×m): ``Eᵀ q`` are their angles."""
        n = len(self.actuators)
        return sp.Matrix(n, len(self.flexible),
                         lambda i, j: 1 if self.flexible[j] == i else 0)

    @cached_property
    def M_links(self) -> sp.Matrix:
        """``M(q)`` plus the armature of the rigid joints (n×n)."""
        a = [0 if k in self.flexible else self.actuators[k].armature
             for k in range(len(self.actuators))]
        return self.dynamics.M + sp.diag(*a)

    def spring(self) -> sp.Matrix:
        """``K (θ − Eᵀ q)`` (m×1): the torque the springs pass from the motors to the links."""
        return self.K * (sp.Matrix(self.theta) - self.E.T * sp.Matrix(self.dynamics.q))

    def link_equations(self, smooth: bool = False) -> sp.Matrix:
        """Residuals (n×1) of the link equations; zero along a solution."""
        d = self.dynamics
        rigid_friction = friction_torque_expr(
            [self.actuators[k] if k in self.rigid else Actuator() for k in range(len(d.q))],
            d.qd, smooth)
        S_R = sp.diag(*[1 if k in self.rigid else 0 for k in range(len(d.q))])
        out = (self.M_links * sp.Matrix(d.qdd) + d.C * sp.Matrix(d.qd) + d.g + rigid_friction
               - S_R * sp.Matrix(self.tau) - self.E * self.spring())
        if self.coupling:
            out += self._coupling_link_terms()
        return out

    def motor_equations(self, smooth: bool = False) -> sp.Matrix:
        """Residuals (m×1) of the motor equations; zero along a solution."""
        motor_friction = friction_torque_expr([self.actuators[k] for k in self.flexible],
                                              self.thetad, smooth)
        out = (self.B * sp.Matrix(self.thetadd) + self.spring() + motor_friction
               - self.E.T * sp.Matrix(self.tau))
        if self.coupling:
            out += self._coupling_motor_terms()
        return out

    def energy(self) -> sp.Expr:
        """Total energy [J] without friction and input: link and motor kinetic energy (and
        the coupling's), gravity potential, spring potential."""
        d = self.dynamics
        qd, thd = sp.Matrix(d.qd), sp.Matrix(self.thetad)
        T = (qd.T * self.M_links * qd)[0, 0] / 2 + (thd.T * self.B * thd)[0, 0] / 2
        if self.coupling:
            T += (qd.T * self.S * thd)[0, 0]
        e = sp.Matrix(self.theta) - self.E.T * sp.Matrix(d.q)
        return T + d.P + (e.T * self.K * e)[0, 0] / 2

    def _total_derivative(self, expr: sp.Expr) -> sp.Expr:
        d = self.dynamics
        chain = list(zip(d.q, d.qd)) + list(zip(d.qd, d.qdd)) + list(zip(d.qdd, self.qddd)) \
            + list(zip(self.qddd, self.qdddd)) + list(zip(self.theta, self.thetad)) \
            + list(zip(self.thetad, self.thetadd))
        symbols = expr.free_symbols
        return sp.Add(*[sp.diff(expr, s) * ds for s, ds in chain if s in symbols])

    def flat_inverse_dynamics(self, smooth: bool = False) -> dict[str, sp.Matrix]:
        """``θ``, ``θ̇``, ``θ̈`` (m×1) and the inputs ``tau`` (n×1) that make the links follow
        ``q(t)``, as expressions in ``q, q̇, q̈, q⁽³⁾, q⁽⁴⁾`` (reduced model only; expanded
        expressions: small models). Symbolic ``K`` and ``B`` are kept."""
        if self.coupling:
            raise NotImplementedError("the flat inverse dynamics is formed for the reduced "
                                      "model (coupling=False) only")
        d = self.dynamics
        tau_L = d.M * sp.Matrix(d.qdd) + d.C * sp.Matrix(d.qd) + d.g
        Kinv = sp.diag(*[1 / self.actuators[k].stiffness for k in self.flexible])
        t0 = self.E.T * tau_L
        t1 = t0.applyfunc(self._total_derivative)
        t2 = t1.applyfunc(self._total_derivative)
        E = self.E.T
        theta = E * sp.Matrix(d.q) + Kinv * t0
        thetad = E * sp.Matrix(d.qd) + Kinv * t1
        thetadd = E * sp.Matrix(d.qdd) + Kinv * t2
        motor_friction = friction_torque_expr([self.actuators[k] for k in self.flexible],
                                              list(thetad), smooth)
        tau_m = self.B * thetadd + t0 + motor_friction
        rigid = RigidActuatorDynamics(d, tuple(
            a if k in self.rigid else Actuator() for k, a in enumerate(self.actuators)))
        tau = rigid.tau(smooth) + self.E * (tau_m - t0)  # flexible rows: τ_L,F → τ_m
        return {"theta": theta, "thetad": thetad, "thetadd": thetadd, "tau": tau}

    def forward_dynamics_function(self, values: Mapping[str, float] | None = None,
                                  smooth: bool = True) -> Callable[..., np.ndarray]:
        """``f(x, tau) -> ẋ`` of this model (with the coupling when ``coupling``), lambdified
        from the symbolic equations: for small models (the numeric
        :func:`flexible_forward_dynamics` is the reduced model's for any size). Derive with
        ``simplify=False`` unless the model is tiny: the equations use the expanded ``M``.

        ``x = (q, q̇, θ, θ̇)`` (2n + 2m,); the equations are linear in the accelerations,
        ``A(x) [q̈; θ̈] + b(x, τ) = 0``, solved with NumPy. Parameters take ``values`` (by
        name) over their defaults.
        """
        d = self.dynamics
        numbers = {p.symbol: float(p.value) for p in d.model.parameters if p.value is not None}
        numbers.update({sp.Symbol(k, real=True): float(v) for k, v in (values or {}).items()})
        residual = self.link_equations(smooth).col_join(self.motor_equations(smooth))
        residual = residual.xreplace(numbers)
        accelerations = list(d.qdd) + list(self.thetadd)
        states = list(d.q) + list(d.qd) + list(self.theta) + list(self.thetad)
        matrix = residual.jacobian(accelerations)
        rest = residual.xreplace({a: 0 for a in accelerations})
        f_matrix = sp.lambdify(states, matrix, "numpy")
        f_rest = sp.lambdify(states + list(self.tau), rest, "numpy")
        n, m = len(d.q), len(self.flexible)

        def forward(x, tau) -> np.ndarray:
            x = np.asarray(x, float)
            acc = np.linalg.solve(np.array(f_matrix(*x), float),
                                  -np.array(f_rest(*x, *tau), float).ravel())
            return np.concatenate([x[n:2 * n], acc[:n], x[2 * n + m:], acc[n:]])

        return forward

    # -- the full model's coupling ----------------------------------------------------------

    def _coupling_link_terms(self) -> sp.Matrix:
        """``d/dt(∂L_c/∂q̇) − ∂L_c/∂q`` of ``L_c = q̇ᵀ S(q) θ̇``."""
        d = self.dynamics
        p = self.S * sp.Matrix(self.thetad)
        L = (sp.Matrix(d.qd).T * p)[0, 0]
        return sp.Matrix([self._total_derivative(p[i]) - sp.diff(L, d.q[i])
                          for i in range(len(d.q))])

    def _coupling_motor_terms(self) -> sp.Matrix:
        """``d/dt(∂L_c/∂θ̇)`` (``L_c`` does not depend on ``θ``)."""
        p = self.S.T * sp.Matrix(self.dynamics.qd)
        return p.applyfunc(self._total_derivative)


def _coupling_matrix(model: RobotModel, q: Sequence[sp.Symbol], actuators: Sequence[Actuator],
                     flexible: Sequence[int]) -> sp.Matrix:
    """``S(q)`` (n×m) of the full model: ``S[i, j] = I_rotor,j r_j (z_j · z_i)`` for every
    revolute joint ``i`` that moves the link carrying rotor ``j`` (the parent link of joint
    ``j``), ``z`` the joint axes in the root frame. The rotor spins about its joint's axis."""
    index = {j.name: k for k, j in enumerate(model.movable_joints)}
    R = {model.root: sp.eye(3)}
    axis: dict[str, sp.Matrix] = {}
    ancestors: dict[str, tuple[str, ...]] = {model.root: ()}
    for joint in model.topological_joints:
        R_origin = sp.Matrix(joint.origin.rotation)
        R_joint = R[joint.parent] * R_origin
        axis[joint.name] = R_joint * sp.Matrix(joint.axis)
        value = q[index[joint.name]] if joint.name in index else 0
        R[joint.child] = R_joint * sp.Matrix(joint_motion(joint, value).rotation)
        moved = (joint.name,) if joint.rotates else ()
        ancestors[joint.child] = ancestors[joint.parent] + moved
    S = sp.zeros(len(q), len(flexible))
    for col, k in enumerate(flexible):
        joint = model.movable_joints[k]
        a = actuators[k]
        if a.rotor_inertia is None or a.gear_ratio is None:
            raise ParameterError(model.source, f"joint '{joint.name}' actuator",
                                 "coupling=True needs rotor_inertia and gear_ratio (the "
                                 "armature alone does not give the rotor's own inertia)")
        for name in ancestors[joint.parent]:
            i = index[name]
            S[i, col] = a.rotor_inertia * a.gear_ratio * (axis[joint.name].T * axis[name])[0, 0]
    return S.applyfunc(sp.simplify) if len(q) <= 3 else S


def spong_dynamics(dynamics: Dynamics, coupling: bool = False) -> SpongDynamics:
    """Spong's flexible-joint model of ``dynamics``'s model (its joints with a ``stiffness``).

    Parameters
    ----------
    dynamics:
        From :func:`eomgen.derive` (``M``, ``C``, ``g``; ``P`` for :meth:`~SpongDynamics.energy`).
    coupling:
        Include the full model's rotor–link coupling ``q̇ᵀ S(q) θ̇`` (needs ``rotor_inertia``
        and ``gear_ratio`` on each flexible joint); the default is the reduced model.

    Raises
    ------
    ParameterError
        ``coupling=True`` on a flexible joint given by its armature only.
    """
    model = dynamics.model
    actuators = joint_actuators(model)
    flexible = flexible_indices(model)
    S = _coupling_matrix(model, dynamics.q, actuators, flexible) if coupling else \
        sp.zeros(len(actuators), len(flexible))
    n = range(len(actuators))
    return SpongDynamics(
        dynamics, actuators, flexible, _symbols("thm", flexible), _symbols("thmd", flexible),
        _symbols("thmdd", flexible), _symbols("tau", n), _symbols("qddd", n),
        _symbols("qdddd", n), coupling, S)
