"""Planar motion: whether a model's bodies all move in parallel planes (:func:`planar_motion`),
and gravity less its component along the plane normal (:func:`in_plane`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..model import RobotModel, vec3
from .inertia import tidy


@dataclass(frozen=True)
class PlanarMotion:
    """Every moving revolute axis is parallel to ``normal`` (world frame, unit) and every
    prismatic axis perpendicular to it: the bodies move in parallel planes. ``gravity`` is how
    gravity relates to the plane: ``"in the plane"``, ``"along the normal"``, ``"tilted"``,
    ``"none"`` or ``"symbolic"``."""

    normal: tuple[float, float, float]
    gravity: str


def _world_axes(model: RobotModel) -> dict[str, tuple[float, ...]] | None:
    """Unit axis of every movable joint in the root frame at q = 0; None when symbolic."""
    rotation = {model.root: np.eye(3)}
    axes = {}
    for joint in model.topological_joints:
        try:
            R = rotation[joint.parent] @ np.array(joint.origin.rotation, dtype=float)
            axis = R @ np.array(joint.axis, dtype=float)
        except TypeError:
            return None
        rotation[joint.child] = R
        if joint.type.is_movable:
            axes[joint.name] = tuple(axis / np.linalg.norm(axis))
    return axes


def planar_motion(model: RobotModel, tolerance: float = 1e-9) -> PlanarMotion | None:
    """Whether ``model``'s bodies move in parallel planes (see :class:`PlanarMotion`).

    At q = 0, in the root frame: every revolute axis is parallel to the first one, n, and every
    prismatic axis is perpendicular to n (both stay so at every q, since rotations about n keep
    n and vectors perpendicular to it). Needs at least one revolute joint; None otherwise, or
    when the geometry is symbolic.
    """
    axes = _world_axes(model)
    if not axes:
        return None
    # a helical joint both turns and slides along its axis: it is in both lists (never planar)
    revolute = [np.array(axes[j.name]) for j in model.movable_joints if j.rotates]
    prismatic = [np.array(axes[j.name]) for j in model.movable_joints if j.lead != 0]
    if not revolute:
        return None
    n = revolute[0]
    if any(np.linalg.norm(np.cross(n, a)) > tolerance for a in revolute):
        return None
    if any(abs(float(n @ a)) > tolerance for a in prismatic):
        return None
    k = int(np.argmax(np.abs(n)))  # normal pointing along the positive dominant axis
    n = n if n[k] > 0 else -n
    n = np.where(np.abs(n) < 1e-15, 0.0, n)
    normal = tuple(float(x) for x in n)
    try:
        g = np.array(model.gravity, dtype=float)
    except TypeError:  # symbolic: classify by which components are non-zero
        support = [k for k in range(3) if model.gravity[k] != 0]
        if all(n[k] == 0 for k in support):
            return PlanarMotion(normal, "in the plane")
        if len(support) == 1 and abs(n[support[0]]) == 1:
            return PlanarMotion(normal, "along the normal")
        return PlanarMotion(normal, "symbolic")
    size = float(np.linalg.norm(g))
    if size == 0:
        relation = "none"
    elif abs(float(g @ n)) <= tolerance * size:
        relation = "in the plane"
    elif float(np.linalg.norm(np.cross(g, n))) <= tolerance * size:
        relation = "along the normal"
    else:
        relation = "tilted"
    return PlanarMotion(normal, relation)


def in_plane(gravity, normal) -> tuple:
    """``gravity`` less its component along ``normal`` (exact zeros where they come out so)."""
    if any(not (isinstance(x, sp.Basic) and x.is_number) for x in gravity):
        # symbolic gravity is only classified "along the normal" when n is a coordinate axis
        return vec3([0 if abs(n) == 1 else x for x, n in zip(gravity, normal)])
    g = [float(x) for x in gravity]
    along = sum(a * b for a, b in zip(g, normal))
    return vec3([tidy(sp.Float(g[i] - along * normal[i], 17), [g[i], along * normal[i]])
                 for i in range(3)])
