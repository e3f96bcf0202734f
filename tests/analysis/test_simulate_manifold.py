"""``eomgen.analysis.simulate`` steps quaternion and planar joints on their own manifolds
(``q ⊕ h v``): every configuration stays on its manifold at round-off whatever the method and
step, and the methods keep their orders.

References, independent of the derived program and of the joint kinds' exponentials: a free
rigid body and a rigid body on a fixed pivot integrated by SciPy's DOP853 at rtol = atol = 1e-12
in the classical form (Euler's equations ``I ω̇ = (I ω) × ω + τ`` in the body frame, the
quaternion rate ``½ q ⊗ (ω, 0)`` integrated as a vector, normalised at the end); the free body's
invariants (energy from eomgen.numeric, angular momentum ``R I ω`` in the world frame); a
planar free body's closed-form motion under gravity (its centre of mass on a parabola, its
angle at constant rate).
"""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen.model.floating import add_free_flyer
from eomgen.model import Inertial, Joint, JointType, Link, build_model
from eomgen.model.joints.lie import quaternion_matrix
from eomgen.model.configuration import difference
from support import write
from support.extras import need

need("scipy", reason="the references are SciPy's DOP853")

from eomgen.analysis.simulate import (RK4, Adaptive, ExplicitEuler,  # noqa: E402
                                      ImplicitMidpoint, SemiImplicitEuler, System, energies,
                                      run_study, simulate)

#: Principal inertias of the tumbling brick [kg m²]: the y axis is the intermediate one.
BRICK = np.diag([1.0, 2.0, 3.0])


def quaternion_rate(quaternion, omega):
    """``½ (x, y, z, w) ⊗ (ω, 0)``, written out here."""
    x, y, z, w = quaternion
    a, b, c = omega
    return 0.5 * np.array([w * a + y * c - z * b, w * b + z * a - x * c,
                           w * c + x * b - y * a, -x * a - y * b - z * c])


def rigid_body_reference(q0, omega0, inertia, times, torque=lambda R: np.zeros(3), linear=None):
    """``(quaternions, ω)`` at ``times`` of a rigid body turning by Euler's equations
    (``torque(R)`` in the body frame), and with ``linear = (p0, v0)`` (free flight, body-frame
    velocity) its origin, by DOP853; quaternions normalised."""
    from scipy.integrate import solve_ivp
    inverse = np.linalg.inv(inertia)

    def rhs(t, z):
        quaternion, omega = z[0:4], z[4:7]
        R = quaternion_matrix(quaternion)
        out = [quaternion_rate(quaternion, omega),
               inverse @ (np.cross(inertia @ omega, omega) + torque(R))]
        if linear is not None:
            out += [R @ z[10:13], -np.cross(omega, z[10:13])]
        return np.concatenate(out)

    z0 = np.concatenate([q0, omega0] + ([] if linear is None else list(linear)))
    solution = solve_ivp(rhs, (times[0], times[-1]), z0, method="DOP853", t_eval=times,
                         rtol=1e-12, atol=1e-12)
    y = solution.y.T
    return y[:, 0:4] / np.linalg.norm(y[:, 0:4], axis=1, keepdims=True), y[:, 4:7], y[:, 7:]


def norm_error(model, q) -> float:
    """``max_j |‖unit part_j‖ − 1|`` of the configuration ``q``, by each joint's kind."""
    return max(j.kind.norm_error(q[j.q_slice]) for j in model.quaternion_joints)


@pytest.fixture(scope="module")
def brick():
    """A free rigid brick, no gravity, the free flyer's origin at its centre of mass."""
    body = build_model("<memory>", "brick",
                       [Link("brick", Inertial(1.0, (0, 0, 0), BRICK.tolist()))], [],
                       gravity=(0, 0, 0))
    model = add_free_flyer(body)
    return model, System(model)


#: The brick spun about its intermediate axis, slightly off it: it flips over every few
#: seconds (the tennis-racket effect), ω and ω̇ far from parallel.
SPIN = (np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]),
        np.array([0.1, 0.0, 0.0, 0.02, 2.0, 0.01]))


def test_tumbling_brick_stays_unit_and_keeps_its_invariants(brick):
    """10 s of tumbling: RK4 at 10 ms keeps every quaternion unit at round-off, the energy and
    the world-frame angular momentum to 1e-8 relative; explicit Euler at 10 ms, whose energy
    is off by percent, keeps the quaternion unit all the same (by construction, not by
    accuracy)."""
    model, system = brick
    q0, v0 = SPIN
    trajectory, _ = simulate(system, RK4(1e-2), q0, v0, 10.0, points=201)
    omega = trajectory.qd[:, 3:]
    assert omega[:, 1].min() < -1.9 and omega[:, 1].max() > 1.9  # it flipped over
    assert max(norm_error(model, q) for q in trajectory.q) <= 1e-12
    K, P = energies(system, trajectory)
    E = K + P
    assert np.abs(E - E[0]).max() <= 1e-8 * E[0]
    L = np.array([quaternion_matrix(q[3:7]) @ BRICK @ w for q, w in zip(trajectory.q, omega)])
    assert np.abs(L - L[0]).max() <= 1e-8 * np.linalg.norm(L[0])
    rough, _ = simulate(system, ExplicitEuler(1e-2), q0, v0, 10.0, points=201)
    K, P = energies(system, rough)
    assert np.abs(K + P - E[0]).max() > 1e-3 * E[0]
    assert max(norm_error(model, q) for q in rough.q) <= 1e-12


def test_tumbling_brick_follows_eulers_equations_at_fourth_order(brick):
    """RK4's Lie group steps against Euler's equations of the free body (module docstring):
    the error falls 16-fold when the step halves (the "frozen" scheme, ``q ⊕ h Σ bᵢ vᵢ``,
    would fall 4-fold: order 2), and is below 1e-8 at 10 ms; SciPy's adaptive DOP853 ends
    on the manifold and within its tolerance."""
    model, system = brick
    q0, v0 = SPIN[0], np.array([0.1, 0.0, 0.0, 0.3, 2.0, 0.5])
    times = np.linspace(0.0, 2.0, 5)
    quaternions, omegas, linear = rigid_body_reference(q0[3:7], v0[3:], BRICK, times,
                                                       linear=(q0[:3], v0[:3]))
    reference = np.concatenate([linear[:, :3], quaternions], axis=1)
    velocities = np.concatenate([linear[:, 3:], omegas], axis=1)

    def error(integrator):
        trajectory, _ = simulate(system, integrator, q0, v0, 2.0, points=5)
        assert max(norm_error(model, q) for q in trajectory.q) <= 1e-12
        return max(max(np.abs(difference(a, b, model)).max() for a, b in
                       zip(trajectory.q, reference)),
                   np.abs(trajectory.qd - velocities).max())

    coarse, fine = error(RK4(4e-2)), error(RK4(2e-2))
    assert 12 < coarse / fine < 20
    assert error(RK4(1e-2)) < 1e-8
    assert error(Adaptive("DOP853", 1e-10)) < 1e-8


@pytest.fixture(scope="module")
def pendulum():
    """A rigid body on a ball joint at a fixed pivot, its centre of mass below and aside."""
    inertia = [[0.02, 0.0, 0.0], [0.0, 0.03, 0.0], [0.0, 0.0, 0.01]]
    model = build_model("<memory>", "ball_pendulum",
                        [Link("base"), Link("bob", Inertial(1.5, (0.1, 0.0, -0.5), inertia))],
                        [Joint("pivot", JointType.SPHERICAL, "base", "bob")])
    return model, System(model)


def pivot_reference(model, q0, v0, times):
    """The ball pendulum by Euler's equations about the pivot (module docstring)."""
    (link,) = [k for k in model.links if k.name == "bob"]
    mass, c = 1.5, np.array([0.1, 0.0, -0.5])
    about_pivot = np.array(link.inertial.inertia, float) + mass * (c @ c * np.eye(3)
                                                                    - np.outer(c, c))
    gravity = np.array([0.0, 0.0, -9.81])
    return rigid_body_reference(q0, v0, about_pivot, times,
                                torque=lambda R: mass * np.cross(c, R.T @ gravity))[:2]


@pytest.mark.parametrize("kind, order, dt", [(RK4, 4, 2e-2), (ImplicitMidpoint, 2, 1e-2),
                                             (SemiImplicitEuler, 1, 2e-3)])
def test_ball_pendulum_follows_eulers_equations_to_the_methods_order(pendulum, kind, order,
                                                                     dt):
    """Each fixed-step method against the pivoted body's Euler equations over 1 s: halving
    the step divides the error by about 2^order; the quaternion stays unit."""
    model, system = pendulum
    q0 = np.array([0.3, -0.2, 0.1, 0.9])
    q0 /= np.linalg.norm(q0)
    v0 = np.array([1.0, -2.0, 3.0])
    times = np.linspace(0.0, 1.0, 5)
    quaternions, omegas = pivot_reference(model, q0, v0, times)

    def error(step):
        trajectory, _ = simulate(system, kind(step), q0, v0, 1.0, points=5)
        assert max(norm_error(model, q) for q in trajectory.q) <= 1e-12
        return max(max(np.abs(difference(a, b, model)).max()
                       for a, b in zip(trajectory.q, quaternions)),
                   np.abs(trajectory.qd - omegas).max())

    ratio = error(dt) / error(dt / 2)
    assert 0.75 * 2 ** order < ratio < 1.3 * 2 ** order


def test_ball_pendulum_keeps_its_energy(pendulum):
    """5 s of swinging: RK4 at 5 ms keeps the energy of eomgen.numeric to 1e-8 relative of
    the kinetic energy's scale, the implicit midpoint rule at 10 ms within 1e-3 (bounded, not
    growing: its second half drifts no further than its first)."""
    model, system = pendulum
    q0 = np.array([0.3, -0.2, 0.1, 0.9]) / np.linalg.norm([0.3, -0.2, 0.1, 0.9])
    v0 = np.array([1.0, -2.0, 3.0])
    for integrator, tolerance in ((RK4(5e-3), 1e-8), (ImplicitMidpoint(1e-2), 1e-3)):
        trajectory, _ = simulate(system, integrator, q0, v0, 5.0)
        K, P = energies(system, trajectory)
        drift = np.abs(K + P - K[0] - P[0])
        assert np.abs(K - K[0]).max() > 0.1 * K.max()  # energy moves between K and P
        assert drift.max() <= tolerance * K.max()
        assert max(norm_error(model, q) for q in trajectory.q) <= 1e-12
        if isinstance(integrator, ImplicitMidpoint):
            half = len(drift) // 2
            assert drift[half:].max() <= 2 * drift[:half].max()


PUCK = """\
name: puck
gravity: [0, -9.81, 0]
links:
  - name: table
  - name: puck
    mass: 2.0
    com: [0.3, 0.1, 0]
    inertia: {ixx: 0.1, iyy: 0.2, izz: 0.25}
joints:
  - name: slide
    type: planar
    parent: table
    child: puck
"""


def test_planar_joint_keeps_cos_and_sin_on_the_circle(tmp_path):
    """A puck on a planar joint (YAML ``type: planar``) thrown spinning, gravity in its plane:
    ``eomgen.analysis.simulate``'s study runs every kind of method, each keeps
    cos² θ + sin² θ = 1 at round-off; RK4's final state is the closed form (the angle at
    constant rate, the centre of mass on a parabola)."""
    model = eomgen.load(write(tmp_path / "puck.yaml", PUCK))
    assert model.configuration_names == ("slide_x", "slide_y", "slide_cos", "slide_sin")
    system = System(model)
    theta0, v0 = 0.4, np.array([1.0, 2.0, 3.0])
    q0 = np.array([0.0, 0.0, np.cos(theta0), np.sin(theta0)])
    integrators = [ExplicitEuler(1e-2), SemiImplicitEuler(1e-2), RK4(1e-2),
                   ImplicitMidpoint(1e-2), Adaptive("RK45", 1e-6)]
    study = run_study(model, integrators, 1.0, q0=q0, qd0=v0, system=system)
    assert [r.status for r in study.runs] == ["ok"] * len(integrators)
    for integrator in integrators:
        trajectory, _ = simulate(system, integrator, q0, v0, 1.0, points=11)
        assert max(norm_error(model, q) for q in trajectory.q) <= 1e-12
    trajectory, _ = simulate(system, RK4(1e-2), q0, v0, 1.0, points=11)
    x, y, c, s = trajectory.q[-1]
    theta = theta0 + v0[2]

    def rotation(a):
        return np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])

    com = np.array([0.3, 0.1])
    velocity = rotation(theta0) @ (v0[:2] + v0[2] * np.array([-com[1], com[0]]))
    expected = rotation(theta0) @ com + velocity + 0.5 * np.array([0.0, -9.81])
    assert abs(np.arctan2(s, c) - np.arctan2(np.sin(theta), np.cos(theta))) < 1e-12
    assert np.abs(np.array([x, y]) + rotation(np.arctan2(s, c)) @ com - expected).max() < 1e-6
