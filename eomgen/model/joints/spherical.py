"""Spherical (ball) joints: three rotational freedoms, the configuration a unit quaternion
(Pinocchio's ``JointModelSpherical``).

* configuration (NQ = 4), ``<name>_qx … <name>_qw``: the quaternion (x, y, z, w) of the
  rotation R from the joint frame to the child link frame;
* velocity (NV = 3), ``<name>_wx … <name>_wz``: the angular velocity ω of the child relative
  to the parent, in the child frame [rad/s].

``q ⊕ v = R exp([v]×)``, ``q1 ⊖ q0 = log(R0ᵀ R1)``; a non-unit quaternion stands for the
normalised one. In the tree: three continuous joints ``<name>_wx``, ``<name>_wy``, ``<name>_wz``
about the child frame's x, y, z axes, held at zero (the chart, :mod:`.base`).
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from .base import ChartKind, zeros
from .lie import (matrix_quaternion, quaternion_matrix, quaternion_rate, quaternion_rotation,
                  quaternion_rotation_symbolic, rotation_rates, so3_exp, so3_log)

_HALF = sp.Rational(1, 2)
_ZERO = sp.S.Zero


def _cross_unit(a, c: int) -> tuple:
    """``a × e_c``."""
    e = [0, 0, 0]
    e[c] = 1
    return (a[1] * e[2] - a[2] * e[1], a[2] * e[0] - a[0] * e[2], a[0] * e[1] - a[1] * e[0])


def quaternion_seeds(quaternion, first: int, prefix: str) -> dict:
    """The tangent seeds (:meth:`ChartKind.tangent_seeds`) of a quaternion ``(x, y, z, w)``
    (symbols) turning at the angular velocity coordinates ``first … first + 2``:
    ``½ (w e_c + (x, y, z) × e_c)`` and ``−½ (x, y, z)_c`` along direction ``c``."""
    x, y, z, w = quaternion
    vector = (x, y, z)
    seeds: dict = {}
    for c in range(3):  # d(x, y, z)/dω_c = ½ (w e_c + (x, y, z) × e_c)
        column = _cross_unit(vector, c)
        for row, entry in enumerate(vector):
            d = _HALF * ((w if row == c else 0) + column[row])
            if d != 0:
                seeds.setdefault(entry, {})[(prefix, first + c)] = d
    seeds[w] = {(prefix, first + c): -_HALF * vector[c] for c in range(3)}
    return seeds


def quaternion_symbolic_rate(quaternion, omega) -> tuple:
    """``d(x, y, z, w)/dt = ½ (x, y, z, w) ⊗ (ω, 0)`` over SymPy (4 expressions)."""
    x, y, z, w = quaternion
    wx, wy, wz = omega
    cross = (y * wz - z * wy, z * wx - x * wz, x * wy - y * wx)
    return tuple((w * omega[i] + cross[i]) / 2 for i in range(3)) + (
        -(x * wx + y * wy + z * wz) / 2,)


def skew_matrix(h) -> sp.Matrix:
    """``[h]×`` as a SymPy matrix."""
    zero = sp.Integer(0)
    return sp.Matrix(((zero, -h[2], h[1]), (h[2], zero, -h[0]), (-h[1], h[0], zero)))


class Spherical(ChartKind):
    name = "spherical"
    nq, nv = 4, 3
    pinocchio = "JointModelSpherical"
    motions = (3, 4, 5)
    velocity_suffixes = ("wx", "wy", "wz")
    configuration_suffixes = ("qx", "qy", "qz", "qw")
    unit_entries, unit_name = slice(0, 4), "quaternion"
    quaternion_offset = 0
    placement_prefix = "Rs"

    def neutral(self) -> np.ndarray:
        return np.array([0.0, 0.0, 0.0, 1.0])

    def integrate(self, q, v) -> np.ndarray:
        return matrix_quaternion(quaternion_matrix(q) @ so3_exp(v))

    def difference(self, q0, q1) -> np.ndarray:
        return so3_log(quaternion_matrix(q0).T @ quaternion_matrix(q1))

    def configuration_rate(self, q, v) -> np.ndarray:
        return quaternion_rate(q, v)

    def random_configuration(self, coordinates, rng) -> np.ndarray:
        quaternion = rng.normal(size=4)
        return quaternion / np.linalg.norm(quaternion)

    def pose(self, q, numbers=None):
        if numbers is None:
            return quaternion_matrix(q), np.zeros(3)
        return quaternion_rotation(numbers, *q), zeros(numbers, 3)

    def placement(self, q, b, number: int):
        x, y, z, w = q
        norm, name, tag = f"qns{number}", f"Rs{number}_{{}}{{}}", ("Rs", number)
        s = b.define(1 / (x * x + y * y + z * z + w * w), norm, (norm,))
        R = quaternion_rotation_symbolic(x, y, z, w, s)
        R = tuple(tuple(b.define(R[i][j], name.format(i + 1, j + 1), (*tag, i + 1, j + 1))
                        for j in range(3)) for i in range(3))
        return R, (_ZERO,) * 3

    def symbolic_rate(self, q, v) -> dict:
        return dict(zip(q, quaternion_symbolic_rate(q, v)))

    def tangent_seeds(self, q, R, first: int, prefix: str) -> dict:
        return quaternion_seeds(q, first, prefix)

    def velocity_transport(self, v):
        return -_HALF * skew_matrix(v)

    def chart_states(self, xi, xid, xidd):
        R, v, vd = rotation_rates(xi, xid, xidd)
        return np.array([matrix_quaternion(r) for r in R]), v, vd

    def norm_error(self, q) -> float:
        return abs(float(np.linalg.norm(np.asarray(q, dtype=float))) - 1.0)

    def describe(self) -> tuple[str, str, str]:
        return ("ball",
                "the quaternion $(x, y, z, w)$ of the rotation from the joint frame to the "
                "child link's frame",
                "the angular velocity $\\omega$ of the child link relative to its parent, in "
                "the child frame (rad/s)")


SPHERICAL = Spherical()

__all__ = ["SPHERICAL", "Spherical", "quaternion_seeds", "quaternion_symbolic_rate",
           "skew_matrix"]
