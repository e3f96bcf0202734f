"""What a compiled MuJoCo model holds besides its tree and its actuators
(:mod:`eomgen.parsers.mjcf.actuators`): the fixed tendons, the gravity compensation, the
equalities, and the findings warned about (or refused) by name: free joints' springs, spatial
tendons, the actuators not read, equality constraints, fluid forces (:mod:`eomgen.parsers.mjcf`).

Each equality kind has its reader in :data:`EQUALITY_READERS`: a first-order ``joint``
equality is a coupling (:class:`~eomgen.model.Coupling`) or, without a second joint, a locked
joint (:class:`JointLock`), and so is a first-order ``tendon`` equality between fixed
tendons; ``connect`` is a point loop and ``weld`` a weld loop (:class:`~eomgen.model.Loop`); a
``joint`` equality of higher order is refused; an inactive equality, a flex one, a ``tendon``
one of higher order or on a spatial tendon is a notice.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Callable, NamedTuple, Union

import numpy as np

from ...errors import UnsupportedError
from ...model import (
    POINT_LOOP,
    WELD as WELD_LOOP,
    Coupling,
    Loop,
    LoopFrame,
    Notice,
    RobotModel,
    Tendon,
    Transform,
    lock_joints,
    make_coupling,
    scalar,
    vec3,
    with_couplings,
)
from .actuators import TRN_TENDON, actuator_notices
from .tree import (FREE, HINGE, SLIDE, actuator_inertia, body_names, disabled, element_name,
                   is_fixed, joint_names, not_modelled, rotation_of_quaternion, tendon_joints)

#: MuJoCo's equality types (``mjtEq``) and wrap type of a joint in a fixed tendon.
CONNECT, WELD, JOINT, TENDON = 0, 1, 2, 3
_WRAP_JOINT = 1
#: MuJoCo's object type of a site (``mjOBJ_SITE``): an equality between two sites.
_OBJ_SITE = 6

_NOT_READ = "not read yet: the model is the tree without it"


def model_notices(m, source: str) -> tuple[Notice, ...]:
    """The findings about ``m`` eomgen warns about (or refuses under ``strict``), in this
    order: free joints' springs, spatial tendons, actuators other than motors, equalities, fluid forces,
    gravity compensation routed through the actuators (``actuatorgravcomp``).

    Raises
    ------
    UnsupportedError
        A ``joint`` equality of order above one.
    """
    jnames = joint_names(m)
    notices: list[Notice] = []
    if not disabled(m, "SPRING"):
        for j in range(m.njnt):
            k = float(m.jnt_stiffness[j])
            if k and int(m.jnt_type[j]) == FREE:
                notices.append(not_modelled(source, f"joint '{jnames[j]}' stiffness",
                                       f"the spring {k:g} of a free joint is not modelled",
                                       "left out", joints=(jnames[j],)))
    for j in range(m.njnt):
        if int(m.jnt_type[j]) == FREE and float(m.dof_armature[int(m.jnt_dofadr[j])]):
            notices.append(not_modelled(source, f"joint '{jnames[j]}' (free) armature",
                                   "MuJoCo's armature acts on the world-frame linear velocity "
                                   "of a free joint, eomgen's on the body-frame one (the same "
                                   "M + a I, a bias a (omega x v) apart)",
                                   "read on eomgen's coordinates", joints=(jnames[j],)))
    for t in range(m.ntendon):
        joints = tendon_joints(m, t)
        where = f"tendon '{element_name(m, 'tendon', t)}'"
        if not is_fixed(m, t):
            notices.append(not_modelled(source, where, "a spatial tendon is not modelled (its "
                                   "spring, damping and the actuators on it)", "left out",
                                   joints=tuple(jnames[j] for j, _ in joints)))
            continue
        armature = getattr(m, "tendon_armature", np.zeros(m.ntendon))[t]
        for attribute, value in (("armature", armature + actuator_inertia(m, t, (TRN_TENDON,))[0]),
                                 ("frictionloss", m.tendon_frictionloss[t])):
            if float(value):
                notices.append(not_modelled(source, f"{where} {attribute}", f"a tendon's "
                                       f"{attribute} is not modelled", "left out",
                                       joints=tuple(jnames[j] for j, _ in joints)))
    notices += actuator_notices(m, source)
    notices += _array_notices(m, source)
    notices += [found for found in equalities(m, source) if isinstance(found, Notice)]
    if m.opt.density or m.opt.viscosity:
        notices.append(not_modelled(source, "option density, viscosity",
                               "fluid forces are not modelled", "left out"))
    if gravity_compensation(m):
        for j in range(m.njnt):
            if bool(m.jnt_actgravcomp[j]):
                notices.append(not_modelled(
                    source, f"joint '{jnames[j]}' actuatorgravcomp", "its gravity "
                    "compensation is in tau_p, not in the actuator forces (MuJoCo's "
                    "qfrc_actuator, where the joint's actuatorfrcrange would clamp it; MuJoCo 4.0 "
                    "drops it in a model without actuators)",
                    "added to the passive forces", joints=(jnames[j],)))
    return tuple(notices)


def gravity_compensation(m) -> tuple[tuple[str, float], ...]:
    """``(body, gravcomp)`` of each body of ``m`` with gravity compensation (MuJoCo's
    ``qfrc_gravcomp``, :attr:`~eomgen.model.RobotModel.gravcomp`); none when gravity is
    disabled or the ``spring`` and ``damper`` flags both are (MuJoCo then skips every
    passive force)."""
    if disabled(m, "GRAVITY") or (disabled(m, "SPRING") and disabled(m, "DAMPER")):
        return ()
    names = body_names(m)
    return tuple((names[b], float(m.body_gravcomp[b])) for b in range(1, m.nbody)
                 if float(m.body_gravcomp[b]))


#: MuJoCo 4's per-element arrays eomgen does not model: ``(array, element, what it adds)``.
_NOT_MODELLED = (("jnt_stiffnesspoly", "joint", "a nonlinear (polynomial) spring"),
                 ("dof_dampingpoly", "dof", "nonlinear (polynomial) damping"),
                 ("tendon_stiffnesspoly", "tendon", "a nonlinear (polynomial) spring"),
                 ("tendon_dampingpoly", "tendon", "nonlinear (polynomial) damping"),
                 ("actuator_dampingpoly", "actuator", "nonlinear (polynomial) damping"),
                 ("actuator_delay", "actuator", "a control delay"))


def _array_notices(m, source: str) -> list[Notice]:
    """One notice per array of :data:`_NOT_MODELLED` with a nonzero entry, naming the first
    three elements (a dof by its joint)."""
    out = []
    for array, kind, what in _NOT_MODELLED:
        values = getattr(m, array, None)
        found = [] if values is None else [i for i in range(len(values)) if np.any(values[i])]
        if not found:
            continue
        element = "joint" if kind == "dof" else kind
        names = list(dict.fromkeys(
            element_name(m, "joint", int(m.dof_jntid[i])) if kind == "dof"
            else element_name(m, kind, i)
            for i in found))
        shown = ", ".join(f"'{n}'" for n in names[:3]) + (", ..." if len(names) > 3 else "")
        out.append(not_modelled(source, f"{element} {shown} {array.split('_', 1)[1]}",
                           f"{what} is not modelled", "left out"))
    return out


def fixed_tendons(m) -> tuple[Tendon, ...]:
    """The fixed tendons of ``m`` that pull (a stiffness or a damping): ``L = Σ c_i q_i``
    (``wrap_prm`` the coefficients), the rest lengths ``tendon_lengthspring`` (a dead band
    since MuJoCo 3; both ends the one length otherwise), ``tendon_stiffness`` (0 when the
    ``spring`` flag is disabled) and ``tendon_damping`` with the ``damping`` of the actuators
    on the tendon times ``gear²`` (0 when ``damper`` is)."""
    jnames = joint_names(m)
    out = []
    for t in range(m.ntendon):
        k = 0.0 if disabled(m, "SPRING") else float(m.tendon_stiffness[t])
        b = 0.0 if disabled(m, "DAMPER") else (float(m.tendon_damping[t])
                                               + actuator_inertia(m, t, (TRN_TENDON,))[1])
        if not is_fixed(m, t) or not (k or b):
            continue
        rest = np.atleast_1d(np.asarray(m.tendon_lengthspring[t], dtype=float))
        out.append(Tendon(element_name(m, "tendon", t), tuple((jnames[j], c) for j, c in
                                                       tendon_joints(m, t)),
                          k, (float(rest[0]), float(rest[-1])), b))
    return tuple(out)


def with_tendons(model: RobotModel, m, source: str) -> RobotModel:
    """``model`` (the tree of ``m``) with its fixed tendons (:func:`fixed_tendons`); one on
    a dropped free body's joints goes with it, one joining such a joint to a kept one is a
    notice."""
    present = {joint.name for joint in model.joints}
    tendons, notices = [], []
    for tendon in fixed_tendons(m):
        names = [name for name, _ in tendon.coefficients]
        kept = tuple(n for n in names if n in present)
        if len(kept) == len(names):
            tendons.append(tendon)
        elif kept:
            notices.append(not_modelled(source, f"tendon '{tendon.name}'", "it joins a dropped free "
                                   "body", "left out", joints=kept))
    return replace(model, tendons=tuple(tendons), notices=tuple(model.notices) + tuple(notices))


def _equality_where(m, e: int, kind: str) -> str:
    inactive = "" if bool(m.eq_active0[e]) else ", inactive"
    return f"equality '{element_name(m, 'eq', e)}' ({kind}{inactive})"


def _equality_bodies(m, e: int) -> tuple[str, ...]:
    return tuple(element_name(m, "body", int(b)) for b in m.eq_obj1id[e:e + 1].tolist()
                 + m.eq_obj2id[e:e + 1].tolist() if int(b) > 0)


def equality_connect(m, e: int, source: str) -> Union[Loop, Notice]:
    """A ``connect`` equality: the point loop ``<name>`` (3 rows, world axes) holding the
    anchor on ``body1`` (frame b, ``eq_data[0:3]`` in body1's frame) on the same point of
    ``body2`` (frame a, ``eq_data[3:6]``, where the compiler put it at ``qpos0``): ``Φ = p_1 −
    p_2``, MuJoCo's own residual and rows, and λ the force on body1 (MuJoCo's
    ``efc_force``). Between sites, the two sites' origins."""
    where = _equality_where(m, e, "connect")
    if not bool(m.eq_active0[e]):
        return _inactive(m, e, source, where)
    data = m.eq_data[e]
    one, two = (_site_frame(m, e, k) if int(m.eq_objtype[e]) == _OBJ_SITE
                else _body_frame(m, e, k, data[3 * k:3 * k + 3]) for k in (0, 1))
    return Loop(element_name(m, "eq", e), POINT_LOOP, two, one)


def equality_weld(m, e: int, source: str) -> Union[Loop, Notice]:
    """A ``weld`` equality: the weld loop ``<name>`` (6 rows, world axes) holding frame b on
    ``body1`` (origin ``eq_data[3:6]``, axes ``relpose``, ``eq_data[6:10]``) on frame a on
    ``body2`` (origin the ``anchor``, ``eq_data[0:3]``): MuJoCo's ``R_1 · relpose = R_2`` and
    its anchor; λ acts on body1. ``torquescale="0"`` leaves the rotation free: a point loop.
    Between sites, the two site frames."""
    where = _equality_where(m, e, "weld")
    if not bool(m.eq_active0[e]):
        return _inactive(m, e, source, where)
    data = m.eq_data[e]
    if int(m.eq_objtype[e]) == _OBJ_SITE:
        one, two = _site_frame(m, e, 0), _site_frame(m, e, 1)
    else:
        one = _body_frame(m, e, 0, data[3:6], rotation_of_quaternion(data[6:10]))
        two = _body_frame(m, e, 1, data[0:3])
    kind = WELD_LOOP if float(data[10]) else POINT_LOOP
    return Loop(element_name(m, "eq", e), kind, two, one)


def _inactive(m, e: int, source: str, where: str) -> Notice:
    return not_modelled(source, where, "an inactive equality is not modelled (MuJoCo enforces it "
                   "only once switched on)", "left out", links=_equality_bodies(m, e))


def _body_frame(m, e: int, k: int, anchor, rotation=None) -> LoopFrame:
    """Equality ``e``'s frame on its body ``k`` (0: body1, 1: body2) at ``anchor`` [m] in
    the body frame, with axes ``rotation`` (the body's when None)."""
    body = int((m.eq_obj1id if k == 0 else m.eq_obj2id)[e])
    return LoopFrame(body_names(m)[body], _pose(anchor, rotation))


def _site_frame(m, e: int, k: int) -> LoopFrame:
    site = int((m.eq_obj1id if k == 0 else m.eq_obj2id)[e])
    return LoopFrame(body_names(m)[int(m.site_bodyid[site])],
                     _pose(m.site_pos[site], rotation_of_quaternion(m.site_quat[site])))


def _pose(anchor, rotation) -> Transform:
    if rotation is None:
        return Transform(translation=vec3(float(v) for v in anchor))
    return Transform(tuple(tuple(scalar(float(v)) for v in row) for row in rotation),
                     vec3(float(v) for v in anchor))


class JointLock(NamedTuple):
    """A joint held at ``position`` [rad or m] by a ``joint`` equality without a second
    joint (``element`` names it)."""

    joint: str
    position: float
    element: str


def equality_joint(m, e: int, source: str) -> Union[Coupling, JointLock, Notice]:
    """A ``joint`` equality, MuJoCo's ``q1 − ref1 = c0 + c1 (q2 − ref2)`` (``polycoef``
    ``c0 … c4``, the refs the joints' ``ref``, MuJoCo's ``qpos0``): first-order, the coupling
    ``q1 = c1 q2 + (ref1 + c0 − c1 ref2)`` (eomgen's ``q`` is MuJoCo's ``qpos``); without
    ``joint2`` (or with ``c1 = 0``) the lock ``q1 = ref1 + c0``; inactive (``active="false"``),
    a notice (MuJoCo does not enforce it unless it is switched on).

    Raises
    ------
    UnsupportedError
        A polynomial of order above one; a joint that is not a hinge or a slide.
    """
    jnames = joint_names(m)
    where = _equality_where(m, e, "joint")
    coefficients = [float(c) for c in m.eq_data[e, :5]]
    order = max((k for k, c in enumerate(coefficients) if c), default=0)
    if order > 1:
        raise UnsupportedError(source, where, f"a joint equality of order {order} (polycoef "
                               f"{' '.join(f'{c:g}' for c in coefficients)}): only first-order "
                               "couplings q1 = c0 + c1 q2 are read")
    ids = [int(m.eq_obj1id[e])] + ([int(m.eq_obj2id[e])] if int(m.eq_obj2id[e]) >= 0 else [])
    for j in ids:
        if int(m.jnt_type[j]) not in (HINGE, SLIDE):
            raise UnsupportedError(source, where, f"joint '{jnames[j]}' is not a hinge or a "
                                   "slide: only one-axis joints are coupled")
    joints = tuple(jnames[j] for j in ids)
    if not bool(m.eq_active0[e]):
        return replace(_inactive(m, e, source, where), links=(), joints=joints)
    ref = [float(m.qpos0[int(m.jnt_qposadr[j])]) for j in ids]
    c0, c1 = coefficients[:2]
    if len(ids) == 1 or c1 == 0:
        return JointLock(joints[0], ref[0] + c0, where)
    return make_coupling(joints[0], {joints[1]: c1}, ref[0] + c0 - c1 * ref[1], where)


def equality_tendon(m, e: int, source: str) -> Union[Coupling, JointLock, Notice]:
    """A ``tendon`` equality between fixed tendons, MuJoCo's ``L1 − L1_0 = c0 + c1 (L2 −
    L2_0)`` (``L_0`` the lengths at ``qpos0``, ``tendon_length0``; ``L = Σ a_i q_i``): first
    order, the coupling of the first joint ``f`` of tendon1, ``q_f = (L1_0 + c0 − c1 L2_0 −
    Σ_{i≠f} a_i q_i + c1 Σ b_j q_j) / a_f``, or its lock when no other joint is left; a spatial
    tendon's, one of higher order or an inactive one, a notice.
    """
    jnames = joint_names(m)
    where = _equality_where(m, e, "tendon")
    ids = [int(m.eq_obj1id[e])] + ([int(m.eq_obj2id[e])] if int(m.eq_obj2id[e]) >= 0 else [])
    coefficients = [float(c) for c in m.eq_data[e, :5]]
    order = max((k for k, c in enumerate(coefficients) if c), default=0)
    joints = tuple(jnames[j] for t in ids for j, _ in tendon_joints(m, t))
    if not all(is_fixed(m, t) for t in ids) or order > 1:
        why = "a spatial tendon's" if order <= 1 else f"an order {order}"
        return not_modelled(source, where, f"{why} equality is not modelled: the model is the tree "
                       "without it", joints=joints)
    if not bool(m.eq_active0[e]):
        return replace(_inactive(m, e, source, where), links=(), joints=joints)
    c0, c1 = coefficients[:2]
    gains: dict[int, float] = {}
    for j, a in tendon_joints(m, ids[0]):
        gains[j] = gains.get(j, 0.0) + a
    rhs = float(m.tendon_length0[ids[0]]) + c0
    if len(ids) > 1 and c1:
        rhs -= c1 * float(m.tendon_length0[ids[1]])
        for j, b in tendon_joints(m, ids[1]):
            gains[j] = gains.get(j, 0.0) - c1 * b
    follower = next((j for j, _ in tendon_joints(m, ids[0]) if gains[j]), None)
    if follower is None:
        return not_modelled(source, where, "the equality moves no joint of tendon1", joints=joints)
    a_f = gains.pop(follower)
    leaders = {jnames[j]: -g / a_f for j, g in gains.items() if g}
    if not leaders:
        return JointLock(jnames[follower], rhs / a_f, where)
    return make_coupling(jnames[follower], leaders, rhs / a_f, where)


def other_equality(m, e: int, source: str) -> Notice:
    """A flex or distance equality: not modelled."""
    kinds = {TENDON: "tendon", 4: "flex", 5: "flexvert", 6: "flexstrain", 7: "distance"}
    return not_modelled(source, _equality_where(m, e, kinds.get(int(m.eq_type[e]), "other")),
                   "this equality is not modelled: the model is the tree without it")


#: The reader of each equality kind (MuJoCo's ``mjtEq`` code): what the equality is in
#: eomgen's model (a coupling, a locked joint), or the notice that it is not modelled.
EQUALITY_READERS: dict[int, Callable[..., Union[Coupling, JointLock, Notice]]] = {
    CONNECT: equality_connect, WELD: equality_weld, JOINT: equality_joint,
    TENDON: equality_tendon}


def equalities(m, source: str) -> list:
    """What each equality of ``m`` is (:data:`EQUALITY_READERS`), in MuJoCo's order."""
    return [EQUALITY_READERS.get(int(m.eq_type[e]), other_equality)(m, e, source)
            for e in range(m.neq)]


def with_equalities(model: RobotModel, m, source: str) -> RobotModel:
    """``model`` (the tree of ``m``) with its equalities: the couplings of ``joint``
    equalities (a chain of them, ``q3`` following ``q2`` following ``q1``, written in the
    independent joints), the locked joints (``model.info["mujoco_locks"]``: ``(joint,
    position)`` pairs, for :func:`eomgen.parsers.mjcf.convert.layout`) and the loops of
    ``connect`` and ``weld`` (:attr:`~eomgen.model.RobotModel.loops`, in MuJoCo's order). An
    equality on a dropped free body's joints or bodies is left out with that body; one
    joining such a joint or body to a kept one is a notice.

    Raises
    ------
    KinematicTreeError
        Two equalities on one follower, a cycle of them (:func:`eomgen.model.check_couplings`),
        a joint locked against its coupling.
    """
    present = {joint.name for joint in model.joints} | {link.name for link in model.links}
    couplings, locks, loops, notices = [], {}, [], []
    for found in equalities(m, source):
        if isinstance(found, Notice):
            continue  # in model_notices
        if isinstance(found, Loop):
            names, element = (found.a.link, found.b.link), f"equality '{found.name}'"
        elif isinstance(found, JointLock):
            names, element = (found.joint,), found.element
        else:
            names = (found.follower,) + tuple(name for name, _ in found.leaders)
            element = found.where
        if not any(name in present for name in names):
            continue
        if not all(name in present for name in names):
            kept = tuple(n for n in names if n in present)
            notices.append(not_modelled(source, element, "it joins a dropped free body", "left out",
                                   **({"links": kept} if isinstance(found, Loop)
                                      else {"joints": kept})))
        elif isinstance(found, Loop):
            loops.append(found)
        elif isinstance(found, JointLock):
            locks[found.joint] = found.position
        else:
            couplings.append(found)
    model = with_couplings(model, _resolved(couplings)) if couplings else model
    if locks:
        model = replace(lock_joints(model, locks), info=model.info + (
            ("mujoco_locks", tuple(locks.items())),))
    return replace(model, loops=tuple(loops), notices=tuple(model.notices) + tuple(notices))


def _resolved(couplings: list[Coupling]) -> list[Coupling]:
    """``couplings`` with each leader that follows another coupling replaced by its own
    leaders (MuJoCo allows chains of joint equalities, eomgen's couplings name independent
    joints); a cycle is left for :func:`eomgen.model.check_couplings` to refuse."""
    by_follower = {c.follower: c for c in couplings}
    out = []
    for coupling in couplings:
        seen = {coupling.follower}
        while any(name in by_follower and name not in seen for name, _ in coupling.leaders):
            leaders: dict = {}
            offset = coupling.offset
            for name, gain in coupling.leaders:
                inner = by_follower.get(name)
                if inner is None or name in seen:
                    leaders[name] = leaders.get(name, 0) + gain
                    continue
                seen.add(name)
                offset += gain * inner.offset
                for leader, k in inner.leaders:
                    leaders[leader] = leaders.get(leader, 0) + gain * k
            coupling = replace(coupling, leaders=tuple(leaders.items()), offset=offset)
        out.append(coupling)
    return out
