"""Spatial and 3×3 algebra of the symbolic engine: the floor every algorithm stands on.

Vectors are tuples of 3 SymPy expressions, 3×3 matrices tuples of 3 rows; spatial vectors are
6-tuples ``[angular; linear]``: a motion ``(ω, v)`` (angular velocity, linear velocity of the
reference point) or a force ``(n, f)`` (moment about the reference point, force). Each function
says in which frame its inputs and result are. Units are those of the inputs (SI throughout
eomgen: rad, m, kg, s).

Two descriptions of the same quantities are used, each by the algorithms it suits:

* **World axes about one point** (:class:`SpatialInertia`, :func:`motion_cross`,
  :func:`force_cross`): the Lagrangian routes of :mod:`eomgen.symbolic.composite` and the frame
  kinematics of :mod:`eomgen.symbolic.frames`;
* **Body coordinates about the body origin** (:class:`JointFrames`): each body's frame is the
  joint frame after the joint has moved (see :mod:`eomgen.model`); a body's quantities go to
  its parent's frame through the joint's placement ``(R_place, r)`` and its motion
  ``Rot(k, q)`` (revolute), ``k q`` (prismatic) or both, ``Rot(k, q)`` and ``pitch · k q``
  (helical); :func:`joint_subspace` is its motion subspace. A spatial inertia in body
  coordinates is the three 3×3 blocks ``(A, B, C)`` of the symmetric 6×6 ``[[A, B], [Bᵀ, C]]`` with ``f = I v``;
  a rigid body has ``A = I_O``, ``B = [h]×``, ``C = m 1``. Used by the Newton–Euler, CRBA and
  ABA programs and the regressor.

The functions build SymPy expressions in a fixed order (sums as ``sp.Add`` of the products in
index order): the programs printed from them, and so every generated file, depend on it.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..model.bodies import BodyTree
from ..model import Vec3
from .monomials import difference, mul, negated, total
from .program import ProgramBuilder, name_expr, name_exprs, name_matrix, name_symmetric


def cross(a, b) -> tuple:
    """The cross product ``a × b`` of two 3-vectors (in the same axes)."""
    return (difference(mul(a[1], b[2]), mul(a[2], b[1])),
            difference(mul(a[2], b[0]), mul(a[0], b[2])),
            difference(mul(a[0], b[1]), mul(a[1], b[0])))


def dot(a, b) -> sp.Expr:
    """The scalar product ``aᵀ b`` of two vectors of the same length (in the same axes)."""
    return total([mul(x, y) for x, y in zip(a, b)])


def matvec(A, v) -> tuple:
    """``A v`` for a 3×3 ``A`` (rows) and a 3-vector ``v``."""
    return tuple(total([mul(A[r][k], v[k]) for k in range(3)]) for r in range(3))


def transpose_apply(A, v) -> tuple:
    """``Aᵀ v`` for a 3×3 ``A`` (rows) and a 3-vector ``v``, without forming ``Aᵀ``: for a
    rotation from frame b to frame a, ``v`` in a's axes to b's."""
    return tuple(total([mul(A[k][r], v[k]) for k in range(3)]) for r in range(3))


def matmul(A, B) -> tuple:
    """``A B`` for two 3×3 matrices (rows); for rotations, ``R_ab R_bc = R_ac``."""
    return tuple(tuple(total([mul(A[r][k], B[k][c]) for k in range(3)]) for c in range(3))
                 for r in range(3))


def transpose(A) -> tuple:
    """``Aᵀ`` of a 3×3 matrix (rows); for a rotation, its inverse."""
    return tuple(tuple(A[c][r] for c in range(3)) for r in range(3))


def add(a, b) -> tuple:
    """``a + b``, entry by entry, of two vectors of the same length."""
    return tuple(x + y for x, y in zip(a, b))


def scale(a, s) -> tuple:
    """``a s``: each entry of the vector ``a`` times the scalar ``s``."""
    return tuple(x * s for x in a)


def skew(h) -> tuple:
    """``[h]×``, the 3×3 with ``[h]× v = h × v`` (of expressions; the numeric one is
    :func:`eomgen.numeric.so3.skew`)."""
    zero = sp.Integer(0)
    return ((zero, -h[2], h[1]), (h[2], zero, -h[0]), (-h[1], h[0], zero))


def skew_times(p, A) -> tuple:
    """``[p]× A`` for a 3-vector ``p`` and a 3×3 ``A``, column by column (``p × A_c``)."""
    cols = [cross(p, tuple(A[r][c] for r in range(3))) for c in range(3)]
    return tuple(tuple(cols[c][r] for c in range(3)) for r in range(3))


def rotation(axis: Vec3, c, s) -> tuple:
    """``Rot(axis, θ)``: the rotation about the unit ``axis`` by the angle θ whose cosine and
    sine are ``c`` and ``s`` (right-handed, axis-angle/Rodrigues form ``c 1 + s [k]× + (1 − c)
    k kᵀ``). For a joint, it maps body axes to the joint frame's axes."""
    x, y, z = axis
    t = 1 - c
    return (
        (t * x * x + c, t * x * y - s * z, t * x * z + s * y),
        (t * x * y + s * z, t * y * y + c, t * y * z - s * x),
        (t * x * z - s * y, t * y * z + s * x, t * z * z + c),
    )


def rotate_back(axis: Vec3, c, s, v) -> tuple:
    """``Rot(axis, θ)ᵀ v`` by Rodrigues' formula, ``v c − (k × v) s + k (k·v)(1 − c)``, for the
    unit ``axis`` k and the angle θ of cosine ``c`` and sine ``s`` (``−s`` gives
    ``Rot(axis, θ) v``)."""
    k_cross_v = cross(axis, v)
    k_dot_v = dot(axis, v)
    return tuple(total([mul(v[r], c), negated(mul(k_cross_v[r], s)),
                        mul(mul(axis[r], k_dot_v), 1 - c)]) for r in range(3))


def aligned_axis(axis) -> tuple[int, int] | None:
    """``(k, sign)`` when ``axis`` is ``sign`` times the k-th unit vector (k = 0, 1, 2), else
    None."""
    values = tuple(axis)
    for k in range(3):
        for sign in (1, -1):
            if values == tuple(sign if j == k else 0 for j in range(3)):
                return k, sign
    return None


def rotate_aligned(k: int, c, s, v, transpose: bool) -> tuple:
    """``Rot(e_k, θ) v``, or ``Rot(e_k, θ)ᵀ v`` with ``transpose``, for the unit vector
    ``e_k`` of axis ``k`` (cosine ``c``, sine ``s``), touching only the two components that
    change."""
    i, j = (k + 1) % 3, (k + 2) % 3
    if transpose:
        s = -s
    w = [None, None, None]
    w[i] = mul(c, v[i]) - mul(s, v[j])
    w[j] = mul(s, v[i]) + mul(c, v[j])
    w[k] = v[k]
    return tuple(w)


def joint_subspace(joint) -> tuple[tuple, tuple]:
    """``(S_ang, S_lin)``: the motion subspace of a one-axis ``joint`` (a
    :class:`~eomgen.model.Joint`) in its body frame, angular part first: ``(k, 0)`` revolute,
    ``(0, k)`` prismatic, ``(k, pitch · k)`` helical (``k`` the unit axis;
    :attr:`~eomgen.model.Joint.rotates`, :attr:`~eomgen.model.Joint.lead`)."""
    k, zero = tuple(joint.axis), (sp.Integer(0),) * 3
    lead = joint.lead
    return (k if joint.rotates else zero,
            zero if lead == 0 else k if lead == 1 else tuple(mul(lead, x) for x in k))


@dataclass
class SpatialInertia:
    """The spatial inertia of a body or subtree **in world axes about a fixed reference point**
    o: mass m [kg], first moment ``h = m c`` [kg m] (c the centre of mass from o), and the
    rotational inertia Ī about o [kg m²] (3×3, rows)."""

    mass: sp.Expr
    h: tuple
    I: tuple

    def __add__(self, other: "SpatialInertia") -> "SpatialInertia":
        return SpatialInertia(
            self.mass + other.mass,
            tuple(a + b for a, b in zip(self.h, other.h)),
            tuple(tuple(a + b for a, b in zip(r, s)) for r, s in zip(self.I, other.I)),
        )

    def apply(self, S: tuple) -> tuple:
        """Momentum ``I S`` of the motion ``S = [ω; v]`` (about o): ``[Ī ω + h × v; m v − h × ω]``."""
        w, v = S[:3], S[3:]
        Iw = matvec(self.I, w)
        hv = cross(self.h, v)
        hw = cross(self.h, w)
        n = tuple(Iw[r] + hv[r] for r in range(3))
        f = tuple(mul(self.mass, v[r]) - hw[r] for r in range(3))
        return n + f


def motion_cross(a: tuple, b: tuple) -> tuple:
    """Spatial motion cross product ``a × b`` = [ω_a × ω_b; ω_a × v_b + v_a × ω_b] (both
    motions in the same axes, about the same point)."""
    wa, va, wb, vb = a[:3], a[3:], b[:3], b[3:]
    w = cross(wa, wb)
    v1, v2 = cross(wa, vb), cross(va, wb)
    return w + tuple(v1[r] + v2[r] for r in range(3))


def force_cross(a: tuple, f: tuple) -> tuple:
    """Spatial force cross product ``a ×* f`` = [ω × n + v × f; ω × f] (motion ``a = [ω; v]``
    and force ``f = [n; f]`` in the same axes, about the same point)."""
    w, v, n, lin = a[:3], a[3:], f[:3], f[3:]
    n1, n2 = cross(w, n), cross(v, lin)
    return tuple(n1[r] + n2[r] for r in range(3)) + cross(w, lin)


class JointFrames:
    """Transforms between each body's frame and its parent's, through the joint.

    Body i's frame is its joint frame after the joint has moved: a parent-frame vector ``v``
    reads ``Rot(k, q)ᵀ R_placeᵀ v`` in body i (a revolute or helical joint about the unit axis
    ``k``, placement rotation ``R_place``; a prismatic joint rotates nothing), and body i's
    origin sits at :meth:`offset` in the parent frame. Rotations use each rotating joint's sine
    and cosine, ``sincos[i] = (s_i, c_i)`` (None for a prismatic joint).
    """

    def __init__(self, tree: BodyTree, q, sincos):
        self.tree, self.q, self.sincos = tree, q, sincos

    @classmethod
    def named(cls, tree: BodyTree, q, b: ProgramBuilder) -> "JointFrames":
        """The frames of ``tree`` with each rotating joint's ``s_k``, ``c_k`` named in ``b``."""
        sincos = []
        for body in tree.bodies:
            k = body.q_index
            if body.joint.rotates:
                sincos.append((name_expr(b, sp.sin(q[k]), f"s{k + 1}", ("s", k + 1)),
                               name_expr(b, sp.cos(q[k]), f"c{k + 1}", ("c", k + 1))))
            else:
                sincos.append(None)
        return cls(tree, q, sincos)

    def to_body(self, i, v) -> tuple:
        """Parent-frame 3-vector → body i frame: Rot(k, q)ᵀ R_placeᵀ v."""
        body = self.tree.bodies[i]
        w = transpose_apply(body.placement.rotation, v)
        if body.joint.rotates:
            s, c = self.sincos[i]
            aligned = aligned_axis(body.joint.axis)
            if aligned is not None:
                return rotate_aligned(aligned[0], c, aligned[1] * s, w, transpose=True)
            return rotate_back(body.joint.axis, c, s, w)
        return w

    def to_parent(self, i, v) -> tuple:
        """Body i frame 3-vector → parent frame: R_place Rot(k, q) v."""
        body = self.tree.bodies[i]
        w = v
        if body.joint.rotates:
            s, c = self.sincos[i]
            aligned = aligned_axis(body.joint.axis)
            if aligned is not None:
                w = rotate_aligned(aligned[0], c, aligned[1] * s, v, transpose=False)
            else:
                w = rotate_back(body.joint.axis, c, -s, v)
        return matvec(body.placement.rotation, w)

    def offset(self, i) -> tuple:
        """Body i's origin in the parent frame [m] (moved by ``q`` along the axis for a
        prismatic joint, by ``pitch · q`` for a helical one)."""
        body = self.tree.bodies[i]
        r = body.placement.translation
        lead = body.joint.lead
        if lead == 0:
            return r
        k = matvec(body.placement.rotation, body.joint.axis)
        move = self.q[body.q_index] if lead == 1 else mul(lead, self.q[body.q_index])
        return tuple(r[j] + k[j] * move for j in range(3))

    def motion_to_body(self, i, ang, lin) -> tuple:
        """Motion ``(ω, v)`` in parent coordinates about the parent origin → body i coordinates
        about body i's origin: ``(ω, v + ω × r)`` rotated into body i."""
        moved = add(lin, cross(ang, self.offset(i)))  # velocity of the point at body i's origin
        return self.to_body(i, ang), self.to_body(i, moved)

    def force_to_parent(self, i, n, f) -> tuple:
        """Force ``(n, f)`` in body i coordinates about its origin → parent coordinates about the
        parent origin: ``(R n + r × R f, R f)``."""
        f_p = self.to_parent(i, f)
        return add(self.to_parent(i, n), cross(self.offset(i), f_p)), f_p

    def inertia_to_parent(self, i, A, B, C, b: ProgramBuilder, tag) -> tuple:
        """``X_iᵀ I X_i``: spatial inertia blocks ``(A, B, C)`` in body i coordinates about its
        origin → parent coordinates about the parent origin, the rotated blocks named in ``b``
        (tags ``("RX", tag, block, c)``, ``("XIX", tag, block, r, c)``, ``("shift", tag, k, r,
        c)``).

        With R the rotation and p the offset of body i in its parent, and P = [p]×: the blocks
        are rotated (R A Rᵀ, R B Rᵀ, R C Rᵀ), then referred to the parent origin:
        A_p = A − B P − (B P)ᵀ − P C P, B_p = B + P C, C_p = C.
        """
        def rotated(X, hint, block, symmetric):
            RX = [name_exprs(b, self.to_parent(i, tuple(X[r][c] for r in range(3))),
                             f"{hint}r{c}_", ("RX", tag, block, c))
                  for c in range(3)]  # RX[c] = column c of R X
            # row r of R X Rᵀ is R times row r of R X
            out = [self.to_parent(i, tuple(RX[c][r] for c in range(3))) for r in range(3)]
            return (name_symmetric if symmetric else name_matrix)(b, out, hint,
                                                                  ("XIX", tag, block))

        A = rotated(A, f"Ar{tag}_", 0, True)
        B = rotated(B, f"Br{tag}_", 1, False)
        C = rotated(C, f"Cr{tag}_", 2, True)
        p = self.offset(i)
        if all(x == 0 for x in p):
            return A, B, C
        BP = name_matrix(b, transpose(skew_times(p, transpose(B))), f"BP{tag}_",
                         ("shift", tag, 0))  # −B [p]×
        PC = name_matrix(b, skew_times(p, C), f"PC{tag}_", ("shift", tag, 1))  # [p]× C
        PCP = transpose(skew_times(p, transpose(PC)))  # −[p]× C [p]×
        A_p = tuple(tuple(A[r][c] + BP[r][c] + BP[c][r] + PCP[r][c] for c in range(3))
                    for r in range(3))
        B_p = tuple(tuple(B[r][c] + PC[r][c] for c in range(3)) for r in range(3))
        return A_p, B_p, C


__all__ = ["JointFrames", "SpatialInertia", "add", "aligned_axis", "cross", "difference", "dot",
           "force_cross", "matmul", "matvec", "motion_cross", "mul", "negated", "rotate_aligned",
           "rotate_back", "rotation", "scale", "skew", "skew_times", "total", "transpose",
           "transpose_apply"]
