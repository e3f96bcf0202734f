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
  body has ``A = I_O``, ``B = [h]×``, ``C = m 1`` (m, h = m c, I_O as in :mod:`eomgen.bodies`).

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

from ..bodies import BodyTree
from ..model import RobotModel, Vec3
from .composite import _cross, _dot, _matvec
from .newton_euler import _Frames, _name, _name_all, grouped_inertials
from .program import Tag, _tag
from .derivation import new_derivation
from .program import Program, ProgramBuilder

_ZERO = sp.Integer(0)


def _add(a, b) -> tuple:
    return tuple(x + y for x, y in zip(a, b))


def _scale(a, s) -> tuple:
    return tuple(x * s for x in a)


def _transpose(A) -> tuple:
    return tuple(tuple(A[c][r] for c in range(3)) for r in range(3))


def _skew_times(p, A) -> tuple:
    """[p]× A, column by column."""
    cols = [_cross(p, tuple(A[r][c] for r in range(3))) for c in range(3)]
    return tuple(tuple(cols[c][r] for c in range(3)) for r in range(3))


def _motion_to_body(frames: _Frames, i, ang, lin) -> tuple:
    """Parent-coordinate motion vector (about the parent origin) → body i coordinates."""
    moved = _add(lin, _cross(ang, frames.offset(i)))  # velocity of the point at body i's origin
    return frames.to_body(i, ang), frames.to_body(i, moved)


def _force_to_parent(frames: _Frames, i, n, f) -> tuple:
    f_p = frames.to_parent(i, f)
    return _add(frames.to_parent(i, n), _cross(frames.offset(i), f_p)), f_p


def _inertia_to_parent(frames: _Frames, i, A, B, C, b: ProgramBuilder, tag) -> tuple:
    """``X_iᵀ I X_i``: body-coordinate spatial inertia → parent coordinates and origin.

    With R the rotation and p the offset of body i in its parent, and P = [p]×: the blocks are
    rotated (R A Rᵀ, R B Rᵀ, R C Rᵀ), then referred to the parent origin:
    A_p = A − B P − (B P)ᵀ − P C P, B_p = B + P C, C_p = C.
    """
    def rotated(X, hint, block, symmetric):
        RX = [_name_all(b, frames.to_parent(i, tuple(X[r][c] for r in range(3))), f"{hint}r{c}_",
                        ("RX", tag, block, c)) for c in range(3)]  # RX[c] = column c of R X
        # row r of R X Rᵀ is R times row r of R X
        out = [frames.to_parent(i, tuple(RX[c][r] for c in range(3))) for r in range(3)]
        return (_symmetric if symmetric else _full)(b, out, hint, ("XIX", tag, block))

    A = rotated(A, f"Ar{tag}_", 0, True)
    B = rotated(B, f"Br{tag}_", 1, False)
    C = rotated(C, f"Cr{tag}_", 2, True)
    p = frames.offset(i)
    if all(x == 0 for x in p):
        return A, B, C
    BP = _full(b, _transpose(_skew_times(p, _transpose(B))), f"BP{tag}_",
               ("shift", tag, 0))  # −B [p]×
    PC = _full(b, _skew_times(p, C), f"PC{tag}_", ("shift", tag, 1))  # [p]× C
    PCP = _transpose(_skew_times(p, _transpose(PC)))  # −[p]× C [p]×
    A_p = tuple(tuple(A[r][c] + BP[r][c] + BP[c][r] + PCP[r][c] for c in range(3))
                for r in range(3))
    B_p = tuple(tuple(B[r][c] + PC[r][c] for c in range(3)) for r in range(3))
    return A_p, B_p, C


def _entry_tag(tag, r, c):
    tag = _tag(tag)
    return None if tag is None else Tag(tag.family, tag.index + (r, c))


def _symmetric(b: ProgramBuilder, A, hint: str, tag=None) -> tuple:
    """Name the upper triangle of a symmetric 3×3 and mirror it (entry (r, c) tagged with
    ``tag``'s index followed by r, c)."""
    named = [[None] * 3 for _ in range(3)]
    for r in range(3):
        for c in range(r, 3):
            named[r][c] = named[c][r] = _name(b, A[r][c], f"{hint}{r}{c}", _entry_tag(tag, r, c))
    return tuple(tuple(row) for row in named)


def _full(b: ProgramBuilder, A, hint: str, tag=None) -> tuple:
    """Name every entry of a 3×3 (entry (r, c) tagged with ``tag``'s index followed by r, c)."""
    return tuple(tuple(_name(b, A[r][c], f"{hint}{r}{c}", _entry_tag(tag, r, c))
                       for c in range(3)) for r in range(3))


def forward_dynamics_program(tree: BodyTree, q, qd, tau, gravity: Vec3, b: ProgramBuilder,
                             grouped: bool = True) -> sp.Matrix:
    """Build q̈(q, q̇, τ) into ``b`` by the Articulated-Body Algorithm.

    Parameters
    ----------
    tree:
        The moving bodies (:func:`eomgen.bodies.body_tree`).
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

    Returns
    -------
    sympy.Matrix
        n×1 joint accelerations [rad/s² or m/s²], in ``JOINT_NAMES`` order.
    """
    n = len(tree.bodies)
    zero = (_ZERO,) * 3
    frames = _Frames.named(tree, q, b)
    inertials = grouped_inertials(tree) if grouped else [body.inertial for body in tree.bodies]

    def subspace(i):
        body = tree.bodies[i]
        k = tuple(body.joint.axis)
        return (k, zero) if body.joint.type.is_revolute else (zero, k)

    # pass 1: velocities, velocity-product accelerations, bias forces
    vel, cvec, IA, pA = [], [], [], []
    for i, body in enumerate(tree.bodies):
        tag = body.q_index + 1
        S_ang, S_lin = subspace(i)
        rate = qd[body.q_index]
        if body.parent < 0:
            ang, lin = zero, zero
        else:
            ang, lin = _motion_to_body(frames, i, *vel[body.parent])
        ang = _name_all(b, _add(ang, _scale(S_ang, rate)), f"v{tag}w", ("Vb", tag, 0))
        lin = _name_all(b, _add(lin, _scale(S_lin, rate)), f"v{tag}v", ("Vb", tag, 1))
        vel.append((ang, lin))
        vJ_ang, vJ_lin = _scale(S_ang, rate), _scale(S_lin, rate)
        c_ang = _cross(ang, vJ_ang)
        c_lin = _add(_cross(ang, vJ_lin), _cross(lin, vJ_ang))
        cvec.append((_name_all(b, c_ang, f"c{tag}w", ("cb", tag, 0)),
                     _name_all(b, c_lin, f"c{tag}v", ("cb", tag, 1))))
        par = inertials[i]
        m, h, I_O = par.mass, par.first_moment, par.inertia
        Bh = ((0, -h[2], h[1]), (h[2], 0, -h[0]), (-h[1], h[0], 0))
        IA.append([I_O, Bh, tuple(tuple(m if r == c else _ZERO for c in range(3)) for r in range(3))])
        # p = v ×* (I v): momentum (I_O ω + h × v_O, m v_O − h × ω)
        mom_n = _name_all(b, _add(_matvec(I_O, ang), _cross(h, lin)), f"h{tag}n", ("hb", tag, 0))
        mom_f = _name_all(b, _add(_scale(lin, m), _cross(ang, h)), f"h{tag}f", ("hb", tag, 1))
        pA.append([_add(_cross(ang, mom_n), _cross(lin, mom_f)), _cross(ang, mom_f)])

    # pass 2: articulated inertias and bias forces, leaves to root
    Uvec: list = [None] * n
    Dinv: list = [None] * n
    uval: list = [None] * n
    for i in reversed(range(n)):
        body = tree.bodies[i]
        tag = body.q_index + 1
        A, B, C = (_symmetric(b, IA[i][0], f"IA{tag}_A", ("IAb", tag, 0)),
                   _full(b, IA[i][1], f"IA{tag}_B", ("IAb", tag, 1)),
                   _symmetric(b, IA[i][2], f"IA{tag}_C", ("IAb", tag, 2)))
        p_n = _name_all(b, pA[i][0], f"pA{tag}n", ("pA", tag, 0))
        p_f = _name_all(b, pA[i][1], f"pA{tag}f", ("pA", tag, 1))
        S_ang, S_lin = subspace(i)
        # U = I^A S (6-vector: moment part, force part)
        U_n = _name_all(b, _add(_matvec(A, S_ang), _matvec(B, S_lin)), f"U{tag}n",
                        ("UA", tag, 0))
        U_f = _name_all(b, _add(_matvec(_transpose(B), S_ang), _matvec(C, S_lin)), f"U{tag}f",
                        ("UA", tag, 1))
        D = _name(b, _dot(S_ang, U_n) + _dot(S_lin, U_f), f"D{tag}", ("D", tag))
        Dinv[i] = _name(b, 1 / D, f"Dinv{tag}", ("Dinv", tag))
        uval[i] = _name(b, tau[body.q_index] - _dot(S_ang, p_n) - _dot(S_lin, p_f), f"u{tag}",
                        ("u", tag))
        Uvec[i] = (U_n, U_f)
        p = body.parent
        if p < 0:
            continue
        # I^a = I^A − U Uᵀ / D; along a coordinate-axis S its row and column vanish exactly
        Ud_n = _name_all(b, _scale(U_n, Dinv[i]), f"Ud{tag}n", ("Ud", tag, 0))
        Ud_f = _name_all(b, _scale(U_f, Dinv[i]), f"Ud{tag}f", ("Ud", tag, 1))
        six_S = S_ang + S_lin
        axis = [j for j in range(6) if six_S[j] != 0]
        exact_zero = set(axis) if len(axis) == 1 and abs(six_S[axis[0]]) == 1 else set()
        U6, Ud6 = U_n + U_f, Ud_n + Ud_f
        full6 = [[(A[r][c] if r < 3 and c < 3 else B[r][c - 3] if r < 3 else
                   B[c][r - 3] if c < 3 else C[r - 3][c - 3]) for c in range(6)] for r in range(6)]
        Ia = [[_ZERO] * 6 for _ in range(6)]
        for r in range(6):
            for c in range(r, 6):
                if r in exact_zero or c in exact_zero:
                    continue
                Ia[r][c] = Ia[c][r] = _name(b, full6[r][c] - Ud6[r] * U6[c], f"Ia{tag}_{r}{c}",
                                            ("Ia", tag, r, c))
        # p^a = p^A + I^a c + U u / D
        c6 = cvec[i][0] + cvec[i][1]
        Iac = [sp.Add(*[Ia[r][k] * c6[k] for k in range(6)]) for r in range(6)]
        pa = [p_n[r] + Iac[r] + Ud_n[r] * uval[i] for r in range(3)]
        pa_f = [p_f[r] + Iac[r + 3] + Ud_f[r] * uval[i] for r in range(3)]
        pa_n = _name_all(b, pa, f"pa{tag}n", ("pa", tag, 0))
        pa_f = _name_all(b, pa_f, f"pa{tag}f", ("pa", tag, 1))
        a_blk = tuple(tuple(Ia[r][c] for c in range(3)) for r in range(3))
        b_blk = tuple(tuple(Ia[r][c + 3] for c in range(3)) for r in range(3))
        c_blk = tuple(tuple(Ia[r + 3][c + 3] for c in range(3)) for r in range(3))
        A_p, B_p, C_p = _inertia_to_parent(frames, i, a_blk, b_blk, c_blk, b, tag)
        IA[p] = [tuple(tuple(x + y for x, y in zip(r1, r2)) for r1, r2 in zip(IA[p][0], A_p)),
                 tuple(tuple(x + y for x, y in zip(r1, r2)) for r1, r2 in zip(IA[p][1], B_p)),
                 tuple(tuple(x + y for x, y in zip(r1, r2)) for r1, r2 in zip(IA[p][2], C_p))]
        n_p, f_p = _force_to_parent(frames, i, pa_n, pa_f)
        pA[p] = [_add(pA[p][0], n_p), _add(pA[p][1], f_p)]

    # pass 3: accelerations, root to leaves
    qdd = sp.zeros(n, 1)
    acc: list = [None] * n
    base = (zero, tuple(-x for x in gravity))
    for i, body in enumerate(tree.bodies):
        tag = body.q_index + 1
        a_ang, a_lin = base if body.parent < 0 else acc[body.parent]
        a_ang, a_lin = _motion_to_body(frames, i, a_ang, a_lin)
        a_ang = _name_all(b, _add(a_ang, cvec[i][0]), f"ap{tag}w", ("aprime", tag, 0))
        a_lin = _name_all(b, _add(a_lin, cvec[i][1]), f"ap{tag}v", ("aprime", tag, 1))
        U_n, U_f = Uvec[i]
        x = _name(b, Dinv[i] * (uval[i] - _dot(U_n, a_ang) - _dot(U_f, a_lin)), f"qdd{tag}",
                  ("qdd", tag))
        qdd[body.q_index, 0] = x
        S_ang, S_lin = subspace(i)
        acc[i] = (_name_all(b, _add(a_ang, _scale(S_ang, x)), f"a{tag}w", ("ab", tag, 0)),
                  _name_all(b, _add(a_lin, _scale(S_lin, x)), f"a{tag}v", ("ab", tag, 1)))
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
    qdd = forward_dynamics_program(d.tree, d.q, d.qd, d.tau, model.gravity, d.builder)
    return ForwardDynamics(d.q, d.qd, d.tau, d.program([("qdd", qdd)]))


def cholesky_program(model: RobotModel) -> ForwardDynamics:
    """The Cholesky route to q̈ as one straight-line program, for comparison with the ABA.

    M(q) from the body-frame CRBA (:func:`eomgen.symbolic.crba.M_program`, O(n²)),
    the bias ``C q̇ + g = τ(q, q̇, 0)`` from the Newton–Euler program, then ``M = L Lᵀ``
    (``L_jj = √(M_jj − Σ_k L_jk²)``, ``L_ij = (M_ij − Σ_k L_ik L_jk) / L_jj``) and two triangular
    solves, unrolled: Featherstone's CRBA-plus-Cholesky route, whose factorisation is O(n³).
    A generated module's ``forward_dynamics`` does the same arithmetic with its own
    M (the root-frame composite program) and a numeric Cholesky factorisation.
    """
    from .crba import M_program
    from .newton_euler import inverse_dynamics_program

    d = new_derivation(model, ("q", "qd", "tau"))
    tree, q, qd, tau, b = d.tree, d.q, d.qd, d.tau, d.builder
    n = model.dof
    M = M_program(tree, q, b)
    bias = inverse_dynamics_program(tree, q, qd, (_ZERO,) * n, model.gravity, b)
    L = [[_ZERO] * n for _ in range(n)]
    inv_diag = [_ZERO] * n
    for j in range(n):
        for i in range(j, n):
            value = M[i, j] - sp.Add(*[L[i][k] * L[j][k] for k in range(j)])
            if i == j:
                L[j][j] = _name(b, sp.sqrt(value), f"L{j + 1}_{j + 1}", ("L", j + 1, j + 1))
                inv_diag[j] = _name(b, 1 / L[j][j], f"Linv{j + 1}", ("Linv", j + 1))
            else:
                L[i][j] = _name(b, value * inv_diag[j], f"L{i + 1}_{j + 1}", ("L", i + 1, j + 1))
    y = [_ZERO] * n
    for i in range(n):
        rhs = tau[i] - bias[i, 0] - sp.Add(*[L[i][k] * y[k] for k in range(i)])
        y[i] = _name(b, rhs * inv_diag[i], f"y{i + 1}", ("ychol", i + 1))
    x = [_ZERO] * n
    for i in reversed(range(n)):
        rhs = y[i] - sp.Add(*[L[k][i] * x[k] for k in range(i + 1, n)])
        x[i] = _name(b, rhs * inv_diag[i], f"qdd{i + 1}", ("qdd", i + 1))
    return ForwardDynamics(q, qd, tau, d.program([("qdd", sp.Matrix(x))]))


def build_forward_dynamics_aba(derivation, wanted) -> dict:
    """The builder of ``qdd_aba`` in :mod:`eomgen.outputs` (``forward_dynamics_aba(q, qd,
    tau)``): :func:`forward_dynamics_program` on the derivation's body tree, q̈ [rad/s² or m/s²]
    in ``JOINT_NAMES`` order."""
    return {"qdd_aba": forward_dynamics_program(derivation.tree, derivation.q, derivation.qd,
                                                derivation.tau, derivation.model.gravity,
                                                derivation.builder)}
