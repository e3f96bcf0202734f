"""The free flyer: a root that moves freely in space, its configuration the root origin and a
unit quaternion (Pinocchio's ``JointModelFreeFlyer``; :func:`eomgen.model.floating.add_free_flyer`
puts one under a robot).

==========  =====================================  =========  ===============================
 q index     configuration (NQ = 7)                 v index    velocity (NV = 6)
==========  =====================================  =========  ===============================
 0, 1, 2     root origin ``p`` in the world [m]     0, 1, 2    root linear velocity, root
                                                               frame [m/s] (``Rᵀ ṗ``)
 3 … 6       quaternion (x, y, z, w) of ``R``       3, 4, 5    root angular velocity ω, root
                                                               frame [rad/s]
==========  =====================================  =========  ===============================

``q ⊕ v`` is the SE(3) exponential in the root frame: ``(R exp([ω]×), p + R V(ω) v_lin)``.
Its entries are named ``base_x … base_qw`` and ``base_vx … base_wz`` whatever the joint's name.
In the tree: three prismatic joints along, then three continuous joints about, the root frame's
x, y, z axes, held at zero (the chart, :mod:`.base`).
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from .base import ChartKind
from .lie import (left_jacobian, matrix_quaternion, quaternion_matrix, quaternion_rate,
                  quaternion_rotation, quaternion_rotation_symbolic, rotation_rates, so3_exp,
                  so3_log)
from .spherical import quaternion_seeds, quaternion_symbolic_rate, skew_matrix

_HALF = sp.Rational(1, 2)

#: The configuration entries (q[0:7]) and velocity entries (v[0:6]) of a free flyer.
CONFIGURATION = ("base_x", "base_y", "base_z", "base_qx", "base_qy", "base_qz", "base_qw")
VELOCITY = ("base_vx", "base_vy", "base_vz", "base_wx", "base_wy", "base_wz")


class FreeFlyer(ChartKind):
    name = "free_flyer"
    described = False  # put under a robot (eomgen.model.floating.add_free_flyer), not written
    base = True
    nq, nv = 7, 6
    pinocchio = "JointModelFreeFlyer"
    motions = (0, 1, 2, 3, 4, 5)
    velocity_suffixes = ("vx", "vy", "vz", "wx", "wy", "wz")
    configuration_suffixes = ("x", "y", "z", "qx", "qy", "qz", "qw")
    unit_entries, unit_name = slice(3, 7), "quaternion"
    quaternion_offset = 3
    placement_prefix = "Rb"

    def velocity_names(self, joint: str) -> tuple[str, ...]:
        return VELOCITY

    def configuration_names(self, joint: str) -> tuple[str, ...]:
        return CONFIGURATION

    def neutral(self) -> np.ndarray:
        q = np.zeros(7)
        q[6] = 1.0
        return q

    def integrate(self, q, v) -> np.ndarray:
        q, v = np.asarray(q, dtype=float), np.asarray(v, dtype=float)
        R = quaternion_matrix(q[3:7])
        out = np.empty(7)
        out[:3] = q[:3] + R @ (left_jacobian(v[3:]) @ v[:3])
        out[3:] = matrix_quaternion(R @ so3_exp(v[3:]))
        return out

    def difference(self, q0, q1) -> np.ndarray:
        q0, q1 = np.asarray(q0, dtype=float), np.asarray(q1, dtype=float)
        R0, R1 = quaternion_matrix(q0[3:7]), quaternion_matrix(q1[3:7])
        w = so3_log(R0.T @ R1)
        out = np.empty(6)
        out[:3] = np.linalg.solve(left_jacobian(w), R0.T @ (q1[:3] - q0[:3]))
        out[3:] = w
        return out

    def configuration_rate(self, q, v) -> np.ndarray:
        q, v = np.asarray(q, dtype=float), np.asarray(v, dtype=float)
        out = np.empty(7)
        out[:3] = quaternion_matrix(q[3:7]) @ v[:3]
        out[3:] = quaternion_rate(q[3:7], v[3:])
        return out

    def random_configuration(self, coordinates, rng) -> np.ndarray:
        quaternion = rng.normal(size=4)
        return np.concatenate([np.asarray(coordinates, dtype=float)[:3],
                               quaternion / np.linalg.norm(quaternion)])

    def pose(self, q, numbers=None):
        if numbers is None:
            return quaternion_matrix(q[3:7]), np.asarray(q[:3], dtype=float)
        return (quaternion_rotation(numbers, *q[3:7]),
                np.array(q[:3], dtype=numbers.dtype))

    def placement(self, q, b, number: int = 0):
        x, y, z, w = q[3:7]
        s = b.define(1 / (x * x + y * y + z * z + w * w), "qn", ("qn",))
        R = quaternion_rotation_symbolic(x, y, z, w, s)
        R = tuple(tuple(b.define(R[i][j], f"Rb{i + 1}{j + 1}", ("Rb", i + 1, j + 1))
                        for j in range(3)) for i in range(3))
        return R, tuple(q[0:3])

    def symbolic_rate(self, q, v) -> dict:
        rates = dict(zip(q[3:7], quaternion_symbolic_rate(q[3:7], v[3:6])))
        R = quaternion_rotation_symbolic(*q[3:7])
        for i in range(3):
            rates[q[i]] = sum((R[i][c] * v[c] for c in range(3)), sp.Integer(0))
        return rates

    def tangent_seeds(self, q, R, first: int, prefix: str) -> dict:
        seeds = {q[row]: {(prefix, first + col): R[row][col] for col in range(3)}
                 for row in range(3)}  # the origin moves along R's columns
        seeds.update(quaternion_seeds(q[3:7], first + 3, prefix))
        return seeds

    def velocity_transport(self, v):
        linear, omega = v[0:3], v[3:6]
        out = sp.zeros(6, 6)
        out[0:3, 0:3] = -_HALF * skew_matrix(omega)
        out[0:3, 3:6] = -_HALF * skew_matrix(linear)
        out[3:6, 3:6] = -_HALF * skew_matrix(omega)
        return out

    def chart_states(self, xi, xid, xidd):
        R, omega, domega = rotation_rates(xi[:, 3:6], xid[:, 3:6], xidd[:, 3:6])
        q = np.concatenate([xi[:, :3], [matrix_quaternion(r) for r in R]], axis=1)
        linear = np.einsum("nji,nj->ni", R, xid[:, :3])  # Rᵀ ṗ
        v = np.concatenate([linear, omega], axis=1)
        vd = np.concatenate([np.einsum("nji,nj->ni", R, xidd[:, :3])
                             - np.cross(omega, linear), domega], axis=1)
        return q, v, vd

    def norm_error(self, q) -> float:
        return abs(float(np.linalg.norm(np.asarray(q, dtype=float)[3:7])) - 1.0)

    def describe(self) -> tuple[str, str, str]:
        return ("free flyer",
                "root origin $p$ in the world (m), then the quaternion $(x, y, z, w)$ of the "
                "root's orientation $R$",
                "the root's twist in the root frame: linear velocity $R^{T} \\dot{p}$ (m/s), "
                "then angular velocity $\\omega$ (rad/s)")


    def refused_as(self, joint: str) -> tuple[str, str, str]:
        return "a quaternion free flyer", "floating_base: quaternion", "; use floating_base: euler"


FREE_FLYER = FreeFlyer()

__all__ = ["CONFIGURATION", "FREE_FLYER", "FreeFlyer", "VELOCITY"]
