"""Lagrangian dynamics through composite bodies, as a straight-line program.

This is the Lagrangian method, M = Σ_l J_lᵀ I_l J_l and c_ijk = ½(∂M_ij/∂q_k + ∂M_ik/∂q_j −
∂M_jk/∂q_i), with the sums over links regrouped by subtree so that no expression grows with the
number of links:

* Every quantity is expressed in the **world (root link) frame**'s orientation; spatial vectors
  are 6-vectors ``[angular; linear]`` referred to one fixed point on the robot, ``o``: the origin
  of the first moving joint (a constant, since nothing before that joint moves). Positions
  ``p_i`` are measured from ``o``. Referring to ``o`` rather than to the root origin keeps the
  digits of a robot far from its root origin (a mobile base in a map frame): about the root
  origin, a robot at distance d with links of size ℓ has inertias with terms m d² that cancel in
  M and lose (d/ℓ)² relative; about ``o`` only link-sized offsets appear. ``S_i`` is the motion axis of joint i
  (``[z_i; p_i × z_i]`` for a revolute joint through ``p_i``, ``[0; z_i]`` for a prismatic one),
  so that the column i of the spatial Jacobian of any body after joint i is ``S_i``.
* ``I^c_j`` is the spatial inertia of the subtree rooted at body j about ``o``, a sum of the
  bodies' inertial parameters (m, h, Ī) moved to the world orientation and to ``o``.
* ``F_j = I^c_j S_j`` (the momentum of the subtree for a unit rate of joint j), and
  ``M_ij = S_iᵀ F_j`` for i an ancestor of (or equal to) j; 0 when i and j lie on different
  branches.
* ``∂M/∂q`` is exact and closed form, from ``∂S_j/∂q_k = S_k × S_j`` (k a strict ancestor of j)
  and ``∂I^c_j/∂q_k = S_k ×* I^c − I^c S_k ×`` (with I^c the composite that joint k moves):

  - ``∂M_ij/∂q_k = S_iᵀ (S_k ×* F_j)``                                  for i ≺ k ⪯ j,
  - ``∂M_ij/∂q_k = −(S_k × S_i)ᵀ I^c_k S_j − (I^c_k S_i)ᵀ (S_k × S_j)``  for j ≺ k,
  - 0 otherwise (in particular for k ⪯ i: moving everything rigidly leaves M_ij unchanged).
* ``g_i = ∂P/∂q_i = −g_vecᵀ f_i`` where ``f_i`` is the linear part of ``F_i`` and
  ``P = −Σ m_l g_vecᵀ c_l`` (``g_vec`` the gravitational acceleration, e.g. (0, 0, −9.81);
  ``c_l`` from the root origin: P is the potential energy in the root frame).

Units: SI (rad, m, kg, s). Sign convention: M q̈ + C q̇ + g = τ.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp

from ..bodies import BodyTree
from ..model import Mat3, Vec3
from .program import ProgramBuilder


def _cross(a: Vec3, b: Vec3) -> tuple:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _dot(a, b) -> sp.Expr:
    return sp.Add(*[x * y for x, y in zip(a, b)])


def _matvec(A, v) -> tuple:
    return tuple(sp.Add(*[A[r][k] * v[k] for k in range(3)]) for r in range(3))


def _matmul(A, B) -> tuple:
    return tuple(tuple(sp.Add(*[A[r][k] * B[k][c] for k in range(3)]) for c in range(3))
                 for r in range(3))


def _rotation(axis: Vec3, c, s) -> tuple:
    """Rotation about unit ``axis`` by the angle whose cosine and sine are ``c`` and ``s``."""
    x, y, z = axis
    t = 1 - c
    return (
        (t * x * x + c, t * x * y - s * z, t * x * z + s * y),
        (t * x * y + s * z, t * y * y + c, t * y * z - s * x),
        (t * x * z - s * y, t * y * z + s * x, t * z * z + c),
    )


@dataclass
class SpatialInertia:
    """Inertial parameters about the reference point o (world orientation): mass, first moment h,
    inertia Ī (3×3)."""

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
        """Momentum ``I S`` of the motion ``S = [ω; v]``: ``[Ī ω + h × v; m v − h × ω]``."""
        w, v = S[:3], S[3:]
        Iw = _matvec(self.I, w)
        hv = _cross(self.h, v)
        hw = _cross(self.h, w)
        n = tuple(Iw[r] + hv[r] for r in range(3))
        f = tuple(self.mass * v[r] - hw[r] for r in range(3))
        return n + f


def motion_cross(a: tuple, b: tuple) -> tuple:
    """Spatial motion cross product ``a × b`` = [ω_a × ω_b; ω_a × v_b + v_a × ω_b]."""
    wa, va, wb, vb = a[:3], a[3:], b[:3], b[3:]
    w = _cross(wa, wb)
    v1, v2 = _cross(wa, vb), _cross(va, wb)
    return w + tuple(v1[r] + v2[r] for r in range(3))


def force_cross(a: tuple, f: tuple) -> tuple:
    """Spatial force cross product ``a ×* f`` = [ω × n + v × f; ω × f]."""
    w, v, n, lin = a[:3], a[3:], f[:3], f[3:]
    n1, n2 = _cross(w, n), _cross(v, lin)
    return tuple(n1[r] + n2[r] for r in range(3)) + _cross(w, lin)


@dataclass
class Kinematics:
    """World-frame kinematics of every body, as intermediates of a program."""

    R: list = field(default_factory=list)   # body rotation (3×3) in world
    p: list = field(default_factory=list)   # body frame origin, from the point o [m]
    S: list = field(default_factory=list)   # joint motion axis, spatial, about o
    origin: tuple = (0, 0, 0)               # o: the reference point, from the root origin [m]
    sin_cos: list = field(default_factory=list)


def forward_kinematics(tree: BodyTree, q, b: ProgramBuilder) -> Kinematics:
    """World rotations ``R_i``, origins ``p_i`` (from the reference point ``o``, the first moving
    joint's origin) and motion axes ``S_i`` (about ``o``) of all bodies."""
    roots = [body for body in tree.bodies if body.parent < 0]
    origin = tuple(sp.sympify(x) for x in roots[0].placement.translation) if roots else (
        sp.Integer(0),) * 3
    kin = Kinematics(origin=origin)
    for i, body in enumerate(tree.bodies):
        n = body.q_index + 1
        joint = body.joint
        if body.parent < 0:
            R0 = body.placement.rotation
            p0 = tuple(sp.sympify(x) - o for x, o in zip(body.placement.translation, origin))
        else:
            Rp, pp = kin.R[body.parent], kin.p[body.parent]
            R0 = tuple(b.define_all(row, f"A{n}_{r}", ("A", n, r)) for r, row in
                       enumerate(_matmul(Rp, body.placement.rotation)))
            p0 = b.define_all(tuple(pp[r] + e for r, e in
                                    enumerate(_matvec(Rp, body.placement.translation))), f"o{n}_",
                                ("o", n))
        z = b.define_all(_matvec(R0, joint.axis), f"z{n}_", ("z", n))
        qi = q[body.q_index]
        if joint.type.is_revolute:
            s = b.define(sp.sin(qi), f"s{n}", ("s", n))
            c = b.define(sp.cos(qi), f"c{n}", ("c", n))
            kin.sin_cos.append((s, c))
            R = tuple(b.define_all(row, f"R{n}_{r}", ("R", n, r)) for r, row in
                      enumerate(_matmul(R0, _rotation(joint.axis, c, s))))
            p = p0
            S = z + b.define_all(_cross(p, z), f"v{n}_", ("v", n))
        else:
            kin.sin_cos.append(None)
            R = R0
            p = b.define_all(tuple(p0[r] + z[r] * qi for r in range(3)), f"p{n}_",
                             ("p", n))
            S = (0, 0, 0) + z
        kin.R.append(R)
        kin.p.append(p)
        kin.S.append(tuple(sp.sympify(x) for x in S))
    return kin


def body_inertia_in_world(tree: BodyTree, kin: Kinematics, b: ProgramBuilder) -> list[SpatialInertia]:
    """Each body's inertial parameters about the reference point ``o``, in world orientation."""
    out = []
    for i, body in enumerate(tree.bodies):
        n = body.q_index + 1
        par = body.inertial
        R, p, m = kin.R[i], kin.p[i], par.mass
        Rh = b.define_all(_matvec(R, par.first_moment), f"Rh{n}_",
                          ("Rh", n))
        RI = _matmul(R, par.inertia)
        RIRt = [[sp.Add(*[RI[r][k] * R[c][k] for k in range(3)]) for c in range(3)] for r in range(3)]
        pp = sp.Add(*[x * x for x in p])
        pRh = _dot(p, Rh)
        I = [[None] * 3 for _ in range(3)]
        for r in range(3):
            for c in range(r, 3):
                value = (RIRt[r][c] + m * ((pp if r == c else 0) - p[r] * p[c])
                         + (2 * pRh if r == c else 0) - p[r] * Rh[c] - Rh[r] * p[c])
                I[r][c] = I[c][r] = b.define(value, f"Iw{n}_{r}{c}", ("Iw", n, r, c))
        h = b.define_all(tuple(m * p[r] + Rh[r] for r in range(3)), f"hw{n}_", ("hw", n))
        out.append(SpatialInertia(m, h, tuple(tuple(row) for row in I)))
    return out


def composite_inertias(tree: BodyTree, bodies: list[SpatialInertia], b: ProgramBuilder) -> list[SpatialInertia]:
    """Spatial inertia of each body's subtree, summed from the tips towards the root."""
    comp = list(bodies)
    for i in reversed(range(len(tree.bodies))):
        n = tree.bodies[i].q_index + 1
        ci = comp[i]
        comp[i] = SpatialInertia(
            b.define(ci.mass, f"mc{n}", ("mc", n)),
            b.define_all(ci.h, f"hc{n}_", ("hc", n)),
            tuple(tuple(b.define(ci.I[r][c], f"Ic{n}_{min(r, c)}{max(r, c)}",
                                  ("Ic", n, min(r, c), max(r, c))) for c in range(3))
                  for r in range(3)),
        )
        parent = tree.bodies[i].parent
        if parent >= 0:
            comp[parent] = comp[parent] + comp[i]
    return comp


def is_ancestor_or_self(tree: BodyTree, a: int, j: int) -> bool:
    while j >= 0:
        if j == a:
            return True
        j = tree.bodies[j].parent
    return False


def derive_program(tree: BodyTree, q, qd, gravity: Vec3, outputs: set[str], b: ProgramBuilder) -> dict:
    """Build M, C and/or g (as asked in ``outputs``) into the program builder ``b``.

    Returns a dict with SymPy matrices in terms of intermediates: ``"M"`` (n×n), ``"C"`` (n×n),
    ``"g"`` (n×1), plus ``"P"`` (1×1 potential energy, when g is asked) and the kinematics.
    """
    n = len(tree.bodies)
    kin = forward_kinematics(tree, q, b)
    world = body_inertia_in_world(tree, kin, b)
    comp = composite_inertias(tree, world, b)
    S = kin.S
    F = [b.define_all(comp[j].apply(S[j]), f"F{tree.bodies[j].q_index + 1}_",
                      ("F", tree.bodies[j].q_index + 1)) for j in range(n)]
    idx = [body.q_index for body in tree.bodies]
    result: dict = {"kinematics": kin, "composite": comp}

    if "M" in outputs:
        M = sp.zeros(n, n)
        for j in range(n):
            for i in [j] + tree.ancestors(j):
                value = b.define(_dot(S[i], F[j]), f"M{idx[i] + 1}_{idx[j] + 1}",
                                 ("M", idx[i] + 1, idx[j] + 1))
                M[idx[i], idx[j]] = M[idx[j], idx[i]] = value
        result["M"] = M
    if "g" in outputs:
        gvec = gravity
        result["g"] = sp.Matrix([[0]] * n)
        for i in range(n):
            result["g"][idx[i], 0] = b.define(-_dot(gvec, F[i][3:]), f"g{idx[i] + 1}",
                                              ("g", idx[i] + 1))
        h_total = comp_total_first_moment(tree, comp)  # about o
        mass = sp.Add(*[comp[i].mass for i, body in enumerate(tree.bodies) if body.parent < 0])
        P_total = -_dot(gvec, tuple(h + mass * o for h, o in zip(h_total, kin.origin)))
        result["P"] = sp.Matrix([[b.define(P_total, "P", ("P",))]])
    if "C" in outputs:
        result["C"] = _coriolis(tree, S, F, comp, qd, idx, b)
    return result


def comp_total_first_moment(tree: BodyTree, comp: list[SpatialInertia]) -> tuple:
    roots = [i for i, body in enumerate(tree.bodies) if body.parent < 0]
    return tuple(sp.Add(*[comp[i].h[r] for i in roots]) for r in range(3))


def _coriolis(tree, S, F, comp, qd, idx, b: ProgramBuilder) -> sp.Matrix:
    """Coriolis matrix from the Christoffel symbols of the first kind."""
    n = len(S)
    cross_cache: dict = {}
    inertia_cache: dict = {}
    force_cache: dict = {}

    def SxS(k, a):  # S_k × S_a
        key = (k, a)
        if key not in cross_cache:
            cross_cache[key] = b.define_all(motion_cross(S[k], S[a]), f"X{idx[k] + 1}_{idx[a] + 1}_",
                                            ("X", idx[k] + 1, idx[a] + 1))
        return cross_cache[key]

    def IS(k, a):  # I^c_k S_a
        if a == k:
            return F[k]
        key = (k, a)
        if key not in inertia_cache:
            inertia_cache[key] = b.define_all(comp[k].apply(S[a]), f"G{idx[k] + 1}_{idx[a] + 1}_",
                                              ("G", idx[k] + 1, idx[a] + 1))
        return inertia_cache[key]

    def SxF(k, j):  # S_k ×* F_j
        key = (k, j)
        if key not in force_cache:
            force_cache[key] = b.define_all(force_cross(S[k], F[j]), f"Y{idx[k] + 1}_{idx[j] + 1}_",
                                            ("Y", idx[k] + 1, idx[j] + 1))
        return force_cache[key]

    anc = [[is_ancestor_or_self(tree, a, c) for c in range(n)] for a in range(n)]
    dM_cache: dict = {}

    def dM(i, j, k):
        """∂M_ij/∂q_k with body indices."""
        if not anc[i][j]:
            i, j = j, i
        if not anc[i][j]:
            return sp.Integer(0)  # different branches: M_ij ≡ 0
        key = (i, j, k)
        if key in dM_cache:
            return dM_cache[key]
        if anc[i][k] and i != k and anc[k][j]:
            value = _dot(S[i], SxF(k, j))
        elif anc[j][k] and j != k:
            a, b_, c, d = SxS(k, i), IS(k, j), IS(k, i), SxS(k, j)
            value = sp.Add(*[-x * y for x, y in zip(a, b_) if x != 0 and y != 0],
                           *[-x * y for x, y in zip(c, d) if x != 0 and y != 0])
        else:
            value = sp.Integer(0)
        value = b.define(value, f"dM{idx[i] + 1}_{idx[j] + 1}_{idx[k] + 1}",
                         ("dM", idx[i] + 1, idx[j] + 1, idx[k] + 1))
        dM_cache[key] = value
        return value

    half = sp.Rational(1, 2)
    christoffel: dict = {}
    C = sp.zeros(n, n)
    for i in range(n):
        for j in range(n):
            terms = []
            for k in range(n):
                if (i, k, j) in christoffel:  # c_ijk = c_ikj
                    c_ijk = christoffel[(i, k, j)]
                else:
                    parts = [x for x in (dM(i, j, k), dM(i, k, j), -dM(j, k, i)) if x != 0]
                    c_ijk = b.define(sp.Add(*[half * x for x in parts]),
                                     f"Gamma{idx[i] + 1}_{idx[j] + 1}_{idx[k] + 1}",
                                     ("Gamma", idx[i] + 1, idx[j] + 1, idx[k] + 1)) if parts else 0
                    christoffel[(i, j, k)] = c_ijk
                if c_ijk != 0:
                    terms.append(c_ijk * qd[idx[k]])
            C[idx[i], idx[j]] = b.define(sp.Add(*terms), f"C{idx[i] + 1}_{idx[j] + 1}",
                                          ("C", idx[i] + 1, idx[j] + 1))
    return C


def build_lagrangian(derivation, wanted) -> dict:
    """The builder of M, C and g in :mod:`eomgen.outputs`: :func:`derive_program` on the
    derivation's body tree for the ``wanted`` ones, with the potential energy ``P`` [J] when g is
    among them."""
    result = derive_program(derivation.tree, derivation.q, derivation.qd,
                            derivation.model.gravity, set(wanted), derivation.builder)
    return {name: result[name] for name in ("M", "C", "g", "P") if name in result}
