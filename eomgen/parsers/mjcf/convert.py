"""MuJoCo's arrays in eomgen's coordinates, for a model read from MJCF
(:mod:`eomgen.parsers.mjcf`): states both ways, and MuJoCo's own mass matrix, bias and passive
forces mapped onto eomgen's ``(q, v)`` (the independent reference of the MJCF tests).

Hinge and slide joints: eomgen's ``q`` and ``v`` entries *are* MuJoCo's ``qpos`` and ``qvel``
entries (same names, same values); only their order can differ, when the free joint is not
MuJoCo's first joint (the free flyer always comes first in eomgen).

A ball joint: MuJoCo's ``qpos`` block is ``(qw, qx, qy, qz)``, eomgen's
``(qx, qy, qz, qw)``; both take ``ω`` of the child in the child frame as the velocity.

The free joint: MuJoCo's ``qpos`` block is ``(x, y, z, qw, qx, qy, qz)``, eomgen's
``(x, y, z, qx, qy, qz, qw)``; MuJoCo's ``qvel`` block is ``(ṗ in world axes, ω in body
axes)``, eomgen's ``(Rᵀ ṗ, ω)`` (both in body axes). So ``v_mj = T(q) v`` with ``T`` the
identity but for the block ``R`` on the linear velocity; generalised forces map by the
transpose (virtual work): ``M = Tᵀ M_mj T``, ``h(q, v) = Tᵀ (bias_mj + M_mj Ṫ v)`` where
``Ṫ v`` is ``R (ω × Rᵀ ṗ)`` on the linear block, ``τ = Tᵀ qfrc`` (``M_mj`` of the rigid
bodies: armature excluded).

A free joint's ``armature`` ``a`` is MuJoCo's on *its* coordinates: ``Tᵀ (a I) T = a I``, so
eomgen's drive mass matrix is exact, but MuJoCo's equations then also hold ``a (ω × Rᵀ ṗ)`` on
the linear rows (``Tᵀ a Ṫ v``), which eomgen's drives (armature on each velocity coordinate) do
not: the parser warns when a free joint has armature.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...model import RobotModel, coupling_map, uncoupled
from .tree import joint_names, rotation_of_quaternion


@dataclass(frozen=True)
class Layout:
    """Where each entry of the whole tree's ``q`` and ``v`` (every movable joint, followers
    of couplings included: NQ_full, NV_full) sits in MuJoCo's ``qpos`` and ``qvel``:
    ``qpos[qpos_index]`` gives it (the quaternion reordered), ``T`` the velocity map at a
    configuration. ``free`` is MuJoCo's qpos and dof address of the free joint (None without
    one); ``nq``, ``nv`` are MuJoCo's sizes.

    With couplings (MuJoCo's ``joint`` equalities, :mod:`eomgen.parsers.mjcf.extras`), the
    model's own ``q`` (NQ) and ``v`` (NV) are the entries ``q_keep`` and ``v_keep`` of the
    whole tree's; ``coupling`` is ``T_c`` (NV_full × NV, ``v_full = T_c v``) and
    ``followers`` says how each follower's entry is made: ``(index, ((leader index, gain),
    …), offset)`` in the whole tree's ``q``. ``locked`` holds MuJoCo's qpos address and value
    of each joint a ``joint`` equality locks."""

    qpos_index: np.ndarray
    dof_index: np.ndarray
    free: tuple[int, int] | None
    nq: int
    nv: int
    q_keep: np.ndarray | None = None
    v_keep: np.ndarray | None = None
    coupling: np.ndarray | None = None
    followers: tuple = ()
    locked: tuple[tuple[int, float], ...] = ()


def layout(m, model: RobotModel) -> Layout:
    """The :class:`Layout` of ``model`` (read from the compiled MuJoCo model ``m``)."""
    by_name = {name: j for j, name in enumerate(joint_names(m))}
    full = uncoupled(model)
    qpos, dofs, free = [], [], None
    if full.free_flyer:
        j = by_name[dict(full.info)["mujoco_free_joint"]]
        qa, da = int(m.jnt_qposadr[j]), int(m.jnt_dofadr[j])
        free = (qa, da)
        qpos += [qa, qa + 1, qa + 2, qa + 4, qa + 5, qa + 6, qa + 3]
        dofs += list(range(da, da + 6))
    balls = {f"{name}_wx": name for name in full.ball_joints}
    virtual = {f"{name}_{axis}" for name in full.ball_joints for axis in ("wy", "wz")}
    for joint in full.movable_joints[6 if full.free_flyer else 0:]:
        if joint.name in virtual:  # taken with the ball joint's first entry
            continue
        j = by_name[balls.get(joint.name, joint.name)]
        qa, da = int(m.jnt_qposadr[j]), int(m.jnt_dofadr[j])
        if joint.name in balls:  # MuJoCo's (w, x, y, z) as (x, y, z, w); ω in the child frame
            qpos += [qa + 1, qa + 2, qa + 3, qa]
            dofs += [da, da + 1, da + 2]
        else:
            qpos.append(qa)
            dofs.append(da)
    locked = tuple((int(m.jnt_qposadr[by_name[name]]), float(value))
                   for name, value in dict(model.info).get("mujoco_locks", ()))
    coupled = {}
    if model.couplings:
        names = full.configuration_names
        T, _ = coupling_map(model)
        coupled = dict(
            q_keep=np.array([names.index(n) for n in model.configuration_names], dtype=int),
            v_keep=np.array([full.joint_names.index(n) for n in model.joint_names], dtype=int),
            coupling=np.array(T.evalf(), dtype=float),
            followers=tuple((names.index(c.follower),
                             tuple((names.index(n), float(k)) for n, k in c.leaders),
                             float(c.offset)) for c in model.couplings))
    return Layout(np.array(qpos, dtype=int), np.array(dofs, dtype=int), free, int(m.nq),
                  int(m.nv), locked=locked, **coupled)


def to_eomgen(lay: Layout, qpos, qvel=None):
    """eomgen's ``q`` (and ``v`` when ``qvel`` is given) from MuJoCo's ``qpos`` (``qvel``);
    with couplings, the independent joints' entries (``qpos`` and ``qvel`` are taken to
    satisfy the couplings)."""
    qpos = np.asarray(qpos, dtype=float)
    q = qpos[lay.qpos_index]
    if lay.q_keep is not None:
        q = q[lay.q_keep]
    if qvel is None:
        return q
    v = _tree_velocity_map(lay, qpos).T @ np.asarray(qvel, dtype=float)  # orthogonal: T⁻¹ = Tᵀ
    return q, (v if lay.v_keep is None else v[lay.v_keep])


def to_mujoco(lay: Layout, q, v):
    """MuJoCo's ``(qpos, qvel)`` from eomgen's ``q`` and ``v`` (followers where their
    couplings put them, locked joints at their positions); entries of joints eomgen does not
    have (a dropped free body's) stay zero."""
    qpos = np.zeros(lay.nq)
    qpos[lay.qpos_index] = full_q(lay, q)
    for index, value in lay.locked:
        qpos[index] = value
    return qpos, velocity_map(lay, qpos) @ np.asarray(v, dtype=float)


def full_q(lay: Layout, q) -> np.ndarray:
    """The whole tree's ``q`` (every movable joint) of eomgen's ``q``: ``q`` itself without
    couplings."""
    q = np.asarray(q, dtype=float)
    if lay.q_keep is None:
        return q
    out = np.zeros(len(lay.qpos_index))
    out[lay.q_keep] = q
    for index, leaders, offset in lay.followers:
        out[index] = sum(gain * out[leader] for leader, gain in leaders) + offset
    return out


def velocity_map(lay: Layout, qpos) -> np.ndarray:
    """``T`` (MuJoCo's nv × NV): ``qvel = T v`` (with couplings, ``T_mj T_c``)."""
    T = _tree_velocity_map(lay, qpos)
    return T if lay.coupling is None else T @ lay.coupling


def _tree_velocity_map(lay: Layout, qpos) -> np.ndarray:
    """MuJoCo's ``qvel`` of the whole tree's ``v`` (nv × NV_full)."""
    T = np.zeros((lay.nv, len(lay.dof_index)))
    T[lay.dof_index, np.arange(len(lay.dof_index))] = 1.0
    if lay.free is not None:
        qa, da = lay.free
        T[da:da + 3, 0:3] = rotation_of_quaternion(np.asarray(qpos)[qa + 3:qa + 7])
    return T


def mujoco_dynamics(m, lay: Layout, q, v) -> dict[str, np.ndarray]:
    """MuJoCo's quantities at eomgen's state ``(q, v)``, in eomgen's coordinates (the joints
    eomgen dropped, a second free body's, at ``qpos0`` and at rest):
    ``M_a`` (``mj_fullM``, armature included), ``M`` (armature removed), ``h`` (``qfrc_bias``
    with the free joint's ``Ṫ v``), ``passive`` (``qfrc_passive``: damping, springs, fluid,
    gravity compensation), and its parts ``damper`` and ``spring`` (``qfrc_damper``,
    ``qfrc_spring``, where this MuJoCo has them)."""
    import mujoco  # an optional dependency, present whenever a compiled model is

    data = mujoco.MjData(m)
    qpos, qvel = to_mujoco(lay, q, v)
    qpos[_absent(m, lay)] = m.qpos0[_absent(m, lay)]
    data.qpos[:], data.qvel[:] = qpos, qvel
    mujoco.mj_forward(m, data)
    full = full_mass_matrix(m, data)
    T = velocity_map(lay, qpos)
    drift = np.zeros(m.nv)  # Ṫ v
    if lay.free is not None:
        qa, da = lay.free
        R = rotation_of_quaternion(qpos[qa + 3:qa + 7])
        drift[da:da + 3] = R @ np.cross(v[3:6], v[0:3])
    rigid = full - np.diag(m.dof_armature)
    return {"M_a": T.T @ full @ T, "M": T.T @ rigid @ T,
            "h": T.T @ (data.qfrc_bias + rigid @ drift),
            "passive": T.T @ data.qfrc_passive,
            **{part: T.T @ getattr(data, f"qfrc_{part}") for part in ("damper", "spring")
               if hasattr(data, f"qfrc_{part}")}}  # parts kept apart since MuJoCo 3.1


def full_mass_matrix(m, data) -> np.ndarray:
    """MuJoCo's dense mass matrix (nv × nv) of ``data`` after ``mj_forward``, by ``mj_fullM``
    in the signature of the installed MuJoCo (before 3.3 it took ``qM``)."""
    import mujoco  # an optional dependency, present whenever a compiled model is

    full = np.zeros((m.nv, m.nv))
    if hasattr(data, "qM"):  # MuJoCo before 3.3: mj_fullM(m, dst, qM)
        mujoco.mj_fullM(m, full, data.qM)
    else:
        mujoco.mj_fullM(m, data, full)
    return full


def _absent(m, lay: Layout) -> np.ndarray:
    """MuJoCo qpos entries eomgen has no coordinate for."""
    mask = np.ones(m.nq, dtype=bool)
    mask[lay.qpos_index] = False
    mask[[index for index, _ in lay.locked]] = False
    return mask
