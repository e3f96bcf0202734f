"""Inverse dynamics τ = M q̈ + C q̇ + g by a symbolic recursive Newton–Euler pass.

The recursion is O(n) and yields far fewer operations than forming M q̈ + C q̇ + g from the
matrices, so generated ``inverse_dynamics`` functions use it; verification checks that it equals
the Lagrangian M q̈ + C q̇ + g.

Frames and conventions: every body quantity is in its own body frame (the joint frame after the
joint has moved, see :mod:`eomgen.model`). ``ω``, ``ω̇`` are the body's angular velocity and
acceleration, ``a`` the linear acceleration of the body-frame origin, with gravity entering as a
base acceleration ``a_0 = −g_vec``. Body inertial parameters are about the body origin (m, h, I_O,
see :mod:`eomgen.bodies`), so the net force and moment about the origin are

    f = m a + ω̇ × h + ω × (ω × h),
    n = I_O ω̇ + ω × (I_O ω) + h × a,

and the joint torque is ``τ_i = ẑ_i · n_i`` (revolute) or ``ẑ_i · f_i`` (prismatic), ``ẑ_i`` the
unit joint axis in body coordinates.
"""

from __future__ import annotations

import sympy as sp

from ..bodies import BodyTree
from ..model import Vec3
from .composite import _cross, _dot, _matvec
from .program import ProgramBuilder


def _rotate_back(axis: Vec3, c, s, v) -> tuple:
    """Rot(axis, q)ᵀ v by Rodrigues' formula: v c − (axis × v) s + axis (axis·v)(1 − c)."""
    k_cross_v = _cross(axis, v)
    k_dot_v = _dot(axis, v)
    return tuple(v[r] * c - k_cross_v[r] * s + axis[r] * k_dot_v * (1 - c) for r in range(3))


def _transpose_apply(R, v) -> tuple:
    """Rᵀ v for a 3×3 rotation given as rows."""
    return tuple(sp.Add(*[R[k][r] * v[k] for k in range(3)]) for r in range(3))


def _aligned(axis) -> tuple[int, int] | None:
    """``(k, sign)`` when ``axis`` is ``sign`` times the k-th unit vector, else None."""
    values = tuple(axis)
    for k in range(3):
        for sign in (1, -1):
            if values == tuple(sign if j == k else 0 for j in range(3)):
                return k, sign
    return None


def _rotate_aligned(k: int, c, s, v, transpose: bool) -> tuple:
    """Rot(e_k, q) v, or its transpose, touching only the two components that change."""
    i, j = (k + 1) % 3, (k + 2) % 3
    if transpose:
        s = -s
    w = [None, None, None]
    w[i] = c * v[i] - s * v[j]
    w[j] = s * v[i] + c * v[j]
    w[k] = v[k]
    return tuple(w)


def inverse_dynamics_program(tree: BodyTree, q, qd, qdd, gravity: Vec3, b: ProgramBuilder) -> sp.Matrix:
    """Build τ(q, q̇, q̈) into ``b``; returns the n×1 matrix of joint efforts [N m or N]."""
    n = len(tree.bodies)
    omega, domega, acc, sincos = [], [], [], []
    zero = (sp.Integer(0),) * 3

    def to_body(i, v):
        """Parent-frame vector → body i frame: Rot(axis, q)ᵀ R_placeᵀ v (revolute)."""
        body = tree.bodies[i]
        w = _transpose_apply(body.placement.rotation, v)
        if body.joint.type.is_revolute:
            s, c = sincos[i]
            aligned = _aligned(body.joint.axis)
            if aligned is not None:
                w = _rotate_aligned(aligned[0], c, aligned[1] * s, w, transpose=True)
            else:
                w = _rotate_back(body.joint.axis, c, s, w)
        return w

    def to_parent(i, v):
        """Body i frame vector → parent frame: R_place Rot(axis, q) v."""
        body = tree.bodies[i]
        w = v
        if body.joint.type.is_revolute:
            s, c = sincos[i]
            aligned = _aligned(body.joint.axis)
            if aligned is not None:
                w = _rotate_aligned(aligned[0], c, aligned[1] * s, v, transpose=False)
            else:
                w = _rotate_back(body.joint.axis, c, -s, v)
        return _matvec(body.placement.rotation, w)

    base_acc = tuple(-x for x in gravity)
    for i, body in enumerate(tree.bodies):
        k = body.q_index
        tag = k + 1
        z = body.joint.axis
        if body.joint.type.is_revolute:
            sincos.append((b.define(sp.sin(q[k]), f"s{tag}"), b.define(sp.cos(q[k]), f"c{tag}")))
        else:
            sincos.append(None)
        if body.parent < 0:
            w_p, dw_p, a_p = zero, zero, base_acc
            r = body.placement.translation
        else:
            w_p, dw_p, a_p = omega[body.parent], domega[body.parent], acc[body.parent]
            r = body.placement.translation
        if body.joint.type.is_revolute:
            # origin acceleration of this body, in the parent frame, then rotated in
            a_o = tuple(a_p[j] + e for j, e in enumerate(
                tuple(x + y for x, y in zip(_cross(dw_p, r), _cross(w_p, _cross(w_p, r))))))
            a = b.define_all(to_body(i, b.define_all(a_o, f"ap{tag}_")), f"a{tag}_")
            w_in = b.define_all(to_body(i, w_p), f"wp{tag}_")
            w = b.define_all(tuple(w_in[j] + z[j] * qd[k] for j in range(3)), f"w{tag}_")
            dw_rel = _cross(w_in, tuple(z[j] * qd[k] for j in range(3)))
            dw = b.define_all(tuple(e + dw_rel[j] + z[j] * qdd[k] for j, e in
                                    enumerate(to_body(i, dw_p))), f"dw{tag}_")
        else:
            r_q = tuple(r[j] + e * q[k] for j, e in enumerate(_matvec(body.placement.rotation, z)))
            a_o = tuple(a_p[j] + e for j, e in enumerate(
                tuple(x + y for x, y in zip(_cross(dw_p, r_q), _cross(w_p, _cross(w_p, r_q))))))
            w = b.define_all(to_body(i, w_p), f"w{tag}_")
            dw = b.define_all(to_body(i, dw_p), f"dw{tag}_")
            cor = _cross(w, tuple(2 * z[j] * qd[k] for j in range(3)))
            a = b.define_all(tuple(e + cor[j] + z[j] * qdd[k] for j, e in
                                   enumerate(to_body(i, b.define_all(a_o, f"ap{tag}_")))), f"a{tag}_")
        omega.append(w)
        domega.append(dw)
        acc.append(a)

    force: list = [None] * n
    moment: list = [None] * n
    for i, body in enumerate(tree.bodies):
        tag = body.q_index + 1
        par = body.inertial
        m, h, I = par.mass, par.first_moment, par.inertia
        w, dw, a = omega[i], domega[i], acc[i]
        f = tuple(m * a[j] + x + y for j, (x, y) in enumerate(zip(_cross(dw, h), _cross(w, _cross(w, h)))))
        Iw = b.define_all(_matvec(I, w), f"Iw{tag}_")
        nn = tuple(x + y + z_ for x, y, z_ in zip(_matvec(I, dw), _cross(w, Iw), _cross(h, a)))
        force[i] = list(f)
        moment[i] = list(nn)

    tau = sp.zeros(n, 1)
    for i in reversed(range(n)):
        body = tree.bodies[i]
        tag = body.q_index + 1
        f = b.define_all(force[i], f"f{tag}_")
        nn = b.define_all(moment[i], f"n{tag}_")
        axis = body.joint.axis
        tau[body.q_index, 0] = b.define(_dot(axis, nn if body.joint.type.is_revolute else f),
                                        f"tau{tag}")
        p = body.parent
        if p >= 0:
            f_p = to_parent(i, f)
            n_p = to_parent(i, nn)
            if body.joint.type.is_revolute:
                r = body.placement.translation
            else:
                r = tuple(body.placement.translation[j] + e * q[body.q_index]
                          for j, e in enumerate(_matvec(body.placement.rotation, axis)))
            f_p = b.define_all(f_p, f"fp{tag}_")
            rf = _cross(r, f_p)
            for j in range(3):
                force[p][j] = force[p][j] + f_p[j]
                moment[p][j] = moment[p][j] + n_p[j] + rf[j]
    return tau
