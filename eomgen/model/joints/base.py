"""What a joint kind is: its sizes, the names of its coordinates, its configuration space
(neutral, integrate, difference, rate) and its motion (transform, motion subspace).

A kind is a type (:class:`JointKind`), one module per kind in this package, one instance each
(:data:`eomgen.model.joints.KINDS`). Frames and signs (Pinocchio's, for every kind):

* ``q`` holds the kind's NQ configuration entries, ``v`` its NV velocity entries;
* :meth:`JointKind.transform` is the pose ``(R, p)`` of the child link frame in the joint frame
  at ``q`` (``R`` rotates child-frame vectors into the joint frame, ``p`` [m]);
* :meth:`JointKind.motion_subspace` ``S`` (6 × NV, linear rows first) at ``q`` gives the
  child's velocity relative to the parent, in the child frame, about its origin: ``S v``;
* :meth:`JointKind.integrate` moves ``q`` along the constant velocity ``v`` for unit time (the
  kind's Lie-group exponential, ``q ⊕ v``), :meth:`JointKind.difference` is its inverse
  (``q1 ⊖ q0``), :meth:`JointKind.configuration_rate` is ``q̇`` at velocity ``v``.

How the algorithms see a kind. One-coordinate kinds (revolute, continuous, prismatic,
helical) are joints of the kinematic tree; the derivation and the references read their motion
from :attr:`rotates` (the child turns by ``q`` about the axis) and :meth:`lead` (it moves
``lead · q`` along the axis: 0, 1 or the helical joint's pitch), so the motion subspace is
``S = (lead · axis, axis if rotates else 0)``. A kind of several coordinates
(:class:`ChainKind`) is, in the tree, a chain of virtual one-axis joints through massless links
at the joint's place (its :meth:`~ChainKind.chain`; :func:`eomgen.model.expand_joints` puts it
there). When its configuration is the chain's coordinates (a universal joint), the chain's
joints are joints of the tree like any other. When it is not (:class:`ChartKind`: the free
flyer, a ball joint, a planar joint), the chain is held at zero, with the pose from ``q`` placed
before it (:meth:`ChainKind.pose`, :meth:`ChartKind.placement`);
:mod:`eomgen.symbolic.charts` has the argument.
"""

from __future__ import annotations

import numpy as np


def zeros(numbers, n: int) -> np.ndarray:
    """``n`` zeros in the number type ``numbers`` (None: float64)."""
    return np.zeros(n) if numbers is None else numbers.zeros(n)


class JointKind:
    """A joint kind (module docstring). The base is a one-coordinate joint whose configuration
    is its coordinate: ``q ⊕ v = q + v``."""

    #: The kind's name, as descriptions write it (``revolute``, ``spherical``, …).
    name: str = ""
    nq: int = 1
    nv: int = 1
    #: The class of Pinocchio's joint model of this kind (``JointModelRevoluteUnaligned``, …).
    pinocchio: str = ""
    #: True when a description writes it as a joint's type (a :class:`eomgen.model.JointType`
    #: member); the free flyer is put under a robot instead.
    described: bool = True
    #: True for a virtual base joint: the joint a scene or a parser puts between the world and
    #: a robot's root (Pinocchio's ``root_joint``; named ``base``), whose velocity is the root's
    #: twist in the root frame (the free flyer).
    base: bool = False
    #: True when the kind rotates its child about its axis, or translates it along its axis.
    rotates: bool = False
    translates: bool = False
    #: Where the kind's quaternion starts in its configuration entries (None: it has none).
    quaternion_offset: int | None = None

    def lead(self, pitch=0):
        """The translation along the axis per unit of the coordinate: 1 for a prismatic joint
        [m/m], the pitch for a helical one [m/rad], 0 for a kind that does not translate (the
        linear part of ``S`` is ``lead · axis``, its angular part ``axis`` when it
        :attr:`rotates`)."""
        return 0

    def __repr__(self) -> str:
        return f"<joint kind {self.name}: nq={self.nq}, nv={self.nv}>"

    def __eq__(self, other) -> bool:  # a kind is its name: ``kind == "spherical"``
        if isinstance(other, str):
            return other == self.name
        return self is other

    def __hash__(self) -> int:
        return hash(self.name)

    def velocity_names(self, joint: str) -> tuple[str, ...]:
        """The names of the joint's velocity entries (its entries of ``JOINT_NAMES``)."""
        return (joint,) if self.nv == 1 else ()

    def configuration_names(self, joint: str) -> tuple[str, ...]:
        """The names of the joint's configuration entries (of ``CONFIGURATION_NAMES``)."""
        return self.velocity_names(joint)

    def check(self, source: str, joint) -> None:
        """Refuse, in one line naming ``source`` and the joint, what this kind cannot be (a
        planar joint off its plane, a helical joint without a finite pitch); a kind without
        such rules accepts every joint."""

    # -- the configuration space (float64, the joint's own entries) --------------------------
    def neutral(self) -> np.ndarray:
        """The neutral configuration (NQ,): Pinocchio's ``neutral``."""
        return np.zeros(self.nq)

    def integrate(self, q, v) -> np.ndarray:
        """``q ⊕ v`` (NQ,): the configuration reached from ``q`` moving at ``v`` for 1 s."""
        return np.asarray(q, dtype=float) + np.asarray(v, dtype=float)

    def difference(self, q0, q1) -> np.ndarray:
        """``q1 ⊖ q0`` (NV,): the velocity with ``q0 ⊕ v = q1``."""
        return np.asarray(q1, dtype=float) - np.asarray(q0, dtype=float)

    def configuration_rate(self, q, v) -> np.ndarray:
        """``q̇`` (NQ,) at velocity ``v`` (NV,)."""
        return np.asarray(v, dtype=float).copy()

    def symbolic_rate(self, q, v) -> dict:
        """``{symbol: q̇}`` of the NQ configuration symbols ``q`` at velocity ``v`` (NV): ``v``
        itself for a kind whose configuration is its coordinates."""
        return dict(zip(q, v))

    def random_configuration(self, coordinates, rng) -> np.ndarray:
        """A configuration (NQ,) for tests and verification from ``coordinates`` (NV values
        drawn by the caller) and ``rng`` (a NumPy generator, for kinds that need more)."""
        return np.asarray(coordinates, dtype=float).copy()

    # -- its motion (float64) ----------------------------------------------------------------
    def transform(self, axis, q, pitch: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """``(R, p)``: the child frame in the joint frame at ``q`` (module docstring)."""
        return np.eye(3), np.zeros(3)

    def motion_subspace(self, axis, q=None, pitch: float = 0.0) -> np.ndarray:
        """``S`` (6 × NV), linear rows first, at ``q`` (NQ; None will do for a kind whose ``S``
        does not depend on it): the child's velocity ``S v`` in its own
        frame."""
        return np.zeros((6, self.nv))


class ChainKind(JointKind):
    """A kind of several coordinates: in the tree a chain of virtual one-axis joints through
    massless links (:meth:`chain`), ``<joint>_<suffix>`` each, the joint recorded in
    :attr:`~eomgen.model.RobotModel.compound_joints` (locked, reduced and named as one). The
    base is a chain whose configuration is its coordinates (module docstring)."""

    #: The chain's unit motions in chain order, as indices into a spatial motion vector
    #: (linear then angular): each virtual joint moves along (0, 1, 2) or turns about
    #: (3, 4, 5) the x, y or z axis of its own joint frame.
    motions: tuple[int, ...] = ()
    #: Suffixes of the velocity entries' names (``<joint>_<suffix>``), the chain's joints.
    velocity_suffixes: tuple[str, ...] = ()

    def velocity_names(self, joint: str) -> tuple[str, ...]:
        return tuple(f"{joint}_{s}" for s in self.velocity_suffixes)

    def chain(self) -> tuple[tuple[str, str, tuple[int, int, int]], ...]:
        """The virtual joints: ``(suffix, "prismatic" or "continuous", axis)`` in chain order
        (a translation along, or a rotation about, an axis of the virtual joint's frame)."""
        out = []
        for suffix, motion in zip(self.velocity_suffixes, self.motions):
            axis = tuple(1 if i == motion % 3 else 0 for i in range(3))
            out.append((suffix, "prismatic" if motion < 3 else "continuous", axis))
        return tuple(out)

    def transform(self, axis, q, pitch: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        return self.pose(np.asarray(q, dtype=float))

    def pose(self, q, numbers=None) -> tuple[np.ndarray, np.ndarray]:
        """``(R, p)``: the child frame in the joint frame at the configuration entries ``q``,
        in the number type ``numbers`` (a :class:`~eomgen.numeric.Numbers`; None: float64).
        A chart places it before its chain (held at zero); a joint locked at ``q`` is fixed
        there (:func:`eomgen.model.lock_joints`)."""
        raise NotImplementedError

    def describe(self) -> tuple[str, str, str]:
        """``(name, configuration, velocity)`` in prose with LaTeX, for documents and
        messages."""
        raise NotImplementedError

    def refused_as(self, joint: str) -> tuple[str, str, str]:
        """``(what, where, hint)`` for a one-line refusal of something not derived for the
        joint ``joint`` of this kind: what it is, the element of the description that made it,
        and a way out (empty when there is none)."""
        name = self.describe()[0]
        return f"a {name} joint", f"{name} joint '{joint}'", ""


class ChartKind(ChainKind):
    """A kind whose configuration is not its coordinates (NQ > NV): in the tree a chain of
    virtual one-axis joints held at zero, their axes the child frame's (:attr:`motions`),
    after the pose of ``q``, its chart (module docstring)."""

    #: Suffixes of the configuration entries' names (``<joint>_<suffix>``).
    configuration_suffixes: tuple[str, ...] = ()
    #: The entries of the configuration (NQ,) that stand for their normalised value (a
    #: quaternion; a planar joint's ``(cos θ, sin θ)``), and their name for messages; None
    #: when the kind has none. Zero length stands for no configuration at all.
    unit_entries: slice | None = None
    unit_name: str = ""
    #: The prefix of the names the derivation gives the pose's entries.
    placement_prefix: str = ""

    def configuration_names(self, joint: str) -> tuple[str, ...]:
        return tuple(f"{joint}_{s}" for s in self.configuration_suffixes)

    def motion_subspace(self, axis=None, q=None, pitch: float = 0.0) -> np.ndarray:
        S = np.zeros((6, self.nv))
        for i, motion in enumerate(self.motions):
            S[motion, i] = 1.0
        return S

    # -- the chart: the pose placed before the chain -----------------------------------------

    def placement(self, q, b, number: int) -> tuple[tuple, tuple]:
        """:meth:`pose` over SymPy: ``(R, p)`` from the configuration symbols ``q`` (NQ), the
        entries named in the program builder ``b`` (the ``number``-th joint of the kind)."""
        raise NotImplementedError

    def symbolic_rate(self, q, v) -> dict:
        """``{symbol: q̇}`` of the NQ configuration symbols ``q`` at velocity ``v``
        (the rotation of the normalised configuration, as the program places it)."""
        raise NotImplementedError

    def tangent_seeds(self, q, R, first: int, prefix: str) -> dict:
        """``{configuration symbol: {(prefix, i): ∂q/∂δᵢ}}`` at ``δ = 0`` for
        ``q ⊕ δ`` (``δ`` the velocity coordinates, from index ``first``); ``R`` the placed
        rotation."""
        raise NotImplementedError

    def velocity_transport(self, v):
        """∂δ̇/∂δ at δ = 0 of ``δ̇ = J_r(δ)⁻¹ v`` (NV × NV SymPy matrix): ``−½ ad(v)`` on the
        kind's motions."""
        raise NotImplementedError

    def chart_states(self, xi, xid, xidd) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(q, v, v̇)`` ((N, NQ), (N, NV), (N, NV)) of chart states ``(ξ, ξ̇, ξ̈)`` ((N, NV)
        each), where ``ξ`` are the chain's coordinates in the parent's joint frame
        (:mod:`eomgen.identification.charts`)."""
        raise NotImplementedError

    def norm_error(self, q) -> float:
        """How far ``q`` (NQ,) is off the kind's configuration manifold: ``|‖u‖ − 1|`` of its
        unit part (a quaternion; a planar joint's ``(cos θ, sin θ)``)."""
        raise NotImplementedError


__all__ = ["ChainKind", "ChartKind", "JointKind", "zeros"]
