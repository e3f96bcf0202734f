"""Rotations (axis-angle, roll-pitch-yaw) and rigid transforms of the model, in SymPy scalars."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Iterable

import sympy as sp

from ..common import reprs
from .scalars import IDENTITY3, ZERO3, Mat3, Vec3, mat3, vec3
from .snapping import exact_angle, snap

def _matmul3(a: Mat3, b: Mat3) -> Mat3:
    return tuple(
        tuple(sp.Add(*[a[i][k] * b[k][j] for k in range(3)]) for j in range(3)) for i in range(3)
    )  # type: ignore[return-value]


def _matvec3(a: Mat3, v: Vec3) -> Vec3:
    return tuple(sp.Add(*[a[i][k] * v[k] for k in range(3)]) for i in range(3))  # type: ignore


def cos_sin(angle) -> tuple[sp.Expr, sp.Expr]:
    """``(cos, sin)`` of ``angle`` (rad) as the model's scalars.

    Symbolic for an angle in parameters; exact for an exact angle whose cosine and sine SymPy
    writes without trigonometric functions (every multiple of π/12, π/8, π/10: ``pi/6`` gives
    √3/2 and 1/2), and for a float snapped to a multiple of π/12 (:func:`exact_angle`); else
    the floats, each snapped to 0 or ±1 when within :data:`~eomgen.model.SNAP_TOLERANCE` of one
    (:func:`snap`).
    """
    if isinstance(angle, sp.Basic) and not angle.is_number:
        return sp.cos(angle), sp.sin(angle)
    exact = exact_angle(angle)
    if exact is not None:
        c, s = sp.cos(exact), sp.sin(exact)
        if not (c.has(sp.cos, sp.sin) or s.has(sp.cos, sp.sin)):
            return c, s
    value = float(angle)
    return snap(math.cos(value), f"cos({value!r})"), snap(math.sin(value), f"sin({value!r})")


def rotation_about_axis(axis: Vec3, angle) -> Mat3:
    """Rotation matrix of ``angle`` (rad, right hand rule) about the unit vector ``axis``
    (its cosine and sine from :func:`cos_sin`)."""
    c, s = cos_sin(angle)
    x, y, z = axis
    t = 1 - c
    return mat3(
        [
            [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
            [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
            [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
        ]
    )


def rotation_from_rpy(rpy: Vec3) -> Mat3:
    """URDF fixed-axis roll-pitch-yaw: ``R = Rz(yaw) · Ry(pitch) · Rx(roll)``."""
    roll, pitch, yaw = rpy
    rx = rotation_about_axis(vec3([1, 0, 0]), roll)
    ry = rotation_about_axis(vec3([0, 1, 0]), pitch)
    rz = rotation_about_axis(vec3([0, 0, 1]), yaw)
    return _matmul3(rz, _matmul3(ry, rx))


@dataclass(frozen=True)
class Transform:
    """A rigid transform: ``p_parent = rotation · p_child + translation``."""

    __repr__ = reprs.field_repr  # its numbers as short as they read back

    rotation: Mat3 = IDENTITY3
    translation: Vec3 = ZERO3

    @staticmethod
    def from_xyz_rpy(xyz: Iterable = (0, 0, 0), rpy: Iterable = (0, 0, 0)) -> "Transform":
        return Transform(rotation_from_rpy(vec3(rpy)), vec3(xyz))

    def __matmul__(self, other: "Transform") -> "Transform":
        rotation = _matmul3(self.rotation, other.rotation)
        moved = _matvec3(self.rotation, other.translation)
        translation = tuple(moved[i] + self.translation[i] for i in range(3))
        return Transform(rotation, translation)  # type: ignore[arg-type]

    def apply(self, point: Vec3) -> Vec3:
        moved = _matvec3(self.rotation, point)
        return tuple(moved[i] + self.translation[i] for i in range(3))  # type: ignore
