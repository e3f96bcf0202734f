"""Every number eomgen takes from a compiled MuJoCo model, held to the rule for numbers in
descriptions (:mod:`eomgen.model.numbers`: finite, magnitude at most 1e12) before anything is
built from it.

MuJoCo's compiler reads ``nan``, ``inf`` and ``1e300`` where the file has them (it warns at
most), and derives others from them (a body's mass and inertia from its geoms, a quaternion
from ``euler``): so the compiled arrays are checked, each named by its MJCF element and the
attribute it comes from. What eomgen does not read (joint ranges, geoms' friction, contact and
rendering options, sensors) is not checked.
"""

from __future__ import annotations

from typing import Iterator

from ...errors import InvalidNumberError
from ...model.numbers import number_problem
from .actuators import is_control
from .tree import BALL, FREE, HINGE, SLIDE, actuator_count, body_names, joint_names

#: MuJoCo's equality types read by eomgen (``mjtEq``) and the ``eq_data`` entries each uses.
_EQUALITY_DATA = {0: (6, "connect", "anchor"), 1: (11, "weld", "anchor, relpose or torquescale"),
                  2: (5, "joint", "polycoef")}
_OBJ_SITE = 6


def _name(m, kind: str, i: int) -> str:
    return getattr(m, kind)(i).name or f"{kind}{i}"


def compiled_numbers(m) -> Iterator[tuple[str, str, object]]:
    """``(element, attribute, value)`` for every number of ``m`` (a ``mujoco.MjModel``) that
    eomgen reads, in MuJoCo's order: the option's gravity, bodies, joints and their dofs,
    equalities (and the sites they join), motors on hinge and slide joints."""
    yield "option", "gravity", m.opt.gravity
    bodies = body_names(m)
    for b in range(1, m.nbody):
        where = f"body '{bodies[b]}'"
        yield where, "pos", m.body_pos[b]
        yield where, "orientation (quat, euler, axisangle, xyaxes or zaxis)", m.body_quat[b]
        compiled = "(of its <inertial> or its geoms)"
        yield where, f"mass {compiled}", m.body_mass[b]
        yield where, f"centre of mass {compiled}", m.body_ipos[b]
        yield where, f"inertia {compiled}", m.body_inertia[b]
        yield where, f"inertia axes {compiled}", m.body_iquat[b]
        yield where, "gravcomp", m.body_gravcomp[b]
    joints = joint_names(m)
    for j in range(m.njnt):
        where = f"joint '{joints[j]}'"
        kind = int(m.jnt_type[j])
        if kind != FREE:
            yield where, "pos", m.jnt_pos[j]
        if kind in (HINGE, SLIDE):
            yield where, "axis", m.jnt_axis[j]
            yield where, "ref", m.qpos0[int(m.jnt_qposadr[j])]
            yield where, "springref", m.qpos_spring[int(m.jnt_qposadr[j])]
        yield where, "stiffness", m.jnt_stiffness[j]
        dofs = {FREE: 6, BALL: 3}.get(kind, 1)
        start = int(m.jnt_dofadr[j])
        for attribute, array in (("armature", m.dof_armature), ("damping", m.dof_damping),
                                 ("frictionloss", m.dof_frictionloss)):
            yield where, attribute, array[start:start + dofs]
    for e in range(m.neq):
        kind = int(m.eq_type[e])
        if kind not in _EQUALITY_DATA:
            continue
        count, name, attribute = _EQUALITY_DATA[kind]
        yield f"equality '{_name(m, 'eq', e)}' ({name})", attribute, m.eq_data[e, :count]
        if kind != 2 and int(m.eq_objtype[e]) == _OBJ_SITE:
            for site in (int(m.eq_obj1id[e]), int(m.eq_obj2id[e])):
                yield f"site '{_name(m, 'site', site)}'", "pos", m.site_pos[site]
                yield f"site '{_name(m, 'site', site)}'", "orientation", m.site_quat[site]
    for i in (i for i in range(actuator_count(m)) if is_control(m, i)):  # the others are not read
        where = f"actuator '{_name(m, 'actuator', i)}'"
        yield where, "gear", m.actuator_gear[i, 0]
        yield where, "gainprm", m.actuator_gainprm[i, :3]
        yield where, "biasprm", m.actuator_biasprm[i, :3]
        yield where, "ctrlrange", m.actuator_ctrlrange[i]
        yield where, "forcerange", m.actuator_forcerange[i]
        yield where, "dynprm", m.actuator_dynprm[i, :2]


def check_compiled(m, source: str) -> None:
    """Refuse the first number of :func:`compiled_numbers` that is not finite or of magnitude
    above 1e12: an :class:`~eomgen.errors.InvalidNumberError` naming ``source``, the element,
    the attribute and the value MuJoCo compiled (angles in radians, a mass from the geoms)."""
    for where, attribute, values in compiled_numbers(m):
        for value in (values.ravel().tolist() if hasattr(values, "ravel") else [values]):
            problem = number_problem(float(value))
            if problem is not None:
                raise InvalidNumberError(source, where, f"{attribute} {problem}: MuJoCo compiled "
                                         f"it to {float(value):g}")
