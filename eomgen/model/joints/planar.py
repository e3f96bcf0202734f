"""Planar joints: the child moves in the joint frame's xy plane (URDF ``planar``, the plane's
normal its ``axis``, which must be the joint frame's z axis), as Pinocchio's
``JointModelPlanar``:

* configuration (NQ = 4): ``<name>_x``, ``<name>_y``, the child origin in the joint frame
  [m]; ``<name>_cos``, ``<name>_sin``, cos θ and sin θ of the child's rotation θ about z;
* velocity (NV = 3): ``<name>_vx``, ``<name>_vy``, the child origin's velocity in the child
  frame [m/s]; ``<name>_wz``, θ̇ [rad/s].

``q ⊕ v`` is the SE(2) exponential in the child frame, ``(θ + ω, p + Rz(θ) V(ω) v_lin)``;
``(cos θ, sin θ)`` of any nonzero length stands for the normalised pair. In the tree: two
prismatic joints along the joint frame's x and y axes, then a continuous joint about its z,
held at zero (the chart, :mod:`.base`).
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from ...errors import UnsupportedError
from .base import ChartKind
from .lie import planar_left_jacobian

_HALF = sp.Rational(1, 2)
_ZERO = sp.S.Zero


def _angle(q) -> float:
    return float(np.arctan2(q[3], q[2]))


def _rotation(theta: float) -> np.ndarray:
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, -s], [s, c]])


class Planar(ChartKind):
    name = "planar"
    nq, nv = 4, 3
    pinocchio = "JointModelPlanar"
    motions = (0, 1, 5)
    velocity_suffixes = ("vx", "vy", "wz")
    configuration_suffixes = ("x", "y", "cos", "sin")
    unit_entries, unit_name = slice(2, 4), "(cos, sin) pair"
    placement_prefix = "Rp"

    def check(self, source: str, joint) -> None:
        if tuple(joint.axis) != (0, 0, 1):
            raise UnsupportedError(source, f"joint '{joint.name}' axis", "a planar joint moves "
                                   "in its joint frame's xy plane (Pinocchio's JointModelPlanar):"
                                   " its axis, the plane's normal, must be 0 0 1; turn the plane "
                                   "with the joint's origin")

    def neutral(self) -> np.ndarray:
        return np.array([0.0, 0.0, 1.0, 0.0])

    def integrate(self, q, v) -> np.ndarray:
        q, v = np.asarray(q, dtype=float), np.asarray(v, dtype=float)
        theta = _angle(q)
        p = q[:2] + _rotation(theta) @ (planar_left_jacobian(v[2]) @ v[:2])
        return np.array([p[0], p[1], np.cos(theta + v[2]), np.sin(theta + v[2])])

    def difference(self, q0, q1) -> np.ndarray:
        q0, q1 = np.asarray(q0, dtype=float), np.asarray(q1, dtype=float)
        t0, t1 = _angle(q0), _angle(q1)
        w = float(np.arctan2(np.sin(t1 - t0), np.cos(t1 - t0)))
        local = _rotation(t0).T @ (q1[:2] - q0[:2])
        return np.concatenate([np.linalg.solve(planar_left_jacobian(w), local), [w]])

    def configuration_rate(self, q, v) -> np.ndarray:
        q, v = np.asarray(q, dtype=float), np.asarray(v, dtype=float)
        c, s = q[2:4] / np.hypot(q[2], q[3])
        return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1], -q[3] * v[2], q[2] * v[2]])

    def random_configuration(self, coordinates, rng) -> np.ndarray:
        x, y, theta = np.asarray(coordinates, dtype=float)[:3]
        return np.array([x, y, np.cos(theta), np.sin(theta)])

    def pose(self, q, numbers=None):
        x, y, c, s = q
        if numbers is None:
            n = 1.0 / np.hypot(float(c), float(s))
            R, p = np.eye(3), np.array([float(x), float(y), 0.0])
        else:
            n = numbers.value(1) / (c * c + s * s) ** numbers.value(0.5)
            R, p = numbers.eye(3), np.array([x, y, numbers.value(0)], dtype=numbers.dtype)
        R[0, 0] = R[1, 1] = c * n
        R[0, 1], R[1, 0] = -s * n, s * n
        return R, p

    def placement(self, q, b, number: int):
        x, y, c, s = q
        n = b.define(1 / sp.sqrt(c * c + s * s), f"rn{number}", (f"rn{number}",))
        cn = b.define(c * n, f"Rp{number}_11", ("Rp", number, 1, 1))
        sn = b.define(s * n, f"Rp{number}_21", ("Rp", number, 2, 1))
        one = sp.Integer(1)
        return ((cn, -sn, _ZERO), (sn, cn, _ZERO), (_ZERO, _ZERO, one)), (x, y, _ZERO)

    def symbolic_rate(self, q, v) -> dict:
        x, y, c, s = q
        n = 1 / sp.sqrt(c * c + s * s)
        return {x: n * (c * v[0] - s * v[1]), y: n * (s * v[0] + c * v[1]),
                c: -s * v[2], s: c * v[2]}

    def tangent_seeds(self, q, R, first: int, prefix: str) -> dict:
        x, y, c, s = q
        return {x: {(prefix, first): R[0][0], (prefix, first + 1): R[0][1]},
                y: {(prefix, first): R[1][0], (prefix, first + 1): R[1][1]},
                c: {(prefix, first + 2): -s}, s: {(prefix, first + 2): c}}

    def velocity_transport(self, v):
        vx, vy, w = v
        return -_HALF * sp.Matrix([[0, -w, vy], [w, 0, -vx], [0, 0, 0]])

    def chart_states(self, xi, xid, xidd):
        theta, omega, domega = xi[:, 2], xid[:, 2], xidd[:, 2]
        c, s = np.cos(theta), np.sin(theta)
        q = np.stack([xi[:, 0], xi[:, 1], c, s], axis=1)
        vx = c * xid[:, 0] + s * xid[:, 1]  # Rᵀ ṗ
        vy = -s * xid[:, 0] + c * xid[:, 1]
        ax = c * xidd[:, 0] + s * xidd[:, 1] + omega * vy  # Rᵀ p̈ − ω ẑ × v
        ay = -s * xidd[:, 0] + c * xidd[:, 1] - omega * vx
        return q, np.stack([vx, vy, omega], axis=1), np.stack([ax, ay, domega], axis=1)

    def norm_error(self, q) -> float:
        return abs(float(np.hypot(float(q[2]), float(q[3]))) - 1.0)

    def describe(self) -> tuple[str, str, str]:
        return ("planar",
                "the child origin $(x, y)$ in the joint frame (m), then $\\cos\\theta$, "
                "$\\sin\\theta$ of its rotation about the joint frame's $z$ axis",
                "the child origin's velocity in the child frame (m/s), then $\\dot\\theta$ "
                "(rad/s)")


PLANAR = Planar()

__all__ = ["PLANAR", "Planar"]
