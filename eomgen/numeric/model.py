"""The numeric description of a robot (Pinocchio's Model): :class:`NumericModel`, built once by
:func:`numeric_model` from a :class:`~eomgen.model.RobotModel`, every parameter replaced by its
number, and the number type the algorithms of :mod:`eomgen.numeric.newton_euler` compute in
(:class:`Numbers`: float64, mpmath). Frames and conventions: that module's docstring.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Mapping

import numpy as np
import sympy as sp

from ..model import (QuaternionJoint, RobotModel, coupling_map, parameter_symbol,
                     uncoupled)
from ..model.coupling import full_configuration

#: Joint type codes stored in :attr:`NumericModel.joint_type`.
FIXED, REVOLUTE, PRISMATIC, HELICAL = 0, 1, 2, 3
#: The codes of the joints that turn their child about the axis (a helical joint also moves
#: it along the axis: :attr:`NumericModel.lead`).
TURNING = (REVOLUTE, HELICAL)



def _type_code(kind) -> int:
    """The code of a one-axis joint kind, from what it does (its motion: ``rotates`` and
    ``translates``), so that a new kind needs no entry here."""
    if kind.nv == 0:
        return FIXED
    if kind.rotates:
        return HELICAL if kind.translates else REVOLUTE
    return PRISMATIC


@dataclass(frozen=True)
class Numbers:
    """The number type an algorithm computes in, and the few operations it needs on it.

    The algorithms of this module are written once over NumPy arrays whose entries are these
    numbers (Pinocchio's algorithms are templated on ``Scalar`` in the same way): float64
    arrays for :data:`FLOAT64`, object arrays of ``mpmath.mpf`` for
    :data:`eomgen.analysis.precision.MPMATH` (the high-precision reference).

    Attributes
    ----------
    name : str
        What the numbers are, for messages.
    dtype : type
        The NumPy dtype of the arrays: ``float`` or ``object``.
    convert : callable
        A number of the description (SymPy or Python) as this type; TypeError when it is not
        a number.
    value : callable
        A caller's value (float, int, or already this type) as this type.
    sin, cos : callable
        The trigonometric functions on this type.
    finite : callable
        True when a number is finite.
    """

    name: str
    dtype: type
    convert: Callable[[Any], Any]
    value: Callable[[Any], Any]
    sin: Callable[[Any], Any]
    cos: Callable[[Any], Any]
    finite: Callable[[Any], bool]

    def zeros(self, shape) -> np.ndarray:
        """An array of exact zeros of this type."""
        if self.dtype is float:
            return np.zeros(shape)
        return np.full(shape, self.value(0), dtype=object)

    def eye(self, n: int) -> np.ndarray:
        """The ``n × n`` identity matrix of this type."""
        if self.dtype is float:
            return np.eye(n)
        out = self.zeros((n, n))
        for i in range(n):
            out[i, i] = self.value(1)
        return out

    def vector(self, x) -> np.ndarray:
        """A caller's sequence of values as a 1-D array of this type."""
        if self.dtype is float:
            return np.asarray(x, dtype=float)
        a = np.asarray(x, dtype=object)
        out = np.empty(a.shape, dtype=object)
        for index, v in np.ndenumerate(a):
            out[index] = self.value(v)
        return out

    def all_finite(self, a: np.ndarray) -> bool:
        """True when every entry of ``a`` is finite."""
        if self.dtype is float or a.dtype != object:
            return bool(np.all(np.isfinite(a)))
        return all(self.finite(x) for x in a.ravel())


#: IEEE double precision: float64 NumPy arrays, NumPy's functions (the default everywhere).
FLOAT64 = Numbers("float64", float, float, float, np.sin, np.cos, np.isfinite)


@dataclass(frozen=True, eq=False)
class NumericModel:
    """A robot with every quantity a number: the fixed description the algorithms read.

    Bodies are the links in topological order (every body after its parent); body 0 is the
    root. Arrays are float64 (indices int64) and read-only. ``nb`` is the number of bodies
    (links), ``n`` the number of degrees of freedom.

    Attributes
    ----------
    name : str
        The robot's name.
    body_names : tuple of str, (nb,)
        Link name of each body.
    joint_of_body : tuple of str, (nb,)
        Name of the joint whose child is the body (``""`` for the root).
    joint_names : tuple of str, (n,)
        The coordinates' joints in description order (``JOINT_NAMES``): the order of ``q``,
        ``qd``, ``qdd``, ``tau``; with coupled joints, the movable joints less the followers.
    parent : (nb,) int array
        Parent body index; ``-1`` for the root.
    joint_type : (nb,) int array
        :data:`FIXED`, :data:`REVOLUTE`, :data:`PRISMATIC` or :data:`HELICAL` (the root counts
        as fixed); the codes of :data:`TURNING` turn the body about the axis.
    lead : (nb,) array
        The body's translation along the axis per unit of its coordinate: 1 (prismatic), the
        pitch [m/rad] (helical), 0 (revolute, fixed, the root); the motion subspace of a
        moving joint is ``S = (ω, v) = (z if it turns else 0, lead · z)``.
    q_index : (nb,) int array
        Index of the body's joint among the tree's movable joints (``tree_joint_names``:
        ``q`` itself without couplings); ``-1`` for fixed joints and the root.
    axis : (nb, 3) array
        Joint axis, a unit vector in the body (child link) frame.
    origin_rotation : (nb, 3, 3) array
        Rotation of the joint frame in the parent frame (identity for the root).
    origin_translation : (nb, 3) array
        Position [m] of the joint frame origin in the parent frame (zero for the root).
    mass : (nb,) array
        Body mass [kg]; zero for massless links.
    com : (nb, 3) array
        Centre of mass [m] in the body frame.
    inertia : (nb, 3, 3) array
        Rotational inertia [kg m²] about the centre of mass, in body frame axes.
    gravity : (3,) array
        Gravitational acceleration [m/s²] in the root frame.
    numbers : Numbers
        The number type of the arrays above (not of the index arrays) and of every result of
        the algorithms: :data:`FLOAT64` unless built for another one.
    joint_places : tuple of QuaternionJoint
        Every joint of the tree in velocity order, with its kind and its first index in ``v``
        and in ``q`` (:attr:`eomgen.model.RobotModel.joint_places` of the uncoupled tree);
        the algorithms ask a place's kind (``nq != nv``: a joint with a chart,
        :attr:`chart_places`), never its name.
    quaternion_bodies : tuple of int
        For each of ``chart_places``, the body whose joint starts its chain (where its pose
        from ``q`` is placed).
    tree_joint_names : tuple of str
        Every movable joint in description order (followers of couplings included): the
        coordinates the recursions run on.
    coupling : (len(tree_joint_names), n) array or None
        ``T`` of the coupling map ``q_tree = T q + c`` (:func:`eomgen.model.coupling_map`);
        None without couplings (``T = 1``). The algorithms run the whole tree at
        ``(T q + c, T q̇, T q̈)`` and return ``Tᵀ τ``: so ``M = Tᵀ M_tree T``, ``h = Tᵀ h_tree``.
    configuration_coupling : (nq_tree, nq) array or None
        The same map on configurations, ``q_tree = P q + c_q``: ``T``'s entries placed at the
        joints' configuration indices, and a quaternion joint's entries (a free flyer's
        position and quaternion, a ball joint's quaternion) copied; ``P = T`` without
        quaternion joints.
    coupling_offset : (nq_tree,) array or None
        ``c_q`` of that map [rad or m]: the followers' offsets.
    """

    name: str
    body_names: tuple[str, ...]
    joint_of_body: tuple[str, ...]
    joint_names: tuple[str, ...]
    parent: np.ndarray
    joint_type: np.ndarray
    q_index: np.ndarray
    axis: np.ndarray
    lead: np.ndarray
    origin_rotation: np.ndarray
    origin_translation: np.ndarray
    mass: np.ndarray
    com: np.ndarray
    inertia: np.ndarray
    gravity: np.ndarray
    numbers: Numbers = FLOAT64
    joint_places: tuple[QuaternionJoint, ...] = ()
    quaternion_bodies: tuple[int, ...] = ()
    tree_joint_names: tuple[str, ...] = ()
    coupling: np.ndarray | None = None
    configuration_coupling: np.ndarray | None = None
    coupling_offset: np.ndarray | None = None

    @property
    def n(self) -> int:
        """Number of degrees of freedom (NV: the length of ``qd``; of ``q`` too without
        quaternion joints)."""
        return len(self.joint_names)

    @property
    def n_tree(self) -> int:
        """Number of the tree's movable joints: :attr:`n`, plus the followers of couplings."""
        return len(self.tree_joint_names) or self.n

    @property
    def nq(self) -> int:
        """Length of the configuration ``q`` (NQ): :attr:`n`, plus one per quaternion joint."""
        return self.n + sum(j.nq - j.nv for j in self.joint_places)

    @property
    def chart_places(self) -> tuple[QuaternionJoint, ...]:
        """The joints whose configuration is not their coordinates (``nq != nv``), with their
        places in ``q`` and ``v``, in velocity order; empty without them."""
        return tuple(place for place in self.joint_places if place.nq != place.nv)

    @property
    def nb(self) -> int:
        """Number of bodies (links, root included)."""
        return len(self.body_names)


def _number(numbers: Numbers, x, what: str):
    try:
        return numbers.convert(x)
    except TypeError:
        raise ValueError(f"{what} is not a number after substitution: {x}") from None


def _vec(numbers: Numbers, v, what: str) -> np.ndarray:
    return np.array([_number(numbers, x, what) for x in v], dtype=numbers.dtype)


def _mat(numbers: Numbers, m, what: str) -> np.ndarray:
    return np.array([[_number(numbers, x, what) for x in row] for row in m], dtype=numbers.dtype)


def configuration_map(model: RobotModel, numbers: Numbers = FLOAT64
                      ) -> tuple[np.ndarray, np.ndarray]:
    """``(P, c_q)`` with ``q_tree = P q + c_q`` (:attr:`NumericModel.configuration_coupling`):
    :func:`eomgen.model.full_configuration` of the coupled ``model`` (affine in ``q``) as a
    matrix and an offset of ``numbers``; ``P = T`` of :func:`eomgen.model.coupling_map`
    without quaternion joints."""
    zero = [sp.Integer(0)] * model.nq
    offset = full_configuration(model, zero)
    columns = []
    for k in range(model.nq):
        unit = list(zero)
        unit[k] = sp.Integer(1)
        columns.append([a - b for a, b in zip(full_configuration(model, unit), offset)])
    P = _mat(numbers, [list(row) for row in zip(*columns)], "coupling gain")
    return P, _vec(numbers, offset, "coupling offset")


def numeric_model(model: RobotModel, values: Mapping | None = None,
                  numbers: Numbers = FLOAT64) -> NumericModel:
    """Build the numeric description of ``model``.

    Parameters
    ----------
    model : RobotModel
        The robot; its expressions may contain parameter symbols.
    values : mapping, optional
        Parameter values overriding the model's defaults, keyed by SymPy symbol or by
        parameter name.
    numbers : Numbers, optional
        The number type of the arrays (and of every algorithm's results): float64 by default.

    Returns
    -------
    NumericModel

    Raises
    ------
    eomgen.DescriptionError
        When a parameter has neither a default nor a given value.
    ValueError
        When a quantity is still not a real number after substitution.
    """
    values = {
        (parameter_symbol(k) if isinstance(k, str) else k): v for k, v in (values or {}).items()
    }
    model = model.with_numeric_parameters(values)
    order = model.topological_joints
    names = (model.root,) + tuple(j.child for j in order)
    index = {name: i for i, name in enumerate(names)}
    q_of_joint = {j.name: k for k, j in enumerate(model.movable_joints)}
    nb = len(names)

    parent = np.full(nb, -1, dtype=np.int64)
    joint_type = np.full(nb, FIXED, dtype=np.int64)
    q_index = np.full(nb, -1, dtype=np.int64)
    axis = numbers.zeros((nb, 3))
    axis[:, 2] = numbers.value(1)
    lead = numbers.zeros(nb)
    rot = numbers.zeros((nb, 3, 3))
    rot[:] = numbers.eye(3)
    trans = numbers.zeros((nb, 3))
    for i, joint in enumerate(order, start=1):
        where = f"joint '{joint.name}'"
        parent[i] = index[joint.parent]
        joint_type[i] = _type_code(joint.type.kind)
        q_index[i] = q_of_joint.get(joint.name, -1)
        axis[i] = _vec(numbers, joint.axis, where + " axis")
        lead[i] = _number(numbers, joint.lead, where + " pitch")
        rot[i] = _mat(numbers, joint.origin.rotation, where + " origin")
        trans[i] = _vec(numbers, joint.origin.translation, where + " origin")

    mass = numbers.zeros(nb)
    com = numbers.zeros((nb, 3))
    inertia = numbers.zeros((nb, 3, 3))
    for i, name in enumerate(names):
        inertial = model.link_by_name[name].inertial
        if inertial is None:
            continue
        where = f"link '{name}' inertial"
        mass[i] = _number(numbers, inertial.mass, where)
        com[i] = _vec(numbers, inertial.com, where)
        inertia[i] = _mat(numbers, inertial.inertia, where)

    arrays = dict(parent=parent, joint_type=joint_type, q_index=q_index, axis=axis, lead=lead,
                  origin_rotation=rot, origin_translation=trans, mass=mass, com=com,
                  inertia=inertia, gravity=_vec(numbers, model.gravity, "gravity"))
    for a in arrays.values():
        if not numbers.all_finite(a):
            raise ValueError(f"model '{model.name}' has a non-finite quantity")
        a.flags.writeable = False
    tree = uncoupled(model)
    places = tree.joint_places
    charts = [place for place in places if place.nq != place.nv]
    coupling = {}
    if model.couplings:
        T = _mat(numbers, coupling_map(model)[0].tolist(), "coupling gain")
        P, c = configuration_map(model, numbers)
        coupling = dict(coupling=T, configuration_coupling=P, coupling_offset=c)
        for a in coupling.values():
            a.flags.writeable = False
    return NumericModel(
        name=model.name,
        body_names=names,
        joint_of_body=("",) + tuple(j.name for j in order),
        joint_names=model.joint_names,
        numbers=numbers,
        joint_places=places,
        quaternion_bodies=tuple(int(np.flatnonzero(q_index == j.v_index)[0]) for j in charts),
        tree_joint_names=tuple(j.name for j in model.movable_joints),
        **coupling,
        **arrays,
    )


__all__ = ["FIXED", "FLOAT64", "HELICAL", "Numbers", "NumericModel", "PRISMATIC", "REVOLUTE",
           "TURNING",
           "configuration_map", "numeric_model"]
