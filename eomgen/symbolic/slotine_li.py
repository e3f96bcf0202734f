"""The Slotine–Li regressor Y_SL(q, q̇, q̇_r, q̈_r) as a straight-line program.

The adaptive controller of Slotine and Li needs, for a *reference* velocity q̇_r and
acceleration q̈_r that differ from the robot's own q̇, q̈, the matrix linear in the parameters π
(the same π as the joint torque regressor, :mod:`eomgen.symbolic.regressor`, Pinocchio's order
per body)::

    Y_SL(q, q̇, q̇_r, q̈_r) π = M(q) q̈_r + C(q, q̇) q̇_r + g(q)

with C the Christoffel matrix of eomgen (``C_ij = Σ_k Γ_ijk q̇_k``), the one for which Ṁ − 2C is
skew-symmetric. With q̇_r = q̇ and q̈_r = q̈ it is the joint torque regressor Y(q, q̇, q̈).

Derivation (spatial vectors, Featherstone's conventions, body coordinates about each body's
origin). Down the tree, with ``X`` the motion transform from the parent and ``s_i`` joint i's
motion axis in its body::

    v_i   = X v_p   + s_i q̇_i                         (the body's velocity)
    v_r,i = X v_r,p + s_i q̇_r,i                       (= J_i q̇_r)
    a_r,i = X a_r,p + s_i q̈_r,i + v_i × s_i q̇_r,i      (= J_i q̈_r + J̇_i q̇_r; a_r,0 = −g)

and body i's share of the force, linear in its spatial inertia I_i (so in π_i)::

    f_i = I_i a_r,i + ½ [ v_i ×* (I_i v_r,i) − I_i (v_i × v_r,i) + v_r,i ×* (I_i v_i) ]

The bracket is B(v_i) v_r,i with the body factorization ``B(v) = ½[(v×*) I − I (v×) +
(I v)×̄*]`` (Echeverri and Wensing's Christoffel-consistent choice; B(v) v = v ×* I v, so at
v_r = v this is Newton–Euler), and ``C = Σ_i J_iᵀ (I_i J̇_i + B(v_i) J_i)`` is the Christoffel
matrix. The torque body j demands of joint i (an ancestor of j, or j) is ``s_i^jᵀ f_j``, so
``Y_SL[i, block j] = s_i^jᵀ A_j`` with ``f_j = A_j π_j`` (A_j: 6 × 10, named once per body).

Actuator columns (those the description declares): armature ``I_a`` multiplies q̈_r,k, viscous
friction ``f_v`` multiplies q̇_r,k and Coulomb friction ``f_c`` multiplies sign(q̇_k), the
robot's own velocity (the friction it feels), so that Y_SL(q, q̇, q̇, q̈) = Y(q, q̇, q̈) there too.
"""

from __future__ import annotations

import sympy as sp

from ..model.bodies import BodyTree
from .program import ProgramBuilder
from .spatial import JointFrames, cross, dot, joint_subspace

# (row, col) pairs of the six inertia parameters, Pinocchio's order xx, xy, yy, xz, yz, zz
INERTIA_ENTRIES = ((0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2))


def spatial_inertia_times(pi, motion) -> tuple:
    """``I (ω, v)`` for the body parameters ``pi`` (10, Pinocchio's order, about the body origin):
    ``(Ī ω + h × v, m v − h × ω)`` with h = m c."""
    m, h = pi[0], pi[1:4]
    inertia = [[None] * 3 for _ in range(3)]
    for k, (r, c) in enumerate(INERTIA_ENTRIES):
        inertia[r][c] = inertia[c][r] = pi[4 + k]
    w, v = motion[:3], motion[3:]
    hv, hw = cross(h, v), cross(h, w)
    return (tuple(dot(inertia[r], w) + hv[r] for r in range(3))
            + tuple(m * v[r] - hw[r] for r in range(3)))


def motion_cross(a, b) -> tuple:
    """``a × b`` of two motion vectors ``(ω, v)``."""
    wa, va, wb, vb = a[:3], a[3:], b[:3], b[3:]
    return cross(wa, wb) + tuple(x + y for x, y in zip(cross(wa, vb), cross(va, wb)))


def force_cross(a, f) -> tuple:
    """``a ×* f`` of a motion vector ``(ω, v)`` and a force ``(n, f)``."""
    w, v, n, f_ = a[:3], a[3:], f[:3], f[3:]
    return tuple(x + y for x, y in zip(cross(w, n), cross(v, f_))) + cross(w, f_)


def body_force(pi, v, v_r, a_r) -> tuple:
    """``f = I a_r + ½ [v ×* (I v_r) − I (v × v_r) + v_r ×* (I v)]`` (6-vector), for symbolic or
    numeric entries: linear in ``pi``."""
    first = force_cross(v, spatial_inertia_times(pi, v_r))
    second = spatial_inertia_times(pi, motion_cross(v, v_r))
    third = force_cross(v_r, spatial_inertia_times(pi, v))
    inertial = spatial_inertia_times(pi, a_r)
    half = sp.Rational(1, 2)
    return tuple(inertial[e] + half * (first[e] - second[e] + third[e]) for e in range(6))


#: Placeholders for one body's parameters while its 6 × 10 block A_j is read off f_j = A_j π_j.
_PI = sp.symbols("SLpi0:10", real=True)


def slotine_li_program(tree: BodyTree, q, qd, qd_r, qdd_r, gravity, b: ProgramBuilder,
                       actuators=()) -> sp.Matrix:
    """Build Y_SL (n × p) into ``b``; columns as :func:`eomgen.symbolic.regressor.
    regressor_program` (10 per body in JOINT_NAMES order, then one group of n per actuator term
    in ``actuators``, a subset of ``("armature", "viscous", "coulomb")``).

    Parameters
    ----------
    tree:
        The moving bodies.
    q, qd, qd_r, qdd_r:
        Joint positions, velocities, reference velocities and reference accelerations (symbols
        in JOINT_NAMES order).
    gravity:
        Gravitational acceleration in the root frame [m/s²].
    """
    n = len(tree.bodies)
    p = 10 * n + len(actuators) * n
    frames = JointFrames.named(tree, q, b)
    zero3 = (sp.Integer(0),) * 3
    vel, vel_r, acc_r, axes_at, blocks = [], [], [], [], []
    for i, body in enumerate(tree.bodies):
        k, tag = body.q_index, body.q_index + 1
        S_ang, S_lin = joint_subspace(body.joint)
        s = S_ang + S_lin
        if body.parent < 0:
            v_p, vr_p, ar_p = zero3 * 2, zero3 * 2, zero3 + tuple(-x for x in gravity)
        else:
            v_p, vr_p, ar_p = vel[body.parent], vel_r[body.parent], acc_r[body.parent]

        def moved(m):
            w_, v_ = frames.motion_to_body(i, m[:3], m[3:])
            return w_ + v_

        v = b.define_all(tuple(x + y * qd[k] for x, y in zip(moved(v_p), s)), f"slv{tag}_")
        v_r = b.define_all(tuple(x + y * qd_r[k] for x, y in zip(moved(vr_p), s)),
                           f"slvr{tag}_")
        coriolis = motion_cross(v, tuple(y * qd_r[k] for y in s))
        a_r = b.define_all(tuple(x + y * qdd_r[k] + c for x, y, c in
                                 zip(moved(ar_p), s, coriolis)), f"slar{tag}_")
        vel.append(v)
        vel_r.append(v_r)
        acc_r.append(a_r)
        force = body_force(_PI, v, v_r, a_r)
        block = [[b.define(sp.expand(f.diff(x)), f"slA{tag}_{e}_{c}") for c, x in enumerate(_PI)]
                 for e, f in enumerate(force)]
        blocks.append(block)
        axes = {i: s}
        if body.parent >= 0:
            for anc, s_anc in axes_at[body.parent].items():
                t = f"{tree.bodies[anc].q_index + 1}_{tag}"
                axes[anc] = b.define_all(moved(s_anc), f"sls{t}_")
        axes_at.append(axes)

    Y = sp.zeros(n, p)
    for j, body in enumerate(tree.bodies):
        col = 10 * body.q_index
        for anc, s_anc in axes_at[j].items():
            row = tree.bodies[anc].q_index
            for c in range(10):
                value = dot(s_anc, [blocks[j][e][c] for e in range(6)])
                Y[row, col + c] = b.define(value, f"YSL{row + 1}_{col + c + 1}")
    for g_idx, term in enumerate(actuators):
        for body in tree.bodies:
            k = body.q_index
            Y[k, 10 * n + g_idx * n + k] = {"armature": qdd_r[k], "viscous": qd_r[k],
                                            "coulomb": sp.sign(qd[k])}[term]
    return Y


__all__ = ["INERTIA_ENTRIES", "slotine_li_program", "body_force", "spatial_inertia_times",
           "motion_cross", "force_cross"]
