"""Forward dynamics q̈ = M(q)⁻¹ (τ − C(q, q̇) q̇ − g(q)) by the Articulated-Body Algorithm, as a
straight-line program.

The Articulated-Body Algorithm (ABA; Featherstone, *Rigid Body Dynamics Algorithms*, 2008,
Table 7.1) costs O(n) operations, where forming M (O(n²)) and solving by Cholesky (O(n³))
costs O(n³): for long chains it is the cheaper route to q̈. eomgen builds it symbolically, like
the Newton–Euler τ program (:mod:`eomgen.symbolic.newton_euler`), so that structural zeros of
rotations, offsets, axes and inertias fold away.

Spatial quantities are in **body coordinates, referred to the body-frame origin** (the joint
frame after the joint has moved, see :mod:`eomgen.model`), as pairs of 3-vectors:

* motion ``v = (ω, v_O)``: angular velocity and linear velocity of the point at the origin;
* force ``f = (n, f)``: moment about the origin and force;
* inertia ``I = (A, B, C)``: the symmetric 6×6 ``[[A, B], [Bᵀ, C]]`` with ``f = I v``; a rigid
  body has ``A = I_O``, ``B = [h]×``, ``C = m 1`` (m, h = m c, I_O as in :mod:`eomgen.model.bodies`).

The joint motion subspace is ``S = (k, 0)`` for a revolute joint about the unit axis ``k``,
``(0, k)`` for a prismatic one. Gravity enters as the base acceleration ``a_0 = (0, −g_vec)``.
The three passes (Featherstone's Table 7.1, with ``c_J = 0``):

1. outward: ``v_i = X_i v_p + S_i q̇_i``, ``c_i = v_i ×ₘ S_i q̇_i``, ``p_i = v_i ×* I_i v_i``;
2. inward: ``U_i = I^A_i S_i``, ``D_i = S_iᵀ U_i``, ``u_i = τ_i − S_iᵀ p^A_i``;
   ``I^a = I^A_i − U_i U_iᵀ / D_i``, ``p^a = p^A_i + I^a c_i + U_i u_i / D_i``, added to the
   parent as ``X_iᵀ I^a X_i`` and ``X_iᵀ p^a``;
3. outward: ``a'_i = X_i a_p + c_i``, ``q̈_i = (u_i − U_iᵀ a'_i) / D_i``, ``a_i = a'_i + S_i q̈_i``.

When ``S_i`` is a coordinate axis of the body frame, ``I^a S_i = 0`` holds exactly, and the row
and column of ``I^a`` along ``S_i`` are set to zero rather than computed.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..model.bodies import BodyTree
from ..model import RobotModel, Vec3
from .builders import builds
from .derivation import new_derivation
from .crba import M_program
from .newton_euler import grouped_inertials, inverse_dynamics_program
from .charts import true_accelerations as chart_to_true
from .program import Program, ProgramBuilder, name_expr, name_exprs, name_matrix, name_symmetric
from .spatial import JointFrames, add, cross, dot, joint_subspace, matvec, scale, skew, transpose

_ZERO = sp.Integer(0)


def forward_dynamics_program(tree: BodyTree, q, qd, tau, gravity: Vec3, b: ProgramBuilder,
                             grouped: bool = True, armature=None) -> sp.Matrix:
    """Build q̈(q, q̇, τ) into ``b`` by the Articulated-Body Algorithm.

    Parameters
    ----------
    tree:
        The moving bodies (:func:`eomgen.model.bodies.body_tree`).
    q, qd, tau:
        Joint position, velocity and effort symbols, in ``JOINT_NAMES`` order [rad or m, rad/s or
        m/s, N m or N].
    gravity:
        Gravitational acceleration in the root frame [m/s²], e.g. (0, 0, −9.81).
    b:
        The program builder the intermediates are defined into.
    grouped:
        Run on the grouped inertial parameters of :func:`~eomgen.symbolic.newton_euler.
        grouped_inertials` (the default): they give the same M(q) and C q̇ + g, hence the same
        q̈, with fewer non-zero parameters and so fewer operations.
    armature:
        Per joint in ``JOINT_NAMES`` order, a drive's reflected rotor inertia [kg m² or kg]
        added to the joint's articulated inertia ``D`` (Featherstone's armature): the result is
        then ``(M + diag(armature))⁻¹ (τ − C q̇ − g)``. None: no armature.

    Returns
    -------
    sympy.Matrix
        n×1 joint accelerations [rad/s² or m/s²], in ``JOINT_NAMES`` order.
    """
    n = len(tree.bodies)
    zero = (_ZERO,) * 3
    frames = JointFrames.named(tree, q, b)
    inertials = grouped_inertials(tree) if grouped else [body.inertial for body in tree.bodies]

    def subspace(i):
        return joint_subspace(tree.bodies[i].joint)

    # pass 1: velocities, velocity-product accelerations, bias forces
    vel, cvec, IA, pA = [], [], [], []
    for i, body in enumerate(tree.bodies):
        tag = body.q_index + 1
        S_ang, S_lin = subspace(i)
        rate = qd[body.q_index]
        if body.parent < 0:
            ang, lin = zero, zero
        else:
            ang, lin = frames.motion_to_body(i, *vel[body.parent])
        ang = name_exprs(b, add(ang, scale(S_ang, rate)), f"v{tag}w", ("Vb", tag, 0))
        lin = name_exprs(b, add(lin, scale(S_lin, rate)), f"v{tag}v", ("Vb", tag, 1))
        vel.append((ang, lin))
        vJ_ang, vJ_lin = scale(S_ang, rate), scale(S_lin, rate)
        c_ang = cross(ang, vJ_ang)
        c_lin = add(cross(ang, vJ_lin), cross(lin, vJ_ang))
        cvec.append((name_exprs(b, c_ang, f"c{tag}w", ("cb", tag, 0)),
                     name_exprs(b, c_lin, f"c{tag}v", ("cb", tag, 1))))
        par = inertials[i]
        m, h, I_O = par.mass, par.first_moment, par.inertia
        IA.append([I_O, skew(h), tuple(tuple(m if r == c else _ZERO for c in range(3)) for r in range(3))])
        # p = v ×* (I v): momentum (I_O ω + h × v_O, m v_O − h × ω)
        mom_n = name_exprs(b, add(matvec(I_O, ang), cross(h, lin)), f"h{tag}n", ("hb", tag, 0))
        mom_f = name_exprs(b, add(scale(lin, m), cross(ang, h)), f"h{tag}f", ("hb", tag, 1))
        pA.append([add(cross(ang, mom_n), cross(lin, mom_f)), cross(ang, mom_f)])

    # pass 2: articulated inertias and bias forces, leaves to root
    Uvec: list = [None] * n
    Dinv: list = [None] * n
    uval: list = [None] * n
    for i in reversed(range(n)):
        body = tree.bodies[i]
        tag = body.q_index + 1
        A, B, C = (name_symmetric(b, IA[i][0], f"IA{tag}_A", ("IAb", tag, 0)),
                   name_matrix(b, IA[i][1], f"IA{tag}_B", ("IAb", tag, 1)),
                   name_symmetric(b, IA[i][2], f"IA{tag}_C", ("IAb", tag, 2)))
        p_n = name_exprs(b, pA[i][0], f"pA{tag}n", ("pA", tag, 0))
        p_f = name_exprs(b, pA[i][1], f"pA{tag}f", ("pA", tag, 1))
        S_ang, S_lin = subspace(i)
        # U = I^A S (6-vector: moment part, force part)
        U_n = name_exprs(b, add(matvec(A, S_ang), matvec(B, S_lin)), f"U{tag}n",
                        ("UA", tag, 0))
        U_f = name_exprs(b, add(matvec(transpose(B), S_ang), matvec(C, S_lin)), f"U{tag}f",
                        ("UA", tag, 1))
        D = dot(S_ang, U_n) + dot(S_lin, U_f)
        if armature is not None:  # a drive's reflected rotor inertia on its joint: M + diag(a)
            D = D + armature[body.q_index]
        D = name_expr(b, D, f"D{tag}", ("D", tag))
        Dinv[i] = name_expr(b, 1 / D, f"Dinv{tag}", ("Dinv", tag))
        uval[i] = name_expr(b, tau[body.q_index] - dot(S_ang, p_n) - dot(S_lin, p_f), f"u{tag}",
                        ("u", tag))
        Uvec[i] = (U_n, U_f)
        p = body.parent
        if p < 0:
            continue
        # I^a = I^A − U Uᵀ / D; along a coordinate-axis S its row and column vanish exactly
        # (not with an armature: then D = Sᵀ I^A S + a is no longer U's entry along S)
        Ud_n = name_exprs(b, scale(U_n, Dinv[i]), f"Ud{tag}n", ("Ud", tag, 0))
        Ud_f = name_exprs(b, scale(U_f, Dinv[i]), f"Ud{tag}f", ("Ud", tag, 1))
        six_S = S_ang + S_lin
        axis = [j for j in range(6) if six_S[j] != 0]
        exact_zero = set(axis) if len(axis) == 1 and abs(six_S[axis[0]]) == 1 else set()
        if armature is not None and armature[body.q_index] != 0:
            exact_zero = set()
        U6, Ud6 = U_n + U_f, Ud_n + Ud_f
        full6 = [[(A[r][c] if r < 3 and c < 3 else B[r][c - 3] if r < 3 else
                   B[c][r - 3] if c < 3 else C[r - 3][c - 3]) for c in range(6)] for r in range(6)]
        Ia = [[_ZERO] * 6 for _ in range(6)]
        for r in range(6):
            for c in range(r, 6):
                if r in exact_zero or c in exact_zero:
                    continue
                Ia[r][c] = Ia[c][r] = name_expr(b, full6[r][c] - Ud6[r] * U6[c], f"Ia{tag}_{r}{c}",
                                            ("Ia", tag, r, c))
        # p^a = p^A + I^a c + U u / D
        c6 = cvec[i][0] + cvec[i][1]
        Iac = [sp.Add(*[Ia[r][k] * c6[k] for k in range(6)]) for r in range(6)]
        pa = [p_n[r] + Iac[r] + Ud_n[r] * uval[i] for r in range(3)]
        pa_f = [p_f[r] + Iac[r + 3] + Ud_f[r] * uval[i] for r in range(3)]
        pa_n = name_exprs(b, pa, f"pa{tag}n", ("pa", tag, 0))
        pa_f = name_exprs(b, pa_f, f"pa{tag}f", ("pa", tag, 1))
        a_blk = tuple(tuple(Ia[r][c] for c in range(3)) for r in range(3))
        b_blk = tuple(tuple(Ia[r][c + 3] for c in range(3)) for r in range(3))
        c_blk = tuple(tuple(Ia[r + 3][c + 3] for c in range(3)) for r in range(3))
        A_p, B_p, C_p = frames.inertia_to_parent(i, a_blk, b_blk, c_blk, b, tag)
        IA[p] = [tuple(tuple(x + y for x, y in zip(r1, r2)) for r1, r2 in zip(IA[p][0], A_p)),
                 tuple(tuple(x + y for x, y in zip(r1, r2)) for r1, r2 in zip(IA[p][1], B_p)),
                 tuple(tuple(x + y for x, y in zip(r1, r2)) for r1, r2 in zip(IA[p][2], C_p))]
        n_p, f_p = frames.force_to_parent(i, pa_n, pa_f)
        pA[p] = [add(pA[p][0], n_p), add(pA[p][1], f_p)]

    # pass 3: accelerations, root to leaves
    qdd = sp.zeros(n, 1)
    acc: list = [None] * n
    base = (zero, tuple(-x for x in gravity))
    for i, body in enumerate(tree.bodies):
        tag = body.q_index + 1
        a_ang, a_lin = base if body.parent < 0 else acc[body.parent]
        a_ang, a_lin = frames.motion_to_body(i, a_ang, a_lin)
        a_ang = name_exprs(b, add(a_ang, cvec[i][0]), f"ap{tag}w", ("aprime", tag, 0))
        a_lin = name_exprs(b, add(a_lin, cvec[i][1]), f"ap{tag}v", ("aprime", tag, 1))
        U_n, U_f = Uvec[i]
        x = name_expr(b, Dinv[i] * (uval[i] - dot(U_n, a_ang) - dot(U_f, a_lin)), f"qdd{tag}",
                  ("qdd", tag))
        qdd[body.q_index, 0] = x
        S_ang, S_lin = subspace(i)
        acc[i] = (name_exprs(b, add(a_ang, scale(S_ang, x)), f"a{tag}w", ("ab", tag, 0)),
                  name_exprs(b, add(a_lin, scale(S_lin, x)), f"a{tag}v", ("ab", tag, 1)))
    return qdd


@dataclass(frozen=True)
class ForwardDynamics:
    """A forward-dynamics program q̈(q, q̇, τ) of one model.

    Attributes
    ----------
    q, qd, tau:
        Input symbols, in ``JOINT_NAMES`` order.
    program:
        Straight-line program with the single output ``"qdd"`` (n×1).
    """

    q: tuple[sp.Symbol, ...]
    qd: tuple[sp.Symbol, ...]
    tau: tuple[sp.Symbol, ...]
    program: Program

    @property
    def inputs(self) -> tuple[sp.Symbol, ...]:
        return self.q + self.qd + self.tau


def aba_program(model: RobotModel) -> ForwardDynamics:
    """The Articulated-Body Algorithm of ``model`` as a straight-line program.

    Parameters kept symbolic in ``model`` stay symbols of the program (then evaluate it with
    their values as further inputs).

    Examples
    --------
    >>> import eomgen
    >>> from eomgen.symbolic.aba import aba_program
    >>> fd = aba_program(eomgen.load(eomgen.example_path("planar_2link")))
    >>> fd.program.output("qdd").shape
    (2, 1)
    """
    d = new_derivation(model, ("q", "qd", "tau"))
    qdd = true_accelerations(d, forward_dynamics_program(d.tree, d.q, d.qd, d.tau,
                                                         model.gravity, d.builder))
    return ForwardDynamics(d.inputs["q"], d.qd, d.tau, d.program([("qdd", qdd)]))


def cholesky_program(model: RobotModel) -> ForwardDynamics:
    """The Cholesky route to q̈ as one straight-line program, for comparison with the ABA.

    M(q) from the body-frame CRBA (:func:`eomgen.symbolic.crba.M_program`, O(n²)),
    the bias ``C q̇ + g = τ(q, q̇, 0)`` from the Newton–Euler program, then ``M = L Lᵀ``
    (``L_jj = √(M_jj − Σ_k L_jk²)``, ``L_ij = (M_ij − Σ_k L_ik L_jk) / L_jj``) and two triangular
    solves, unrolled: Featherstone's CRBA-plus-Cholesky route, whose factorisation is O(n³).
    A generated module's ``forward_dynamics`` does the same arithmetic with its own
    M (the root-frame composite program) and a numeric Cholesky factorisation.
    """
    d = new_derivation(model, ("q", "qd", "tau"))
    tree, q, qd, tau, b = d.tree, d.q, d.qd, d.tau, d.builder
    n = model.dof
    M = M_program(tree, q, b)
    bias = inverse_dynamics_program(tree, q, qd, d.accelerations((_ZERO,) * n), model.gravity, b)
    L = [[_ZERO] * n for _ in range(n)]
    inv_diag = [_ZERO] * n
    for j in range(n):
        for i in range(j, n):
            value = M[i, j] - sp.Add(*[L[i][k] * L[j][k] for k in range(j)])
            if i == j:
                L[j][j] = name_expr(b, sp.sqrt(value), f"L{j + 1}_{j + 1}", ("L", j + 1, j + 1))
                inv_diag[j] = name_expr(b, 1 / L[j][j], f"Linv{j + 1}", ("Linv", j + 1))
            else:
                L[i][j] = name_expr(b, value * inv_diag[j], f"L{i + 1}_{j + 1}", ("L", i + 1, j + 1))
    y = [_ZERO] * n
    for i in range(n):
        rhs = tau[i] - bias[i, 0] - sp.Add(*[L[i][k] * y[k] for k in range(i)])
        y[i] = name_expr(b, rhs * inv_diag[i], f"y{i + 1}", ("ychol", i + 1))
    x = [_ZERO] * n
    for i in reversed(range(n)):
        rhs = y[i] - sp.Add(*[L[k][i] * x[k] for k in range(i + 1, n)])
        x[i] = name_expr(b, rhs * inv_diag[i], f"qdd{i + 1}", ("qdd", i + 1))
    qdd = true_accelerations(d, sp.Matrix(x))
    return ForwardDynamics(d.inputs["q"], qd, tau, d.program([("qdd", qdd)]))


@builds("qdd_aba")
def build_forward_dynamics_aba(derivation, wanted) -> dict:
    """The builder of ``qdd_aba`` in :mod:`eomgen.outputs` (``forward_dynamics_aba(q, qd,
    tau)``): :func:`forward_dynamics_program` on the derivation's body tree, q̈ [rad/s² or m/s²]
    in ``JOINT_NAMES`` order."""
    qdd = forward_dynamics_program(derivation.tree, derivation.q, derivation.qd, derivation.tau,
                                   derivation.model.gravity, derivation.builder)
    return {"qdd_aba": true_accelerations(derivation, qdd)}


def true_accelerations(derivation, qdd: sp.Matrix) -> sp.Matrix:
    """``qdd`` (n×1) from a forward-dynamics program, as the model's accelerations: for
    a model whose configuration is not its coordinates (a free flyer, a ball joint) the chart's
    turned into the derivative of the joint's velocity
    (:func:`eomgen.symbolic.charts.true_accelerations`), named ``vd…``."""
    if derivation.model.nq == derivation.model.dof:  # no chart
        return qdd
    b = derivation.builder
    true = chart_to_true(derivation, derivation.qd, list(qdd))
    return sp.Matrix([b.define(e, f"vd{k + 1}", ("qdd", k + 1)) if e != qdd[k] else e
                      for k, e in enumerate(true)])
