"""Numeric rigid-body dynamics in NumPy (Newton–Euler): the independent reference for the symbolic
engine.

The design follows Pinocchio's Model/Data split. :func:`numeric_model` turns a
:class:`~eomgen.model.RobotModel` into a :class:`NumericModel` once: every parameter replaced
by its number, every quantity stored as a read-only float64 array. The algorithms are free
functions of ``(nm, q, ...)``; their working storage is local to each call, so a
``NumericModel`` can be shared freely (threads included) and nothing depends on call order.

Conventions
-----------
Frames are those of :mod:`eomgen.model` (URDF's):

* Body ``i`` is link ``i``; its frame is the link frame. Body 0 is the root link, fixed in the
  world; the *world* frame of this module is the root link frame.
* ``T_parent_child(q) = origin · motion(axis, q)``: the joint frame sits at ``origin`` in the
  parent frame, and the child frame is the joint frame rotated by ``q`` [rad] about ``axis``
  (revolute, right hand rule) or translated by ``q`` [m] along it (prismatic). ``axis`` is a
  unit vector in the child frame.
* Fixed joints are bodies whose joint has no motion: the recursion passes through them, so
  links rigidly attached to others keep their own frame and inertia (no merging).
* Generalised coordinates: ``q[k]`` belongs to ``model.joint_names[k]``, i.e. description
  order (``JOINT_NAMES`` order), which may differ from the tree order the recursions use.
* Coupled joints (:mod:`eomgen.model.coupling`, a URDF ``<mimic>``): ``q`` holds the
  independent joints only; the recursions run the whole tree at ``q_tree = T q + c``,
  ``q̇_tree = T q̇``, ``q̈_tree = T q̈`` and return ``Tᵀ τ_tree``, so that ``M = Tᵀ M_tree T`` and
  ``C q̇ + g = Tᵀ (C q̇ + g)_tree`` are the reduced model's.
* Quaternion joints (a free flyer, ball joints: :mod:`eomgen.model.quaternion`): ``q`` is the
  configuration (NQ entries, ``CONFIGURATION_NAMES``, Pinocchio's layout) and ``qd``, ``qdd``,
  ``tau`` are velocities (NV entries, ``JOINT_NAMES``): a free flyer's root twist in the root
  frame (linear then angular) and the wrench on the root, a ball joint's angular velocity of the
  child in the child frame. The recursions hold the joint's virtual joints at zero and place its
  pose from ``q`` (:mod:`eomgen.numeric.quaternion_chart`), as the derivation does.
* Units: SI. ``tau[k]`` is a torque [N m] for a revolute joint and a force [N] for a
  prismatic one; it is the generalised force the joint actuator applies to the child body
  (and, reacting, to the parent), positive along ``+axis``.
* ``gravity`` is the gravitational acceleration [m/s²] in the root frame, e.g. ``(0, 0,
  -9.81)``; the equations of motion are ``M(q) q̈ + C(q, q̇) q̇ + g(q) = tau``.

Examples
--------
A point mass ``m = 2`` kg hanging ``l = 0.5`` m below a joint about ``y`` (gravity ``-z``):

>>> from eomgen.model import (Inertial, Joint, JointType, Link, Transform, build_model,
...                           scalar, vec3)
>>> bob = Inertial(scalar(2.0), vec3([0, 0, -0.5]))
>>> pendulum = build_model(
...     "<doc>", "pendulum", [Link("base"), Link("bob", bob)],
...     [Joint("swing", JointType.REVOLUTE, "base", "bob", Transform(), vec3([0, 1, 0]))])
>>> nm = numeric_model(pendulum)
>>> round(float(gravity_torques(nm, [np.pi / 2])[0]), 12)  # m g l sin q, bob held sideways
9.81
"""

from __future__ import annotations

import numpy as np

from .model import (FIXED, FLOAT64, HELICAL, PRISMATIC, REVOLUTE, TURNING, Numbers, NumericModel,
                    numeric_model)
from .quaternion_chart import chart_coordinates, chart_offset, placements
from .so3 import rotation_about, skew

# ----------------------------------------------------------------------------------------------
# Kinematics shared by the algorithms
# ----------------------------------------------------------------------------------------------

def _check(nm: NumericModel, name: str, x, size: int | None = None) -> np.ndarray:
    """``x`` as an (n,) array of the model's numbers (``size`` entries when given), or a
    ValueError naming the argument."""
    if not isinstance(nm, NumericModel):
        raise ValueError(f"expected a NumericModel (see numeric_model), got {type(nm).__name__}")
    a = nm.numbers.vector(x)
    size = nm.n if size is None else size
    if a.shape != (size,):
        what = (f"joints {', '.join(nm.joint_names) or 'none'}" if size == nm.n else
                f"the configuration of {nm.name}, quaternions included")
        raise ValueError(f"{name} must have shape ({size},) ({what}), got shape {a.shape}")
    if not nm.numbers.all_finite(a):
        raise ValueError(f"{name} has a non-finite entry")
    return a


def _configuration(nm: NumericModel, q) -> tuple[np.ndarray, dict]:
    """The coordinates the recursions index (n_tree,) and the poses placed from the quaternions
    (:func:`~eomgen.numeric.quaternion_chart.placements`), from ``q`` (nq,): with couplings the
    whole tree's ``T q + c``."""
    q = _check(nm, "q", q, nm.nq)
    if nm.coupling is not None:
        q = nm.configuration_coupling @ q + nm.coupling_offset
    if nm.nq == nm.n:  # every configuration entry is a coordinate: no chart to place
        return q, {}
    return chart_coordinates(nm, q), placements(nm, q)


def _tangent(nm: NumericModel, name: str, x) -> np.ndarray:
    """A velocity-like argument (n,) as the recursions take it (n_tree,): itself, or with
    couplings the whole tree's ``T x``."""
    x = _check(nm, name, x)
    return x if nm.coupling is None else nm.coupling @ x


def _parent_transforms(nm: NumericModel, q: np.ndarray, placed: dict | None = None
                       ) -> tuple[np.ndarray, np.ndarray]:
    """Pose of every body frame in its parent's frame at the coordinates ``q`` (n,), the
    quaternion joints' poses ``placed`` (by velocity index, :func:`_configuration`) after their
    origins.

    Returns
    -------
    R : (nb, 3, 3) array
        ``R[i]`` rotates body-``i`` coordinates into parent coordinates (``ᵖR_i``).
    p : (nb, 3) array
        ``p[i]`` is the body-``i`` origin in parent coordinates [m] (``ᵖp_i``).
    """
    R = nm.origin_rotation.copy()
    p = nm.origin_translation.copy()
    for i in range(1, nm.nb):
        k = nm.q_index[i]
        if k < 0:
            continue
        if placed and k in placed:
            Rq, pq = placed[k]
            p[i] = p[i] + R[i] @ pq
            R[i] = R[i] @ Rq
        if nm.joint_type[i] != REVOLUTE:  # prismatic, helical: moves along the axis
            p[i] = p[i] + R[i] @ (nm.axis[i] * (nm.lead[i] * q[k]))
        if nm.joint_type[i] in TURNING:  # (the axis is the same in the turned frame)
            R[i] = R[i] @ rotation_about(nm.axis[i], q[k], nm.numbers)
    return R, p


def _velocities(nm: NumericModel, R: np.ndarray, p: np.ndarray, qd: np.ndarray):
    """Angular velocity ``ω_i`` [rad/s] and origin velocity ``v_i`` [m/s] of every body,
    in body-``i`` coordinates (outward recursion)."""
    w = nm.numbers.zeros((nm.nb, 3))
    v = nm.numbers.zeros((nm.nb, 3))
    for i in range(1, nm.nb):
        j = nm.parent[i]
        Rt = R[i].T
        w[i] = Rt @ w[j]
        v[i] = Rt @ (v[j] + np.cross(w[j], p[i]))
        k = nm.q_index[i]
        if k >= 0:
            if nm.joint_type[i] in TURNING:
                w[i] += qd[k] * nm.axis[i]
            if nm.joint_type[i] != REVOLUTE:
                v[i] += (nm.lead[i] * qd[k]) * nm.axis[i]
    return w, v


# ----------------------------------------------------------------------------------------------
# Algorithms
# ----------------------------------------------------------------------------------------------

def rnea(nm: NumericModel, q, qd, qdd) -> np.ndarray:
    """Inverse dynamics by the recursive Newton–Euler algorithm: ``tau = M q̈ + C q̇ + g``.

    Outward recursion (root to tips), every quantity of body ``i`` in body-``i`` coordinates,
    with ``R = ᵖR_i``, ``p = ᵖp_i`` the pose of body ``i`` in its parent ``p``, ``z`` the
    joint axis and ``q̇, q̈`` the joint rate and acceleration::

        ω_i  = Rᵀ ω_p                    (+ q̇ z                     revolute, helical)
        ω̇_i  = Rᵀ ω̇_p                    (+ Rᵀω_p × q̇ z + q̈ z       revolute, helical)
        v̇_i  = Rᵀ (v̇_p + ω̇_p × p + ω_p × (ω_p × p))
                                         (+ λ (2 ω_i × q̇ z + q̈ z)    prismatic, helical)
        v̇_ci = v̇_i + ω̇_i × c_i + ω_i × (ω_i × c_i)
        F_i  = m_i v̇_ci,     N_i = I_ci ω̇_i + ω_i × I_ci ω_i

    starting from the root at rest with ``v̇_0 = -gravity`` (gravity enters as an upward
    acceleration of the base). Here ``v̇_i`` is the acceleration of the body-``i`` origin,
    ``c_i`` the centre of mass and ``I_ci`` the inertia about it. Inward recursion (tips to
    root), ``f_i`` and ``n_i`` being the force [N] and moment [N m] about the body origin that
    the parent exerts on body ``i`` through the joint::

        f_i = F_i + Σ_children ⁱR_c f_c
        n_i = N_i + c_i × F_i + Σ_children (ⁱR_c n_c + ⁱp_c × ⁱR_c f_c)
        tau = n_i · z  (revolute),   f_i · z  (prismatic),   n_i · z + λ f_i · z  (helical)

    with ``λ`` the joint's lead (1 prismatic, the pitch helical: :attr:`NumericModel.lead`).

    Fixed joints are bodies with no joint motion; the root's forces are not returned. A
    quaternion joint's chain runs with its virtual joints at zero below the pose placed from
    ``q``, and takes the chart accelerations ``q̈ − n(q̇)``
    (:mod:`eomgen.numeric.quaternion_chart`). With coupled joints the whole tree runs at
    ``(T q + c, T q̇, T q̈)`` and the result is ``Tᵀ τ_tree`` (:attr:`NumericModel.coupling`).

    Parameters
    ----------
    nm : NumericModel
    q : (nq,) array_like
        Joint positions [rad or m] in ``nm.joint_names`` order; with quaternion joints the
        configuration (NQ entries, Pinocchio's layout, module docstring).
    qd : (n,) array_like
        Joint velocities [rad/s or m/s] in ``nm.joint_names`` order.
    qdd : (n,) array_like
        Joint accelerations [rad/s² or m/s²], same order.

    Returns
    -------
    tau : (n,) ndarray
        Joint torques [N m] / forces [N], same order, positive along ``+axis`` (a free flyer:
        the force then moment on the root, root frame).

    Raises
    ------
    ValueError
        When an argument does not have shape (n,) or is not finite.
    """
    q, placed = _configuration(nm, q)
    qd = _tangent(nm, "qd", qd)
    qdd = _tangent(nm, "qdd", qdd)
    if nm.nq != nm.n:
        qdd = qdd - chart_offset(nm, qd)
    nb = nm.nb
    R, p = _parent_transforms(nm, q, placed)
    zeros = nm.numbers.zeros

    w = zeros((nb, 3))
    wd = zeros((nb, 3))
    vd = zeros((nb, 3))
    vd[0] = -nm.gravity
    F = zeros((nb, 3))
    N = zeros((nb, 3))
    for i in range(1, nb):
        j = nm.parent[i]
        Rt = R[i].T
        w[i] = Rt @ w[j]
        wd[i] = Rt @ wd[j]
        vd[i] = Rt @ (vd[j] + np.cross(wd[j], p[i]) + np.cross(w[j], np.cross(w[j], p[i])))
        k = nm.q_index[i]
        if k >= 0:
            z = nm.axis[i]
            if nm.joint_type[i] in TURNING:
                wd[i] += np.cross(w[i], qd[k] * z) + qdd[k] * z
                w[i] += qd[k] * z
            if nm.joint_type[i] != REVOLUTE:  # (ω_i × z is the parent's: z × z = 0)
                lead = nm.lead[i]
                vd[i] += 2.0 * np.cross(w[i], (lead * qd[k]) * z) + (lead * qdd[k]) * z
        c = nm.com[i]
        vdc = vd[i] + np.cross(wd[i], c) + np.cross(w[i], np.cross(w[i], c))
        I = nm.inertia[i]
        F[i] = nm.mass[i] * vdc
        N[i] = I @ wd[i] + np.cross(w[i], I @ w[i])

    f = F.copy()
    n = N + np.cross(nm.com, F)
    tau = zeros(nm.n_tree)
    for i in range(nb - 1, 0, -1):
        k = nm.q_index[i]
        if k >= 0:
            kind = nm.joint_type[i]
            s = n[i] if kind == REVOLUTE else f[i] if kind == PRISMATIC else (
                n[i] + nm.lead[i] * f[i])
            tau[k] = s @ nm.axis[i]
        j = nm.parent[i]
        fj = R[i] @ f[i]
        f[j] += fj
        n[j] += R[i] @ n[i] + np.cross(p[i], fj)
    return tau if nm.coupling is None else nm.coupling.T @ tau


def gravity_torques(nm: NumericModel, q) -> np.ndarray:
    """Gravity vector ``g(q) = rnea(q, 0, 0)``: the (n,) torques/forces that hold the robot
    still at ``q`` (``q`` (nq,) as :func:`rnea` takes it)."""
    zero = np.zeros(nm.n)
    return rnea(nm, q, zero, zero)


def M_rnea(nm: NumericModel, q) -> np.ndarray:
    """Joint-space mass matrix ``M(q)``, (n, n), rows and columns in ``nm.joint_names`` order.

    Column ``i`` is ``rnea(q, 0, e_i) - rnea(q, 0, 0)`` (n + 1 RNEA calls, O(n²) overall);
    ``q`` (nq,) as :func:`rnea` takes it.
    """
    q = _check(nm, "q", q, nm.nq)
    zero = nm.numbers.zeros(nm.n)
    g = rnea(nm, q, zero, zero)
    M = nm.numbers.zeros((nm.n, nm.n))
    for i in range(nm.n):
        e = nm.numbers.zeros(nm.n)
        e[i] = nm.numbers.value(1)
        M[:, i] = rnea(nm, q, zero, e) - g
    return M


def M_crba(nm: NumericModel, q) -> np.ndarray:
    """Joint-space mass matrix ``M(q)`` by the composite-rigid-body algorithm, (n, n), the
    same matrix as :func:`M_rnea` in one inward pass and one walk up from each joint.

    Spatial quantities in body coordinates, angular part first: body ``i``'s inertia about
    its origin ``[[I_ci − m [c]×², m [c]×], [−m [c]×, m 1]]``; the composite inertia ``I^c_i``
    (the body and everything below it) gathers each child's through ``ᶜX_iᵀ I^c_c ᶜX_i``,
    ``ᶜX_i = [[Rᵀ, 0], [−Rᵀ [p]×, Rᵀ]]`` taking motions from body ``i`` to its child
    (pose ``(R, p)`` in ``i``). With ``S_i`` the joint's motion (``(z, 0)`` revolute, ``(0, z)``
    prismatic, ``(z, λ z)`` helical of lead ``λ``, its pitch), ``M[k_i, k_j] = S_jᵀ (ʲX_iᵀ I^c_i S_i)`` for every joint ``j`` on the path from
    ``i`` to the root. ``q`` (nq,) as :func:`rnea` takes it; with couplings ``Tᵀ M_tree T``.
    """
    x, placed = _configuration(nm, q)
    R, p = _parent_transforms(nm, x, placed)
    numbers, nb = nm.numbers, nm.nb
    zeros = numbers.zeros
    X = zeros((nb, 6, 6))  # motion transform parent -> body i
    Ic = zeros((nb, 6, 6))
    S = zeros((nb, 6))
    for i in range(1, nb):
        Rt = R[i].T
        X[i, :3, :3] = Rt
        X[i, 3:, 3:] = Rt
        X[i, 3:, :3] = -Rt @ skew(p[i], numbers)
        c, m = nm.com[i], nm.mass[i]
        C = skew(c, numbers)
        Ic[i, :3, :3] = nm.inertia[i] - m * (C @ C)
        Ic[i, :3, 3:] = m * C
        Ic[i, 3:, :3] = -m * C
        Ic[i, 3:, 3:] = m * numbers.eye(3)
        if nm.joint_type[i] in TURNING:
            S[i, :3] = nm.axis[i]
        if nm.joint_type[i] != REVOLUTE:
            S[i, 3:] = nm.lead[i] * nm.axis[i]
    for i in range(nb - 1, 1, -1):
        j = nm.parent[i]
        if j > 0:
            Ic[j] = Ic[j] + X[i].T @ Ic[i] @ X[i]
    M = zeros((nm.n_tree, nm.n_tree))
    for i in range(1, nb):
        k = nm.q_index[i]
        if k < 0:
            continue
        F = Ic[i] @ S[i]
        M[k, k] = S[i] @ F
        j = i
        while nm.parent[j] > 0:
            F = X[j].T @ F
            j = nm.parent[j]
            col = nm.q_index[j]
            if col >= 0:
                M[k, col] = M[col, k] = S[j] @ F
    return M if nm.coupling is None else nm.coupling.T @ M @ nm.coupling


def coriolis_times_qd(nm: NumericModel, q, qd) -> np.ndarray:
    """Velocity product ``C(q, q̇) q̇ = rnea(q, q̇, 0) - rnea(q, 0, 0)``, shape (n,), in
    ``nm.joint_names`` order (centrifugal and Coriolis torques/forces); ``q`` (nq,) as
    :func:`rnea` takes it."""
    q = _check(nm, "q", q, nm.nq)
    zero = np.zeros(nm.n)
    return rnea(nm, q, qd, zero) - rnea(nm, q, zero, zero)


def forward_dynamics(nm: NumericModel, q, qd, tau) -> np.ndarray:
    """Joint accelerations ``q̈ = M(q)⁻¹ (τ − C(q, q̇) q̇ − g(q))``, shape (n,), from
    :func:`M_crba` and :func:`rnea` (a float64 model; ``q`` (nq,) as :func:`rnea` takes it, with
    quaternion joints ``q̈`` is ``v̇``). Raises ``numpy.linalg.LinAlgError`` for a singular M."""
    zero = nm.numbers.zeros(nm.n)
    h = rnea(nm, q, qd, zero)
    return np.linalg.solve(M_crba(nm, q), _check(nm, "tau", tau) - h)


def kinetic_energy(nm: NumericModel, q, qd) -> float:
    """Kinetic energy [J]: ``K = Σ_i ½ m_i |v_ci|² + ½ ω_iᵀ I_ci ω_i`` (= ½ q̇ᵀ M(q) q̇).

    Parameters
    ----------
    q : (nq,) array_like
        Joint positions in ``nm.joint_names`` order (the configuration, as :func:`rnea`).
    qd : (n,) array_like
        Joint velocities in ``nm.joint_names`` order.
    """
    q, placed = _configuration(nm, q)
    qd = _tangent(nm, "qd", qd)
    R, p = _parent_transforms(nm, q, placed)
    w, v = _velocities(nm, R, p, qd)
    vc = v + np.cross(w, nm.com)
    Iw = np.einsum("ijk,ik->ij", nm.inertia, w)
    return float(0.5 * (nm.mass @ np.einsum("ij,ij->i", vc, vc)) + 0.5 * np.sum(w * Iw))


def _world_poses(nm: NumericModel, q: np.ndarray, placed: dict
                 ) -> tuple[np.ndarray, np.ndarray]:
    R, p = _parent_transforms(nm, q, placed)
    Rw = np.empty_like(R)
    pw = np.empty_like(p)
    Rw[0] = nm.numbers.eye(3)
    pw[0] = nm.numbers.zeros(3)
    for i in range(1, nm.nb):
        j = nm.parent[i]
        Rw[i] = Rw[j] @ R[i]
        pw[i] = pw[j] + Rw[j] @ p[i]
    return Rw, pw


def world_state(nm: NumericModel, q, qd) -> tuple[np.ndarray, ...]:
    """Every body's motion in world (root) axes at ``q̈ = 0``, for the frame kinematics
    (:mod:`eomgen.numeric.frames`, whose docstring has the recursion): ``(R, p, z, ω, v, ω̇,
    a, q̇_tree)``, ``R`` (nb, 3, 3) and ``p`` (nb, 3) the body poses, ``z`` (nb, 3) the joint
    axes, ``ω``, ``v`` the angular velocity and the origin's velocity, ``ω̇``, ``a`` their
    classical accelerations (a quaternion joint's chain at the chart accelerations ``−n(v)``),
    and the tree's joint velocities."""
    x, placed = _configuration(nm, q)
    qd = _tangent(nm, "qd", qd)
    zeros = nm.numbers.zeros
    qdd = zeros(nm.n_tree)
    if nm.nq != nm.n:
        qdd = -chart_offset(nm, qd)
    Rw, pw = _world_poses(nm, x, placed)
    z = np.einsum("ijk,ik->ij", Rw, nm.axis)
    w, v, wd, a = (zeros((nm.nb, 3)) for _ in range(4))
    for i in range(1, nm.nb):
        j = nm.parent[i]
        r = pw[i] - pw[j]
        w[i], wd[i] = w[j], wd[j]
        v[i] = v[j] + np.cross(w[j], r)
        a[i] = a[j] + np.cross(wd[j], r) + np.cross(w[j], np.cross(w[j], r))
        k = nm.q_index[i]
        if k < 0:
            continue
        motion = z[i] * qd[k]
        if nm.joint_type[i] in TURNING:
            wd[i] = wd[i] + np.cross(w[j], motion) + z[i] * qdd[k]
            w[i] = w[i] + motion
        if nm.joint_type[i] != REVOLUTE:  # prismatic, helical: lead · the motion along z
            lead = nm.lead[i]
            v[i] = v[i] + lead * motion
            a[i] = a[i] + 2.0 * np.cross(w[j], lead * motion) + z[i] * (lead * qdd[k])
    return Rw, pw, z, w, v, wd, a, qd


def potential_energy(nm: NumericModel, q) -> float:
    """Gravitational potential energy [J]: ``P = -Σ_i m_i gravityᵀ p_ci``, with ``p_ci`` the
    centre of mass of body ``i`` in the root frame (zero when every centre of mass is at the
    root origin; with gravity ``(0, 0, -9.81)``, raising a mass raises P). ``g(q) = ∂P/∂q``.

    Parameters
    ----------
    q : (nq,) array_like
        Joint positions in ``nm.joint_names`` order (the configuration, as :func:`rnea`).
    """
    Rw, pw = _world_poses(nm, *_configuration(nm, q))
    pc = pw + np.einsum("ijk,ik->ij", Rw, nm.com)
    return float(-(nm.mass @ (pc @ nm.gravity)))


def link_poses(nm: NumericModel, q) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Forward kinematics: pose of every link frame in the root frame.

    Parameters
    ----------
    q : (nq,) or (n,) array_like
        Joint positions in ``nm.joint_names`` order (the configuration, as :func:`rnea`). With
        quaternion joints, (n,) values are taken as the coordinates of their virtual joints
        (the chain of one-axis joints the model holds, :mod:`eomgen.model.quaternion`), with
        no pose placed from a quaternion: how the chain draws.

    Returns
    -------
    dict
        ``{link name: (R, p)}`` with ``R`` (3, 3) the rotation taking link coordinates to root
        coordinates and ``p`` (3,) the link origin [m] in the root frame; the root maps to
        ``(I, 0)``. Every link is present, massless and fixed-joint links included.
    """
    if nm.nq != nm.n and np.shape(q) == (nm.n,):
        Rw, pw = _world_poses(nm, _check(nm, "q", q), {})
    else:
        Rw, pw = _world_poses(nm, *_configuration(nm, q))
    return {name: (Rw[i], pw[i]) for i, name in enumerate(nm.body_names)}


__all__ = [
    "Numbers",
    "FLOAT64",
    "NumericModel",
    "numeric_model",
    "rnea",
    "gravity_torques",
    "M_rnea",
    "M_crba",
    "coriolis_times_qd",
    "forward_dynamics",
    "kinetic_energy",
    "potential_energy",
    "link_poses",
    "FIXED",
    "REVOLUTE",
    "PRISMATIC",
    "HELICAL",
    "TURNING",
]
