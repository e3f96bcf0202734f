"""Exact derivatives of the dynamics as straight-line programs (issue 25).

The derivatives are the dynamics' own programs differentiated once in forward mode
(:func:`forward_mode`): each assignment ``x = f(a, b, …)`` of the Newton–Euler (or ABA) program
that depends on a seeded input gets, per direction ``d``, the assignment
``dx_d = Σ ∂f/∂a · da_d`` over the arguments whose derivative along ``d`` is not a structural
zero. The partials ``∂f/∂a`` are named once and shared by every direction (a number times a
symbol too, such as ``2 ω_x`` of ``ω_x²``, when it multiplies several derivatives); every
derivative is defined in the derivation's builder, so it reuses the dynamics' intermediates
(sines, rotations, velocities) and identical terms are shared (hash-consing). A quantity that does not depend on a
direction has no derivative along it (nothing is computed), which is where the structure of the
tree shows: ∂/∂q_j of a body's velocity exists only below joint j.

Outputs (symbols of :mod:`eomgen.outputs`), n = NV joints, ``JOINT_NAMES`` order; derivatives
with respect to q are along the tangent, NV columns (:mod:`eomgen.symbolic.tangent`: for a
quaternion free flyer or ball joints, ``d/dε f(q ⊕ ε eᵢ)`` with v held fixed, as Pinocchio's;
each q entry's own direction otherwise):

* ``dtau_dq``, ``dtau_dqd`` (n × n): ∂τ/∂q and ∂τ/∂q̇ of τ(q, q̇, q̈) (Newton–Euler); ∂τ/∂q̈ = M.
* ``dg_dq`` (n × n): ∂g/∂q of g(q) = τ(q, 0, 0).
* ``Minv`` (n × n): M(q)⁻¹ = ∂q̈/∂τ from the straight-line factors M = Lᵀ D L of the mass
  matrix, the joints taken leaves first so that a branched tree's zeros stay zero
  (:func:`symmetric_inverse`); symmetric, the upper triangle is computed and mirrored. On the
  Panda this is 1,148 CasADi instructions against 1,607 for the ABA program differentiated
  along τ, and it gives the accelerations ``q̈ = M⁻¹ (τ − τ(q, q̇, 0))`` for 2 × 49
  multiply-adds more where the ABA costs 1,823.
* ``dqdd_dq``, ``dqdd_dqd`` (n × n): ∂q̈/∂q = −M⁻¹ ∂τ/∂q and ∂q̈/∂q̇ = −M⁻¹ ∂τ/∂q̇, the
  Newton–Euler derivatives taken at that q̈ held fixed (the implicit function theorem on
  τ(q, q̇, q̈(q, q̇, τ)) = τ; what Pinocchio's ``computeABADerivatives`` does).
* ``A_lin`` (2n × 2n) and ``B_lin`` (2n × n): ẋ = f(x, τ), x = (q, q̇), linearized:
  A = [[T, I], [∂q̈/∂q, ∂q̈/∂q̇]], B = [[0], [M⁻¹]], T = 0 but for quaternion joints
  (:func:`eomgen.symbolic.tangent.velocity_transport`).
* ``dtau_a_dqd`` (n × n): ∂τ_a/∂q̇ = ∂τ/∂q̇ + diag(d) of the drive torques
  τ_a = τ + a q̈ + d q̇ + f sign(q̇) (∂τ_a/∂q = ∂τ/∂q; the Coulomb sign's derivative is 0 for
  q̇_i ≠ 0).
* ``dqdd_a_dq``, ``dqdd_a_dqd``, ``Minv_a`` (n × n): the drives' forward dynamics
  q̈ = (M + diag(a))⁻¹ (τ − C q̇ − g − d q̇ − f tanh(q̇ / w)) differentiated
  (:func:`drive_forward_dynamics_jacobians`); with quaternion joints q̈ is v̇ and ∂/∂q is along
  the tangent, as for the plain derivatives (the drives sit on the one-DOF joints).
* ``dtau``, ``dqdd``, ``AB``, ``dtau_a``, ``dqdd_a``: the several-result functions, side by
  side.

With coupled joints (:mod:`eomgen.symbolic.couplings`: the whole tree at ``q = T q_r + c``,
``q̇ = T q̇_r``) every output is in the independent coordinates, n = NV_r: the efforts' rows
``Tᵀ τ`` are differentiated along the independent ``q_r`` (tangent) and ``q̇_r``, so
``∂τ_r/∂q_r = Tᵀ ∂τ/∂q T`` and ``∂g_r/∂q_r = Tᵀ ∂g/∂q T`` exactly; ``M_r⁻¹`` is the inverse
of ``M_r = Tᵀ M T`` (``+ Tᵀ diag(a) T`` with the drives) from the same straight-line factors,
``q̈_r = M_r⁻¹ (τ_r − Tᵀ h)`` (``h = τ(q, q̇, 0)``, plus the smoothed friction with the
drives), and ``∂q̈_r/∂x_r = −M_r⁻¹ Tᵀ ∂τ/∂x T`` at ``T q̈_r`` held fixed, as without
couplings; the drives' ``diag(d)`` and ``diag(τ_f′)`` enter as ``Tᵀ diag(·) T``. One path
serves both: without couplings T is the identity.
"""

from __future__ import annotations

import sympy as sp

from ..model import joint_actuators
from ..outputs import BY_SYMBOL
from .builders import builds
from .couplings import independent
from .drives import friction_torque_expr
from .newton_euler import inverse_dynamics_program
from .program import ProgramBuilder, name_expr
from .tangent import tangent_seeds, velocity_transport

#: the key of this module's work in ``Derivation.shared``
_SHARED = __name__


def _relevant(assignments, outputs, seeds, frozen) -> list:
    """The assignments that depend on a seed and that ``outputs`` need, in program order
    (dependencies through ``frozen`` symbols cut)."""
    active = set(seeds)
    depends = []
    for assignment in assignments:
        symbol, expr = assignment
        if symbol in frozen:
            continue
        free = getattr(assignment, "free", None) or expr.free_symbols
        if free & active:
            active.add(symbol)
            depends.append((symbol, expr, free))
    needed: set = set()
    for e in outputs:
        needed |= e.free_symbols
    kept = []
    for symbol, expr, free in reversed(depends):
        if symbol in needed:
            kept.append((symbol, expr, free))
            needed |= free
    return kept[::-1]


def differentiate(b: ProgramBuilder, expr, free, D, hint: str, name: bool, partials: dict):
    """``{direction: d expr}`` of ``expr`` given the derivatives ``D`` of its free symbols,
    zeros left out; each derivative named in ``b`` (with ``name``) with the hint
    ``<hint>_<direction>``."""
    args = [a for a in free if a in D]
    if not args:
        return {}
    terms: dict = {}
    for a in sorted(args, key=lambda s: s.name):
        p = sp.diff(expr, a)
        if p == 0:
            continue
        if not p.is_Number:
            if p in partials:
                p = partials[p]
            else:  # a number times a symbol too, when it multiplies several derivatives
                uses = sum(1 for da in D[a].values() if not da.is_Number)
                named = name_expr(b, p, f"p{hint}", scaled=uses > 1)
                if named is not p:
                    partials[p] = named
                p = named
        for direction, da in D[a].items():
            terms.setdefault(direction, []).append(p * da)
    out = {}
    for direction, parts in terms.items():
        total = sp.Add(*parts)
        if total == 0:
            continue
        out[direction] = name_expr(b, total, f"d{hint}_{direction[0]}{direction[1] + 1}") \
            if name else total
    return out


def forward_mode(b: ProgramBuilder, outputs, seeds: dict, frozen=frozenset()) -> list[dict]:
    """Forward-mode derivatives of the expressions ``outputs`` (in terms of ``b``'s
    intermediates) along the seeded inputs, defined in ``b``.

    Parameters
    ----------
    b:
        The builder the outputs' intermediates were defined in.
    outputs:
        Expressions to differentiate.
    seeds:
        ``{input symbol: direction}``: the input is the direction's variable (derivative 1);
        or ``{input symbol: {direction: derivative}}``: the input's derivative along each
        direction (an expression; a tangent direction of a quaternion, :func:`tangent_seeds`).
    frozen:
        Intermediates held constant (their derivative is zero, their definition not followed).

    Returns
    -------
    list of dict
        Per output, ``{direction: derivative}`` with the structural zeros left out.

    Examples
    --------
    >>> x, y = sp.symbols("x y", real=True)
    >>> b = ProgramBuilder({"x", "y"})
    >>> s = b.define(sp.sin(x) * y, "s")
    >>> forward_mode(b, [s * s], {x: ("x", 0), y: ("y", 0)})
    [{('x', 0): d_x1, ('y', 0): d_y1}]
    >>> b.assignments[1:]
    [(ps, y*cos(x)), (ps_, sin(x)), (p, 2*s), (d_x1, p*ps), (d_y1, p*ps_)]
    """
    return forward_mode_map(b, outputs, seeds, frozen)[0]


def forward_mode_map(b: ProgramBuilder, outputs, seeds: dict, frozen=frozenset()) \
        -> tuple[list[dict], dict]:
    """:func:`forward_mode`'s result and the map ``{symbol: {direction: derivative}}`` of every
    intermediate it differentiated (the seeds included), which a second pass
    (:mod:`eomgen.symbolic.second_derivatives`) reuses."""
    D: dict = {s: dict(d) if isinstance(d, dict) else {d: sp.Integer(1)}
               for s, d in seeds.items()}
    outputs = [sp.sympify(e) for e in outputs]
    partials: dict = {}
    for symbol, expr, free in _relevant(list(b.assignments), outputs, seeds, frozen):
        derivative = differentiate(b, expr, free, D, symbol.name, True, partials)
        if derivative:
            D[symbol] = derivative
    return [differentiate(b, e, e.free_symbols, D, "", True, partials) for e in outputs], D


def _jacobian(rows: list[dict], prefix: str, n: int) -> sp.Matrix:
    return sp.Matrix(len(rows), n, lambda i, j: rows[i].get((prefix, j), sp.Integer(0)))


def _seeds(symbols, prefix: str) -> dict:
    return {s: (prefix, k) for k, s in enumerate(symbols)}


def _product(b: ProgramBuilder, A: sp.Matrix, B: sp.Matrix, hint: str) -> sp.Matrix:
    """−A B, each nonzero entry named ``<hint><i><j>``."""
    rows, inner, cols = A.rows, A.cols, B.cols
    out = sp.zeros(rows, cols)
    for i in range(rows):
        for j in range(cols):
            total = sp.Add(*[A[i, k] * B[k, j] for k in range(inner)
                             if A[i, k] != 0 and B[k, j] != 0])
            if total != 0:
                out[i, j] = name_expr(b, -total, f"{hint}{i + 1}_{j + 1}")
    return out


def _work(derivation) -> dict:
    return derivation.shared.setdefault(_SHARED, {})


def _nv(derivation) -> int:
    """The number of derivative columns: the model's NV (the independent ones with couplings)."""
    return len(derivation.inputs["qd"])


def _efforts(derivation, tau) -> list:
    """The derivation's joint efforts ``tau`` in the model's coordinates: ``Tᵀ τ`` with coupled
    joints (virtual work), ``τ`` itself otherwise."""
    T = derivation.coupling
    return list(tau) if T is None else list(T.T * sp.Matrix(tau))


def _tangent_seeds(derivation) -> dict:
    """The q seeds of :func:`forward_mode`: along the tangent of the model's own ``q`` (the
    independent one with couplings) and the velocity seeds along ``q̇``."""
    return {**tangent_seeds(independent(derivation)), **_seeds(derivation.inputs["qd"], "qd")}


def symmetric_inverse(b: ProgramBuilder, M: sp.Matrix, hint: str) -> sp.Matrix:
    """The inverse of the symmetric positive definite ``M`` (n × n) as a straight-line program
    in ``b``, factored from its last row and column up: ``M = Lᵀ D L`` (L unit lower
    triangular, no square roots), ``Z = L⁻¹``, then ``M⁻¹ = Z D⁻¹ Zᵀ``, upper triangle computed
    and mirrored; structural zeros skipped, each nonzero named ``<hint>…`` (indices of M).
    Exact (rational operations only), O(n³) at most.

    With the joints of a tree in the model's order (parents before children), eliminating the
    leaves first creates no fill-in: ``L[i, j]`` is nonzero only when joint j is an ancestor of
    joint i, as in Featherstone's factorization of a tree's mass matrix (*Rigid Body Dynamics
    Algorithms*, §6.5), so a branched tree keeps its zeros."""
    n = M.rows
    last = list(reversed(range(n)))  # work on the reversed matrix, leaves first
    R = M.extract(last, last)

    def label(i: int, j: int) -> str:  # the indices of M, 1-based
        return f"{n - i}_{n - j}"

    L, W, inv_D = sp.eye(n), sp.zeros(n, n), [sp.Integer(0)] * n
    for j in range(n):
        D = R[j, j] - sp.Add(*[L[j, k] * W[j, k] for k in range(j)])
        inv_D[j] = name_expr(b, 1 / name_expr(b, D, f"{hint}_D{n - j}"), f"{hint}_iD{n - j}")
        for i in range(j + 1, n):
            total = R[i, j] - sp.Add(*[L[i, k] * W[j, k] for k in range(j)])
            if total != 0:
                W[i, j] = name_expr(b, total, f"{hint}_W{label(i, j)}")   # L[i, j] D_j
                L[i, j] = name_expr(b, W[i, j] * inv_D[j], f"{hint}_L{label(i, j)}")
    Z = sp.eye(n)
    for j in range(n):
        for i in range(j + 1, n):
            total = -sp.Add(*[L[i, k] * Z[k, j] for k in range(j, i)
                              if L[i, k] != 0 and Z[k, j] != 0])
            if total != 0:
                Z[i, j] = name_expr(b, total, f"{hint}_Z{label(i, j)}")
    out = sp.zeros(n, n)
    for i in range(n):
        for j in range(i, n):
            total = sp.Add(*[Z[k, i] * Z[k, j] * inv_D[k] for k in range(j, n)
                             if Z[k, i] != 0 and Z[k, j] != 0])
            if total != 0:
                out[i, j] = out[j, i] = name_expr(b, total, f"{hint}{label(j, i)}")
    return out.extract(last, last)


def _solved_dynamics(derivation, armature=None, friction=None, hint: str = "s", efforts=None):
    """``(M⁻¹, q̈)`` of the model in its own coordinates: ``M_r = Tᵀ (M + diag(armature)) T``
    (``M + diag(armature)`` without couplings) inverted by :func:`symmetric_inverse` (leaves
    first: no fill-in on a branched tree), and
    ``q̈ = M_r⁻¹ (τ_r − Tᵀ (τ(q, q̇, 0) + friction))``, each acceleration named; ``τ_r`` the
    input τ, or ``efforts`` (expressions, in the model's own coordinates) when given."""
    b, T, n = derivation.builder, derivation.coupling, _nv(derivation)
    M = derivation.output("M")
    if armature is not None:
        M = M + sp.diag(*armature)
    if T is not None:
        M = T.T * M * T
    Minv = symmetric_inverse(b, M, f"Minv_{hint}")
    zero = (sp.Integer(0),) * n
    bias = inverse_dynamics_program(derivation.tree, derivation.q, derivation.qd,
                                    derivation.accelerations(zero),
                                    derivation.model.gravity, b, hint=f"h_{hint}")
    if friction is not None:
        bias = bias + friction
    tau = derivation.tau if efforts is None else efforts
    rhs = [t - e for t, e in zip(tau, _efforts(derivation, bias))]
    qdd = [b.define(sp.Add(*[Minv[i, k] * rhs[k] for k in range(n)]), f"qdd_{hint}{i + 1}")
           for i in range(n)]
    return Minv, sp.Matrix(qdd)


def inverse_dynamics_jacobians(derivation) -> tuple[sp.Matrix, sp.Matrix]:
    """(∂τ/∂q, ∂τ/∂q̇) of the derivation's τ output (both n × n)."""
    work = _work(derivation)
    if "dtau" not in work:
        tau = _efforts(derivation, derivation.output("tau"))
        n = _nv(derivation)
        rows = forward_mode(derivation.builder, tau, _tangent_seeds(derivation))
        work["dtau"] = (_jacobian(rows, "q", n), _jacobian(rows, "qd", n))
    return work["dtau"]


def gravity_jacobian(derivation) -> sp.Matrix:
    """∂g/∂q of g(q) = τ(q, 0, 0) (Newton–Euler), n × n."""
    zero = (sp.Integer(0),) * len(derivation.q)
    g = inverse_dynamics_program(derivation.tree, derivation.q, zero, zero,
                                 derivation.model.gravity, derivation.builder, hint="g")
    rows = forward_mode(derivation.builder, _efforts(derivation, g),
                        tangent_seeds(independent(derivation)))
    return _jacobian(rows, "q", _nv(derivation))


def inverse_mass_matrix(derivation) -> sp.Matrix:
    """M(q)⁻¹ (n × n; ``(Tᵀ M T)⁻¹`` with coupled joints) from the straight-line LDLᵀ factors
    of M (:func:`_solved_dynamics`)."""
    return _dynamics(derivation)[0]


def _dynamics(derivation) -> tuple[sp.Matrix, sp.Matrix]:
    """``(M⁻¹, q̈)`` of :func:`_solved_dynamics`, built once per derivation."""
    work = _work(derivation)
    if "dynamics" not in work:
        work["dynamics"] = _solved_dynamics(derivation)
    return work["dynamics"]


def _efforts_at(derivation, qdd, hint: str) -> tuple[sp.Matrix, sp.Matrix]:
    """(∂τ/∂q, ∂τ/∂q̇) of the Newton–Euler τ(q, q̇, q̈) at the named accelerations ``qdd``
    held fixed (the implicit function theorem's half of ∂q̈; ∂/∂q in tangent coordinates)."""
    b, n = derivation.builder, _nv(derivation)
    inputs = set(derivation.inputs["q"]) | set(derivation.inputs["qd"])
    frozen = set()
    for e in qdd:  # a named intermediate (±), or free of q and q̇ (e.g. τ_1 / m of a lone body)
        named = e.is_Symbol or (e.is_Mul and e.args[0] == -1 and e.args[1].is_Symbol)
        if not named and e.free_symbols & inputs:
            raise ValueError(f"forward-dynamics acceleration {e} is not a named intermediate")
        frozen |= e.free_symbols - inputs
    tau = inverse_dynamics_program(derivation.tree, derivation.q, derivation.qd,
                                   derivation.accelerations(tuple(qdd)),
                                   derivation.model.gravity, b, hint=hint)
    rows = forward_mode(b, _efforts(derivation, tau), _tangent_seeds(derivation),
                        frozenset(frozen))
    return _jacobian(rows, "q", n), _jacobian(rows, "qd", n)


def forward_dynamics_jacobians(derivation) -> tuple[sp.Matrix, sp.Matrix, sp.Matrix]:
    """(∂q̈/∂q, ∂q̈/∂q̇, M⁻¹) at q̈ = ABA(q, q̇, τ), each n × n."""
    work = _work(derivation)
    if "dqdd" not in work:
        b = derivation.builder
        Minv, qdd = _dynamics(derivation)
        dq, dqd = _efforts_at(derivation, qdd, "tau_a")
        work["dqdd"] = (_product(b, Minv, dq, "dqdd_dq"), _product(b, Minv, dqd, "dqdd_dqd"),
                        Minv)
    return work["dqdd"]


def drive_inverse_dynamics_jacobians(derivation) -> tuple[sp.Matrix, sp.Matrix]:
    """(∂τ_a/∂q, ∂τ_a/∂q̇) of the drive torques τ_a = τ + a q̈ + d q̇ + f sign(q̇): ∂τ/∂q, and
    ∂τ/∂q̇ + diag(d) (the exact Coulomb sign has derivative 0 wherever q̇_i ≠ 0)."""
    dq, dqd = inverse_dynamics_jacobians(derivation)
    damping = sp.diag(*[a.damping for a in joint_actuators(derivation.model)])
    T = derivation.coupling
    return dq, dqd + (damping if T is None else T.T * damping * T)


def drive_forward_dynamics_jacobians(derivation) -> tuple[sp.Matrix, sp.Matrix, sp.Matrix]:
    """(∂q̈/∂q, ∂q̈/∂q̇, M_a⁻¹) of the drives' forward dynamics
    q̈ = M_a⁻¹ (τ − C q̇ − g − τ_f(q̇)), M_a = M + diag(a), τ_f = d q̇ + f tanh(q̇ / w) (the
    smoothed Coulomb friction of simulation), each n × n:

    * M_a⁻¹ = ∂q̈/∂τ from the straight-line factors of M + diag(a) (:func:`_solved_dynamics`);
    * ∂q̈/∂q = −M_a⁻¹ ∂τ/∂q and ∂q̈/∂q̇ = −M_a⁻¹ (∂τ/∂q̇ + diag(τ_f′(q̇))), with the rigid
      bodies' ∂τ taken at that q̈ held fixed (implicit function theorem on
      τ(q, q̇, q̈) + a q̈ + τ_f(q̇) = τ).
    """
    work = _work(derivation)
    if "dqdd_a" not in work:
        b, T, qd = derivation.builder, derivation.coupling, derivation.qd
        actuators = joint_actuators(derivation.model)
        friction = friction_torque_expr(actuators, qd, smooth=True)
        Minv, qdd = _solved_dynamics(derivation, [a.armature for a in actuators], friction,
                                     "d")
        dq, dqd = _efforts_at(derivation, qdd, "tau_d")
        x = [sp.Dummy(f"x{k}") for k in range(len(qd))]  # the law's slope at each joint's q̇
        law = friction_torque_expr(actuators, x, smooth=True)
        slope = [sp.diff(law[k, 0], x[k]).subs(x[k], v) for k, v in enumerate(qd)]
        slope = sp.diag(*[name_expr(b, s, f"dtau_f{k + 1}") for k, s in enumerate(slope)])
        dqd = dqd + (slope if T is None else T.T * slope * T)
        work["dqdd_a"] = (_product(b, Minv, dq, "dqdd_a_dq"),
                          _product(b, Minv, dqd, "dqdd_a_dqd"), Minv)
    return work["dqdd_a"]


def applied_forward_dynamics(derivation, forces, armature, hint: str):
    """``(M_a⁻¹, q̈)`` of the forward dynamics under the joint forces ``forces`` (expressions
    f(q, q̇, …), NV entries in the derivation's joints) with the drives' ``armature``:
    ``q̈ = M_a⁻¹ Tᵀ (f − τ(q, q̇, 0))``, ``M_a = Tᵀ (M + diag(armature)) T``, from the
    straight-line LDLᵀ factors (:func:`_solved_dynamics`), in the model's own coordinates (the
    independent ones with couplings; T the identity without). Built once per ``hint`` (one
    hint names one set of forces), the intermediates' names starting with it."""
    work = _work(derivation).setdefault("applied", {})
    if hint not in work:
        work[hint] = _solved_dynamics(derivation, armature, None, hint,
                                      efforts=_efforts(derivation, forces))
    return work[hint]


def input_jacobians(derivation, exprs, inputs=()) -> tuple[sp.Matrix, ...]:
    """The Jacobians of the expressions ``exprs`` (of the builder's intermediates) by
    :func:`forward_mode`: ∂/∂q along the tangent (the independent q with couplings), ∂/∂q̇,
    then ∂/∂ each input named in ``inputs`` (e.g. ``"ctrl"``, ``"act"``), one matrix each
    (``len(exprs)`` rows)."""
    seeds = _tangent_seeds(derivation)
    for name in inputs:
        seeds.update(_seeds(derivation.inputs[name], name))
    rows = forward_mode(derivation.builder, exprs, seeds)
    sizes = [("q", _nv(derivation)), ("qd", _nv(derivation))]
    sizes += [(name, len(derivation.inputs[name])) for name in inputs]
    return tuple(_jacobian(rows, prefix, n) for prefix, n in sizes)


def applied_forward_dynamics_jacobians(derivation, forces, armature, hint: str, inputs=()):
    """``(M_a⁻¹, q̈, ∂q̈/∂q, ∂q̈/∂q̇, *∂q̈/∂inputs)`` of the forward dynamics under joint forces
    given as expressions ``forces`` = f(q, q̇, u) (NV entries in the derivation's joints, e.g.
    the actuators' and the springs' of :mod:`eomgen.symbolic.controls`) instead of the input
    τ, ``u`` the further inputs named in ``inputs`` (``"ctrl"``, ``"act"``: one more Jacobian
    each, in that order)::

        q̈ = M_a⁻¹ Tᵀ (f(q, q̇, u) − τ(q, q̇, 0)),     M_a = Tᵀ (M + diag(armature)) T
        ∂q̈/∂x = −M_a⁻¹ Tᵀ (∂τ/∂x − ∂f/∂x)          (x = q along the tangent, or q̇)
        ∂q̈/∂u = M_a⁻¹ Tᵀ ∂f/∂u

    with the Newton–Euler ∂τ taken at that q̈ held fixed (the implicit function theorem on
    τ(q, q̇, q̈) + a q̈ = f(q, q̇, u), as :func:`drive_forward_dynamics_jacobians`) and ∂f by
    :func:`forward_mode` through the builder's intermediates (:func:`input_jacobians`). The
    state Jacobians n × n (n = NV, the independent NV with couplings; T the identity
    without), ∂q̈/∂u n × len(u), the intermediates' names starting with ``hint``."""
    b = derivation.builder
    f = _efforts(derivation, forces)
    Minv, qdd = applied_forward_dynamics(derivation, forces, armature, hint)
    dq, dqd = _efforts_at(derivation, qdd, f"tau_{hint}")
    df = input_jacobians(derivation, f, inputs)
    dq, dqd = dq - df[0], dqd - df[1]
    return (Minv, qdd, _product(b, Minv, dq, f"dqdd_{hint}_dq"),
            _product(b, Minv, dqd, f"dqdd_{hint}_dqd"),
            *(_product(b, Minv, -du, f"dqdd_{hint}_d{name}")
              for name, du in zip(inputs, df[2:])))


def linearization(derivation) -> tuple[sp.Matrix, sp.Matrix]:
    """A (2n × 2n) and B (2n × n) of ẋ = f(x, τ), x = (q, q̇), n = NV: with quaternion
    joints x = (δ, v) in the chart δ ↦ q ⊕ δ at δ = 0, whose position rows are
    δ̇ = J_r(δ)⁻¹ v (:func:`eomgen.symbolic.tangent.velocity_transport`)."""
    n = _nv(derivation)
    dq, dqd, Minv = forward_dynamics_jacobians(derivation)
    transport = velocity_transport(independent(derivation))
    A = sp.Matrix.vstack(sp.Matrix.hstack(transport, sp.eye(n)), sp.Matrix.hstack(dq, dqd))
    B = sp.Matrix.vstack(sp.zeros(n, n), Minv)
    return A, B


@builds("dtau_dq", "dtau_dqd", "dtau", "dg_dq", "dqdd_dq", "dqdd_dqd", "Minv", "dqdd", "A_lin",
        "B_lin", "AB", "dtau_a_dqd", "dtau_a", "dqdd_a_dq", "dqdd_a_dqd", "Minv_a", "dqdd_a")
def build_derivatives(derivation, wanted) -> dict:
    """The builder of the derivative outputs of :mod:`eomgen.outputs` (see the module's
    docstring for each symbol)."""
    result = {}
    for symbol in sorted(wanted):
        if symbol in ("dtau_dq", "dtau_dqd"):
            value = inverse_dynamics_jacobians(derivation)[symbol == "dtau_dqd"]
        elif symbol == "dg_dq":
            value = gravity_jacobian(derivation)
        elif symbol in ("dqdd_dq", "dqdd_dqd", "Minv"):
            value = forward_dynamics_jacobians(derivation)[
                ("dqdd_dq", "dqdd_dqd", "Minv").index(symbol)]
        elif symbol == "dtau_a_dqd":
            value = drive_inverse_dynamics_jacobians(derivation)[1]
        elif symbol in ("dqdd_a_dq", "dqdd_a_dqd", "Minv_a"):
            value = drive_forward_dynamics_jacobians(derivation)[
                ("dqdd_a_dq", "dqdd_a_dqd", "Minv_a").index(symbol)]
        elif symbol in ("A_lin", "B_lin"):
            value = linearization(derivation)[symbol == "B_lin"]
        else:  # a several-result function: its results side by side
            value = sp.Matrix.hstack(*(derivation.output(p) for p in BY_SYMBOL[symbol].returns))
        result[symbol] = value
    return result


__all__ = ["applied_forward_dynamics", "applied_forward_dynamics_jacobians", "build_derivatives",
           "drive_forward_dynamics_jacobians", "drive_inverse_dynamics_jacobians",
           "forward_dynamics_jacobians", "forward_mode", "forward_mode_map", "gravity_jacobian",
           "input_jacobians", "inverse_dynamics_jacobians", "inverse_mass_matrix",
           "linearization", "symmetric_inverse"]
