"""Coupled joints: a follower joint whose position is an affine function of other joints'.

A :class:`Coupling` says ``q_follower = Σ_l k_l q_leader_l + c`` (a URDF ``<mimic>``:
one leader, ``k`` its ``multiplier``, ``c`` its ``offset``; a scene's ``couplings``: a
differential's linear relation). A model keeps the *independent* coordinates only: its
``joint_names`` (``JOINT_NAMES``) are its movable joints less the followers, in description
order, and ``dof`` counts them. The followers stay in the kinematic tree (``movable_joints``).

With every follower written in its leaders' coordinates, the whole joint vector is the affine
map of the independent one (:func:`coupling_map`)::

    q_full = T q + c,    q̇_full = T q̇,    q̈_full = T q̈       (T: n_full × n, constant)

and the dynamics in the independent coordinates are exact: ``M_r = Tᵀ M T``, ``C_r = Tᵀ C T``
(the Christoffel symbols of the reduced Lagrangian, C evaluated at ``q̇_full = T q̇``),
``g_r = Tᵀ g``, ``τ_r = Tᵀ τ`` (the efforts on the independent joints equivalent, by virtual
work, to the efforts on all of them), Jacobians ``J T``.

Rules, each refused with a one-line error naming the element: a coupling names movable joints
of the model only (not fixed, not missing), a follower is coupled once and leads no other
coupling (no chains, no cycles), a joint never follows itself.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Mapping, Sequence

import sympy as sp

from ..common import reprs
from ..errors import KinematicTreeError, UnsupportedError
from .joints import KINDS
from .scalars import scalar


@dataclass(frozen=True)
class Coupling:
    """``q[follower] = Σ gain · q[leader] + offset`` (rad or m; gains in rad/rad, m/m, m/rad
    or rad/m as the joints' kinds make them).

    Attributes
    ----------
    follower:
        The joint whose position is given by the others (not an independent coordinate).
    leaders:
        ``(joint, gain)`` pairs, the leaders being independent movable joints.
    offset:
        The follower's position when every leader is at 0 [rad or m].
    element:
        Where the coupling was declared (``"joint 'x' <mimic>"``, ``"couplings[0]"``), for
        error messages; no part of comparing couplings.
    """

    __repr__ = reprs.field_repr  # its numbers as short as they read back

    follower: str
    leaders: tuple[tuple[str, sp.Expr], ...]
    offset: sp.Expr = sp.Integer(0)
    element: str = field(default="", compare=False)

    @property
    def where(self) -> str:
        return self.element or f"coupling of joint '{self.follower}'"


def make_coupling(follower: str, leaders: Mapping[str, object] | Sequence[tuple[str, object]],
                  offset=0, element: str = "") -> Coupling:
    """A :class:`Coupling` with gains and offset made SymPy numbers (floats kept as given)."""
    pairs = leaders.items() if isinstance(leaders, Mapping) else leaders
    return Coupling(follower, tuple((str(name), _number(k)) for name, k in pairs),
                    _number(offset), element)


def _number(value) -> sp.Expr:
    return value if isinstance(value, sp.Basic) else scalar(value)


def check_couplings(source: str, model, couplings: Sequence[Coupling]) -> None:
    """Refuse couplings that do not fit ``model`` (its joints and free flyer), one line naming
    ``source`` and the coupling's element (:attr:`Coupling.element`).

    Raises
    ------
    KinematicTreeError
        A joint that is not defined or not movable, a follower coupled twice, a coupling
        cycle, a follower that is itself a leader.
    UnsupportedError
        A coupling of a free flyer's or floating base's virtual joint.
    """
    joints = {j.name: j for j in model.joints}
    movable = {j.name for j in model.movable_joints}
    balls = {virtual: (KINDS[kind].describe()[0], name) for kind, name in model.compound_joints
             for virtual in KINDS[kind].velocity_names(name)}
    followers: dict[str, Coupling] = {}
    for coupling in couplings:
        where = coupling.where
        names = [coupling.follower] + [name for name, _ in coupling.leaders]
        if not coupling.leaders:
            raise KinematicTreeError(source, where, "a coupling needs at least one leader")
        for name in names:
            if name not in joints:
                raise KinematicTreeError(source, where, f"joint '{name}' is not defined")
            if name not in movable:
                raise KinematicTreeError(source, where, f"joint '{name}' is "
                                         f"{joints[name].type.value}: only movable joints "
                                         "can be coupled")
            if name in balls:
                raise UnsupportedError(source, where, f"joint '{name}' is a virtual joint of "
                                       f"{balls[name][0]} joint '{balls[name][1]}': only one-axis joints "
                                       "can be coupled")
        leaders = [name for name, _ in coupling.leaders]
        if len(set(leaders)) != len(leaders):
            raise KinematicTreeError(source, where, "a leader is listed twice")
        if coupling.follower in followers:
            raise KinematicTreeError(source, where, f"joint '{coupling.follower}' already "
                                     f"follows ({followers[coupling.follower].where})")
        followers[coupling.follower] = coupling
    for coupling in couplings:
        cycle = _cycle(coupling.follower, followers)
        if cycle:
            raise KinematicTreeError(source, coupling.where, "coupling cycle "
                                     + " -> ".join(f"'{n}'" for n in cycle))
    for coupling in couplings:
        for name, _ in coupling.leaders:
            if name in followers:
                raise KinematicTreeError(
                    source, coupling.where, f"leader '{name}' is itself a follower "
                    f"({followers[name].where}); couple '{coupling.follower}' to the "
                    "independent joints directly")


def _cycle(start: str, followers: dict[str, Coupling]) -> list[str]:
    """The joints of a cycle of leaders through ``start`` (``start`` at both ends), or []."""
    seen: set[str] = set()

    def walk(name: str, path: list[str]) -> list[str]:
        coupling = followers.get(name)
        for leader, _ in (coupling.leaders if coupling else ()):
            if leader == start:
                return path + [leader]
            if leader not in seen:
                seen.add(leader)
                found = walk(leader, path + [leader])
                if found:
                    return found
        return []

    return walk(start, [start])


def couple(model, follower: str, leader: str | Mapping[str, object], ratio=1, offset=0,
           element: str = ""):
    """A copy of ``model`` whose joint ``follower`` follows: ``q[follower] = ratio ·
    q[leader] + offset`` (or, with ``leader`` a mapping ``{joint: gain}``, the linear form
    ``Σ gain · q[joint] + offset``). The follower leaves ``joint_names``; the model keeps its
    earlier couplings.

    Parameters
    ----------
    model:
        A :class:`~eomgen.model.RobotModel`.
    follower, leader:
        Names of movable joints of ``model``.
    ratio, offset:
        The gain [rad/rad, m/m, ...] and the offset [rad or m].
    element:
        How errors name the coupling (default ``"coupling of joint '<follower>'"``).

    Raises
    ------
    KinematicTreeError, UnsupportedError
        As :func:`check_couplings`.

    Examples
    --------
    >>> import eomgen
    >>> arm = eomgen.load(eomgen.example_path("elbow_rrr"))
    >>> couple(arm, "elbow", "shoulder", ratio=-1).joint_names
    ('waist', 'shoulder')
    """
    leaders = {leader: ratio} if isinstance(leader, str) else dict(leader)
    if not isinstance(leader, str) and ratio != 1:
        raise ValueError("give the gains in the leader mapping, not as ratio")
    return with_couplings(model, model.couplings + (
        make_coupling(follower, leaders, offset, element),))


def with_couplings(model, couplings: Sequence[Coupling]):
    """A copy of ``model`` with exactly ``couplings`` (checked by :func:`check_couplings`)."""
    couplings = tuple(couplings)
    check_couplings(model.source, model, couplings)
    return replace(model, couplings=couplings)


def uncoupled(model):
    """``model`` with every follower read as an independent joint again (the whole tree's
    coordinates, ``T = 1``)."""
    return replace(model, couplings=()) if model.couplings else model


def coupling_map(model) -> tuple[sp.Matrix, sp.Matrix]:
    """``(T, c)`` with ``q_full = T q + c``: ``T`` is (number of movable joints) × ``dof``,
    rows in ``movable_joints`` order, columns in ``joint_names`` order; an independent joint's
    row is a unit row, a follower's its gains; ``c`` holds the followers' offsets."""
    full = [j.name for j in model.movable_joints]
    column = {name: k for k, name in enumerate(model.joint_names)}
    by_follower = {c.follower: c for c in model.couplings}
    T = sp.zeros(len(full), len(column))
    c = sp.zeros(len(full), 1)
    for row, name in enumerate(full):
        coupling = by_follower.get(name)
        if coupling is None:
            T[row, column[name]] = 1
            continue
        for leader, gain in coupling.leaders:
            T[row, column[leader]] += gain
        c[row] = coupling.offset
    return T, c


def full_configuration(model, q) -> tuple:
    """The whole tree's configuration (``uncoupled(model).nq`` entries) of the independent
    configuration ``q`` (``model.nq`` entries; SymPy or float entries): each independent
    joint's entry copied, each quaternion joint's block copied (a quaternion joint is never
    coupled), each follower ``Σ gain · q[leader] + offset``. Without quaternion joints this is
    ``T q + c`` of :func:`coupling_map`."""
    slots = dict((key, (index, size)) for key, index, size in _configuration_slots(model))
    by_follower = {c.follower: c for c in model.couplings}
    out: list = []
    for key, _, size in _configuration_slots(uncoupled(model)):
        coupling = by_follower.get(key)
        if coupling is None:
            start = slots[key][0]
            out.extend(q[start:start + size])
        else:
            out.append(sum((gain * q[slots[leader][0]] for leader, gain in coupling.leaders),
                           coupling.offset))
    return tuple(out)


def _configuration_slots(model) -> list[tuple[object, int, int]]:
    """Per coordinate, in ``q`` order: ``(key, index in q, entries in q)``, the key a joint
    name of ``joint_names`` or ``("quaternion", name)`` for a joint whose configuration is
    not its coordinates (:attr:`~eomgen.model.RobotModel.joint_places`)."""
    return [(place.name if place.nq == place.nv else ("quaternion", place.name),
             place.q_index, place.nq) for place in model.joint_places]


def locked_couplings(model, positions: Mapping[str, object]
                     ) -> tuple[dict[str, object], tuple[Coupling, ...]]:
    """What locking ``positions`` (joint: value) does to ``model``'s couplings:
    ``(positions, couplings)``, the positions completed with each follower whose leaders are
    all locked (at the value its coupling gives) and the couplings left, the locked leaders'
    terms folded into their offsets.

    Raises
    ------
    KinematicTreeError
        A follower locked while a leader of its coupling moves, or locked at a value its
        locked leaders contradict.
    """
    positions = dict(positions)
    kept = []
    for coupling in model.couplings:
        moving = tuple((n, k) for n, k in coupling.leaders if n not in positions)
        offset = coupling.offset + sum((k * _number(positions[n]) for n, k in coupling.leaders
                                        if n in positions), sp.Integer(0))
        follower = coupling.follower
        if moving:
            if follower in positions:
                raise KinematicTreeError(
                    model.source, f"joint '{follower}'", "cannot lock a coupled joint while "
                    f"its leader '{moving[0][0]}' moves ({coupling.where}): lock the leader")
            kept.append(replace(coupling, leaders=moving, offset=offset))
            continue
        if follower in positions:
            given = _number(positions[follower])
            difference = sp.N(given - offset)
            if not (difference.is_number and abs(float(difference)) <= 1e-9):
                raise KinematicTreeError(
                    model.source, f"joint '{follower}'", f"locked at {given}, but its coupling "
                    f"({coupling.where}) puts it at {offset} with the leaders' locked values")
        positions[follower] = offset
    return positions, tuple(kept)


__all__ = ["Coupling", "check_couplings", "couple", "coupling_map", "full_configuration",
           "locked_couplings",
           "make_coupling", "uncoupled", "with_couplings"]
