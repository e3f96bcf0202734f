"""A loop closure of a scene (:class:`Loop`): two frames of the kinematic tree held together.

A closed chain (a four-bar, a five-bar, a Delta robot) is described as a tree (the joints of
the description) plus loops: for each cut joint, frame A (a link and a pose in it) on one side
and frame B on the other, which the loop holds at the same point (``point``, a spherical
joint), the same point and axis (``hinge``, a revolute joint) or the same pose (``weld``).
A ``plane`` (the unit normal of the loop's plane, world axes) keeps only the rows in that plane:
the two in-plane translations, and for a weld the rotation about the normal (a planar
mechanism's other rows are identically zero, and the KKT system would be singular).

Plain data; :mod:`eomgen.symbolic.loops` builds the constraint ``Φ(q)``, its Jacobian and
``J̇ q̇`` (the rows, axes and signs are in its docstring), :mod:`eomgen.numeric.loops` the
numbers.
"""

from __future__ import annotations

from dataclasses import dataclass

from .transforms import Transform

#: The kinds of loop: what the cut joint was (a ball, a revolute joint, a rigid joint).
POINT_LOOP, HINGE, WELD = "point", "hinge", "weld"
LOOP_KINDS = (POINT_LOOP, HINGE, WELD)


@dataclass(frozen=True)
class LoopFrame:
    """One end of a loop: the frame at ``pose`` in the frame of link ``link``."""

    link: str
    pose: Transform = Transform()


@dataclass(frozen=True)
class Loop:
    """Frames ``a`` and ``b`` held together (see the module docstring).

    Attributes
    ----------
    name:
        Names its rows (``<name>.x`` …) and its forces.
    kind:
        ``point`` (3 rows: B's origin on A's), ``hinge`` (5 rows: and B's ``axis`` along A's),
        ``weld`` (6 rows: and the same orientation).
    a, b:
        The two frames; the loop force acts on b's body at b's origin, its opposite on a's.
    axis:
        A hinge's axis, unit, in the axes of frame a (and of frame b: the closed loop aligns
        them).
    plane:
        The unit normal (world axes) of a planar loop, or None for a spatial one.
    """

    name: str
    kind: str
    a: LoopFrame
    b: LoopFrame
    axis: tuple[float, float, float] = (0.0, 0.0, 1.0)
    plane: tuple[float, float, float] | None = None

    def __post_init__(self):
        if self.kind not in LOOP_KINDS:
            raise ValueError(f"loop '{self.name}': type must be one of {', '.join(LOOP_KINDS)}, "
                             f"got {self.kind!r}")

    @property
    def translations(self) -> tuple[str, ...]:
        """Names of its translational rows: ``x, y, z`` (world axes), or ``u, v`` (the in-plane
        axes of :func:`in_plane_axes`)."""
        return ("x", "y", "z") if self.plane is None else ("u", "v")

    @property
    def rotations(self) -> tuple[str, ...]:
        """Names of its rotational rows: a weld ``rx, ry, rz`` (world axes; planar: ``rn``
        about the normal), a hinge ``r1, r2`` (about the two axes of frame a normal to its
        axis; planar: none), a point none."""
        if self.kind == WELD:
            return ("rx", "ry", "rz") if self.plane is None else ("rn",)
        if self.kind == HINGE and self.plane is None:
            return ("r1", "r2")
        return ()

    @property
    def rows(self) -> tuple[str, ...]:
        """The names of its rows, ``<name>.<axis>``, translations first."""
        return tuple(f"{self.name}.{r}" for r in self.translations + self.rotations)

    @property
    def size(self) -> int:
        """Rows of the loop: point 3, hinge 5, weld 6; planar point or hinge 2, planar weld 3."""
        return len(self.rows)


def in_plane_axes(normal) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """Two unit vectors ``t1, t2`` with ``(t1, t2, n)`` right-handed, ``n`` the unit ``normal``:
    ``t1`` is the coordinate axis least aligned with ``n`` (the first of a tie), made
    orthogonal to it, ``t2 = n × t1`` (for ``n = z``: ``x`` and ``y``; ``n = y``: ``z`` and
    ``x``). A planar loop's rows ``u, v``, and a hinge's two rotation rows about its axis.

    >>> in_plane_axes((0, 0, 1))
    ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    """
    n = [float(x) for x in normal]
    norm = sum(x * x for x in n) ** 0.5
    n = [x / norm for x in n]
    k = min(range(3), key=lambda i: (abs(n[i]), i))
    t1 = [(1.0 if i == k else 0.0) - n[k] * n[i] for i in range(3)]
    s = sum(x * x for x in t1) ** 0.5
    t1 = [x / s for x in t1]
    t2 = [n[1] * t1[2] - n[2] * t1[1], n[2] * t1[0] - n[0] * t1[2], n[0] * t1[1] - n[1] * t1[0]]
    return tuple(t1), tuple(t2)
