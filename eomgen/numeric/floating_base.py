"""Floating-base coordinates, numerically: ZYX Euler angles of the base and the map to and from
Pinocchio's free flyer (quaternion position, body-frame velocity), in NumPy.

The coordinates are those :func:`eomgen.model.floating.add_floating_base` gives a robot (its
module docstring has the layout): ``q[0:3]`` the root origin in the world, ``q[3:6]`` yaw ψ,
pitch θ, roll φ, the root's rotation ``R = Rz(ψ) Ry(θ) Rx(φ)``. These functions need no
Pinocchio; :class:`PinocchioFreeFlyer` evaluates a Pinocchio model in these coordinates.

**The singularity.** The map from Euler rates to the body angular velocity,
``ω_b = E(θ, φ) [ψ̇, θ̇, φ̇]`` (:func:`euler_rate_matrix`), has ``det E = −cos θ``: at pitch
θ = ±π/2 the yaw and roll axes line up (gimbal lock), a rotation about the lost axis has no
Euler rates, and the mass matrix in these coordinates is singular. :func:`euler_singularity`
measures ``|cos θ|`` and :func:`check_euler` refuses states closer than a tolerance; keep the
trunk's pitch well inside (−π/2, π/2) (a walking or standing robot does).

**Pinocchio's free flyer** (``JointModelFreeFlyer``) uses ``q = [p, quaternion (x, y, z, w)]``
(nq = 7) and ``v = [Rᵀ ṗ, ω_b]`` (nv = 6): the linear velocity of the root origin and the
angular velocity, both in the *root link* frame. With ``T(q)`` the block-diagonal
``diag(Rᵀ, E(θ, φ), 1)`` (:func:`velocity_map`), ``v = T q̇`` and, because generalised
forces map by the transpose (virtual work),

    M = Tᵀ M_pin T,    C q̇ = Tᵀ (h_pin(q, v) + M_pin Ṫ q̇),    g = Tᵀ g_pin,

where ``h_pin = C_pin v`` (:func:`dynamics_from_free_flyer`). :func:`to_free_flyer` and
:func:`from_free_flyer` convert states both ways.

>>> q = np.array([0.1, 0.2, 0.3, 0.4, -0.5, 0.6])
>>> qp, v = to_free_flyer(q, np.arange(6.0))
>>> q2, qd2 = from_free_flyer(qp, v)
>>> bool(np.allclose(q2, q) and np.allclose(qd2, np.arange(6.0)))
True
"""

from __future__ import annotations

import numpy as np

from ..model.joints.lie import matrix_quaternion, quaternion_matrix  # importable here too
# The model operations its old path offered with these maps (eomgen.moved points it here).
from ..model.floating import (  # noqa: F401
    EULER_JOINTS,
    WORLD,
    add_floating_base,
    check_spatial_inertia,
    virtual_chain,
)

__all__ = [
    "SINGULARITY_TOLERANCE", "EulerSingularityError", "base_rotation", "euler_angles",
    "euler_rate_matrix", "euler_singularity", "check_euler", "velocity_map",
    "velocity_map_dot_qd", "to_free_flyer", "from_free_flyer", "dynamics_from_free_flyer",
    "matrix_quaternion", "quaternion_matrix", "PinocchioFreeFlyer",
]

#: :func:`check_euler` refuses states with ``|cos θ|`` below this.
SINGULARITY_TOLERANCE = 1e-6


class EulerSingularityError(ValueError):
    """A state at (or too close to) the Euler-angle singularity, pitch θ = ±π/2."""


# ----------------------------------------------------------------------------------------------
# Euler angles
# ----------------------------------------------------------------------------------------------

def _rz(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _ry(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _rx(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def base_rotation(yaw: float, pitch: float, roll: float) -> np.ndarray:
    """``R = Rz(yaw) Ry(pitch) Rx(roll)``: root link axes in the world frame, (3, 3)."""
    return _rz(yaw) @ _ry(pitch) @ _rx(roll)


def euler_angles(R) -> np.ndarray:
    """``(yaw, pitch, roll)`` [rad] with ``R = Rz(yaw) Ry(pitch) Rx(roll)``, pitch in
    [−π/2, π/2], yaw and roll in (−π, π]; at the singularity (``|cos pitch| = 0``) roll is 0."""
    R = np.asarray(R, dtype=float)
    pitch = np.arctan2(-R[2, 0], np.hypot(R[0, 0], R[1, 0]))
    if np.hypot(R[0, 0], R[1, 0]) < 1e-15:
        return np.array([np.arctan2(-R[0, 1], R[1, 1]), pitch, 0.0])
    return np.array([np.arctan2(R[1, 0], R[0, 0]), pitch, np.arctan2(R[2, 1], R[2, 2])])


def euler_rate_matrix(pitch: float, roll: float) -> np.ndarray:
    """``E`` with ``ω_b = E [ψ̇, θ̇, φ̇]``, ω_b the root's angular velocity in the root frame,
    (3, 3); ``det E = −cos θ``."""
    st, ct = np.sin(pitch), np.cos(pitch)
    sr, cr = np.sin(roll), np.cos(roll)
    return np.array([[-st, 0.0, 1.0], [ct * sr, cr, 0.0], [ct * cr, -sr, 0.0]])


def euler_singularity(q) -> float:
    """``|cos θ|`` of the base pitch ``q[4]``: 1 far from the singularity, 0 on it."""
    return float(abs(np.cos(np.asarray(q, dtype=float)[4])))


def check_euler(q, tolerance: float = SINGULARITY_TOLERANCE) -> None:
    """Raise :class:`EulerSingularityError` when ``|cos q[4]| < tolerance`` (pitch ≈ ±π/2)."""
    distance = euler_singularity(q)
    if distance < tolerance:
        raise EulerSingularityError(
            f"base pitch {float(np.asarray(q)[4]):.17g} rad is at the Euler-angle singularity "
            f"(|cos pitch| = {distance:.3g} < {tolerance:g}): yaw and roll axes line up and M "
            "is singular in these coordinates")


def velocity_map(q) -> np.ndarray:
    """``T(q)``, (n, n): Pinocchio's free-flyer velocity ``v = T q̇`` (module docstring)."""
    q = np.asarray(q, dtype=float)
    n = len(q)
    T = np.eye(n)
    T[:3, :3] = base_rotation(*q[3:6]).T
    T[3:6, 3:6] = euler_rate_matrix(q[4], q[5])
    return T


def velocity_map_dot_qd(q, qd) -> np.ndarray:
    """``Ṫ(q, q̇) q̇``, (n,): the part of Pinocchio's v̇ that Euler accelerations do not give,
    ``v̇ = T q̈ + Ṫ q̇``."""
    q = np.asarray(q, dtype=float)
    qd = np.asarray(qd, dtype=float)
    yaw_d, pitch_d, roll_d = qd[3:6]
    pitch, roll = q[4], q[5]
    st, ct, sr, cr = np.sin(pitch), np.cos(pitch), np.sin(roll), np.cos(roll)
    w_b = euler_rate_matrix(pitch, roll) @ qd[3:6]
    v_b = base_rotation(*q[3:6]).T @ qd[:3]
    out = np.zeros(len(q))
    out[:3] = -np.cross(w_b, v_b)                    # d(Rᵀ)/dt ṗ = −ω_b × Rᵀ ṗ
    out[3] = -ct * pitch_d * yaw_d
    out[4] = (-st * pitch_d * sr + ct * cr * roll_d) * yaw_d - sr * roll_d * pitch_d
    out[5] = (-st * pitch_d * cr - ct * sr * roll_d) * yaw_d - cr * roll_d * pitch_d
    return out


def to_free_flyer(q, qd) -> tuple[np.ndarray, np.ndarray]:
    """Euler coordinates to Pinocchio's free flyer.

    Parameters
    ----------
    q, qd : (6 + k,) array_like
        ``[x, y, z, yaw, pitch, roll, joints…]`` and its time derivative.

    Returns
    -------
    q_pin : (7 + k,) ndarray
        ``[p, quaternion (x, y, z, w), joints…]``.
    v : (6 + k,) ndarray
        ``[Rᵀ ṗ, ω_b, joint rates…]`` (root-frame linear and angular velocity).
    """
    q = np.asarray(q, dtype=float)
    qd = np.asarray(qd, dtype=float)
    R = base_rotation(*q[3:6])
    return (np.concatenate([q[:3], matrix_quaternion(R), q[6:]]),
            velocity_map(q) @ qd)


def from_free_flyer(q_pin, v) -> tuple[np.ndarray, np.ndarray]:
    """Pinocchio's free flyer to Euler coordinates (inverse of :func:`to_free_flyer`).

    Raises
    ------
    EulerSingularityError
        When the base pitch is at the singularity (no Euler rates give that ω).
    """
    q_pin = np.asarray(q_pin, dtype=float)
    v = np.asarray(v, dtype=float)
    R = quaternion_matrix(q_pin[3:7])
    q = np.concatenate([q_pin[:3], euler_angles(R), q_pin[7:]])
    check_euler(q)
    return q, np.linalg.solve(velocity_map(q), v)


def dynamics_from_free_flyer(q, qd, M_pin, h_pin, g_pin):
    """M, C q̇ and g in Euler coordinates from Pinocchio's free-flyer ones at the same state.

    Parameters
    ----------
    q, qd : (n,) array_like
        Euler-coordinate state (``[x, y, z, yaw, pitch, roll, joints…]``).
    M_pin : (n, n) array_like
        Pinocchio's mass matrix at ``to_free_flyer(q, qd)[0]``.
    h_pin : (n,) array_like
        Pinocchio's velocity product ``C_pin v`` at ``to_free_flyer(q, qd)`` (without gravity).
    g_pin : (n,) array_like
        Pinocchio's gravity vector there.

    Returns
    -------
    M, Cqd, g : ndarrays (n, n), (n,), (n,)
        ``Tᵀ M_pin T``, ``Tᵀ (h_pin + M_pin Ṫ q̇)`` and ``Tᵀ g_pin`` (module docstring).
    """
    T = velocity_map(q)
    M_pin = np.asarray(M_pin, dtype=float)
    return (T.T @ M_pin @ T, T.T @ (np.asarray(h_pin) + M_pin @ velocity_map_dot_qd(q, qd)),
            T.T @ np.asarray(g_pin))


class PinocchioFreeFlyer:
    """Pinocchio's free-flyer model of a URDF (its own reader, ``JointModelFreeFlyer``),
    evaluated in eomgen's Euler coordinates: for interoperation and as a reference.

    Pinocchio is optional; it is imported when an instance is made.

    Parameters
    ----------
    urdf:
        The URDF file.
    joint_names:
        The floating eomgen model's ``joint_names`` (virtual joints first): the order of
        eomgen's q.
    locked:
        Joints Pinocchio locks at 0 (``buildReducedModel``), as a scene locks them.

    Attributes
    ----------
    model, data:
        ``pinocchio.Model`` and ``pinocchio.Data``.
    idx:
        (n,) ints: Pinocchio's velocity coordinate k is eomgen's ``idx[k]``.
    """

    def __init__(self, urdf, joint_names, locked=()):
        import pinocchio as pin  # optional dependency: imported when an instance is made

        self.pin = pin
        model = pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer())
        if locked:
            ids = [model.getJointId(name) for name in locked]
            model = pin.buildReducedModel(model, ids, pin.neutral(model))
        self.model, self.data = model, model.createData()
        names = list(model.names)[2:]  # after 'universe' and the free flyer
        if sorted(names) != sorted(joint_names[6:]):
            raise ValueError("Pinocchio's joints are not the model's: "
                             f"{sorted(set(names) ^ set(joint_names[6:]))}")
        self.idx = np.array(list(range(6)) + [joint_names.index(n) for n in names])

    def state(self, q, qd):
        """Pinocchio's ``(q, v)`` (its joint order) of eomgen's Euler state."""
        q = np.asarray(q, dtype=float)
        q_ff, v = to_free_flyer(q, qd)
        q_pin = np.concatenate([q_ff[:7], q[self.idx[6:]]])
        return q_pin, v[self.idx]

    def dynamics(self, q, qd):
        """Pinocchio's M, C q̇, g mapped to Euler coordinates (:func:`dynamics_from_free_flyer`),
        eomgen's order."""
        pin = self.pin
        q_pin, v = self.state(q, qd)
        n = len(q)
        M = pin.crba(self.model, self.data, q_pin)
        M = np.triu(M) + np.triu(M, 1).T
        g = pin.computeGeneralizedGravity(self.model, self.data, q_pin)
        h = pin.rnea(self.model, self.data, q_pin, v, np.zeros(n)) - g
        M_o = np.empty((n, n))
        M_o[np.ix_(self.idx, self.idx)] = M
        h_o, g_o = np.empty(n), np.empty(n)
        h_o[self.idx], g_o[self.idx] = h, g
        return dynamics_from_free_flyer(q, qd, M_o, h_o, g_o)
