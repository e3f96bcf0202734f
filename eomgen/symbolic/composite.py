"""M, C and g in world axes: composite bodies, the Christoffel symbols of the closed-form ∂M/∂q
and Echeandia and Wensing's Coriolis recursion, as straight-line programs.

These are the world-frame routes among which :mod:`eomgen.symbolic.routes` chooses (beside the
body-frame CRBA of :mod:`eomgen.symbolic.crba` and the Newton–Euler g of
:mod:`eomgen.symbolic.newton_euler`); every route gives the same matrices, C is always the
Christoffel C. :func:`forward_kinematics` (world rotations, origins and motion axes) is also
what :mod:`eomgen.symbolic.frames` builds on.

The world-frame programs are the Lagrangian method, M = Σ_l J_lᵀ I_l J_l and c_ijk = ½(∂M_ij/∂q_k + ∂M_ik/∂q_j −
∂M_jk/∂q_i), with the sums over links regrouped by subtree so that no expression grows with the
number of links:

* Every quantity is expressed in the **world (root link) frame**'s orientation; spatial vectors
  are 6-vectors ``[angular; linear]`` referred to one fixed point on the robot, ``o``: the origin
  of the first moving joint (a constant, since nothing before that joint moves). Positions
  ``p_i`` are measured from ``o``. Referring to ``o`` rather than to the root origin keeps the
  digits of a robot far from its root origin (a mobile base in a map frame): about the root
  origin, a robot at distance d with links of size ℓ has inertias with terms m d² that cancel in
  M and lose (d/ℓ)² relative; about ``o`` only link-sized offsets appear. ``S_i`` is the motion axis of joint i
  (``[z_i; p_i × z_i]`` for a revolute joint through ``p_i``, ``[0; z_i]`` for a prismatic one,
  ``[z_i; p_i × z_i + λ z_i]`` for a helical one of pitch ``λ``),
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

from ..model.bodies import BodyTree
from ..model import Vec3
from .program import ProgramBuilder
from .spatial import (SpatialInertia, cross, dot, force_cross, matmul, matvec, motion_cross,
                      mul, rotation)


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
                       enumerate(matmul(Rp, body.placement.rotation)))
            p0 = b.define_all(tuple(pp[r] + e for r, e in
                                    enumerate(matvec(Rp, body.placement.translation))), f"o{n}_",
                                ("o", n))
        z = b.define_all(matvec(R0, joint.axis), f"z{n}_", ("z", n))
        qi = q[body.q_index]
        if joint.rotates:
            s = b.define(sp.sin(qi), f"s{n}", ("s", n))
            c = b.define(sp.cos(qi), f"c{n}", ("c", n))
            kin.sin_cos.append((s, c))
            R = tuple(b.define_all(row, f"R{n}_{r}", ("R", n, r)) for r, row in
                      enumerate(matmul(R0, rotation(joint.axis, c, s))))
            p = p0
            if joint.lead == 0:
                S = z + b.define_all(cross(p, z), f"v{n}_", ("v", n))
            else:  # helical: the origin slides λ q along z; S = (z, p × z + λ z)
                lead = joint.lead
                p = b.define_all(tuple(p0[r] + z[r] * (lead * qi) for r in range(3)),
                                 f"p{n}_", ("p", n))
                S = z + b.define_all(tuple(e + lead * z[r] for r, e in enumerate(cross(p0, z))),
                                     f"v{n}_", ("v", n))
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
        Rh = b.define_all(matvec(R, par.first_moment), f"Rh{n}_",
                          ("Rh", n))
        RI = matmul(R, par.inertia)
        RIRt = [[sp.Add(*[mul(RI[r][k], R[c][k]) for k in range(3)]) for c in range(3)]
                for r in range(3)]
        pp = sp.Add(*[x * x for x in p])
        pRh = dot(p, Rh)
        I = [[None] * 3 for _ in range(3)]
        for r in range(3):
            for c in range(r, 3):
                value = (RIRt[r][c] + m * ((pp if r == c else 0) - mul(p[r], p[c]))
                         + (2 * pRh if r == c else 0) - mul(p[r], Rh[c]) - mul(Rh[r], p[c]))
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


def world_composites(tree: BodyTree, q, b: ProgramBuilder) -> tuple:
    """World-frame kinematics, body and composite inertias and ``F_j = I^c_j S_j`` of every
    body (built once per builder, tree and q)."""
    key = ("world composites", id(tree), tuple(q))
    if key in b.memo:
        return b.memo[key][1]
    kin = forward_kinematics(tree, q, b)
    world = body_inertia_in_world(tree, kin, b)
    comp = composite_inertias(tree, world, b)
    F = [b.define_all(comp[j].apply(kin.S[j]), f"F{tree.bodies[j].q_index + 1}_",
                      ("F", tree.bodies[j].q_index + 1)) for j in range(len(tree.bodies))]
    b.memo[key] = (tree, (kin, world, comp, F))  # the tree kept alive: its id stays its own
    return b.memo[key][1]


def composite_M_program(tree: BodyTree, q, b: ProgramBuilder) -> sp.Matrix:
    """M(q) as ``M_ij = S_iᵀ F_j`` in world axes (module docstring), n×n, ``JOINT_NAMES``
    order [kg m², kg m, kg]."""
    n = len(tree.bodies)
    kin, _, _, F = world_composites(tree, q, b)
    idx = [body.q_index for body in tree.bodies]
    M = sp.zeros(n, n)
    for j in range(n):
        for i in [j] + tree.ancestors(j):
            value = b.define(dot(kin.S[i], F[j]), f"M{idx[i] + 1}_{idx[j] + 1}",
                             ("M", idx[i] + 1, idx[j] + 1))
            M[idx[i], idx[j]] = M[idx[j], idx[i]] = value
    return M


def composite_gravity_program(tree: BodyTree, q, gravity: Vec3, b: ProgramBuilder) -> sp.Matrix:
    """g(q) as ``g_i = −g_vecᵀ f_i``, ``f_i`` the linear part of ``F_i`` (module docstring),
    n×1 [N m or N]."""
    _, _, _, F = world_composites(tree, q, b)
    g = sp.zeros(len(tree.bodies), 1)
    for i, body in enumerate(tree.bodies):
        g[body.q_index, 0] = b.define(-dot(gravity, F[i][3:]), f"g{body.q_index + 1}",
                                      ("g", body.q_index + 1))
    return g


def christoffel_coriolis_program(tree: BodyTree, q, qd, b: ProgramBuilder) -> sp.Matrix:
    """C(q, q̇) from the Christoffel symbols of the first kind and the closed-form ∂M/∂q of the
    module docstring, n×n, ``JOINT_NAMES`` order."""
    kin, _, comp, F = world_composites(tree, q, b)
    return _coriolis(tree, kin.S, F, comp, qd, [body.q_index for body in tree.bodies], b)


def potential_energy(tree: BodyTree, kin: Kinematics, gravity: Vec3) -> sp.Expr:
    """``P = −g_vecᵀ Σ_l m_l c_l`` [J], ``c_l`` the centre of mass of body l from the root
    origin: ``m_l c_l = m_l (o + p_l) + R_l h_l`` with the body's own first moment ``h_l``."""
    moment = [sp.Integer(0)] * 3
    for i, body in enumerate(tree.bodies):
        par = body.inertial
        Rh = matvec(kin.R[i], par.first_moment)
        for r in range(3):
            moment[r] += par.mass * (kin.origin[r] + kin.p[i][r]) + Rh[r]
    return -dot(gravity, moment)


def coriolis_program(tree: BodyTree, q, qd, b: ProgramBuilder) -> sp.Matrix:
    """The Christoffel-consistent Coriolis matrix C(q, q̇) (n×n, ``JOINT_NAMES`` order).

    Echeandia and Wensing's recursion ("Numerical methods to compute the Coriolis matrix and
    Christoffel symbols for rigid-body systems", J. Comput. Nonlinear Dyn. 16(9), 2021), here
    with every quantity in world axes about the reference point ``o``. With ``V_k`` the spatial
    velocity of body k, ``Ṡ_k = V_k × S_k`` and, per body,
    ``B_k = ½ (V_k ×* I_k − I_k V_k × + (I_k V_k) ×̄*)`` (``f ×̄* u = u ×* f``), the matrix

        C = Σ_k J_kᵀ (I_k J̇_k + B_k J_k)

    has ``C q̇`` the Coriolis and centrifugal efforts and ``C + Cᵀ = Ṁ`` (``B_k + B_kᵀ = İ_k``),
    and it is exactly the matrix of the Christoffel symbols of the first kind,
    ``C_ij = Σ_k c_ijk q̇_k`` (their Theorem). Summed over subtrees, ``B^c_j = ½ (İ^c_j +
    (h^c_j) ×̄*)`` needs only the composite inertia's rate ``İ^c_j`` (a first-moment rate and a
    symmetric 3×3, the mass being constant) and the subtree's momentum ``h^c_j = Σ I_k V_k``.
    For i an ancestor of (or equal to) j:

        C_ij = S_iᵀ (I^c_j Ṡ_j + B^c_j S_j),    C_ji = Ṡ_iᵀ I^c_j S_j + S_iᵀ B^c_jᵀ S_j,

    and 0 for joints on different branches. O(n²) operations for a chain, against O(n³) for
    the Christoffel symbols themselves. Inertial parameters are the grouped ones of
    :func:`~eomgen.symbolic.newton_euler.grouped_inertials`, which give the same M and so the
    same C.
    """
    n = len(tree.bodies)
    idx = [body.q_index + 1 for body in tree.bodies]
    kin, world, comp, F_all = world_composites(tree, q, b)
    S = kin.S
    zero6 = (sp.Integer(0),) * 6
    V, Sd = [], []
    for i, body in enumerate(tree.bodies):
        V_p = V[body.parent] if body.parent >= 0 else zero6
        Sd.append(b.define_all(motion_cross(V_p, S[i]), f"Sd{idx[i]}_", ("Sd", idx[i])))
        V.append(b.define_all(tuple(V_p[r] + S[i][r] * qd[body.q_index] for r in range(6)),
                              f"V{idx[i]}_", ("V", idx[i])))
    # per body: momentum I_k V_k, rates of the first moment and of the rotational inertia
    momentum, h_rate, I_rate = [], [], []
    for i, par in enumerate(world):
        w, v = V[i][:3], V[i][3:]
        momentum.append(list(par.apply(V[i])))
        wh = cross(w, par.h)
        h_rate.append([par.mass * v[r] + wh[r] for r in range(3)])
        A = [cross(w, tuple(par.I[r][c] for r in range(3))) for c in range(3)]  # columns of [ω]× Ī
        hv = 2 * dot(par.h, v)
        I_rate.append([[A[c][r] + A[r][c] - v[r] * par.h[c] - par.h[r] * v[c]
                        + (hv if r == c else 0) for c in range(3)] for r in range(3)])
    for i in reversed(range(n)):
        tag = idx[i]
        momentum[i] = b.define_all(momentum[i], f"hV{tag}_", ("hV", tag))
        h_rate[i] = b.define_all(h_rate[i], f"hd{tag}_", ("hd", tag))
        for r in range(3):
            for c in range(r, 3):
                I_rate[i][r][c] = I_rate[i][c][r] = b.define(I_rate[i][r][c], f"Id{tag}_{r}{c}",
                                                             ("Id", tag, r, c))
        parent = tree.bodies[i].parent
        if parent >= 0:
            momentum[parent] = [x + y for x, y in zip(momentum[parent], momentum[i])]
            h_rate[parent] = [x + y for x, y in zip(h_rate[parent], h_rate[i])]
            I_rate[parent] = [[x + y for x, y in zip(r1, r2)]
                              for r1, r2 in zip(I_rate[parent], I_rate[i])]
    half = sp.Rational(1, 2)
    C = sp.zeros(n, n)
    for j in range(n):
        tag = idx[j]
        F = F_all[j]  # I^c_j S_j
        rate = SpatialInertia(sp.Integer(0), tuple(h_rate[j]), tuple(tuple(r) for r in I_rate[j]))
        IdS = rate.apply(S[j])                                # İ^c_j S_j
        X = force_cross(S[j], momentum[j])                    # S_j ×* h^c_j
        ISd = comp[j].apply(Sd[j])
        F1 = b.define_all(tuple(ISd[r] + half * (IdS[r] + X[r]) for r in range(6)), f"Fa{tag}_",
                          ("Fa", tag))
        C[tag - 1, tag - 1] = b.define(dot(S[j], F1), f"C{tag}_{tag}", ("C", tag, tag))
        ancestors = tree.ancestors(j)
        if not ancestors:
            continue
        F3 = b.define_all(tuple(half * (IdS[r] - X[r]) for r in range(6)), f"Fb{tag}_",
                          ("Fb", tag))
        for i in ancestors:
            a, c = tree.bodies[i].q_index, tree.bodies[j].q_index
            C[a, c] = b.define(dot(S[i], F1), f"C{idx[i]}_{tag}", ("C", idx[i], tag))
            C[c, a] = b.define(dot(Sd[i], F) + dot(S[i], F3), f"C{tag}_{idx[i]}",
                               ("C", tag, idx[i]))
    return C


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
            value = dot(S[i], SxF(k, j))
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
